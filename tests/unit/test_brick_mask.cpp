#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "grid/brick_mask.hpp"
#include "grid/coord.hpp"

namespace levelset {

TEST(BrickMask, SetTestCountRankAgainstBoolArray) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    BrickMask m;
    std::vector<bool> ref(kBrickVoxels, false);
    const int density = trial % 5;
    for (int n = 0; n < kBrickVoxels; ++n) {
      const bool on = int(rng() % 5) < density;
      m.assign(n, on);
      ref[n] = on;
    }
    int count = 0;
    std::vector<int> order;
    for (int n = 0; n < kBrickVoxels; ++n) {
      EXPECT_EQ(m.test(n), ref[n]);
      int below_in_word = 0;
      for (int k = n & ~63; k < n; ++k) below_in_word += ref[k];
      EXPECT_EQ(m.rank_in_word(n), below_in_word);
      if (ref[n]) { ++count; order.push_back(n); }
    }
    EXPECT_EQ(m.count(), count);
    EXPECT_EQ(m.none(), count == 0);
    std::vector<int> visited;
    m.for_each_set([&](int n) { visited.push_back(n); });
    EXPECT_EQ(visited, order);
  }
}

TEST(Coord, BrickAndLocalIndexRoundTripIncludingNegatives) {
  for (int z = -17; z <= 17; z += 3)
    for (int y = -9; y <= 9; ++y)
      for (int x = -20; x <= 20; x += 7) {
        const Coord c{x, y, z};
        const Coord b = brick_of(c);
        EXPECT_EQ(brick_origin(b) + local_coord(local_index(c)), c);
        for (int a = 0; a < 3; ++a) {
          EXPECT_LE(brick_origin(b)[a], c[a]);
          EXPECT_LT(c[a], brick_origin(b)[a] + kBrickDim);
        }
      }
}

TEST(Coord, KeysSortInZYXOrder) {
  const Coord a{5, -3, -2}, b{-7, -2, -2}, c{-1000, -1000, 4};
  EXPECT_LT(brick_key(a), brick_key(b));  // same z, smaller y first
  EXPECT_LT(brick_key(b), brick_key(c));  // smaller z first
  EXPECT_LT(brick_key(Coord{-1, 0, 0}), brick_key(Coord{0, 0, 0}));
  EXPECT_TRUE(brick_in_range(Coord{-kBrickCoordLimit, 0, kBrickCoordLimit - 1}));
  for (const Coord c : {a, b, c, Coord{-kBrickCoordLimit, kBrickCoordLimit - 1, 0}})
    EXPECT_EQ(brick_from_key(brick_key(c)), c);
  EXPECT_FALSE(brick_in_range(Coord{kBrickCoordLimit, 0, 0}));
}

}  // namespace levelset
