// evolve's axis lines (evolve/axis_lines.hpp): the samples each active voxel's upwind stencil
// reads, gathered by brick rows, against the tile read directly.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <random>

#include "evolve/axis_lines.hpp"

namespace levelset::evolve::detail {
namespace {

struct Fixture {
  std::vector<float> tile = std::vector<float>(std::size_t(kDim) * kDim * kDim);
  std::vector<std::uint32_t> rows = std::vector<std::uint32_t>(std::size_t(kDim) * kDim);
  BrickMask active;
};

// A tile of distinct random values, every sample active (no extrapolation), and a brick mask
// with a share `density` of its voxels set, plus whole and empty rows.
Fixture random_fixture(std::mt19937& rng, double density) {
  Fixture f;
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (float& v : f.tile) v = u(rng);
  for (std::uint32_t& r : f.rows) r = (1u << kDim) - 1u;
  std::bernoulli_distribution on(density);
  for (int n = 0; n < kBrickVoxels; ++n)
    if (on(rng)) f.active.set(n);
  f.active.words[3] |= std::uint64_t{0xff} << 16;       // a whole row (y = 2, z = 3)
  f.active.words[5] &= ~(std::uint64_t{0xff} << 40);    // an empty row (y = 5, z = 5)
  return f;
}

// Sample j of the k-th active voxel along axis a is the tile's sample j - 3 steps from it, on
// both gather paths, for sparse, half and full bricks; and upwind_sides' WENO5 sides equal
// one_side on the tile bit for bit.
TEST(AxisLines, RowGatherReadsEachActiveVoxelsStencilFromTheTile) {
  std::mt19937 rng(5);
  auto lines = std::make_unique<AxisLines>();
  auto vec = std::make_unique<CentreSamples>(), plain = std::make_unique<CentreSamples>();
  auto sides = std::make_unique<UpwindSides>();
  for (double density : {0.1, 0.5, 0.9, 1.0}) {
    const Fixture f = random_fixture(rng, density);
    fill_axis_lines(f.tile.data(), f.rows.data(), kStencilReach, *lines);
    SidesWanted all;
    all.minus = {true, true, true};
    all.plus = {true, true, true};
    upwind_sides(*lines, f.active, Scheme::Weno5, all, *sides);
    for (int a = 0; a < 3; ++a) {
      const int n_vec = gather_centre_samples(*lines, f.active, a, *vec, true);
      const int n_plain = gather_centre_samples(*lines, f.active, a, *plain, false);
      ASSERT_EQ(n_vec, f.active.count());
      ASSERT_EQ(n_plain, n_vec);
      int k = 0;
      int mismatches = 0;
      f.active.for_each_set([&](int n) {
        const Coord l = local_coord(n);
        const float* c = f.tile.data() + tile_index(l.x, l.y, l.z);
        for (int j = 0; j < CentreSamples::kCount; ++j) {
          const float want = c[(j - kStencilReach) * kTileStride[a]];
          mismatches += vec->at[std::size_t(j)][std::size_t(k)] != want;
          mismatches += plain->at[std::size_t(j)][std::size_t(k)] != want;
        }
        const double m = one_side(c, kTileStride[a], Scheme::Weno5, true);
        const double p = one_side(c, kTileStride[a], Scheme::Weno5, false);
        mismatches += std::memcmp(&m, &sides->minus[std::size_t(a)][std::size_t(k)], sizeof m) != 0;
        mismatches += std::memcmp(&p, &sides->plus[std::size_t(a)][std::size_t(k)], sizeof p) != 0;
        ++k;
      });
      EXPECT_EQ(mismatches, 0) << "axis " << a << ", density " << density;
    }
  }
}

}  // namespace
}  // namespace levelset::evolve::detail
