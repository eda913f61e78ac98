// BrickTable: open-addressing hash map from brick key to brick index (linear probing,
// power-of-two capacity, load <= 1/2). Built once per topology; lookups never allocate.
// Memory: 12 bytes per slot, 24-48 bytes per brick.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

#include "grid/coord.hpp"

namespace levelset {

class BrickTable {
 public:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  void rebuild(const std::vector<std::uint64_t>& keys_in_index_order) {
    std::size_t cap = 16;
    while (cap < 2 * keys_in_index_order.size()) cap <<= 1;
    keys_.assign(cap, kEmpty);
    index_.assign(cap, kNoBrick);
    shift_ = 64 - std::countr_zero(cap);
    for (std::size_t i = 0; i < keys_in_index_order.size(); ++i) {
      std::size_t s = slot(keys_in_index_order[i]);
      while (keys_[s] != kEmpty) s = (s + 1) & (cap - 1);
      keys_[s] = keys_in_index_order[i];
      index_[s] = static_cast<std::uint32_t>(i);
    }
  }

  std::uint32_t find(std::uint64_t key) const {
    if (keys_.empty()) return kNoBrick;
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t s = slot(key);; s = (s + 1) & mask) {
      if (keys_[s] == key) return index_[s];
      if (keys_[s] == kEmpty) return kNoBrick;
    }
  }

  std::size_t memory_bytes() const {
    return keys_.capacity() * sizeof(std::uint64_t) + index_.capacity() * sizeof(std::uint32_t);
  }

 private:
  std::size_t slot(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }

  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> index_;
  int shift_ = 60;
};

}  // namespace levelset
