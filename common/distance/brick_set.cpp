#include "distance/brick_set.hpp"

#include <algorithm>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace levelset {

BrickSet dilate_bricks(const std::vector<Coord>& shell, int reach) {
  std::vector<std::uint64_t> keys;
  keys.reserve(shell.size() * std::size_t((2 * reach + 1) * (2 * reach + 1) * (2 * reach + 1)));
  for (const Coord& b : shell)
    for (int dz = -reach; dz <= reach; ++dz)
      for (int dy = -reach; dy <= reach; ++dy)
        for (int dx = -reach; dx <= reach; ++dx) {
          const Coord n = b + Coord{dx, dy, dz};
          if (brick_in_range(n)) keys.push_back(brick_key(n));
        }
  tbb::parallel_sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  BrickSet set;
  set.bricks.resize(keys.size());
  // Keys pack (x, y, z) + offset in 21 bits each (coord.hpp); decode rather than keep pairs.
  constexpr std::int64_t off = kBrickCoordLimit;
  constexpr std::uint64_t mask = (std::uint64_t{1} << kBrickCoordBits) - 1;
  tbb::parallel_for(std::size_t(0), keys.size(), [&](std::size_t i) {
    const std::uint64_t k = keys[i];
    set.bricks[i] = {std::int32_t(std::int64_t(k & mask) - off),
                     std::int32_t(std::int64_t((k >> kBrickCoordBits) & mask) - off),
                     std::int32_t(std::int64_t((k >> (2 * kBrickCoordBits)) & mask) - off)};
  });
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
