// Brick: the per-brick record of a NarrowBand (8^3 voxels), and BrickRecord, the plain
// (coordinates, active mask, inside mask) triple that builders and the file reader hand in.
//
// Signs of inactive voxels are stored compactly: most bricks have all their inactive voxels
// on one side of the surface (signs = kSignsAllOutside / kSignsAllInside); only bricks whose
// inactive voxels lie on both sides ("mixed", ~1/4 on thin bands) own a 512-bit mask in the
// band's side table. Active voxels take their sign from their value.
// Size: 120 bytes per brick (coords 12, offsets 8, active mask 64, ranks 8, neighbours 24).
#pragma once

#include <array>
#include <bit>
#include <cstdint>

#include "grid/brick_mask.hpp"
#include "grid/coord.hpp"

namespace levelset {

inline constexpr std::uint32_t kSignsAllOutside = 0xffffffffu;
inline constexpr std::uint32_t kSignsAllInside = 0xfffffffeu;

enum class Face : int { MinusX = 0, PlusX, MinusY, PlusY, MinusZ, PlusZ };

struct Brick {
  Coord coord;                               // brick coordinates (voxel index >> 3)
  std::uint32_t value_offset = 0;            // first value of this brick in NarrowBand::values()
  std::uint32_t signs = kSignsAllOutside;    // sign rule for inactive voxels, or mask index
  BrickMask active;                          // voxel holds a value
  std::uint64_t packed_ranks = 0;            // active voxels before word w=1..7, 9 bits each
  std::array<std::uint32_t, 6> neighbor{};   // -x,+x,-y,+y,-z,+z brick index or kNoBrick

  // Active voxels in the words before word w (w in [0, 8)).
  int rank_base(int w) const { return w == 0 ? 0 : int((packed_ranks >> (9 * (w - 1))) & 511u); }
  int active_count() const { return rank_base(7) + std::popcount(active.words[7]); }
  // Slot of active voxel n within this brick's values.
  int slot(int n) const { return rank_base(n >> 6) + active.rank_in_word(n); }
};

struct BrickRecord {
  Coord coord;
  BrickMask active;
  BrickMask inside;  // sign of every voxel; for active voxels it must match value < 0
};

}  // namespace levelset
