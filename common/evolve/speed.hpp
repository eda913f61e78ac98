// Speed functions for the level set equation u_t + beta |grad u| = 0 (thesis 2.2.3, 3, 4.7).
//
// A SpeedFunction turns the per-voxel quantities of one brick's active voxels (a SpeedBatch
// of at most 512 samples, structure of arrays) into two speeds per voxel:
//   advective  beta_a: multiplies the upwinded |grad u| (Godunov / ENO / WENO, hyperbolic);
//   parabolic  beta_p: multiplies the central |grad u| (curvature terms, not upwinded).
// The motion is u_t + beta_a |grad u|_upwind + beta_p |grad u|_central = 0; beta > 0 moves the
// surface outward (along grad u; u is negative inside). Only the inputs named in `needs` are
// filled in the batch (the rest are null): principal curvatures cost an eigen-solve per voxel
// and are computed only when asked for.
// Units: world units and time units; curvatures in 1 / world units (H = k1 + k2, a sphere of
//   radius r has H = 2 / r); speeds in world units per time.
// Stability: `diffusion` bounds the coefficient b of the parabolic part (|beta_p| <= b |kappa|
//   in the sense of the explicit limit dt <= h^2 / (6 b)); 0 when there is none.
// Threading: eval is called concurrently for different bricks; it must not keep state.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/vec3.hpp"

namespace levelset::evolve {

enum SpeedNeeds : std::uint32_t {
  kNeedsNothing = 0,
  kNeedsPosition = 1u << 0,   // x, y, z (world)
  kNeedsNormal = 1u << 1,     // nx, ny, nz (unit, outward)
  kNeedsMean = 1u << 2,       // H
  kNeedsPrincipal = 1u << 3,  // K, k1, k2 (and H)
  kNeedsMeanAverage = 1u << 4,  // kavg: area-weighted mean of H over the surface
  kNeedsGradNorm = 1u << 5,   // |grad u| (central)
  kNeedsDist = 1u << 6,       // dist (field)
  kNeedsDistGradient = 1u << 7,  // dgx dgy dgz, and dn = grad dist . n (needs the normal)
  kNeedsImage = 1u << 8,      // img (field)
  kNeedsEdge = 1u << 9,       // edge (field)
  kNeedsRoi = 1u << 10,       // roi (field)
  kNeedsGauss = 1u << 11,     // K (and H) without k1, k2: closed forms, no eigen-solve
};

// Fields a session may carry (thesis 4.9: the distance to a point cloud, an image, an edge
// indicator, a region of influence), sampled at voxel centres in world units; called
// concurrently. A speed that reads a field the options do not give is an error.
struct SpeedFields {
  std::function<double(const Vec3d&)> dist;
  std::function<Vec3d(const Vec3d&)> dist_gradient;
  std::function<double(const Vec3d&)> image;
  std::function<double(const Vec3d&)> edge;
  std::function<double(const Vec3d&)> roi;
};

struct SpeedBatch {
  int count = 0;                    // samples (<= 512)
  double time = 0, h = 1, kavg = 0;
  const float* d = nullptr;         // value u (always present)
  const float* x = nullptr;         // world position
  const float* y = nullptr;
  const float* z = nullptr;
  const float* nx = nullptr;        // unit normal
  const float* ny = nullptr;
  const float* nz = nullptr;
  const float* mean = nullptr;      // H = k1 + k2
  const float* gauss = nullptr;     // K
  const float* k1 = nullptr;
  const float* k2 = nullptr;
  const float* grad = nullptr;      // |grad u|
  const float* dist = nullptr;      // fields
  const float* dgx = nullptr;
  const float* dgy = nullptr;
  const float* dgz = nullptr;
  const float* dn = nullptr;
  const float* img = nullptr;
  const float* edge = nullptr;
  const float* roi = nullptr;
};

struct SpeedOutput {
  float* advective = nullptr;  // beta_a, count entries
  float* parabolic = nullptr;  // beta_p, count entries
};

struct SpeedFunction {
  std::string name;
  std::uint32_t needs = kNeedsNothing;
  bool has_advective = true;   // false: beta_a is 0 everywhere (no upwind derivatives needed)
  bool has_parabolic = false;  // false: beta_p is 0 everywhere
  double diffusion = 0.0;      // bound on the parabolic coefficient (see above)
  std::function<void(const SpeedBatch&, const SpeedOutput&)> eval;
};

// A typed speed formula (formula/formula.hpp) with named constants: its top-level terms that
// read curvatures (H K k1 k2 kavg) form the parabolic part, the others the advective part.
// Only the inputs the formula reads are computed. The fields of a session (dist dgx dgy dgz
// dn img edge roi) come from EvolutionOptions::fields.
// The diffusion bound is probed from the parabolic part (largest |beta_p| over curvatures of
// size <= 1 / world unit, at least 0.05). Errors: those of formula::compile.
SpeedFunction formula_speed(std::string_view formula, const std::map<std::string, double, std::less<>>& constants = {});

// Built-in speeds (thesis chapter 3), defined as formulas:
SpeedFunction constant_speed(double c);                  // "c": offset
SpeedFunction mean_curvature_flow();                     // "-H"
SpeedFunction mean_gaussian_flow();                      // "-sign(H)*sqrt(max(K,0))" (eq. 3.4/5.2)
SpeedFunction volume_preserving_flow();                  // "-(H-kavg)" (eq. 3.5)
SpeedFunction curvature_regularized(double c, double eps);  // "c - c*eps*H" (eq. 3.6 with c = 1)

// The built-ins by name: "constant" (c), "mean-curvature", "mean-gaussian",
// "volume-preserving", "one-minus-eps-kappa" (c, eps). Error{InvalidArgument} naming the
// known ones for anything else or a non-finite parameter.
SpeedFunction builtin_speed(std::string_view name, double c = 1.0, double eps = 0.1);
std::vector<std::string> builtin_speed_names();

// A built-in name (with c and eps) when it is one, else a formula with named constants.
SpeedFunction speed_from_text(std::string_view name_or_formula, double c, double eps,
                              const std::map<std::string, double, std::less<>>& constants);

}  // namespace levelset::evolve
