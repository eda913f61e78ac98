// Voronoi regions by multi-source fast marching (thesis 3.5): against the brute-force
// nearest seed under unit cost, and against separate single-seed marches (geodesic
// distances) around an obstacle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "apps/voronoi.hpp"
#include "core/error.hpp"

namespace levelset::apps {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

TEST(Voronoi, UnitCostRegionsAreTheNearestSeedCells) {
  VoronoiOptions o;
  o.grid = dense_grid_for_resolution(BBox{{0, 0, 0}, {1, 1, 1}}, 32);
  o.seeds = {{{0.21, 0.33, 0.27}, 3}, {{0.77, 0.18, 0.62}, 7}, {{0.42, 0.81, 0.55}, 1},
             {{0.68, 0.64, 0.13}, 4}, {{0.15, 0.71, 0.86}, 9}};
  const VoronoiResult r = voronoi_regions(o);
  const DenseGrid& g = r.field.grid;
  const double h = g.voxel_size;
  std::uint64_t mismatches = 0, total = 0;
  double worst_distance_error = 0;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Vec3d p = g.world(i, j, k);
        double d1 = kInf, d2 = kInf;
        std::int32_t l1 = -1;
        for (const Seed& s : o.seeds) {
          const double d = length(p - s.position);
          if (d < d1) d2 = d1, d1 = d, l1 = s.label;
          else if (d < d2) d2 = d;
        }
        const std::size_t v = g.index(i, j, k);
        ++total;
        worst_distance_error = std::max(worst_distance_error, std::abs(r.field.time[v] - d1));
        if (r.field.label[v] == l1) continue;
        ++mismatches;
        // Within a voxel of the bisector, where d2 - d1 < 2 x (distance to the bisector).
        EXPECT_LT(d2 - d1, 2 * h) << "node " << i << " " << j << " " << k << " far from a bisector";
      }
  EXPECT_LT(double(mismatches), 0.02 * double(total));
  EXPECT_LT(worst_distance_error, 0.5 * h);
  EXPECT_EQ(r.unreached, 0u);
  EXPECT_EQ(r.region_voxels.size(), 5u);
  std::uint64_t sum = 0;
  for (const auto& [label, count] : r.region_voxels) sum += count;
  EXPECT_EQ(sum, g.voxel_count());
  EXPECT_GT(r.boundary_voxels, 0u);
}

// Two seeds on either side of a wall with a gap at the top: the region of the left seed
// ends at the wall, except what it reaches through the gap first. Reference: the arrival
// times of two separate single-seed marches (the smaller one decides).
TEST(Voronoi, ObstaclesGiveGeodesicRegions) {
  VoronoiOptions o;
  const double h = 0.02;
  BBox box;
  box.extend({0, 0, -2 * h});
  box.extend({1, 1, 2 * h});
  o.grid = dense_grid_for_voxel_size(box, h);
  const DenseGrid& g = o.grid;
  o.obstacles.mask.assign(g.voxel_count(), 0);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Vec3d p = g.world(i, j, k);
        o.obstacles.mask[g.index(i, j, k)] = std::abs(p.x - 0.3) < 0.03 && p.y < 0.8;
      }
  o.seeds = {{{0.1, 0.2, 0.0}, 0}, {{0.6, 0.3, 0.0}, 1}};
  const VoronoiResult r = voronoi_regions(o);

  std::vector<FastMarchingResult> single;
  for (const Seed& s : o.seeds) {
    FastMarchingOptions one = o;
    one.seeds = {s};
    single.push_back(fast_marching(one));
  }
  std::uint64_t mismatches = 0, geodesic_not_euclidean = 0;
  for (std::size_t v = 0; v < g.voxel_count(); ++v) {
    if (r.field.blocked[v]) {
      EXPECT_EQ(r.field.label[v], -1);
      continue;
    }
    const double t0 = single[0].time[v], t1 = single[1].time[v];
    EXPECT_NEAR(r.field.time[v], std::min(t0, t1), 0.5 * h);
    const std::int32_t expected = t0 <= t1 ? 0 : 1;
    if (r.field.label[v] != expected) {
      ++mismatches;
      EXPECT_LT(std::abs(t0 - t1), 2 * h);  // within a voxel of the (geodesic) bisector
    }
    // Nodes nearer the left seed as the crow flies but geodesically nearer the right one.
    const int i = int(v % std::size_t(g.nx)), j = int(v / std::size_t(g.nx) % std::size_t(g.ny));
    const Vec3d p = g.world(i, j, 0);
    const bool euclid_left = length(p - o.seeds[0].position) < length(p - o.seeds[1].position) - 2 * h;
    if (euclid_left && r.field.label[v] == 1) ++geodesic_not_euclidean;
  }
  EXPECT_LT(mismatches, g.voxel_count() / 100);
  // Just right of the wall: nearer seed 0 by straight line (0.279 < 0.312), but seed 0 must
  // climb to the gap first.
  EXPECT_GT(geodesic_not_euclidean, 50u);
  const std::size_t probe = g.index(int(std::lround(0.36 / h)), int(std::lround(0.1 / h)), 2);
  EXPECT_EQ(r.field.label[probe], 1);
}

TEST(Voronoi, SeedsMayShareALabelAndBadLabelsAreRejected) {
  VoronoiOptions o;
  o.grid = dense_grid_for_resolution(BBox{{0, 0, 0}, {1, 1, 1}}, 12);
  o.seeds = {{{0.1, 0.1, 0.1}, 2}, {{0.9, 0.9, 0.9}, 2}, {{0.5, 0.5, 0.5}, 5}};
  const VoronoiResult r = voronoi_regions(o);
  EXPECT_EQ(r.region_voxels.size(), 2u);
  o.seeds[1].label = -1;
  EXPECT_THROW(voronoi_regions(o), Error);
  o.seeds.clear();
  EXPECT_THROW(voronoi_regions(o), Error);
}

}  // namespace levelset::apps
