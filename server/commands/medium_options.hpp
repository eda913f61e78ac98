// Options shared by the dense-grid subcommands (path, voronoi): the grid (--bounds with
// --resolution or --voxel-size, or the frame of a --cost-grid file), the cost (--cost
// formula over x y z h, or --cost-grid COST.nrrd) and obstacles (--obstacles OBST.lsg,
// inside = blocked, with --clearance), turned into the apps' DenseGrid, CostField and
// Obstacles (common/apps/cost_field.hpp).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "apps/cost_field.hpp"
#include "apps/dense_grid.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::cli {

struct MediumArgs {
  std::string obstacles;       // .lsg
  double clearance = 0.0;      // world units
  std::string cost;            // formula
  std::string cost_grid;       // .nrrd
  std::string bounds;          // "xmin,ymin,zmin,xmax,ymax,zmax"
  int resolution = 0;
  double voxel_size = 0.0;
  double padding = 0.1;        // fraction of the longest side around the default bounds
  int order = 2;
};

void add_medium_options(CLI::App* sub, MediumArgs& args);

struct Medium {
  apps::DenseGrid grid;
  apps::CostField cost;
  apps::Obstacles obstacles;   // obstacles.band points into `band`
  std::unique_ptr<NarrowBand> band;
  double seconds_read = 0;
};

// Default bounds (no --bounds, no --cost-grid): the box around `points` and the obstacle
// band's active voxels, padded by `padding` x its longest side (at least 1 world unit /
// 100 when the box is a point). Default resolution 128.
Medium load_medium(const MediumArgs& args, const std::vector<Vec3d>& points);

// "x,y,z" -> point; Error{InvalidArgument} naming `what` when malformed or not finite.
Vec3d parse_point(std::string_view text, std::string_view what);

}  // namespace levelset::cli
