// BrickMask: one bit per voxel of an 8x8x8 brick (8 words of 64 bits, word = z-slice).
// rank(n) counts set bits below n: with a per-word base it maps a voxel to its slot in
// the brick's packed value array in O(1) (one popcount).
#pragma once

#include <array>
#include <bit>
#include <cstdint>

namespace levelset {

struct BrickMask {
  std::array<std::uint64_t, 8> words{};

  constexpr bool test(int n) const { return (words[n >> 6] >> (n & 63)) & 1u; }
  constexpr void set(int n) { words[n >> 6] |= std::uint64_t{1} << (n & 63); }
  constexpr void reset(int n) { words[n >> 6] &= ~(std::uint64_t{1} << (n & 63)); }
  constexpr void assign(int n, bool on) { on ? set(n) : reset(n); }
  constexpr int count() const {
    int c = 0;
    for (auto w : words) c += std::popcount(w);
    return c;
  }
  constexpr bool none() const {
    std::uint64_t any = 0;
    for (auto w : words) any |= w;
    return any == 0;
  }
  // Number of set bits strictly below n, counting within word n>>6 only.
  constexpr int rank_in_word(int n) const {
    return std::popcount(words[n >> 6] & ((std::uint64_t{1} << (n & 63)) - 1));
  }
  constexpr bool operator==(const BrickMask&) const = default;

  // Calls f(n) for every set bit n in increasing order.
  template <typename F>
  constexpr void for_each_set(F&& f) const {
    for (int w = 0; w < 8; ++w) {
      for (std::uint64_t m = words[w]; m != 0; m &= m - 1) f((w << 6) | std::countr_zero(m));
    }
  }
};

}  // namespace levelset
