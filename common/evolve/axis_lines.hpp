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
//   extrapolated (the others keep the tile's value). Layout (AxisLines::at): the samples of
//   one brick row (y, z) of centres at one position along the axis lie side by side, x
//   fastest, so a row's stencil samples are whole runs of 8 (x lines are rows of the tile; the
//   y and z lines are stored as planes across them).
// gather_centre_samples(lines, active, axis, samples, allow_vector)
//   The 7 samples along `axis` around each of the brick's active voxels (ascending local
//   index) into samples.at[j][k]; returns the count. Brick row by brick row: each row's 7 runs
//   of 8 samples packed to its active voxels (one vector permutation per run where the CPU has
//   AVX2 and allow_vector, else one sample at a time; the same samples either way).
// upwind_sides(lines, active, scheme, want, sides)
//   D-u and D+u (value units per voxel) along each axis at the brick's active voxels, for the
//   axes and sides `want` asks for: the lines' samples around each voxel are gathered, then
//   one_sided_batch evaluates them all (vector code, bit for bit one_side).
//   sides.at(a, k) is the pair at the k-th active voxel; sides not wanted are left as they were.
// Cost: O(3 * 64 * kDim) copies per brick (runs of 8) plus the extrapolated gaps;
//   upwind_sides 7 runs of 8 per brick row with an active voxel and axis, packed to the active
//   voxels, and about 60 flops per active voxel, axis and side (WENO5, vector). No allocation.
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
  // x: [z][y][p] (p = x - kLo); y: [z][p][x] (p = y - kLo); z: [y][p][x] (p = z - kLo).
  std::array<float, 3 * kBrickDim * kBrickDim * kLen> data{};
  static constexpr std::size_t kAxisSize = std::size_t(kBrickDim) * kBrickDim * kLen;
  // Sample at position p along axis a of the line through brick voxel (x, y, z) (the axis's
  // own coordinate ignored), and the step between consecutive p.
  static constexpr std::size_t index(int a, int x, int y, int z, int p) {
    return a == 0   ? std::size_t((z * kBrickDim + y) * kLen + p)
           : a == 1 ? kAxisSize + std::size_t((z * kLen + p) * kBrickDim + x)
                    : 2 * kAxisSize + std::size_t((y * kLen + p) * kBrickDim + x);
  }
  static constexpr std::ptrdiff_t step(int a) { return a == 0 ? 1 : kBrickDim; }
  float* at(int a, int x, int y, int z, int p) { return data.data() + index(a, x, y, z, p); }
  const float* at(int a, int x, int y, int z, int p) const { return data.data() + index(a, x, y, z, p); }
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
int gather_centre_samples(const AxisLines& lines, const BrickMask& active, int axis, CentreSamples& samples,
                          bool allow_vector = true);
void upwind_sides(const AxisLines& lines, const BrickMask& active, Scheme scheme, const SidesWanted& want,
                  UpwindSides& sides);

}  // namespace levelset::evolve::detail
