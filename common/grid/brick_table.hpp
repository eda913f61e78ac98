// BrickTable: open-addressing hash map from brick coordinates to brick index (linear
// probing, power-of-two capacity, load <= 1/2). Slots hold only the brick index (4 bytes);
// the key is compared against the brick's own coordinates, so the table costs 8-16 bytes
// per brick. Built once per topology; lookups never allocate.
#pragma once

#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "grid/brick.hpp"

namespace levelset {

class BrickTable {
 public:
  void rebuild(std::span<const Brick> bricks) {
    std::size_t cap = 16;
    while (cap < 2 * bricks.size()) cap <<= 1;
    slots_.assign(cap, kNoBrick);
    shift_ = 64 - std::countr_zero(cap);
    for (std::size_t i = 0; i < bricks.size(); ++i) {
      std::size_t s = slot(bricks[i].coord);
      while (slots_[s] != kNoBrick) s = (s + 1) & (cap - 1);
      slots_[s] = static_cast<std::uint32_t>(i);
    }
  }

  // Requires brick_in_range(c).
  std::uint32_t find(const Coord& c, std::span<const Brick> bricks) const {
    if (slots_.empty()) return kNoBrick;
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t s = slot(c);; s = (s + 1) & mask) {
      const std::uint32_t i = slots_[s];
      if (i == kNoBrick || bricks[i].coord == c) return i;
    }
  }

  std::size_t memory_bytes() const { return slots_.capacity() * sizeof(std::uint32_t); }

 private:
  std::size_t slot(const Coord& c) const {
    return static_cast<std::size_t>((brick_key(c) * 0x9E3779B97F4A7C15ull) >> shift_);
  }

  std::vector<std::uint32_t> slots_;
  int shift_ = 60;
};

}  // namespace levelset
