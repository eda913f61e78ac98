#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <utility>

#include <tbb/task_arena.h>

#include "core/error.hpp"
#include "distance/orient_faces.hpp"
#include "distance/unique_faces.hpp"
#include "distance_test_meshes.hpp"

namespace levelset {
namespace {

// Every manifold edge (exactly two uses) is used once in each direction.
void expect_consistent(const TriangleMesh& m, const std::string& what) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed, undirected;
  for (const auto& f : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = f[k], b = f[(k + 1) % 3];
      ++directed[{a, b}];
      ++undirected[std::minmax(a, b)];
    }
  int manifold = 0;
  for (const auto& [e, n] : undirected) {
    if (n != 2) continue;
    ++manifold;
    EXPECT_EQ(directed[std::make_pair(e.first, e.second)], 1)
        << what << " edge " << e.first << "-" << e.second;
  }
  EXPECT_GT(manifold, 0) << what;
}

TEST(OrientFaces, RandomlyFlippedSphereAndTorusComeBackAsGenerated) {
  for (int which = 0; which < 2; ++which) {
    const TriangleMesh original = which == 0 ? test::icosphere(3) : test::torus(2.0, 0.6, 40, 16);
    ASSERT_GT(test::signed_volume6(original), 0.0);
    TriangleMesh scrambled = original;
    const std::vector<bool> flipped = test::flip_random_half(scrambled, 5 + which);
    const OrientResult r = orient_faces(scrambled, {});
    EXPECT_EQ(r.components, 1u);
    EXPECT_EQ(r.inconsistent_edges, 0u);
    EXPECT_EQ(r.nonmanifold_edges, 0u);
    std::uint64_t expected_flips = 0;
    for (std::size_t t = 0; t < original.triangles.size(); ++t) {
      expected_flips += flipped[t];
      // Same triangle up to a cyclic rotation.
      const auto& a = original.triangles[t];
      const auto& b = r.mesh.triangles[t];
      const bool same = (a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) ||
                        (a[0] == b[1] && a[1] == b[2] && a[2] == b[0]) ||
                        (a[0] == b[2] && a[1] == b[0] && a[2] == b[1]);
      ASSERT_TRUE(same) << "mesh " << which << " face " << t;
    }
    EXPECT_EQ(r.faces_flipped, expected_flips);
    EXPECT_EQ(r.mesh.vertices, original.vertices);
  }
}

TEST(OrientFaces, SplitVerticesJoinByPosition) {
  // A pure soup: every face has its own three vertices (as after splitting along seams).
  const TriangleMesh shared = test::icosphere(2);
  TriangleMesh soup;
  for (const auto& f : shared.triangles) {
    const std::uint32_t base = std::uint32_t(soup.vertices.size());
    for (std::uint32_t v : f) soup.vertices.push_back(shared.vertices[v]);
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  const TriangleMesh original = soup;
  const std::vector<bool> flipped = test::flip_random_half(soup, 3);
  const OrientResult r = orient_faces(soup, {});
  EXPECT_EQ(r.components, 1u);
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    const auto& a = original.triangles[t];
    const auto& b = r.mesh.triangles[t];
    // Same orientation as generated: b is a cyclic rotation of a.
    const bool same = (a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) ||
                      (a[0] == b[1] && a[1] == b[2] && a[2] == b[0]) ||
                      (a[0] == b[2] && a[1] == b[0] && a[2] == b[1]);
    ASSERT_TRUE(same) << t << (flipped[t] ? " (flipped)" : "");
  }
  TriangleMesh bad = soup;
  bad.vertices[0].y = std::numeric_limits<double>::infinity();
  try {
    (void)orient_faces(bad, {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NonFinite);
  }
}

TEST(OrientFaces, InwardSphereIsTurnedOutward) {
  TriangleMesh inward = test::icosphere(2, 3.0, {10, -4, 7});
  for (auto& f : inward.triangles) std::swap(f[1], f[2]);
  const OrientResult r = orient_faces(inward, {});
  EXPECT_EQ(r.faces_flipped, inward.triangles.size());
  // Volume about the mesh's own centre (it is far from the origin).
  TriangleMesh centred = r.mesh;
  for (auto& v : centred.vertices) v -= Vec3d{10, -4, 7};
  EXPECT_GT(test::signed_volume6(centred), 0.0);
}

TEST(OrientFaces, CgalShuffledMeshesBecomeConsistentWithPositiveVolume) {
  for (const char* name : {"tet-shuffled.off", "cube-shuffled.off", "blobby-shuffled.off"}) {
    const TriangleMesh m = test::load_cgal_mesh(name);
    const OrientResult r = orient_faces(m, {});
    expect_consistent(r.mesh, name);
    EXPECT_EQ(r.inconsistent_edges, 0u) << name;
    // Positive volume about the centroid of the vertices.
    TriangleMesh centred = r.mesh;
    Vec3d c{};
    for (const auto& v : centred.vertices) c += v;
    c = c / double(centred.vertices.size());
    for (auto& v : centred.vertices) v -= c;
    EXPECT_GT(test::signed_volume6(centred), 0.0) << name;
  }
}

TEST(OrientFaces, ComponentsDegenerateAndNonManifoldFaces) {
  // Two spheres, one inward; plus a degenerate face and a fin on a non-manifold edge.
  TriangleMesh a = test::icosphere(1, 1.0, {0, 0, 0});
  TriangleMesh b = test::icosphere(1, 1.0, {5, 0, 0});
  for (auto& f : b.triangles) std::swap(f[0], f[1]);
  TriangleMesh m = a;
  const std::uint32_t off = std::uint32_t(m.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto f : b.triangles) m.triangles.push_back({f[0] + off, f[1] + off, f[2] + off});
  const std::size_t spheres = m.triangles.size();
  const std::uint32_t e0 = m.triangles[0][0], e1 = m.triangles[0][1];  // an edge of sphere a
  m.triangles.push_back({e0, e0, e1});                                 // repeated index
  m.vertices.push_back(m.vertices[e0]);  // a distinct index at the same position
  m.triangles.push_back({e0, e1, std::uint32_t(m.vertices.size() - 1)});  // zero area
  // A fin on edge (e0, e1) makes that edge non-manifold (three non-degenerate faces).
  m.vertices.push_back({0, 0, 3});
  m.triangles.push_back({e0, e1, std::uint32_t(m.vertices.size() - 1)});
  const OrientResult r = orient_faces(m, {});
  EXPECT_EQ(r.degenerate_faces, 2u);
  EXPECT_EQ(r.nonmanifold_edges, 1u);
  EXPECT_EQ(r.components, 3u);  // two spheres and the fin (the sphere stays connected)
  EXPECT_EQ(r.mesh.triangles[spheres], m.triangles[spheres]);
  EXPECT_EQ(r.mesh.triangles[spheres + 1], m.triangles[spheres + 1]);
  TriangleMesh first, second;
  first.vertices = second.vertices = r.mesh.vertices;
  for (auto& v : second.vertices) v -= Vec3d{5, 0, 0};
  for (std::size_t t = 0; t < a.triangles.size(); ++t)
    first.triangles.push_back(r.mesh.triangles[t]);
  for (std::size_t t = a.triangles.size(); t < spheres; ++t)
    second.triangles.push_back(r.mesh.triangles[t]);
  EXPECT_GT(test::signed_volume6(first), 0.0);
  EXPECT_GT(test::signed_volume6(second), 0.0);
  expect_consistent(first, "first");
  expect_consistent(second, "second");
}

TEST(OrientFaces, MoebiusStripReportsTheInconsistentEdge) {
  TriangleMesh m;
  const int n = 12;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n, half = a / 2;
    for (int s : {-1, 1}) {
      const double r = 2 + 0.5 * s * std::cos(half);
      m.vertices.push_back({r * std::cos(a), r * std::sin(a), 0.5 * s * std::sin(half)});
    }
  }
  for (int i = 0; i < n; ++i) {
    const std::uint32_t p0 = 2 * i, p1 = 2 * i + 1;
    std::uint32_t q0 = 2 * ((i + 1) % n), q1 = 2 * ((i + 1) % n) + 1;
    if (i == n - 1) std::swap(q0, q1);  // the half twist
    m.triangles.push_back({p0, q0, q1});
    m.triangles.push_back({p0, q1, p1});
  }
  const OrientResult r = orient_faces(m, {});
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.inconsistent_edges, 1u);
}

TEST(OrientFaces, DeterministicAcrossThreadCountsAndRejectsBadIndices) {
  TriangleMesh m = test::load_cgal_mesh("blobby-shuffled.off");
  OrientResult one, two;
  tbb::task_arena(1).execute([&] { one = orient_faces(m, {}); });
  tbb::task_arena(2).execute([&] { two = orient_faces(m, {}); });
  EXPECT_EQ(one.mesh.triangles, two.mesh.triangles);
  EXPECT_EQ(one.faces_flipped, two.faces_flipped);
  m.triangles.push_back({0, 1, std::uint32_t(m.vertices.size())});
  try {
    (void)orient_faces(m, {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
  }
}

}  // namespace
}  // namespace levelset

namespace levelset {
namespace {

// unique_faces' output shares one index per position: orienting it with the weld skipped gives
// exactly what the full weld gives (the closest point transform relies on this).
TEST(OrientFaces, WeldedInputSkipsTheWeldWithTheSameResult) {
  for (const char* name : {"cube-shuffled.off", "knot.off", "elephant-with-holes.off"}) {
    TriangleMesh m = test::load_cgal_mesh(name);
    test::flip_random_half(m, 9);
    const TriangleMesh unique = unique_faces(m).mesh;
    OrientOptions welded;
    welded.welded = true;
    const OrientResult a = orient_faces(unique, OrientOptions{});
    const OrientResult b = orient_faces(unique, welded);
    EXPECT_GT(a.faces_flipped, 0u) << name;
    EXPECT_EQ(a.mesh.triangles, b.mesh.triangles) << name;
    EXPECT_EQ(a.faces_flipped, b.faces_flipped) << name;
    EXPECT_EQ(a.components, b.components) << name;
    EXPECT_EQ(a.inconsistent_edges, b.inconsistent_edges) << name;
  }
}

}  // namespace
}  // namespace levelset
