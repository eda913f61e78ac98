// Integer index space of the narrow band: voxel coordinates, brick coordinates, keys.
//
// A voxel (i,j,k) sits at world position origin + h*(i,j,k). Bricks are 8x8x8 voxels;
// brick coordinates are voxel coordinates >> 3 (floor division, also for negatives).
// Within a brick, voxels are numbered x fastest: n = x + 8*y + 64*z, so mask word z
// holds one z-slice. Brick keys pack (x,y,z) brick coordinates into 63 bits and sort
// in (z,y,x) order, which is also the storage order of bricks in a NarrowBand.
#pragma once

#include <cstdint>
#include <cstdlib>

namespace levelset {

struct Coord {
  std::int32_t x = 0, y = 0, z = 0;

  constexpr Coord operator+(const Coord& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Coord operator-(const Coord& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr bool operator==(const Coord& o) const = default;
  constexpr std::int32_t& operator[](int a) { return a == 0 ? x : (a == 1 ? y : z); }
  constexpr std::int32_t operator[](int a) const { return a == 0 ? x : (a == 1 ? y : z); }
};

inline constexpr int kBrickLog2 = 3;
inline constexpr int kBrickDim = 1 << kBrickLog2;              // 8
inline constexpr int kBrickVoxels = kBrickDim * kBrickDim * kBrickDim;  // 512

// Brick coordinates must fit in 21 signed bits each: voxel indices in [-2^23, 2^23).
inline constexpr int kBrickCoordBits = 21;
inline constexpr std::int32_t kBrickCoordLimit = 1 << (kBrickCoordBits - 1);  // 2^20
inline constexpr std::int32_t kVoxelCoordLimit = kBrickCoordLimit * kBrickDim;

inline constexpr std::uint32_t kNoBrick = 0xffffffffu;

constexpr Coord brick_of(const Coord& voxel) {
  return {voxel.x >> kBrickLog2, voxel.y >> kBrickLog2, voxel.z >> kBrickLog2};
}
constexpr Coord brick_origin(const Coord& brick) {
  return {brick.x * kBrickDim, brick.y * kBrickDim, brick.z * kBrickDim};
}
constexpr int local_index(int x, int y, int z) { return x | (y << 3) | (z << 6); }
constexpr int local_index(const Coord& voxel) {
  return local_index(voxel.x & 7, voxel.y & 7, voxel.z & 7);
}
constexpr Coord local_coord(int n) { return {n & 7, (n >> 3) & 7, n >> 6}; }

constexpr bool brick_in_range(const Coord& b) {
  return b.x >= -kBrickCoordLimit && b.x < kBrickCoordLimit && b.y >= -kBrickCoordLimit &&
         b.y < kBrickCoordLimit && b.z >= -kBrickCoordLimit && b.z < kBrickCoordLimit;
}

// Requires brick_in_range(b).
constexpr std::uint64_t brick_key(const Coord& b) {
  constexpr std::uint64_t off = kBrickCoordLimit;
  constexpr std::uint64_t mask = (std::uint64_t{1} << kBrickCoordBits) - 1;
  return (((static_cast<std::uint64_t>(b.z) + off) & mask) << (2 * kBrickCoordBits)) |
         (((static_cast<std::uint64_t>(b.y) + off) & mask) << kBrickCoordBits) |
         ((static_cast<std::uint64_t>(b.x) + off) & mask);
}

constexpr Coord brick_from_key(std::uint64_t key) {
  constexpr std::uint64_t mask = (std::uint64_t{1} << kBrickCoordBits) - 1;
  return {static_cast<std::int32_t>(key & mask) - kBrickCoordLimit,
          static_cast<std::int32_t>((key >> kBrickCoordBits) & mask) - kBrickCoordLimit,
          static_cast<std::int32_t>((key >> (2 * kBrickCoordBits)) & mask) - kBrickCoordLimit};
}

// Inclusive index-space box; empty when min > max.
struct IndexBox {
  Coord min{1, 1, 1};
  Coord max{0, 0, 0};
  constexpr bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  constexpr void extend(const Coord& c) {
    if (empty()) { min = max = c; return; }
    if (c.x < min.x) min.x = c.x;
    if (c.y < min.y) min.y = c.y;
    if (c.z < min.z) min.z = c.z;
    if (c.x > max.x) max.x = c.x;
    if (c.y > max.y) max.y = c.y;
    if (c.z > max.z) max.z = c.z;
  }
  constexpr bool operator==(const IndexBox&) const = default;
};

}  // namespace levelset
