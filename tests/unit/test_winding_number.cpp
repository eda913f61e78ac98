#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/error.hpp"
#include "distance/winding_number.hpp"
#include "distance_test_meshes.hpp"
#include "geometry/point_triangle.hpp"

namespace levelset {
namespace {

double distance_to_mesh(const TriangleMesh& m, const Vec3d& p) {
  double best = 1e300;
  for (const auto& f : m.triangles)
    best = std::min(
        best, closest_point_on_triangle(p, m.vertices[f[0]], m.vertices[f[1]], m.vertices[f[2]])
                  .distance_squared);
  return std::sqrt(best);
}

// Random points in the mesh's bounding box grown by 20%, at least `gap` (relative to the box
// diagonal) from the surface.
std::vector<Vec3d> sample_points(const TriangleMesh& m, int count, double gap, std::uint32_t seed) {
  const BBox box = m.bounds();
  const Vec3d e = box.extent();
  const double diag = length(e);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-0.2, 1.2);
  std::vector<Vec3d> out;
  while (int(out.size()) < count) {
    const Vec3d p = box.min + Vec3d{e.x * U(rng), e.y * U(rng), e.z * U(rng)};
    if (distance_to_mesh(m, p) >= gap * diag) out.push_back(p);
  }
  return out;
}

void expect_closed_mesh_accurate(const TriangleMesh& m, const char* name) {
  const WindingNumberTree tree = build_winding_tree(m);
  int inside = 0;
  double worst2 = 0.0, worst4 = 0.0;
  for (const Vec3d& p : sample_points(m, 400, 0.01, 3)) {
    const double exact = winding_number_exact(m, p);
    // Closed and outward: exactly 0 or 1 up to rounding.
    ASSERT_LT(std::min(std::abs(exact), std::abs(exact - 1.0)), 1e-9) << name;
    worst2 = std::max(worst2, std::abs(winding_number(tree, p) - exact));
    worst4 = std::max(worst4, std::abs(winding_number(tree, p, 4.0) - exact));
    inside += exact > 0.5;
  }
  EXPECT_LT(worst2, 1e-2) << name;  // default beta = 2
  EXPECT_LT(worst4, 1e-3) << name;
  EXPECT_GT(inside, 3) << name;
}

TEST(WindingNumber, ClosedMeshesAreOneInsideZeroOutside) {
  expect_closed_mesh_accurate(test::icosphere(4, 2.0, {0.3, -0.2, 0.1}), "icosphere");
  expect_closed_mesh_accurate(test::torus(2.0, 0.7, 60, 24), "torus");
  expect_closed_mesh_accurate(test::load_cgal_mesh("knot.off"), "knot.off");
  expect_closed_mesh_accurate(test::load_cgal_mesh("cube.off"), "cube.off");
}

TEST(WindingNumber, OpenHemisphereIsHalfAtTheCentreOfItsOpening) {
  const TriangleMesh m = test::hemisphere(24, 48);
  const WindingNumberTree tree = build_winding_tree(m);
  // The full hemisphere subtends 2 pi from its centre; the mesh's inscribed polygon a bit less.
  EXPECT_NEAR(winding_number(tree, {0, 0, 0}), 0.5, 5e-3);
  EXPECT_NEAR(winding_number_exact(m, {0, 0, 0}), 0.5, 5e-3);
  // Inside the dome: between 1/2 and 1; below the opening: between 0 and 1/2; far away: ~0.
  const double dome = winding_number(tree, {0, 0, 0.5});
  EXPECT_GT(dome, 0.5);
  EXPECT_LT(dome, 1.0);
  const double below = winding_number(tree, {0, 0, -0.5});
  EXPECT_GT(below, 0.0);
  EXPECT_LT(below, 0.5);
  EXPECT_NEAR(dome + below, 1.0, 0.02);  // solid angles of the dome seen from +-z sum to ~4 pi
  EXPECT_NEAR(winding_number(tree, {0, 0, 50}), 0.0, 1e-3);
  for (const Vec3d& p : {Vec3d{0.1, 0.2, 0.3}, Vec3d{0.3, -0.5, -0.2}, Vec3d{2, 1, 0.5}}) {
    EXPECT_NEAR(winding_number(tree, p), winding_number_exact(m, p), 1e-2);
    EXPECT_NEAR(winding_number(tree, p, 4.0), winding_number_exact(m, p), 1e-3);
  }
}

TEST(WindingNumber, ErrorShrinksWithBeta) {
  const TriangleMesh m = test::load_cgal_mesh("knot.off");
  const WindingNumberTree tree = build_winding_tree(m);
  std::mt19937_64 rng(9);
  const BBox box = m.bounds();
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst[3] = {0, 0, 0};
  const double betas[3] = {1.0, 2.0, 4.0};
  for (int i = 0; i < 300; ++i) {
    // Anywhere in the box, close to the surface or not.
    const Vec3d p =
        box.min + Vec3d{box.extent().x * U(rng), box.extent().y * U(rng), box.extent().z * U(rng)};
    const double exact = winding_number_exact(m, p);
    for (int b = 0; b < 3; ++b)
      worst[b] = std::max(worst[b], std::abs(winding_number(tree, p, betas[b]) - exact));
  }
  EXPECT_LT(worst[2], worst[1]);
  EXPECT_LT(worst[1], worst[0]);
  EXPECT_LT(worst[1], 1e-2);
  EXPECT_LT(worst[2], 5e-4);
  // beta so large that every leaf is summed exactly: the brute-force value up to rounding.
  const Vec3d p = box.center();
  EXPECT_NEAR(winding_number(tree, p, 1e9), winding_number_exact(m, p), 1e-12);
}

// A node's expansion is its solid-angle field's Taylor series to second order, so its error
// falls as r^-5 with the distance r (one order per doubling more than a first-order series'
// r^-4): a soup of six random triangles (one leaf, the root) seen from 24 directions at 4, 8
// and 16 times its radius, against the exact sum.
TEST(WindingNumber, FarFieldIsASecondOrderExpansion) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  TriangleMesh soup;
  for (int t = 0; t < 6; ++t) {
    for (int k = 0; k < 3; ++k) soup.vertices.push_back(Vec3d{N(rng), N(rng), N(rng)} * 0.4);
    soup.triangles.push_back({std::uint32_t(3 * t), std::uint32_t(3 * t + 1), std::uint32_t(3 * t + 2)});
  }
  const WindingNumberTree tree = build_winding_tree(soup);
  ASSERT_EQ(tree.nodes.size(), 1u);
  const double radius = tree.nodes[0].radius;
  std::vector<Vec3d> directions;
  for (int i = 0; i < 24; ++i) {
    const Vec3d v{N(rng), N(rng), N(rng)};
    directions.push_back(v / length(v));
  }
  double worst[3] = {0, 0, 0};
  for (int s = 0; s < 3; ++s)
    for (const Vec3d& d : directions) {
      const Vec3d p = tree.nodes[0].center + d * (radius * double(4 << s));
      worst[s] = std::max(worst[s], std::abs(winding_number(tree, p, 1.0) - winding_number_exact(soup, p)));
    }
  EXPECT_GT(worst[0], 0.0);
  EXPECT_GT(worst[0] / worst[1], 26.0);  // r^-5: 32 per doubling (33 and 31.6 here); r^-4 would give 16
  EXPECT_GT(worst[1] / worst[2], 26.0);
  EXPECT_LT(worst[0], 1e-3);
}

TEST(WindingNumber, SoupsFlippedFacesAndEmptyMesh) {
  // Flipping faces changes the exact value; the tree follows the exact value.
  TriangleMesh m = test::icosphere(3);
  test::flip_random_half(m, 4);
  const WindingNumberTree tree = build_winding_tree(m);
  for (const Vec3d& p : {Vec3d{0, 0, 0}, Vec3d{0.5, 0.1, 0}, Vec3d{3, 0, 0}})
    EXPECT_NEAR(winding_number(tree, p, 4.0), winding_number_exact(m, p), 1e-3);
  EXPECT_EQ(winding_number(build_winding_tree(TriangleMesh{}), {0, 0, 0}), 0.0);
  // Tree identical for any thread count.
  const TriangleMesh big = test::icosphere(5);
  WindingNumberTree one, two;
  tbb::task_arena(1).execute([&] { one = build_winding_tree(big); });
  tbb::task_arena(2).execute([&] { two = build_winding_tree(big); });
  ASSERT_EQ(one.nodes.size(), two.nodes.size());
  EXPECT_EQ(one.order, two.order);
  for (std::size_t i = 0; i < one.nodes.size(); ++i) {
    EXPECT_EQ(one.nodes[i].center, two.nodes[i].center);
    EXPECT_EQ(one.far[i].cubic, two.far[i].cubic);
    EXPECT_EQ(one.far[i].quad, two.far[i].quad);
  }
}

// The lazily built tree: one build, the same tree for every caller, also when it is first
// asked for from inside parallel tasks (the build's own parallel parts must not pick up those
// outer tasks and call get() again on the same thread).
TEST(WindingNumber, LazyTreeIsBuiltOnceAlsoFromInsideParallelTasks) {
  const TriangleMesh m = test::load_cgal_mesh("bunny00.off");
  const LazyWindingTree lazy(m);
  EXPECT_FALSE(lazy.built());
  std::vector<const WindingNumberTree*> seen(512, nullptr);
  tbb::parallel_for(std::size_t(0), seen.size(), [&](std::size_t i) { seen[i] = &lazy.get(); });
  EXPECT_TRUE(lazy.built());
  for (const WindingNumberTree* t : seen) ASSERT_EQ(t, seen[0]);
  const WindingNumberTree direct = build_winding_tree(m);
  const Vec3d c = (m.bounds().min + m.bounds().max) * 0.5;
  EXPECT_EQ(winding_number(*seen[0], c), winding_number(direct, c));
  EXPECT_EQ(seen[0]->order, direct.order);
  const LazyWindingTree given(direct);
  EXPECT_EQ(&given.get(), &direct);
}

TEST(WindingNumber, BuildRejectsBadInput) {
  TriangleMesh m = test::icosphere(1);
  m.triangles.push_back({0, 1, 9999});
  EXPECT_THROW((void)build_winding_tree(m), Error);
  m.triangles.pop_back();
  m.vertices[3].x = std::nan("");
  try {
    (void)build_winding_tree(m);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NonFinite);
  }
}

TEST(WindingNumber, BatchEqualsTheSingleQueriesBitForBit) {
  const TriangleMesh knot = test::load_cgal_mesh("knot.off");
  const WindingNumberTree tree = build_winding_tree(knot);
  // A brick-sized cluster of points near the surface, and points spread over the box.
  const BBox box = knot.bounds();
  const double h = box.longest_side() / 64.0;
  std::vector<Vec3d> points;
  const Vec3d corner = knot.vertices[0] - Vec3d{4, 4, 4} * h;
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) points.push_back(corner + Vec3d{double(i), double(j), double(k)} * h);
  const std::vector<Vec3d> spread = sample_points(knot, 300, 0.0, 5);
  points.insert(points.end(), spread.begin(), spread.end());
  for (const double beta : {2.0, 3.0}) {
    std::vector<double> batch(points.size());
    winding_numbers(tree, points, beta, batch);
    int differ = 0;
    for (std::size_t i = 0; i < points.size(); ++i) differ += batch[i] != winding_number(tree, points[i], beta);
    EXPECT_EQ(differ, 0) << "beta " << beta;
  }
  std::vector<double> none;
  winding_numbers(tree, {}, 2.0, none);  // an empty batch is fine
}

}  // namespace
}  // namespace levelset
