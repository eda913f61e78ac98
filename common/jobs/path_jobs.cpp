// Path planning and Voronoi regions as jobs (apps/path_planning, apps/voronoi), on a dense
// grid; obstacles are the input level set (inside = blocked), when the job has an input set.
//   path    { from = (x, y, z)  to = (x, y, z)  cost = FORMULA over x y z h (default 1)
//             clearance = 0  order = 2  seed_radius = 2  resolution = 128 | voxel_size = H
//             bounds_min = (...)  bounds_max = (...)  padding = 0.1 }
//   voronoi { seeds = (x1, y1, z1, x2, y2, z2, ...)  (labels 0, 1, ...)  and the grid,
//             cost and obstacle keys above }
// Outputs: path: STEM.path.txt (# header lines, then "x y z" from start to goal);
// voronoi: STEM.labels.nrrd (int32, -1 = blocked or unreached), STEM.time.nrrd (float32).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>

#include "apps/path_planning.hpp"
#include "apps/voronoi.hpp"
#include "core/error.hpp"
#include "io/nrrd_file.hpp"
#include "jobs/applications.hpp"

namespace levelset::jobs {

namespace {

const std::vector<std::string> kMediumKeys = {"cost",       "clearance",  "order",      "seed_radius", "resolution",
                                              "voxel_size", "bounds_min", "bounds_max", "padding"};

std::vector<std::string> with_medium(std::vector<std::string> keys) {
  keys.insert(keys.end(), kMediumKeys.begin(), kMediumKeys.end());
  return keys;
}

// The obstacles (the input level set, when there is an input set), the grid and the cost.
struct Medium {
  std::unique_ptr<NarrowBand> band;
  apps::DenseGrid grid;
  apps::CostField cost;
  apps::Obstacles obstacles;
  int order = 2;
  double seed_radius = 2;
};

Medium medium_of(JobContext& ctx, const config::Set& s, const std::vector<Vec3d>& points) {
  Medium m;
  if (ctx.root().find("input") != nullptr) {
    m.band = std::make_unique<NarrowBand>(ctx.input_band(ctx.section("input", JobContext::input_keys())));
    m.obstacles.band = m.band.get();
    m.obstacles.clearance = ctx.number(s, "clearance", 0.0, 0.0, 1e30);
  }
  BBox box;
  if (ctx.has(s, "bounds_min") || ctx.has(s, "bounds_max")) {
    box.extend(ctx.vec3(s, "bounds_min", {0, 0, 0}));
    box.extend(ctx.vec3(s, "bounds_max", {0, 0, 0}));
    const Vec3d lo = ctx.vec3(s, "bounds_min", {0, 0, 0}), hi = ctx.vec3(s, "bounds_max", {0, 0, 0});
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z))
      throw Error(ErrorCode::InvalidArgument, ctx.place(s, "bounds_min"), "need bounds_min < bounds_max on every axis");
  } else {
    box = apps::padded_problem_bounds(points, m.band.get(), ctx.number(s, "padding", 0.1, 0.0, 10.0));
  }
  const double h = ctx.number(s, "voxel_size", 0.0, 0.0, 1e30);
  m.grid = h > 0 ? apps::dense_grid_for_voxel_size(box, h)
                 : apps::dense_grid_for_resolution(box, ctx.integer(s, "resolution", 128, 4, 4096));
  m.cost.formula = ctx.text(s, "cost", "");
  m.order = ctx.integer(s, "order", 2, 1, 2);
  m.seed_radius = ctx.number(s, "seed_radius", 2.0, 0.0, 16.0);
  return m;
}

NrrdFrame frame_of(const apps::DenseGrid& g) {
  NrrdFrame f;
  f.sizes[0] = g.nx;
  f.sizes[1] = g.ny;
  f.sizes[2] = g.nz;
  f.spacing = g.voxel_size;
  f.origin = g.origin;
  return f;
}

}  // namespace

void run_path_job(JobContext& ctx) {
  const config::Set& s = ctx.section("path", with_medium({"from", "to"}));
  if (!ctx.has(s, "from") || !ctx.has(s, "to"))
    throw Error(ErrorCode::InvalidArgument, ctx.options().name, "the path set needs 'from = (x, y, z)' and 'to = (x, y, z)'");
  const Vec3d from = ctx.vec3(s, "from", {}), to = ctx.vec3(s, "to", {});
  Medium m = medium_of(ctx, s, {from, to});
  apps::PathOptions o;
  o.grid = m.grid;
  o.start = from;
  o.goal = to;
  o.cost = m.cost;
  o.obstacles = m.obstacles;
  o.order = m.order;
  o.seed_radius = m.seed_radius;
  o.progress = ctx.options().progress;
  const apps::PathResult r = apps::plan_path(o);
  char line[256];
  std::snprintf(line, sizeof line, "path: length %.6g, travel time %.6g, %zu points on a %dx%dx%d grid", r.length,
                r.arrival_time, r.points.size(), m.grid.nx, m.grid.ny, m.grid.nz);
  ctx.log(line);
  ctx.stats()["path"] = {{"length", r.length},
                         {"arrival_time", r.arrival_time},
                         {"points", r.points.size()},
                         {"grid", {m.grid.nx, m.grid.ny, m.grid.nz}},
                         {"voxel_size", m.grid.voxel_size},
                         {"first_order_fallbacks", r.first_order_fallbacks},
                         {"seconds", {{"cost", r.seconds_cost}, {"march", r.seconds_march}, {"trace", r.seconds_trace}}}};
  const std::string path = ctx.output_path(stem(ctx.options().name) + ".path.txt");
  std::ofstream out(path, std::ios::trunc);
  out.precision(17);
  out << "# levelset path: length " << r.length << " travel_time " << r.arrival_time << " points " << r.points.size()
      << "\n# grid " << m.grid.nx << " " << m.grid.ny << " " << m.grid.nz << " voxel_size " << m.grid.voxel_size << "\n";
  for (const Vec3d& p : r.points) out << p.x << " " << p.y << " " << p.z << "\n";
  if (!out) throw Error(ErrorCode::IoError, path, "cannot write the path");
  ctx.add_output(path);
}

void run_voronoi_job(JobContext& ctx) {
  const config::Set& s = ctx.section("voronoi", with_medium({"seeds"}));
  const std::vector<Vec3d> seeds = ctx.points(s, "seeds");
  Medium m = medium_of(ctx, s, seeds);
  apps::VoronoiOptions o;
  o.grid = m.grid;
  for (std::size_t i = 0; i < seeds.size(); ++i) o.seeds.push_back({seeds[i], static_cast<std::int32_t>(i)});
  o.cost = m.cost;
  o.obstacles = m.obstacles;
  o.order = m.order;
  o.seed_radius = m.seed_radius;
  o.progress = ctx.options().progress;
  const apps::VoronoiResult r = apps::voronoi_regions(o);
  nlohmann::json regions = nlohmann::json::object();
  for (const auto& [label, count] : r.region_voxels) regions[std::to_string(label)] = count;
  ctx.stats()["voronoi"] = {{"regions", regions},
                            {"unreached", r.unreached},
                            {"boundary_voxels", r.boundary_voxels},
                            {"grid", {m.grid.nx, m.grid.ny, m.grid.nz}},
                            {"voxel_size", m.grid.voxel_size},
                            {"origin", {m.grid.origin.x, m.grid.origin.y, m.grid.origin.z}}};
  ctx.log("voronoi: " + std::to_string(r.region_voxels.size()) + " regions, " + std::to_string(r.boundary_voxels) +
          " boundary nodes");
  const std::string labels = ctx.output_path(stem(ctx.options().name) + ".labels.nrrd");
  save_nrrd(labels, frame_of(m.grid), std::span<const std::int32_t>(r.field.label));
  ctx.add_output(labels);
  std::vector<float> time(r.field.time.size());
  for (std::size_t i = 0; i < time.size(); ++i)
    time[i] = std::isfinite(r.field.time[i]) ? static_cast<float>(r.field.time[i]) : std::numeric_limits<float>::infinity();
  const std::string times = ctx.output_path(stem(ctx.options().name) + ".time.nrrd");
  save_nrrd(times, frame_of(m.grid), std::span<const float>(time));
  ctx.add_output(times);
}

}  // namespace levelset::jobs
