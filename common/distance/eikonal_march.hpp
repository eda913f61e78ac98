// Step 2 of redistance() with RedistanceMethod::March (redistance.hpp): fast marching
// (Sethian) of |grad d| = 1 outward from the fixed interface voxels.
//
// march(w, order, limit, progress)
//   Inputs: a domain whose fixed voxels hold their distances (init_interface) and whose
//   other voxels hold kInf; order 1 or 2 as in sweep(); limit = the half-width in voxels.
//   Output: w.dist of every free domain voxel reached with a value <= limit holds its
//   unsigned distance in voxels; the others stay kInf. Voxels are accepted smallest
//   tentative value first, each fixed when accepted (ties broken by voxel id), until the
//   smallest tentative value exceeds the limit. The trial set is a TrialQueue: binary
//   min-heaps with lazy deletion, one per 1/256-voxel slice of [0, limit] (the pop order of
//   one global heap, with small heaps).
// Cost: O(N log N) for N voxels reached (tentative values live in w.dist, negated).
// Threading: the initial front is found per brick in parallel (TBB); the inside and the outside
//   march in parallel (two tasks), each reading only its own side and the fixed voxels, so
//   the result does not depend on the thread count.
//   Errors: Error{Cancelled} from progress, checked every 65536 heap pops.
#pragma once

#include "core/progress.hpp"
#include "distance/redistance_domain.hpp"

namespace levelset::detail {

void march(RedistanceDomain& w, int order, double limit, const ProgressHook& progress);

}  // namespace levelset::detail
