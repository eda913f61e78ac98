// csg: Boolean operations on two narrow bands (thesis 3.5, 5.1.4, Table 3.1), with optional
//   fairing of the seam where the two surfaces meet.
//
//   union         min(a, b)
//   intersection  max(a, b)
//   difference    max(a, -b)    (A minus B)
//
// Inputs: two NarrowBands A and B (world distances, negative inside; any voxel sizes and
//   origins); options.
// Method:
//   1. Result frame: voxel size options.voxel_size, or the finer of the two; origin that of
//      the band with that voxel size (A's when they tie or when the size is given); half-width
//      options.half_width, or the larger of the two.
//   2. Candidate bricks: every result brick within one result voxel of an allocated brick of
//      A or B (the result's zero level lies on A's or B's zero level, so no other brick can
//      hold it). Each candidate voxel takes the operator applied to the trilinear samples of
//      A and B (grid/interpolate.hpp: outside a band the sample is +-its background with the
//      band's sign, so the signs are right everywhere, not only in the bands); a voxel is
//      active when |value| is below both inputs' background (clamped samples carry no
//      distance) or a 6-neighbour has the other sign (the band invariant). Bricks outside the
//      candidates take their sign from the x-row rule (grid/narrow_band.hpp), exact because
//      no zero crossing lies there; far_inside follows the operator on the inputs' far signs.
//   3. Redistance (distance/redistance.hpp, zero level kept) to the result half-width: the
//      min/max of two distance fields is a distance field only away from the seam; after this
//      the result is a proper band again.
//   4. Seam fairing (options.seam_time > 0): mean curvature flow with the speed multiplied
//      by a region of influence (SpeedFields::roi, thesis 3.5: "a smoothed box function
//      around the boundary intersections"): roi = 1 where |a| <= R and |b| <= R (R =
//      options.seam_radius, world units), falling smoothly (half cosine) to 0 at 2R, 0 where
//      a sample is clamped at its band's background (no distance known there). A and B are
//      the inputs (the roi field does not move). Outside 2R the surface does not move
//      (up to the redistance's <= 0.01 h). Choose 2R below the inputs' band half-widths.
// Output: CsgResult: the band; counts.
// Units: world. Cost: O(candidate bricks * 1000) trilinear samples of each input (8 reads
//   each), then a redistance; seam fairing O(steps * active voxels) with steps ~
//   6 * seam_time / h^2 / cfl.
// Threading: TBB over bricks; identical results for any thread count.
// Errors (thrown): Error{InvalidArgument} for non-finite or non-positive voxel_size /
//   half_width / seam_radius (when fairing) / seam_time, a half_width below 2; LimitExceeded
//   when the candidate bricks exceed options.max_bricks (e.g. a voxel size far finer than the
//   inputs'); Error{Cancelled} from the progress hook; Error{NonFinite} if the seam fairing
//   met a NaN.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/progress.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::apps {

enum class CsgOp { Union, Intersection, Difference };

// "union", "intersection", "difference"; Error{InvalidArgument} otherwise.
CsgOp csg_op_from_name(std::string_view name);
std::string_view csg_op_name(CsgOp op);

struct CsgOptions {
  CsgOp op = CsgOp::Union;
  double voxel_size = 0;               // world units; 0: the finer input's
  double half_width = 0;               // voxels; 0: the larger input's
  double seam_time = 0;                // seam fairing time (world units^2); 0: none
  double seam_radius = 0;              // R, world units; needed when seam_time > 0
  int seam_redistance_every = 10;
  std::uint64_t max_bricks = std::uint64_t{1} << 22;  // candidate brick budget (2^31 voxels)
  ProgressHook progress;
};

struct CsgResult {
  NarrowBand band;
  std::uint64_t candidate_bricks = 0;
  int seam_steps = 0;
  double seam_time = 0;
  double seconds = 0;
};

CsgResult csg(const NarrowBand& a, const NarrowBand& b, const CsgOptions& options);

// The value of the operator on two signed distances.
double csg_combine(CsgOp op, double a, double b);

// The seam's region of influence at p (see 4. above), from the two inputs; thread-safe.
double seam_region_of_influence(const NarrowBand& a, const NarrowBand& b, double radius, const Vec3d& p);

}  // namespace levelset::apps
