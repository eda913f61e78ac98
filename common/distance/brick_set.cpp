#include "distance/brick_set.hpp"

#include <algorithm>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace levelset {

namespace {

// Keys pack (x, y, z) + offset in 21 bits each (coord.hpp).
Coord key_to_brick(std::uint64_t k) {
  constexpr std::int64_t off = kBrickCoordLimit;
  constexpr std::uint64_t mask = (std::uint64_t{1} << kBrickCoordBits) - 1;
  return {std::int32_t(std::int64_t(k & mask) - off), std::int32_t(std::int64_t((k >> kBrickCoordBits) & mask) - off),
          std::int32_t(std::int64_t((k >> (2 * kBrickCoordBits)) & mask) - off)};
}

}  // namespace

BrickSet dilate_bricks(const std::vector<Coord>& shell, int reach) {
  // Separably, one axis at a time (the Chebyshev ball is a box): at most (2 reach + 1) times
  // the result's keys at once, not (2 reach + 1)^3 times the input's.
  std::vector<Coord> bricks = shell;
  std::vector<std::uint64_t> keys;
  for (int axis = 0; axis < 3; ++axis) {
    keys.clear();
    keys.reserve(bricks.size() * std::size_t(2 * reach + 1));
    for (const Coord& b : bricks)
      for (int d = -reach; d <= reach; ++d) {
        Coord n = b;
        n[axis] += d;
        if (brick_in_range(n)) keys.push_back(brick_key(n));
      }
    tbb::parallel_sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    if (axis < 2) {
      bricks.resize(keys.size());
      for (std::size_t i = 0; i < keys.size(); ++i) bricks[i] = key_to_brick(keys[i]);
    }
  }
  BrickSet set;
  set.bricks.resize(keys.size());
  tbb::parallel_for(std::size_t(0), keys.size(), [&](std::size_t i) { set.bricks[i] = key_to_brick(keys[i]); });
  set.keys = std::move(keys);
  return set;
}

std::uint32_t BrickSet::slot_of(const Coord& brick) const {
  if (!brick_in_range(brick)) return kNoBrick;
  const std::uint64_t key = brick_key(brick);
  const auto it = std::lower_bound(keys.begin(), keys.end(), key);
  return it != keys.end() && *it == key ? std::uint32_t(it - keys.begin()) : kNoBrick;
}

}  // namespace levelset
