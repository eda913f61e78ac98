// The upwind derivatives of evolve's spatial operator for one brick, by lines.
//
// The operator works on a dense tile around each brick: the brick plus kStencilReach voxels on
// every side (kDim^3 samples, x fastest, tile_index), with one bit per sample in `rows`
// (bit x - kLo of rows[(y - kLo) + kDim (z - kLo)]: the sample is an active band voxel).
//
// fill_axis_lines(tile, rows, reach, lines)
//   Lines of samples along each axis through the brick's voxels, with the samples beyond the
//   band's edge (which hold +-W h, not values of the field) replaced by extrapolation from the
//   active samples of the line (quadratic through the last three, linear through two), up to
//   `reach` samples from them, so that upwind stencils near the edge see a smooth field. Only
//   the samples a stencil of half-width `reach` around an active brick voxel reads are
//   extrapolated (the others keep the tile's value). line(a, i, j)[k] is the sample at
//   coordinate k + kLo along axis a (k in [0, kDim)), at (i, j) in [0, 8)^2 across (for a = 0:
//   (y, z); 1: (x, z); 2: (x, y)). Only lines through at least one active brick voxel are
//   filled.
// upwind_sides(lines, active, scheme, want, sides)
//   D-u and D+u (value units per voxel) along each axis at the brick's active voxels, for the
//   axes and sides `want` asks for: the lines' samples around each voxel are gathered, then
//   one_sided_batch evaluates them all (vector code, bit for bit one_side).
//   sides.at(a, k) is the pair at the k-th active voxel; sides not wanted are left as they were.
// Cost: O(3 * 64 * kDim) copies per brick plus the extrapolated gaps; upwind_sides 7 copies
//   and about 60 flops per active voxel, axis and side (WENO5, vector). No allocation.
//   Threading: pure functions over caller-owned buffers (one per thread).
// Internal to levelset_core (namespace evolve::detail).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "evolve/derivatives.hpp"
#include "evolve/upwind_batch.hpp"
#include "grid/brick_mask.hpp"
#include "grid/coord.hpp"

namespace levelset::evolve::detail {

inline constexpr int kLo = -kStencilReach, kHi = kBrickDim + kStencilReach, kDim = kHi - kLo;
constexpr int tile_index(int x, int y, int z) { return (x - kLo) + kDim * ((y - kLo) + kDim * (z - kLo)); }
// The tile's strides along x, y and z (tile_index).
inline constexpr std::ptrdiff_t kTileStride[3] = {1, kDim, kDim * kDim};

struct AxisLines {
  static constexpr int kLen = kDim;
  std::array<float, 3 * kBrickDim * kBrickDim * kLen> data{};
  float* line(int a, int i, int j) { return data.data() + std::size_t(((a * kBrickDim + i) * kBrickDim + j) * kLen); }
  const float* line(int a, int i, int j) const {
    return data.data() + std::size_t(((a * kBrickDim + i) * kBrickDim + j) * kLen);
  }
};

// Which one-sided derivatives to compute, per axis.
struct SidesWanted {
  std::array<bool, 3> minus{}, plus{};
};

struct UpwindSides {
  CentreSamples samples;  // the current axis's samples (scratch)
  // [axis][k]: D-u and D+u at the brick's k-th active voxel (ascending local index).
  std::array<std::array<double, kBrickVoxels>, 3> minus{}, plus{};
  OneSided at(int a, int k) const { return {minus[std::size_t(a)][std::size_t(k)], plus[std::size_t(a)][std::size_t(k)]}; }
};

void fill_axis_lines(const float* tile, const std::uint32_t* rows, int reach, AxisLines& lines);
void upwind_sides(const AxisLines& lines, const BrickMask& active, Scheme scheme, const SidesWanted& want,
                  UpwindSides& sides);

}  // namespace levelset::evolve::detail
