// The fast march's trial heap (distance/eikonal_trial_heap.hpp): keys order by value, then
// tile index; random pushes, decreases and pops against a reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "distance/eikonal_trial_heap.hpp"

namespace levelset {
namespace {

// Keys order by value, then tile index; -0 reads as 0.
TEST(TrialHeap, KeysOrderByValueThenTile) {
  using detail::trial_key;
  EXPECT_LT(trial_key(0.0f, 5), trial_key(1e-30f, 0));
  EXPECT_LT(trial_key(1.5f, 3), trial_key(1.5f, 4));
  EXPECT_LT(trial_key(1.5f, 1727), trial_key(std::nextafter(1.5f, 2.0f), 0));
  EXPECT_EQ(trial_key(-0.0f, 7), trial_key(0.0f, 7));
  EXPECT_EQ(detail::key_tile(trial_key(2.25f, 1234)), 1234);
}

// Random pushes and decreases against a reference: pops come out in key order and each voxel
// once, with its last (smallest) key.
TEST(TrialHeap, PopsInKeyOrderWithDecreases) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> value(0.0f, 3.0f);
  detail::TrialHeap heap;
  for (int trial = 0; trial < 20; ++trial) {
    heap.clear();
    std::map<int, std::uint64_t> current;  // tile -> key in the heap
    for (int op = 0; op < 2000; ++op) {
      const int t = int(rng() % 512) * 3;  // tile indices spread over a halo-2 tile
      const float v = value(rng);
      const std::uint64_t k = detail::trial_key(v, t);
      const auto it = current.find(t);
      if (it == current.end()) {
        if (current.size() == 512) continue;
        heap.push(k);
        current[t] = k;
      } else if (k < it->second) {
        heap.decrease(k);
        it->second = k;
      }
      if (op % 7 == 0 && !heap.empty()) {  // interleaved pops: the smallest key
        std::uint64_t smallest = ~std::uint64_t{0};
        for (const auto& [tile, key] : current) smallest = std::min(smallest, key);
        ASSERT_EQ(heap.pop(), smallest);
        current.erase(detail::key_tile(smallest));
      }
    }
    std::vector<std::uint64_t> expected;
    for (const auto& [tile, key] : current) expected.push_back(key);
    std::sort(expected.begin(), expected.end());
    std::vector<std::uint64_t> popped;
    while (!heap.empty()) popped.push_back(heap.pop());
    EXPECT_EQ(popped, expected);
  }
}

}  // namespace
}  // namespace levelset
