// weld_exact, unique_faces and orient_faces group by hash tables and a counting sort (one pass
// each, no comparison sort of everything): checked against brute-force references built with
// std::map on soups with many exact repeats, and on a cone whose apex has more edges than the
// insertion-sorted buckets take.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>

#include "core/index_hash_table.hpp"
#include "distance/open_edges.hpp"
#include "distance/orient_faces.hpp"
#include "distance/unique_faces.hpp"
#include "distance_test_meshes.hpp"

namespace levelset {
namespace {

TEST(WeldExact, LowestIndexPerExactPositionSignedZerosEqualNaNsAlone) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Vec3d> p = {{0, 0, 0}, {1, 2, 3}, {-0.0, 0, -0.0}, {1, 2, 3}, {nan, 0, 0},
                                {nan, 0, 0}, {1, 2, std::nextafter(3.0, 4.0)}, {1, 2, 3}};
  const std::vector<std::uint32_t> expected = {0, 1, 0, 1, 4, 5, 6, 1};
  EXPECT_EQ(weld_exact(p), expected);
}

TEST(WeldExact, MatchesAMapOnManyRepeats) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> coord(-6, 6);
  std::vector<Vec3d> p(50000);
  for (Vec3d& v : p) v = {0.25 * coord(rng), 0.25 * coord(rng), 0.25 * coord(rng)};  // 2197 distinct
  std::map<std::tuple<double, double, double>, std::uint32_t> first;
  std::vector<std::uint32_t> expected(p.size());
  for (std::uint32_t i = 0; i < p.size(); ++i)
    expected[i] = first.try_emplace({p[i].x, p[i].y, p[i].z}, i).first->second;
  EXPECT_EQ(weld_exact(p), expected);
}

TEST(UniqueFaces, MatchesABruteForceGroupingOfRepeatedFaces) {
  // Faces over 30 vertices, many of them repeated with either orientation and rotated.
  std::mt19937 rng(11);
  TriangleMesh m;
  for (int i = 0; i < 30; ++i) m.vertices.push_back({std::cos(i * 0.7) * (1 + i), std::sin(i * 1.3) * i, 0.1 * i * i});
  std::uniform_int_distribution<std::uint32_t> vertex(0, 29);
  std::uniform_int_distribution<int> coin(0, 1), turn(0, 2);
  for (int f = 0; f < 3000; ++f) {
    std::array<std::uint32_t, 3> t = {vertex(rng), vertex(rng), vertex(rng)};
    if (coin(rng)) std::swap(t[1], t[2]);
    const int r = turn(rng);
    m.triangles.push_back({t[r], t[(r + 1) % 3], t[(r + 2) % 3]});
  }
  // Reference: group by the sorted vertex set; net orientation; keep the first face of the
  // net orientation (degenerate faces: a repeated index, none have zero area otherwise).
  std::map<std::array<std::uint32_t, 3>, std::vector<std::pair<std::uint32_t, int>>> groups;
  std::uint64_t degenerate = 0;
  for (std::uint32_t f = 0; f < m.triangles.size(); ++f) {
    std::array<std::uint32_t, 3> t = m.triangles[f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++degenerate;
      continue;
    }
    const int rot = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
    const int orientation = t[(rot + 1) % 3] < t[(rot + 2) % 3] ? 1 : -1;
    std::sort(t.begin(), t.end());
    groups[t].push_back({f, orientation});
  }
  std::vector<bool> keep(m.triangles.size(), false);
  std::uint64_t duplicates = 0, repeated_sets = 0;
  for (const auto& [key, faces] : groups) {
    int net = 0;
    for (const auto& [f, o] : faces) net += o;
    repeated_sets += faces.size() > 1;
    bool kept = false;
    for (const auto& [f, o] : faces)
      if (net != 0 && o == (net > 0 ? 1 : -1)) {
        keep[f] = kept = true;
        break;
      }
    duplicates += faces.size() - (kept ? 1 : 0);
  }
  ASSERT_GT(repeated_sets, 100u);
  const UniqueFacesResult r = unique_faces(m);
  EXPECT_EQ(r.degenerate_removed, degenerate);
  EXPECT_EQ(r.duplicates_removed, duplicates);
  ASSERT_EQ(r.mesh.triangles.size(), m.triangles.size());
  for (std::size_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = r.mesh.triangles[f];
    if (keep[f])
      EXPECT_EQ(t, m.triangles[f]) << "face " << f;
    else
      EXPECT_TRUE(t[0] == t[1] && t[1] == t[2]) << "face " << f;
  }
}

TEST(OrientFaces, ConeWithAHighDegreeApexBecomesConsistentAndOutward) {
  // A closed cone: 200 side faces meet at the apex and 200 base faces at the base centre
  // (both vertices carry more edges than the insertion-sorted buckets).
  constexpr int kSides = 200;
  TriangleMesh cone;
  cone.vertices.push_back({0, 0, 2});  // apex
  cone.vertices.push_back({0, 0, 0});  // base centre
  for (int i = 0; i < kSides; ++i) {
    const double a = 2 * 3.141592653589793 * i / kSides;
    cone.vertices.push_back({std::cos(a), std::sin(a), 0});
  }
  for (std::uint32_t i = 0; i < kSides; ++i) {
    const std::uint32_t p = 2 + i, q = 2 + (i + 1) % kSides;
    cone.triangles.push_back({0, p, q});
    cone.triangles.push_back({1, q, p});
  }
  ASSERT_GT(test::signed_volume6(cone), 0.0);
  TriangleMesh scrambled = cone;
  const std::vector<bool> flipped = test::flip_random_half(scrambled, 3);
  const OrientResult r = orient_faces(scrambled, {});
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.inconsistent_edges, 0u);
  EXPECT_EQ(r.nonmanifold_edges, 0u);
  std::uint64_t expected_flips = 0;
  for (bool f : flipped) expected_flips += f;
  EXPECT_EQ(r.faces_flipped, expected_flips);
  EXPECT_GT(test::signed_volume6(r.mesh), 0.0);
  for (std::size_t t = 0; t < cone.triangles.size(); ++t) {
    const auto& a = cone.triangles[t];
    const auto& b = r.mesh.triangles[t];
    const bool same = (a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) || (a[0] == b[1] && a[1] == b[2] && a[2] == b[0]) ||
                      (a[0] == b[2] && a[1] == b[0] && a[2] == b[1]);
    EXPECT_TRUE(same) << "face " << t;
  }
}

}  // namespace
}  // namespace levelset

namespace levelset {
namespace {

// IndexHashTable grown from 16 slots to hold 50,000 distinct keys among 200,000 lookups:
// every key maps to the id of its first occurrence, as a std::map says.
TEST(IndexHashTable, GrowsAndMapsEveryKeyToItsFirstId) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<std::uint64_t> pick(0, 49999);
  std::vector<std::uint64_t> keys;  // distinct, by id
  std::map<std::uint64_t, std::uint32_t> reference;
  IndexHashTable table(1);
  int grown = 0;
  for (int i = 0; i < 200000; ++i) {
    const std::uint64_t key = pick(rng) * 0x100000001ull;  // keys that differ in high bits too
    if (table.full()) {
      table.grow([&](std::uint32_t id) { return keys[id]; });
      ++grown;
    }
    const std::uint32_t id =
        table.find_or_insert(key, std::uint32_t(keys.size()), [&](std::uint32_t k) { return keys[k] == key; });
    const bool fresh = id == keys.size();
    if (fresh) keys.push_back(key);
    const auto [it, inserted] = reference.try_emplace(key, id);
    ASSERT_EQ(it->second, id) << "lookup " << i;
    ASSERT_EQ(inserted, fresh) << "lookup " << i;
  }
  EXPECT_EQ(keys.size(), reference.size());
  EXPECT_GT(grown, 10);
}

}  // namespace
}  // namespace levelset
