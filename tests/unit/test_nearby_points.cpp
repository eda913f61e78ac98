// NearbyPoints (apps/nearby_points.hpp): k-nearest queries answered from one radius query
// around a centre must equal the kd-tree's, for positions anywhere within the reach (also at
// its corners, where the bound is tight), for sets smaller than k, with duplicated points, and
// off the reach (the tree's fallback); sheet_fit over it equals sheet_fit over the tree; on a
// lattice, where equal distances are everywhere, a walk of nearby queries (each bounded by the
// one before) returns exactly the k smallest by (distance, index).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>
#include <utility>
#include <vector>

#include "apps/nearby_points.hpp"
#include "apps/point_distance.hpp"

namespace levelset::apps {
namespace {

// Points on a wavy sheet z = 0.1 sin(3x) cos(2y) over [-1, 1]^2 with noise, some duplicated.
std::vector<Vec3d> wavy_sheet(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> g(0, 0.005);
  std::vector<Vec3d> p;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng);
    p.push_back({x, y, 0.1 * std::sin(3 * x) * std::cos(2 * y) + g(rng)});
    if (i % 97 == 0) p.push_back(p.back());  // exact duplicates: equal distances
  }
  return p;
}

// Compares NearbyPoints against the tree at `queries` random positions within `reach` of
// `centre` (and the box's corners); the distances must agree exactly, and the index sets too
// (up to equidistant points, which here are duplicates at the same position).
void expect_same_as_tree(const PointIndex& index, const Vec3d& centre, double reach, int k,
                         unsigned seed) {
  NearbyPoints near(index);
  near.prepare(centre, reach, k);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3d> queries;
  const double c = reach / std::sqrt(3.0);
  for (int i = 0; i < 8; ++i)
    queries.push_back(centre + Vec3d{(i & 1) ? c : -c, (i & 2) ? c : -c, (i & 4) ? c : -c});
  while (queries.size() < 300) {
    const Vec3d d{u(rng), u(rng), u(rng)};
    if (length(d) <= 1.0) queries.push_back(centre + d * reach);
  }
  for (const Vec3d& x : queries) {
    for (const int want : {1, k / 2, k}) {
      std::array<std::uint32_t, 256> ia{}, ib{};
      std::array<double, 256> da{}, db{};
      const int na = index.k_nearest(x, want, ia.data(), da.data());
      const int nb = near.k_nearest(x, want, ib.data(), db.data());
      ASSERT_EQ(na, nb);
      for (int i = 0; i < na; ++i) {
        ASSERT_EQ(da[std::size_t(i)], db[std::size_t(i)]) << "rank " << i;
        ASSERT_EQ(index.points()[ia[std::size_t(i)]], index.points()[ib[std::size_t(i)]])
            << "rank " << i;
      }
    }
  }
}

TEST(NearbyPoints, EqualsTheTreeWithinTheReach) {
  const PointIndex index(wavy_sheet(20000, 1));
  expect_same_as_tree(index, {0.1, -0.2, 0.0}, 0.05, 46, 2);
  expect_same_as_tree(index, {0.9, 0.95, 0.02}, 0.08, 16, 3);  // at the set's edge
  expect_same_as_tree(index, {0.0, 0.0, 0.3}, 0.02, 32, 4);    // off the sheet
  expect_same_as_tree(index, {-0.5, 0.5, 0.0}, 0.0, 8, 5);     // a single position
}

TEST(NearbyPoints, SmallSetsAndFallbacks) {
  const PointIndex few(wavy_sheet(20, 6));  // fewer points than k
  expect_same_as_tree(few, {0, 0, 0}, 0.5, 46, 7);
  const PointIndex index(wavy_sheet(5000, 8));
  NearbyPoints near(index);
  near.prepare({0, 0, 0}, 0.05, 16);
  std::array<std::uint32_t, 256> ia{}, ib{};
  std::array<double, 256> da{}, db{};
  // Beyond the reach, or more points than prepared for: the tree answers.
  for (const auto& [x, k] : {std::pair{Vec3d{0.5, 0.5, 0}, 16}, std::pair{Vec3d{0.01, 0, 0}, 40}}) {
    const int na = index.k_nearest(x, k, ia.data(), da.data());
    ASSERT_EQ(near.k_nearest(x, k, ib.data(), db.data()), na);
    for (int i = 0; i < na; ++i) EXPECT_EQ(da[std::size_t(i)], db[std::size_t(i)]);
  }
  near.prepare({0, 0, 0}, -1.0, 16);  // nothing prepared: the tree
  const int na = index.k_nearest({0, 0, 0}, 16, ia.data(), da.data());
  ASSERT_EQ(near.k_nearest({0, 0, 0}, 16, ib.data(), db.data()), na);
  for (int i = 0; i < na; ++i) EXPECT_EQ(da[std::size_t(i)], db[std::size_t(i)]);
}

// A sparse patch next to a dense cluster: the centre's k nearest are far, so the candidate
// ball would hold the whole cluster; prepare gives up past its cap and the answers (from the
// tree) are still exact. PointIndex::within with a cap reports the overflow.
TEST(NearbyPoints, CrowdedNeighbourhoodFallsBackToTheTree) {
  std::vector<Vec3d> p;
  for (int i = 0; i < 8; ++i) p.push_back({double(i) * 0.1, 0.0, 0.0});
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(0.0, 0.05);
  for (int i = 0; i < 100000; ++i) p.push_back({2.0 + u(rng), u(rng), u(rng)});
  const PointIndex index(p);
  std::vector<std::pair<std::uint32_t, double>> found;
  EXPECT_FALSE(index.within({2.0, 0.0, 0.0}, 1.0, 500, found));
  EXPECT_EQ(found.size(), 500u);
  EXPECT_TRUE(index.within({0.0, 0.0, 0.0}, 0.25, 500, found));
  EXPECT_EQ(found.size(), 3u);  // 0, 0.1 and 0.2
  expect_same_as_tree(index, {0.3, 0.0, 0.0}, 0.1, 46, 13);
}

// The k smallest (squared distance, index) pairs by brute force, the distances computed as
// PointIndex does (x - p per axis, squared and added in axis order).
std::vector<std::pair<double, std::uint32_t>> brute_k_nearest(const std::vector<Vec3d>& points,
                                                              const Vec3d& x, int k) {
  std::vector<std::pair<double, std::uint32_t>> all;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    double d = 0.0, diff = x.x - points[i].x;
    d += diff * diff;
    diff = x.y - points[i].y;
    d += diff * diff;
    diff = x.z - points[i].z;
    d += diff * diff;
    all.push_back({d, i});
  }
  std::sort(all.begin(), all.end());
  all.resize(std::size_t(k));
  return all;
}

TEST(NearbyPoints, LatticeWalkBreaksTiesByIndex) {
  // A 41 x 41 lattice of spacing 1 in z = 0, every 7th point doubled: most query positions
  // below see several points at exactly the same distance.
  std::vector<Vec3d> p;
  for (int j = 0; j <= 40; ++j)
    for (int i = 0; i <= 40; ++i) {
      p.push_back({double(i), double(j), 0.0});
      if ((i + 41 * j) % 7 == 0) p.push_back(p.back());
    }
  const PointIndex index(p);
  for (const int k : {8, 46, 132}) {
    NearbyPoints near(index);
    const Vec3d centre{20.0, 20.0, 0.0};
    near.prepare(centre, 4.0, k);
    // A walk in half-lattice steps over the reach (on lattice points, midpoints, cell centres,
    // and one step off the plane), then a jump back to the centre.
    std::vector<Vec3d> walk;
    for (int a = -5; a <= 5; ++a)
      for (int b = -5; b <= 5; ++b)
        walk.push_back(centre + Vec3d{0.5 * a, 0.5 * b, (a + b) % 3 == 0 ? 0.5 : 0.0});
    walk.push_back(centre);
    for (const Vec3d& x : walk) {
      if (length(x - centre) > 4.0) continue;
      std::array<std::uint32_t, 256> idx{};
      std::array<double, 256> d2{};
      ASSERT_EQ(near.k_nearest(x, k, idx.data(), d2.data()), k);
      const auto want = brute_k_nearest(p, x, k);
      for (int i = 0; i < k; ++i) {
        ASSERT_EQ(d2[std::size_t(i)], want[std::size_t(i)].first) << "k " << k << " rank " << i;
        ASSERT_EQ(idx[std::size_t(i)], want[std::size_t(i)].second) << "k " << k << " rank " << i;
      }
    }
  }
}

TEST(NearbyPoints, SheetFitIsTheSame) {
  const PointIndex index(wavy_sheet(20000, 9));
  NearbyPoints near(index);
  const Vec3d centre{0.2, 0.3, 0.0};
  near.prepare(centre, 0.04, 46);
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> u(-0.023, 0.023);  // within 0.04 of the centre
  for (int i = 0; i < 200; ++i) {
    const Vec3d x = centre + Vec3d{u(rng), u(rng), u(rng)};
    const Vec3d n{0.0, 0.0, 1.0};
    const SheetFit a = sheet_fit(index, x, n, 8, 46, 0.01), b = sheet_fit(near, x, n, 8, 46, 0.01);
    ASSERT_EQ(a.has_height, b.has_height);
    EXPECT_EQ(a.height_offset, b.height_offset);
    EXPECT_EQ(a.height_residual, b.height_residual);
    EXPECT_EQ(a.plane.signed_offset(n, 0.0, 0.0), b.plane.signed_offset(n, 0.0, 0.0));
  }
}

}  // namespace
}  // namespace levelset::apps
