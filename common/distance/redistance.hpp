// redistance: rebuild the signed distance of a narrow band from its own zero level set
// (reinitialisation, thesis 2.3 and open issue 5.3 'Reinitialization'), without extracting
// an explicit surface and without moving the zero level.
//
// Inputs: a NarrowBand whose values lost the distance property (|grad u| != 1) but whose
//   signs and band invariant hold (every voxel with a 6-neighbour of opposite sign is active);
//   RedistanceOptions below. Units: values in world units, half-widths in voxels, tolerance
//   relative to the voxel size h.
// Output: a NarrowBand with the input's voxel size, origin and far_inside and half-width
//   W = options.half_width (0: the input's), holding the signed distance d to the input's
//   zero level set (world units, negative inside) at every domain voxel with |d| <= W*h.
//   The domain is the input's active voxels, dilated (26-neighbourhood) by ceil(W - W_in)
//   voxels when the band grows; new bricks take the input's signs (NarrowBand::is_inside).
//   Every voxel keeps the input's sign, the band invariant holds, bricks left without active
//   voxels are dropped unless a brick row needs one to carry its sign.
// Method:
//   1. Interface voxels (a 6-neighbour of opposite sign) are initialised subcell-accurately
//      (in the spirit of Russo & Smereka 2000): the distance to the plane through the zero
//      crossings on the voxel's grid edges, d = 1/sqrt(sum_a g_a^2) voxels, where g_a is
//      the inverse crossing distance along axis a (the nearer crossing, by linear
//      interpolation of the two end values) and, on axes without a crossing, |du/dx_a|/|u|
//      from central differences (one-sided next to the band edge). Exact for linear u;
//      these values stay fixed, so edge crossings move by O(h^2) only.
//   2. |grad d| = 1 is solved outward on both sides with the first-order Godunov upwind
//      update (thesis 2.28 / 4.4) on the unsigned distance:
//      - Sweep: fast sweeping (Zhao 2005) brick by brick: each iteration sweeps every brick
//        that saw a change in the 8 alternating orderings (stopping early once a sweep
//        changes nothing, which leaves the result unchanged) on a dense 10^3 tile whose
//        halo holds the face neighbours' values; bricks run in two checkerboard colours, so
//        bricks sweeping concurrently never share a face. Stops when an iteration's largest
//        change is < tolerance*h, when no brick changed, or after max_sweep_iterations.
//      - March: fast marching (Sethian) with a binary min-heap (lazy deletion) from the
//        interface voxels outward until the smallest tentative distance exceeds W*h.
//      Both converge to the same discrete solution (up to rounding).
// Cost: O(domain voxels) per sweep iteration (typically 3-4 iterations), O(N log N) for the
//   march; growing the band adds O(ceil(W - W_in) * bricks). Memory: 4-8 bytes per voxel of
//   the domain's bricks (dense per brick) besides the input and the output.
// Threading: TBB. Interface set-up, sweeping and output assembly run per brick in parallel;
//   the march itself is serial. Results are bit-identical for any thread count.
// Errors: Error{InvalidArgument} for half_width not 0 and not finite in [1, 1024],
//   max_sweep_iterations < 1 or a negative / non-finite tolerance; Error{LimitExceeded} when
//   growing leaves the index range or the domain exceeds 2^23 bricks; Error{Cancelled} from
//   the progress hook (checked between phases, sweep iterations and heap batches).
//   An input without bricks gives an empty band with the same frame (and the new W).
#pragma once

#include <cstdint>

#include "core/progress.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

enum class RedistanceMethod { Sweep, March };

struct RedistanceOptions {
  RedistanceMethod method = RedistanceMethod::Sweep;
  double half_width = 0.0;        // voxels; 0 keeps the input's, otherwise in [1, 1024]
  // 1: the first-order Godunov update (thesis 2.28); 2: second-order one-sided differences
  // wherever two upwind values continue monotonically (first order elsewhere).
  int order = 2;
  int max_sweep_iterations = 8;   // Sweep: each iteration = 8 ordered sweeps per brick
  double tolerance = 1e-6;        // Sweep: stop when the largest change < tolerance * h
  ProgressHook progress;
};

struct RedistanceResult {
  NarrowBand band;
  std::uint64_t interface_voxels = 0;  // voxels initialised from the zero crossings
  int sweep_iterations = 0;            // Sweep: iterations run; March: 0
  double seconds = 0.0;
};

RedistanceResult redistance(const NarrowBand& in, const RedistanceOptions& options);

}  // namespace levelset
