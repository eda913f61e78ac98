#include "commands/number_checks.hpp"
#include "commands/medium_options.hpp"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>

#include "core/error.hpp"
#include "grid/lsg_file.hpp"
#include "io/image_reader.hpp"

namespace levelset::cli {

namespace {

std::vector<double> parse_numbers(std::string_view text, std::size_t count, std::string_view what) {
  std::vector<double> out;
  std::string s(text);
  const char* p = s.c_str();
  for (std::size_t i = 0; i < count; ++i) {
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p || !std::isfinite(v))
      throw Error(ErrorCode::InvalidArgument, std::string(what),
                  "expected " + std::to_string(count) + " finite numbers separated by commas, got '" + s + "'");
    out.push_back(v);
    p = end;
    if (i + 1 < count) {
      if (*p != ',')
        throw Error(ErrorCode::InvalidArgument, std::string(what),
                    "expected " + std::to_string(count) + " numbers separated by commas, got '" + s + "'");
      ++p;
    }
  }
  if (*p != '\0')
    throw Error(ErrorCode::InvalidArgument, std::string(what), "trailing text in '" + s + "'");
  return out;
}

}  // namespace

Vec3d parse_point(std::string_view text, std::string_view what) {
  const std::vector<double> v = parse_numbers(text, 3, what);
  return {v[0], v[1], v[2]};
}

void add_medium_options(CLI::App* sub, MediumArgs& a) {
  sub->add_option("--obstacles", a.obstacles, "Obstacles as a level set (.lsg): inside = blocked");
  sub->add_option("--clearance", a.clearance,
                  "Keep this world distance from the obstacles (below the band's half-width)");
  sub->add_option("--cost", a.cost, "Cost (time per unit length, 1/speed) as a formula over x y z h, e.g. '1 + 2*y'");
  sub->add_option("--cost-grid", a.cost_grid,
                  "Cost per node as a NRRD volume (fixes the grid; +inf = blocked)");
  sub->add_option("--bounds", a.bounds, "Grid box xmin,ymin,zmin,xmax,ymax,zmax (default: the points and obstacles, padded)");
  auto* res = sub->add_option("--resolution,-r", a.resolution, "Voxels along the longest side of the box (default 128)")
                  ->transform(levelset::cli::in_range(2, 1 << 15));
  auto* vs = sub->add_option("--voxel-size", a.voxel_size, "Voxel size in world units")->transform(levelset::cli::positive());
  res->excludes(vs);
  sub->add_option("--order", a.order, "Fast marching order: 1 or 2 (default)")->check(CLI::IsMember({1, 2}));
}

Medium load_medium(const MediumArgs& a, const std::vector<Vec3d>& points) {
  const auto t0 = std::chrono::steady_clock::now();
  Medium m;
  if (!a.cost.empty() && !a.cost_grid.empty())
    throw Error(ErrorCode::InvalidArgument, "--cost", "give --cost or --cost-grid, not both");
  if (!a.obstacles.empty()) {
    m.band = std::make_unique<NarrowBand>(load_lsg(a.obstacles).band);
    m.obstacles.band = m.band.get();
    m.obstacles.clearance = a.clearance;
  }
  if (!a.cost_grid.empty()) {
    if (!a.bounds.empty() || a.resolution > 0 || a.voxel_size > 0)
      throw Error(ErrorCode::InvalidArgument, "--cost-grid", "the cost grid fixes the grid: drop --bounds/--resolution/--voxel-size");
    ImageReadOptions read_options;
    read_options.max_voxels = apps::kDefaultMaxGridVoxels;
    read_options.allow_infinite = true;  // +Inf = blocked
    ImageReadResult vol = read_image(a.cost_grid, read_options);
    const ImageVolume& img = vol.image;
    if (img.spacing.x != img.spacing.y || img.spacing.x != img.spacing.z)
      throw Error(ErrorCode::UnsupportedFormat, a.cost_grid, "a cost grid needs cubic voxels (equal spacings)");
    m.grid.nx = static_cast<int>(img.nx);
    m.grid.ny = static_cast<int>(img.ny);
    m.grid.nz = static_cast<int>(img.nz);
    m.grid.voxel_size = img.spacing.x;
    m.grid.origin = img.origin;
    apps::validate_grid(m.grid, apps::kDefaultMaxGridVoxels, a.cost_grid);
    m.cost.values.assign(img.samples.begin(), img.samples.end());
  } else {
    BBox box;
    if (!a.bounds.empty()) {
      const std::vector<double> b = parse_numbers(a.bounds, 6, "--bounds");
      box.extend({b[0], b[1], b[2]});
      box.extend({b[3], b[4], b[5]});
      if (!(b[0] < b[3] && b[1] < b[4] && b[2] < b[5]))
        throw Error(ErrorCode::InvalidArgument, "--bounds", "expected min < max on every axis");
    } else {
      box = apps::padded_problem_bounds(points, m.band.get(), a.padding);
    }
    m.grid = a.voxel_size > 0 ? apps::dense_grid_for_voxel_size(box, a.voxel_size)
                              : apps::dense_grid_for_resolution(box, a.resolution > 0 ? a.resolution : 128);
    m.cost.formula = a.cost;
  }
  m.seconds_read = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return m;
}

}  // namespace levelset::cli
