// Scoring of reconstructions for bench_reconstruct: distances to the true mesh, topology, and
// the reference (Open3D's screened Poisson through poisson_reference.py), shared by the fixed
// cases and the sweep.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/vec3.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::bench {

// Distances above max(kGrossFraction, kGrossNoise noise) of the truth's bounding-box diagonal
// (noise: the points' sigma as a fraction of it) are gross errors (a missed or fused part, a
// closed gap), not a fit's inaccuracy or the noise's: Row::gross is the part of the Chamfer
// they carry.
constexpr double kGrossFraction = 5e-3;
constexpr double kGrossNoise = 3.0;
double gross_threshold(const TriangleMesh& truth, double noise);

struct Row {
  double chamfer = 0, hausdorff = 0, seconds = 0, genus = 0;
  double gross = 0;  // the part of chamfer carried by distances above the gross threshold
  bool watertight = false;
  std::uint64_t components = 0;
};

// Symmetric mean (Chamfer) and max (Hausdorff) of exact point-to-mesh distances between 200k
// area samples of `mesh` and the given samples of the truth, the Chamfer's part above `gross`
// (world; gross_threshold); watertight, genus, components.
Row score(const TriangleMesh& truth, const std::vector<Vec3d>& truth_samples, const TriangleMesh& mesh, double seconds,
          double gross);

struct PoissonRun {
  bool ok = false;
  std::string error;
  TriangleMesh mesh;
  double seconds = 0;  // normals, orientation and Poisson (not file reading)
};

// Screened Poisson, depth 8, normals estimated and oriented with 16 neighbours. With a
// non-empty `cache` path (without extension) the result is kept there (cache.ply + cache.json)
// and reused: the sweep's reference does not change while ours is developed.
PoissonRun run_poisson(const std::vector<Vec3d>& points, const std::string& cache);

// bench_reconstruct --sweep (bench_reconstruct_sweep.cpp).
int run_reconstruct_sweep(int argc, char** argv);

}  // namespace levelset::bench
