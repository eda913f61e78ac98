// Step 2 of redistance() with RedistanceMethod::March (redistance.hpp): fast marching
// (Sethian) of |grad d| = 1 outward from the fixed interface voxels, brick by brick in
// parallel (domain decomposition with the bricks as subdomains).
//
// march(w, order, limit, tolerance, progress)
//   Inputs: a domain whose fixed voxels hold their distances (init_interface) and whose
//   other voxels hold kInf; order 1 or 2 as in sweep(); limit = the half-width in voxels;
//   tolerance in voxels.
//   Output: w.dist of every free domain voxel reached with a value <= limit holds its
//   unsigned distance in voxels; the others stay kInf. Returns the rounds run. With w.cap
//   (optional, per voxel) a free voxel is accepted only up to min(limit, its cap), and one
//   left unknown passes nothing on (close_membranes: no membrane distance beyond where the
//   mesh is nearer).
//   Each brick marches on a tile with its face neighbours' current values (1 voxel deep, 2
//   for second order) as boundary data: its free voxels are recomputed from scratch, the
//   smallest tentative value accepted first (ties by tile index) and fixed when accepted,
//   until the smallest exceeds the limit; updates read accepted voxels of their own side,
//   boundary voxels of their own side and fixed voxels. Rounds (brick_rounds, two
//   checkerboard colours) re-march a brick whenever a neighbour changed, by the tolerance or
//   more, a value that it may read: one at most the value of the voxel across the face. They
//   end when none did (at most kMaxMarchRounds). First order: values only decrease from
//   round to round, and the fixed point is the discrete solution of one global march (up to
//   rounding); second order: within 0.01 h of it (the march's own order dependence).
// Cost: O(n log n) per brick march of n voxels (TrialHeap, in cache); a band of half-width 3
//   takes 3-4 rounds, each brick marching about twice (knot R = 512: 26.7k marches of 13.1k
//   bricks).
// Threading: TBB over the bricks of a colour; results are bit-identical for any thread
//   count. Errors: Error{Cancelled} from progress, checked after each round.
#pragma once

#include "core/progress.hpp"
#include "distance/redistance_domain.hpp"

namespace levelset::detail {

inline constexpr int kMaxMarchRounds = 64;

int march(RedistanceDomain& w, int order, double limit, float tolerance, const ProgressHook& progress);

}  // namespace levelset::detail
