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
//      from the input's values (in the spirit of Russo & Smereka 2000) and then kept fixed,
//      so the zero level does not move (edge crossings by linear interpolation move by
//      O(h^2 * curvature) only; measured <= 0.01 h on the test shapes):
//      - d_T, where the 3x3x3 stencil is active: the second-order Taylor expansion of u
//        along its normal, u = g d - (u_nn / 2) d^2 with g = |grad u| and u_nn from central
//        differences; exact for distance fields and for u = d * f with f smooth;
//      - otherwise, or where d_T disagrees with d_P by more than 0.1 voxel (thin features,
//        kinks, missing neighbours): d_P, the distance to the plane through the zero
//        crossings on the voxel's edges, 1/sqrt(sum_a g_a^2) with g_a = the inverse
//        distance to the nearer crossing along axis a (linear interpolation) or, on axes
//        without a crossing, |du/dx_a| / |u|. Exact for linear u, first order in curvature.
//      The result never exceeds the distance to the nearest edge crossing (<= 1 voxel).
//   2. |grad d| = 1 is solved outward on both sides on the unsigned distance with the
//      Godunov upwind update (thesis 2.28 / 4.4); with order = 2 (default) an axis uses the
//      second-order one-sided difference (3T - 4T1 + T2) / 2 wherever the two upwind values
//      continue monotonically (across the zero level too, through the fixed interface
//      values), first order elsewhere (order = 1: first order everywhere).
//      - Sweep: fast sweeping (Zhao 2005) brick by brick on a dense tile whose halo holds
//        the face neighbours' values (1 voxel deep, 2 for second order). Each iteration
//        sweeps every brick with pending work in up to 8 alternating orderings, the first
//        pair chosen per brick along increasing distance from its interface voxels (their
//        centroid against the brick's centre, else the neighbours'); bricks run
//        in two checkerboard colours, so bricks sweeping concurrently never share a face,
//        and a brick is revisited only when a neighbour changed values it reads. Within a
//        brick only voxels whose stencil changed are re-evaluated (same values, less work).
//        Stops when an iteration's largest change is < tolerance*h, nothing is pending, or
//        after max_sweep_iterations.
//      - March: fast marching (Sethian) from the interface voxels outward, brick by brick
//        (domain decomposition): each brick marches on a tile holding its face neighbours'
//        current values as boundary data, accepting the smallest tentative value first (a
//        heap with decrease-key over the brick's voxels, in cache) until the smallest exceeds
//        W*h; rounds in the sweep's two checkerboard colours re-march a brick when a
//        neighbour changed a value it reads (one upwind of the voxel across the face), until
//        none did.
//      First order: both give the same discrete solution (up to rounding). Second order:
//      they differ by < 0.01 h (the march fixes a value when it is accepted).
//      RedistanceResult reports the sweep's iterations or the march's rounds.
// Accuracy (tests/unit/test_redistance.cpp, u distorted by 1 + 0.5 sin sin sin, W = 3):
//   sphere R=128: |d - exact| <= 0.001 h, ||grad d| - 1| <= 0.0003 (first order: 0.025 h,
//   0.010); torus R=192: 0.003 h, 0.0015; knot R=256: 0.008 h, 0.006.
// Cost: Sweep O(domain voxels) per iteration, typically 3-4 iterations (each voxel is
//   evaluated ~6 times); March O(n log n) per brick march of n voxels, typically 3-4 rounds
//   with each brick marching about twice (knot R=512, W=3). Growing the band adds
//   O(ceil(W - W_in) * bricks). Memory: 4 bytes per voxel of the domain's bricks plus masks,
//   besides the input and the output.
// Threading: TBB. Interface set-up, sweeping or marching (per brick, in two checkerboard
//   colours) and output assembly run per brick in parallel. Results are bit-identical for any
//   thread count.
// Errors: Error{InvalidArgument} for half_width not 0 and not finite in [1, 1024], order not
//   1 or 2, max_sweep_iterations < 1 or a negative / non-finite tolerance;
//   Error{LimitExceeded} when growing leaves the index range or the domain exceeds 2^23
//   bricks; Error{Cancelled} from the progress hook (checked between phases, sweep
//   iterations and march rounds). An input without bricks gives an empty band with
//   the same frame (and the new W); one without zero crossings gives no active voxels.
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
  double tolerance = 1e-6;        // stop when the largest change < tolerance * h (March: changes
                                  // below it do not re-march the neighbours)
  ProgressHook progress;
};

struct RedistanceResult {
  NarrowBand band;
  std::uint64_t interface_voxels = 0;  // voxels initialised from the zero crossings
  int sweep_iterations = 0;            // Sweep: iterations run; March: 0
  int march_rounds = 0;                // March: rounds over the bricks; Sweep: 0
  double seconds = 0.0;
};

RedistanceResult redistance(const NarrowBand& in, const RedistanceOptions& options);

}  // namespace levelset
