// Batch subcommands of levelsetd. Each takes plain arguments (parsed by main.cpp with
// CLI11), runs the same core functions the daemon uses, prints to stdout and returns
// the process exit code. Errors propagate as levelset::Error; main.cpp prints them.
#pragma once

#include <string>
#include <vector>

#include "evolve/evolution.hpp"
#include "grid/narrow_band.hpp"
#include "surface/surface_result.hpp"

namespace levelset::cli {

struct InfoArgs {
  std::string path;
  bool json = false;
};
int run_info(const InfoArgs& args);

struct PrimitiveArgs {
  std::string shape;
  int resolution = 256;
  double band = 3.0;
  std::string output;
  std::string stats;
};
int run_primitive(const PrimitiveArgs& args);

struct CptArgs {
  std::string mesh;
  int resolution = 256;
  double voxel_size = 0.0;  // > 0 overrides resolution
  double band = 3.0;
  bool closest_points = false;
  std::string method = "auto";  // auto, characteristic or slab (CptMethod)
  std::string output;
  std::string stats;
};
int run_cpt(const CptArgs& args);

struct RedistanceArgs {
  std::string input;
  std::string method = "sweep";
  double band = 0.0;  // 0 = keep the input's half-width
  int order = 2;      // 1: first-order Godunov update (the thesis's); 2: second order
  std::string output;
  std::string stats;
};
int run_redistance(const RedistanceArgs& args);

struct SampleArgs {
  std::string input;
  std::string points;
  std::string output;
};
int run_sample(const SampleArgs& args);

struct MeshArgs {
  std::string input;
  std::string output;
  std::string method = "mc";
  double iso = 0.0;
  std::string stats;
};
int run_mesh(const MeshArgs& args);

struct MeasureArgs {
  std::string input;
  std::string method = "mc";
  double iso = 0.0;
  bool json = false;
};
int run_measure(const MeasureArgs& args);

// The surface of a band by marching cubes ("mc") or surface nets ("nets").
SurfaceResult extract_surface(const NarrowBand& band, const std::string& method, double iso);

struct EvolveArgs {
  std::string input;
  std::string output;
  std::string speed;               // a built-in speed name or a formula
  std::vector<std::string> constants;  // NAME=VALUE for the formula
  double c = 1.0;                  // speed parameters (constant / one-minus-eps-kappa)
  double eps = 0.1;
  std::vector<double> velocity;    // x,y,z: constant advection velocity (world units per time)
  int steps = 0;
  double time = 0.0;
  std::string scheme = "godunov";  // godunov | eno2 | weno5
  std::string hamiltonian = "godunov";  // godunov | llf
  int rk = 1;
  double cfl = 0.0;                // 0: 0.5 for --rk 1, 0.9 for --rk 3
  int redistance_every = 0;
  double drift_tolerance = evolve::kDefaultDriftTolerance;
  double band_growth_limit = evolve::kDefaultBandGrowthLimit;
  bool extension = false;
  int report_every = 0;            // print a progress line every N steps (0: none)
  std::string stats;
};
int run_evolve(const EvolveArgs& args);

}  // namespace levelset::cli
