// job = reconstruct: a watertight surface through unorganised points (apps/reconstruction,
// thesis 5.1.3). The points come from a file, or are sampled (by area, seeded, optionally
// with Gaussian noise) on a built-in shape or a mesh; then the true surface is known and
// the stats hold the accuracy: symmetric mean (Chamfer) and Hausdorff distances between the
// result and the truth, in world units, voxels and bounding-box diagonals.
// Every run also reports the fit: the distances from the input points to the result.
//   input { points = FILE (.xyz .xyzn .pwn .ply)  |  sample = knot  |  sample_mesh = FILE
//           count = 20000  noise = 0 (x the bbox diagonal)  seed = 1 }
//   reconstruct { levels = 0 (from the data)  neighbors = 8  curvature_weight = 0.3  max_steps =
//   120
//                 snap_passes = 1  clean_final_passes = 2  tolerance = 0.01  shell_offset = 1
//                 guard_flow = yes  guard_snaps = yes  free_distance = 1  carve_gaps = yes
//                 pierce_tunnels = yes  narrow_gaps = yes cut_webs = yes  cut_sheets = yes
//                 web_tunnels = yes  denoised_clearance = yes  refit_moved = yes  widen_smooth =
//                 yes facing_points = yes accuracy_samples = 100000 }
//   (guard_*: keep the start shell's topology in the coarse flow / the snaps; free_distance:
//   coarse voxels from the nearest sample beyond which the flow may change it; carve_gaps,
//   pierce_tunnels, narrow_gaps, cut_webs, cut_sheets, web_tunnels, denoised_clearance,
//   refit_moved, widen_smooth, facing_points: apps/reconstruction.hpp's options)
// The raster's resolution / voxel_size / band are the final level's; with neither resolution
// nor voxel_size the resolution follows from the points (stats: reconstruct.resolution,
// resolution_from_data, sampling).
#include <functional>
#include <memory>

#include "apps/mesh_distance.hpp"
#include "apps/reconstruction.hpp"
#include "apps/sample_points.hpp"
#include "core/error.hpp"
#include "geometry/analytic_shapes.hpp"
#include "io/mesh_reader.hpp"
#include "io/point_cloud_reader.hpp"
#include "jobs/applications.hpp"

namespace levelset::jobs {

void run_reconstruct_job(JobContext& ctx) {
  const config::Set& in = ctx.section("input", {"points", "sample", "sample_mesh", "count", "noise", "seed"});
  const config::Set& s =
      ctx.section("reconstruct",
                  {"levels",        "neighbors",          "curvature_weight", "max_steps",
                   "snap_passes",   "clean_final_passes", "guard_flow",       "guard_snaps",
                   "free_distance", "carve_gaps",         "pierce_tunnels",   "narrow_gaps",
                   "cut_webs",      "cut_sheets",         "web_tunnels",      "denoised_clearance",
                   "refit_moved",   "widen_smooth",       "facing_points",    "tolerance",
                   "shell_offset",  "accuracy_samples"});
  const int given = (ctx.has(in, "points") ? 1 : 0) + (ctx.has(in, "sample") ? 1 : 0) + (ctx.has(in, "sample_mesh") ? 1 : 0);
  if (given != 1)
    throw Error(ErrorCode::InvalidArgument, ctx.options().name,
                "the input set needs exactly one of points = FILE, sample = SHAPE, sample_mesh = FILE");

  // Every option is read (and checked) before the points are read or sampled and the work
  // starts, so a bad value fails at once.
  apps::ReconstructionOptions o;
  const JobContext::Raster r = ctx.raster(0, 3);  // no resolution: chosen from the points
  o.resolution = r.voxel_size > 0 ? 0 : r.resolution;
  o.voxel_size = r.voxel_size;
  o.half_width = r.band;
  o.levels = ctx.integer(s, "levels", o.levels, 0, 6);  // 0: from the data
  o.neighbors = ctx.integer(s, "neighbors", o.neighbors, 1, 256);
  o.curvature_weight = ctx.number(s, "curvature_weight", o.curvature_weight, 0.0, 100.0);
  o.max_steps = ctx.integer(s, "max_steps", o.max_steps, 1, 100000);
  o.snap_passes = ctx.integer(s, "snap_passes", o.snap_passes, 0, 16);
  o.clean_final_passes = ctx.integer(s, "clean_final_passes", o.clean_final_passes, 0, 16);
  o.guard_flow = ctx.flag(s, "guard_flow", o.guard_flow);
  o.guard_snaps = ctx.flag(s, "guard_snaps", o.guard_snaps);
  o.free_distance = ctx.number(s, "free_distance", o.free_distance, 0.0, 100.0);
  o.carve_gaps = ctx.flag(s, "carve_gaps", o.carve_gaps);
  o.pierce_tunnels = ctx.flag(s, "pierce_tunnels", o.pierce_tunnels);
  o.narrow_gaps = ctx.flag(s, "narrow_gaps", o.narrow_gaps);
  o.cut_webs = ctx.flag(s, "cut_webs", o.cut_webs);
  o.web_tunnels = ctx.flag(s, "web_tunnels", o.web_tunnels);
  o.cut_sheets = ctx.flag(s, "cut_sheets", o.cut_sheets);
  o.denoised_clearance = ctx.flag(s, "denoised_clearance", o.denoised_clearance);
  o.refit_moved = ctx.flag(s, "refit_moved", o.refit_moved);
  o.widen_smooth = ctx.flag(s, "widen_smooth", o.widen_smooth);
  o.facing_points = ctx.flag(s, "facing_points", o.facing_points);
  o.tolerance = ctx.number(s, "tolerance", o.tolerance, 1e-9, 10.0);
  o.shell_offset = ctx.number(s, "shell_offset", o.shell_offset, 1.0, 16.0);
  o.progress = ctx.options().progress;
  o.log = [&ctx](const std::string& line) { ctx.log(line); };
  const std::size_t accuracy_samples = static_cast<std::size_t>(ctx.integer(s, "accuracy_samples", 100000, 1000, 1 << 24));

  // The points, and the true surface when they were sampled from one.
  std::vector<Vec3d> points;
  std::unique_ptr<AnalyticShape> shape;
  TriangleMesh truth_mesh;
  std::function<double(const Vec3d&)> truth_distance;
  std::unique_ptr<apps::MeshDistance> truth_mesh_distance;
  apps::SurfaceSampleOptions sampling;
  sampling.count = static_cast<std::size_t>(ctx.integer(in, "count", 20000, 4, 1 << 24));
  sampling.progress = ctx.options().progress;
  sampling.seed = static_cast<std::uint64_t>(ctx.integer(in, "seed", 1, 0, 1 << 30));
  const double noise = ctx.number(in, "noise", 0.0, 0.0, 0.1);
  if (ctx.has(in, "points")) {
    const std::string path = ctx.input_path(in, "points");
    points = read_point_cloud(path).cloud.points;
    ctx.log("input: " + std::to_string(points.size()) + " points from " + path);
  } else if (ctx.has(in, "sample")) {
    shape = make_builtin_shape(ctx.word(in, "sample", "", builtin_shape_names()));
    sampling.noise = noise * length(shape->bounds().extent());
    points = apps::sample_shape_surface(*shape, sampling);
    truth_distance = [&](const Vec3d& p) { return std::abs(shape->distance(p)); };
    ctx.log("input: " + std::to_string(points.size()) + " points sampled on the built-in " + shape->name());
  } else {
    const std::string path = ctx.input_path(in, "sample_mesh");
    truth_mesh = read_mesh(path).mesh;
    sampling.noise = noise * length(truth_mesh.bounds().extent());
    points = apps::sample_mesh_surface(truth_mesh, sampling);
    truth_mesh_distance = std::make_unique<apps::MeshDistance>(truth_mesh);
    truth_distance = [&](const Vec3d& p) { return truth_mesh_distance->distance(p); };
    ctx.log("input: " + std::to_string(points.size()) + " points sampled on " + path);
  }

  const apps::ReconstructionResult result = apps::reconstruct_surface(points, o);
  ctx.stats()["reconstruct"] = {{"points", points.size()},     {"voxel_size", result.voxel_size},
                                {"steps", result.steps},       {"seconds", result.seconds},
                                {"resolution", result.resolution},
                                {"resolution_from_data", o.resolution == 0 && o.voxel_size <= 0.0},
                                {"sampling", {{"spacing", result.sampling.spacing}, {"noise", result.sampling.noise},
                                              {"denoised_noise", result.denoised_noise}}},
                                {"isolated_points", result.isolated_points}, {"duplicate_points", result.duplicate_points},
                                {"coverage", result.coverage},
                                {"levels", stages_json(result.stages)}};
  ctx.stats()["mesh"] = measures_json(result.measures);

  // Fit to the data, with or without a true surface: the distances from the input points to
  // the result (for noisy points about the noise; a scan's outliers show in the maximum).
  if (result.mesh.triangles.empty()) {
    // Nothing to measure (MeshDistance needs triangles); the outputs are still written.
    ctx.log("the reconstruction is empty: no fit or accuracy");
    ctx.write_band(result.band);
    ctx.write_mesh(result.mesh);
    return;
  }
  const apps::MeshDistance ours_distance(result.mesh);
  {
    const apps::OneSidedDistance f = apps::distances_to(
        points, [&](const Vec3d& p) { return ours_distance.distance(p); }, ctx.options().progress);
    ctx.stats()["fit"] = {{"mean", f.mean}, {"rms", f.rms}, {"max", f.max},
                          {"mean_voxels", f.mean / result.voxel_size}, {"max_voxels", f.max / result.voxel_size}};
    char line[160];
    std::snprintf(line, sizeof line, "fit: the points lie %.3g voxel from the surface on average, %.3g at most",
                  f.mean / result.voxel_size, f.max / result.voxel_size);
    ctx.log(line);
  }

  if (truth_distance) {
    // Accuracy against the true surface, from dense samples of both.
    apps::SurfaceSampleOptions dense;
    dense.count = accuracy_samples;
    dense.seed = 12345;
    dense.progress = ctx.options().progress;
    const std::vector<Vec3d> ours = apps::sample_mesh_surface(result.mesh, dense);
    const std::vector<Vec3d> truth = shape ? apps::sample_shape_surface(*shape, dense) : apps::sample_mesh_surface(truth_mesh, dense);
    const apps::SurfaceDistance d =
        apps::surface_distance(ours, truth_distance, truth, [&](const Vec3d& p) { return ours_distance.distance(p); },
                               ctx.options().progress);
    const BBox box = shape ? shape->bounds() : truth_mesh.bounds();
    const double diagonal = length(box.extent());
    ctx.stats()["accuracy"] = {{"chamfer", d.chamfer},
                               {"hausdorff", d.hausdorff},
                               {"chamfer_voxels", d.chamfer / result.voxel_size},
                               {"hausdorff_voxels", d.hausdorff / result.voxel_size},
                               {"chamfer_diagonals", d.chamfer / diagonal},
                               {"diagonal", diagonal},
                               {"samples", dense.count}};
    char line[200];
    std::snprintf(line, sizeof line, "accuracy: Chamfer %.3g voxel (%.3g of the diagonal), Hausdorff %.3g voxel",
                  d.chamfer / result.voxel_size, d.chamfer / diagonal, d.hausdorff / result.voxel_size);
    ctx.log(line);
  }
  ctx.write_band(result.band);
  ctx.write_mesh(result.mesh);
}

}  // namespace levelset::jobs
