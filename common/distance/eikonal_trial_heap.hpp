// TrialHeap: the trial set of one brick's fast march (eikonal_march.cpp), a binary min-heap
// of trial keys with decrease-key, so that each tile voxel is in it at most once.
//
// trial_key(v, t): the key of value v >= 0 (-0 allowed) at tile index t < 65536: the value's
//   bits (non-negative floats order like their bit patterns) above t, so one integer
//   comparison orders by value, then tile index. key_tile(k) = t.
// push(k): a voxel not in the heap. decrease(k): a voxel in the heap, with a smaller key than
//   its current one. pop(): the smallest key (the heap must not be empty).
// Capacity: kBrickVoxels entries (a brick's voxels), tile indices below TileGeom<2>::kVoxels.
// Cost: O(log n) per operation, no allocation (fixed arrays, about 7.5 KiB).
// Threading: not thread-safe; one per thread.
#pragma once

#include <bit>
#include <cstdint>

#include "distance/redistance_tile.hpp"

namespace levelset::detail {

// A trial key: the value's bits (non-negative floats order like their bit patterns) above the
// tile index, so that one integer comparison orders by value, then tile index.
inline std::uint64_t trial_key(float v, int t) {
  return std::uint64_t(std::bit_cast<std::uint32_t>(v + 0.0f)) << 16 | std::uint64_t(t);
}
inline int key_tile(std::uint64_t k) { return int(k & 0xffff); }

// Binary min-heap of trial keys with decrease-key (each tile voxel at most once): the trial
// set of one brick, at most its 512 voxels.
class TrialHeap {
 public:
  bool empty() const { return n_ == 0; }
  std::uint64_t top() const { return key_[0]; }
  void push(std::uint64_t k) { sift_up(n_++, k); }
  // k is smaller than the voxel's key in the heap.
  void decrease(std::uint64_t k) { sift_up(pos_[key_tile(k)], k); }
  std::uint64_t pop() {
    const std::uint64_t top = key_[0], last = key_[--n_];
    int i = 0;
    for (;;) {
      int c = 2 * i + 1;
      if (c >= n_) break;
      if (c + 1 < n_ && key_[c + 1] < key_[c]) ++c;
      if (!(key_[c] < last)) break;
      place(i, key_[c]);
      i = c;
    }
    if (n_ > 0) place(i, last);
    return top;
  }
  void clear() { n_ = 0; }

 private:
  void place(int i, std::uint64_t k) {
    key_[i] = k;
    pos_[key_tile(k)] = std::uint16_t(i);
  }
  void sift_up(int i, std::uint64_t k) {
    while (i > 0) {
      const int p = (i - 1) >> 1;
      if (!(k < key_[p])) break;
      place(i, key_[p]);
      i = p;
    }
    place(i, k);
  }
  std::uint64_t key_[kBrickVoxels];
  std::uint16_t pos_[TileGeom<2>::kVoxels];
  int n_ = 0;
};

}  // namespace levelset::detail
