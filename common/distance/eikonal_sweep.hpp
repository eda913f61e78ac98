// Step 2 of redistance() with RedistanceMethod::Sweep (redistance.hpp): fast sweeping
// (Zhao 2005) of |grad d| = 1 outward from the fixed interface voxels, brick by brick.
//
// sweep(w, order, max_iterations, tolerance, progress)
//   Inputs: a domain whose fixed voxels hold their distances (init_interface) and whose
//   other voxels hold kInf; order 1 (Godunov) or 2 (second-order one-sided differences where
//   two upwind values continue monotonically, first order elsewhere); tolerance in voxels.
//   Output: w.dist of the free domain voxels (domain minus fixed) holds the unsigned distance
//   in voxels (kInf where nothing reaches). Returns the iterations run.
//   Each iteration sweeps every brick with pending work in up to 8 alternating orderings on a
//   dense tile whose halo holds the face neighbours' values (1 voxel deep, 2 for second
//   order); only voxels whose stencil changed are re-evaluated, and a brick is revisited only
//   when a neighbour changed values it reads. Stops when an iteration's largest change is
//   < tolerance, nothing is pending, or after max_iterations.
// Cost: O(domain voxels) per iteration, typically 3-4 iterations.
// Threading: TBB, bricks in two checkerboard colours (concurrent bricks never share a
//   face); results are bit-identical for any thread count. progress.step after each
//   iteration (fractions 0.1 to 0.9). Errors: Error{Cancelled} from progress.
#pragma once

#include "core/progress.hpp"
#include "distance/redistance_domain.hpp"

namespace levelset::detail {

int sweep(RedistanceDomain& w, int order, int max_iterations, float tolerance, const ProgressHook& progress);

}  // namespace levelset::detail
