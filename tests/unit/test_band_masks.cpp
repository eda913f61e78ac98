// Marching cubes' counting pass reads bits instead of values: the cell classes from the band's
// masks (band_masks), the owned edges as row masks, the triangle counts from a 256-entry table.
// Each is checked against the value form it replaces, on every brick of bands with unallocated
// neighbours, random fields with ambiguous faces, and several iso levels.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "grid/band_builder.hpp"
#include "shape_band.hpp"
#include "surface/band_masks.hpp"
#include "surface/cell_loops.hpp"
#include "surface/cell_tile.hpp"

namespace levelset {
namespace {

using namespace surface_detail;

// Random values on a sparse set of bricks (every third brick of a 4^3 block missing, some
// voxels inactive), so that tiles meet unallocated neighbours on both sides of the surface.
NarrowBand sparse_random_band(unsigned seed) {
  GridFrame frame;
  frame.voxel_size = 0.5;
  frame.half_width = 3.0;
  BandBuilder builder(frame);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(-1.4f, 1.4f);
  std::uniform_int_distribution<int> coin(0, 9);
  for (int bz = 0; bz < 4; ++bz)
    for (int by = 0; by < 4; ++by)
      for (int bx = 0; bx < 4; ++bx) {
        if ((bx + 2 * by + 3 * bz) % 3 == 0) continue;
        BrickMask active, inside;
        float dense[kBrickVoxels];
        for (int n = 0; n < kBrickVoxels; ++n) {
          dense[n] = value(rng);
          active.assign(n, coin(rng) != 0);
          inside.assign(n, dense[n] < 0.0f);
        }
        builder.add_brick({bx, by, bz}, active, inside, dense);
      }
  return builder.finish(false);
}

void expect_masks_match_values(const NarrowBand& band, double iso, const char* what) {
  SCOPED_TRACE(std::string(what) + " iso " + std::to_string(iso));
  const DecodedBand decoded = decode_band(band, iso);
  EXPECT_EQ(decoded.work, bricks_with_crossings(band, iso));
  CellTile tile;
  ValidCells from_values, from_masks;
  int mixed = 0;
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) {
    gather_cell_tile(band, b, tile, decoded.values.values());
    // The row-copy gather from decoded bricks against the general box gather from the band.
    CellTile plain;
    gather_cell_tile(band, b, plain);
    ASSERT_TRUE(std::equal(plain.values.begin(), plain.values.begin() + CellTile::kSize, tile.values.begin()))
        << "brick " << b;
    ASSERT_EQ(plain.active_rows, tile.active_rows) << "brick " << b;
    from_values.compute(tile, iso);
    const NeighborSigns signs =
        resolve_neighbor_signs(band, tile.around, -CellTile::kHalo, CellTile::kDim - CellTile::kHalo);
    ASSERT_EQ(signs.known, tile.signs.known) << "brick " << b;
    ASSERT_EQ(signs.inside, tile.signs.inside) << "brick " << b;
    cell_masks(band, decoded, tile.around, signs, from_masks);
    ASSERT_EQ(from_masks.active_rows, from_values.active_rows) << "brick " << b;
    ASSERT_EQ(from_masks.inside_rows, from_values.inside_rows) << "brick " << b;
    ASSERT_EQ(from_masks.valid_rows, from_values.valid_rows) << "brick " << b;
    ASSERT_EQ(from_masks.mixed_rows, from_values.mixed_rows) << "brick " << b;
    mixed += from_values.mixed_cells;
    for (int z = 0; z < kBrickDim; ++z)
      for (int y = 0; y < kBrickDim; ++y) {
        // The row mask against the edge-by-edge test it replaces.
        std::uint32_t cr[3], expected = 0;
        from_values.crossing_edges(y, z, cr);
        for (int x = 0; x < kBrickDim; ++x)
          for (int a = 0; a < 3; ++a)
            if (((cr[a] >> (x + 1)) & 1u) && from_values.edge_used(x, y, z, a)) expected |= 1u << (3 * x + a);
        ASSERT_EQ(from_values.owned_edges(y, z), expected) << "brick " << b << " row " << y << " " << z;
        for (int x = 0; x < kBrickDim; ++x) {
          if (!((from_values.mixed_row(y, z) >> (x + ValidCells::kH)) & 1u)) continue;
          for (int i = 0; i < 8; ++i) {
            const int cx = x + (i & 1), cy = y + ((i >> 1) & 1), cz = z + ((i >> 2) & 1);
            ASSERT_EQ(corner_value(decoded, tile.around, cx, cy, cz, iso),
                      double(tile.values[std::size_t(CellTile::index(cx, cy, cz))]) - iso);
          }
        }
      }
  }
  EXPECT_GT(mixed, 0) << "the band has no surface at this iso: the test checks nothing";
}

TEST(BandMasks, CellClassesFromMasksMatchTheGatheredValues) {
  const auto knot = test::make_shape_band("knot", 64);
  const double h = knot.band.voxel_size();
  for (double iso : {0.0, 0.7 * h, -1.3 * h}) expect_masks_match_values(knot.band, iso, "knot");
  for (unsigned seed : {1u, 2u})
    for (double iso : {0.0, 0.25, -0.4}) expect_masks_match_values(sparse_random_band(seed), iso, "sparse random");
}

TEST(CellLoops, UnambiguousTriangleCountsMatchTheLoops) {
  int ambiguous = 0;
  for (int m = 0; m < 256; ++m) {
    // A mask without an ambiguous face: its loops (and counts) are those of decisions 0.
    const int plain = cell::ambiguous_faces(m) != 0 ? -1 : int(cell::loops_for(m, 0).fan_triangles);
    // A mask with an ambiguous face: two decisions on it give different loop sets.
    bool depends = false;
    for (int d = 1; d < 64 && !depends; ++d)
      depends = cell::loops_for(m, d).loop_count != cell::loops_for(m, 0).loop_count ||
                cell::loops_for(m, d).edges != cell::loops_for(m, 0).edges;
    EXPECT_EQ(plain < 0, depends) << "mask " << m;
    ambiguous += plain < 0;
    for (int d = 0; d < 64; ++d) {
      const cell::LoopSet& ls = cell::loops_for(m, d);
      int triangles = 0, centres = 0;
      for (int l = 0; l < ls.loop_count; ++l) {
        const int n = ls.length[l];
        const bool centre = n > 3 && ((ls.doubled_face_loops >> l) & 1);
        triangles += n == 3 ? 1 : (centre ? n : n - 2);
        centres += centre;
      }
      ASSERT_EQ(ls.fan_triangles, triangles) << "mask " << m << " decisions " << d;
      ASSERT_EQ(ls.centre_vertices, centres) << "mask " << m << " decisions " << d;
      if (plain >= 0) {
        ASSERT_EQ(triangles, plain) << "mask " << m << " decisions " << d;
        ASSERT_EQ(centres, 0) << "mask " << m;
      }
    }
  }
  EXPECT_GT(ambiguous, 0);
  EXPECT_LT(ambiguous, 256);
}

TEST(CellLoops, LookupMatchesClassify) {
  const cell::LoopLookup& lookup = cell::loop_lookup();
  for (int m = 0; m < 256; ++m) ASSERT_EQ(int(lookup.ambiguous[m]), cell::ambiguous_faces(m)) << "mask " << m;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  int with_decisions = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    double a[8];
    for (double& v : a) v = value(rng);
    int m, d;
    cell::classify(a, m, d);
    ASSERT_EQ(cell::face_decisions(a, lookup.ambiguous[m]), d) << "trial " << trial;
    ASSERT_EQ(&lookup.at(m, d), &cell::loops_for(m, d));
    with_decisions += d != 0;
  }
  EXPECT_GT(with_decisions, 100);
}

}  // namespace
}  // namespace levelset
