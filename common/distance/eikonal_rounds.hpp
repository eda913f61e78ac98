// Rounds over the bricks of a redistance() domain (redistance.hpp), shared by the sweep and
// the march: each round visits, in two checkerboard colours, every brick with pending work
// and hands it to a kernel that updates the brick's free voxels from a tile holding its face
// neighbours' current values; a brick gets work again when a neighbour changed values it
// reads (its layer within the stencil's reach at their common face) or when its own kernel
// asks for another visit.
//
// brick_rounds(w, free_mask, max_rounds, tolerance, stage, progress, kernel)
//   Inputs: the domain; per brick its free voxels (domain minus fixed; bricks without any are
//   never visited); kernel(b, bits) -> BrickPass, where bit f < 6 of bits = the neighbour
//   across face f changed its layer there and bit 6 (kOwnWork) = the brick's own work (set
//   for every brick before the first round). The kernel may write only brick b's values.
//   Output: the rounds run. Stops when a round's largest change is below the tolerance,
//   nothing is pending, or after max_rounds.
// Cost: the kernels' plus O(bricks) per round. Threading: TBB; bricks of one colour never
//   share a face, so concurrent kernels read only values no other kernel writes, and the
//   result is bit-identical for any thread count. progress.step(0.1 + 0.8 * round /
//   max_rounds, stage) after each round; Error{Cancelled} from progress.
#pragma once

#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

#include "core/progress.hpp"
#include "distance/redistance_domain.hpp"

namespace levelset::detail {

// What one kernel call did to its brick.
struct BrickPass {
  float max_change = 0.0f;         // largest change of a value, in voxels
  std::uint8_t changed_faces = 0;  // bit f: values within the stencil's reach of face f changed
  bool more_work = false;          // visit the brick again next round
};

inline constexpr std::uint8_t kOwnWork = 1u << 6;

using BrickKernel = std::function<BrickPass(std::uint32_t brick, std::uint8_t bits)>;

int brick_rounds(const RedistanceDomain& w, const std::vector<BrickMask>& free_mask, int max_rounds,
                 float tolerance, std::string_view stage, const ProgressHook& progress, const BrickKernel& kernel);

// Per brick, the domain voxels that are not fixed.
std::vector<BrickMask> free_masks(const RedistanceDomain& w);

}  // namespace levelset::detail
