#include <gtest/gtest.h>

#include <array>
#include <random>
#include <vector>

#include "core/error.hpp"
#include "grid/band_accessor.hpp"
#include "grid/band_builder.hpp"
#include "grid/tile.hpp"
#include "shape_band.hpp"

namespace levelset {
namespace {

using test::make_shape_band;

// Dense reference of value_or_background over an index box.
struct DenseGrid {
  Coord lo, hi;  // inclusive
  std::vector<float> v;
  explicit DenseGrid(const NarrowBand& band, Coord l, Coord h) : lo(l), hi(h) {
    v.resize(std::size_t(hi.x - lo.x + 1) * (hi.y - lo.y + 1) * (hi.z - lo.z + 1));
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) at({x, y, z}) = band.value_or_background({x, y, z});
  }
  float& at(const Coord& c) {
    return v[std::size_t(c.x - lo.x) +
             std::size_t(hi.x - lo.x + 1) * (std::size_t(c.y - lo.y) + std::size_t(hi.y - lo.y + 1) * std::size_t(c.z - lo.z))];
  }
};

TEST(BandAccessor, AgreesWithPointQueriesEverywhere) {
  for (const char* shape : {"sphere", "knot"}) {
    const auto sb = make_shape_band(shape, 48);
    BandAccessor acc(sb.band);
    for (int z = -10; z <= 58; ++z)
      for (int y = -10; y <= 58; ++y)
        for (int x = -10; x <= 58; ++x) {
          const Coord c{x, y, z};
          ASSERT_EQ(acc.value(c), sb.band.value_or_background(c));
          ASSERT_EQ(acc.probe(c), sb.band.value(c));
          ASSERT_EQ(acc.is_active(c), sb.band.is_active(c));
          ASSERT_EQ(acc.is_inside(c), sb.band.is_inside(c));
        }
  }
}

// 7- and 27-point stencils around every active voxel, read through one accessor in storage
// order, match a dense reference, and crossing brick faces costs no hash lookup in the
// common case.
TEST(BandAccessor, StencilsAcrossBrickFacesMatchDenseReference) {
  const auto sb = make_shape_band("knot", 96);
  const NarrowBand& band = sb.band;
  DenseGrid dense(band, {-12, -12, -12}, {108, 108, 108});
  BandAccessor acc(band);
  std::uint64_t queries = 0;
  std::uint64_t crossing = 0;
  band.for_each_active([&](const Coord& c, float) {
    double lap_acc = -6.0 * acc.value(c), lap_ref = -6.0 * dense.at(c);
    double box_acc = 0, box_ref = 0;
    for (int a = 0; a < 3; ++a)
      for (int s = -1; s <= 1; s += 2) {
        Coord n = c;
        n[a] += s;
        lap_acc += acc.value(n);
        lap_ref += dense.at(n);
      }
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Coord n = c + Coord{dx, dy, dz};
          if (!(brick_of(n) == brick_of(c))) ++crossing;
          box_acc += acc.value(n);
          box_ref += dense.at(n);
        }
    queries += 1 + 6 + 27;
    ASSERT_EQ(lap_acc, lap_ref);
    ASSERT_EQ(box_acc, box_ref);
  });
  ASSERT_GT(crossing, queries / 10);  // the test really crosses brick boundaries
  // Hashes happen when iteration moves on to a non-adjacent brick and for broken diagonals.
  EXPECT_LT(acc.hash_lookups(), queries / 200)
      << acc.hash_lookups() << " hash lookups for " << queries << " queries";
}

// decode_brick (16 voxels per expanding load where the CPU has AVX-512) against the plain form
// and against the band's own lookups, on bricks with partial rows, mixed stored signs, full and
// empty rows.
TEST(DecodeBrick, VectorAndPlainFormsAgreeWithTheBand) {
  GridFrame frame;
  frame.voxel_size = 0.5;
  frame.half_width = 3.0;
  BandBuilder builder(frame);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> value(-1.4f, 1.4f);
  std::uniform_int_distribution<int> pattern(0, 3);
  for (int bz = 0; bz < 3; ++bz)
    for (int by = 0; by < 3; ++by)
      for (int bx = 0; bx < 3; ++bx) {
        BrickMask active, inside;
        float dense[kBrickVoxels];
        const int kind = pattern(rng);  // 0: random voxels, 1: full, 2: whole rows, 3: sparse
        for (int n = 0; n < kBrickVoxels; ++n) {
          dense[n] = value(rng);
          const bool on = kind == 1 || (kind == 2 ? ((n >> 3) % 3 == 0) : (rng() % (kind == 3 ? 9 : 2)) == 0);
          active.assign(n, on);
          inside.assign(n, on ? dense[n] < 0.0f : (rng() & 1) != 0);
        }
        builder.add_brick({bx, by, bz}, active, inside, dense);
      }
  const NarrowBand band = builder.finish(false);
  std::array<float, kBrickVoxels> fast{}, plain{};
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) {
    decode_brick(band, b, fast);
    decode_brick_portable(band, b, plain);
    ASSERT_EQ(fast, plain) << "brick " << b;
    const Coord origin = brick_origin(band.bricks()[b].coord);
    for (int n = 0; n < kBrickVoxels; ++n) ASSERT_EQ(fast[std::size_t(n)], band.value_or_background(origin + local_coord(n)));
  }
}

class TileTest : public ::testing::TestWithParam<int> {};

TEST_P(TileTest, GatherMatchesAccessorIncludingHalo) {
  const int halo = GetParam();
  const auto sb = make_shape_band("torus", 48);
  const NarrowBand& band = sb.band;
  const TileShape shape{halo};
  std::vector<float> tile(shape.size()), tile2(shape.size());
  const std::size_t dim = std::size_t(shape.dim());
  std::vector<std::uint32_t> rows(dim * dim), rows3(dim * dim);
  std::vector<float> tile3(shape.size());
  const DecodedBricks decoded_bricks = decode_bricks(band);
  const std::span<const float> decoded = decoded_bricks.values();
  BandAccessor acc(band);
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) {
    gather_tile(band, b, halo, tile);
    gather_tile(band, b, halo, tile2, rows);
    ASSERT_EQ(tile, tile2);
    // From the decoded bricks: the same box and active rows.
    gather_box(band, decoded, brick_neighborhood(band, b), -halo, kBrickDim + halo, tile3, rows3);
    ASSERT_EQ(tile, tile3) << "brick " << b;
    ASSERT_EQ(rows, rows3) << "brick " << b;
    // The star only: the same values and rows where at most one coordinate leaves the brick,
    // no active bit elsewhere (the values there are left as they were: a sentinel).
    std::fill(tile3.begin(), tile3.end(), 1234.5f);
    gather_box(band, decoded, brick_neighborhood(band, b), -halo, kBrickDim + halo, tile3, rows3, GatherRegion::Star);
    for (int z = -halo; z < kBrickDim + halo; ++z)
      for (int y = -halo; y < kBrickDim + halo; ++y)
        for (int x = -halo; x < kBrickDim + halo; ++x) {
          auto out = [](int c) { return c < 0 || c >= kBrickDim; };
          const bool star = int(out(x)) + int(out(y)) + int(out(z)) <= 1;
          const std::size_t i = shape.index(x, y, z);
          const std::uint32_t bit = (rows3[std::size_t(y + halo) + dim * std::size_t(z + halo)] >> (x + halo)) & 1u;
          const std::uint32_t full = (rows[std::size_t(y + halo) + dim * std::size_t(z + halo)] >> (x + halo)) & 1u;
          ASSERT_EQ(tile3[i], star ? tile[i] : 1234.5f) << "brick " << b << " at " << x << "," << y << "," << z;
          ASSERT_EQ(bit, star ? full : 0u) << "brick " << b << " at " << x << "," << y << "," << z;
        }
    const Coord o = brick_origin(band.bricks()[b].coord);
    for (int z = -halo; z < kBrickDim + halo; ++z)
      for (int y = -halo; y < kBrickDim + halo; ++y)
        for (int x = -halo; x < kBrickDim + halo; ++x) {
          const Coord c = o + Coord{x, y, z};
          ASSERT_EQ(tile[shape.index(x, y, z)], acc.value(c)) << "brick " << b << " at " << x << "," << y << "," << z;
          const std::uint32_t row = rows[std::size_t(y + halo) + dim * std::size_t(z + halo)];
          ASSERT_EQ(((row >> (x + halo)) & 1u) != 0, band.is_active(c))
              << "active bit, brick " << b << " at " << x << "," << y << "," << z;
        }
  }
  std::vector<std::uint32_t> wrong(dim * dim + 1);
  EXPECT_THROW(gather_tile(band, 0, halo, tile, wrong), Error);
  EXPECT_THROW(gather_box(band, std::span<const float>(decoded).first(kBrickVoxels), brick_neighborhood(band, 0), -halo,
                          kBrickDim + halo, tile3, rows3),
               Error);
}

INSTANTIATE_TEST_SUITE_P(Halos, TileTest, ::testing::Values(0, 1, 2, 3, 8));

TEST(Tile, ScatterWritesActiveVoxelsAndSignsOnly) {
  auto sb = make_shape_band("sphere", 40);
  NarrowBand& band = sb.band;
  const NarrowBand before = band;
  const TileShape shape{1};
  std::vector<float> tile(shape.size());
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) {
    gather_tile(band, b, 1, tile);
    for (float& v : tile) v = -v;
    scatter_active(band, b, 1, tile);
  }
  for (int z = -2; z <= 42; ++z)
    for (int y = -2; y <= 42; ++y)
      for (int x = -2; x <= 42; ++x) {
        const Coord c{x, y, z};
        if (before.is_active(c)) {
          ASSERT_EQ(*band.value(c), -*before.value(c));
          ASSERT_EQ(band.is_inside(c), -*before.value(c) < 0.0f);
        } else if (band.find_brick(brick_of(c)) != kNoBrick) {
          // Inactive voxels of allocated bricks keep their stored sign. (Unallocated ones
          // follow their row's neighbours, whose signs this test flips on purpose.)
          ASSERT_FALSE(band.is_active(c));
          ASSERT_EQ(band.is_inside(c), before.is_inside(c));
        }
      }
}

TEST(Tile, RejectsBadHaloAndSizes) {
  const auto sb = make_shape_band("sphere", 24);
  std::vector<float> small(10);
  EXPECT_THROW(gather_tile(sb.band, 0, 1, small), Error);
  std::vector<float> big(TileShape{9}.size());
  EXPECT_THROW(gather_tile(sb.band, 0, 9, big), Error);
  EXPECT_THROW(gather_tile(sb.band, 0, -1, small), Error);
}

}  // namespace
}  // namespace levelset
