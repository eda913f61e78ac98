#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <filesystem>
#include <random>

#include <tbb/task_arena.h>

#include "core/error.hpp"
#include "distance/closest_point_transform.hpp"
#include "distance/unique_faces.hpp"
#include "geometry/point_triangle.hpp"
#include "grid/build_from_sdf.hpp"
#include "io/mesh_reader.hpp"
#include "distance_test_meshes.hpp"

namespace levelset {

namespace {

using test::box_mesh;
using test::brute_force_distance;
using test::icosphere;
using test::ray_parity_inside;

CptResult run_cpt(const TriangleMesh& mesh, int resolution, double band = 3.0, bool closest = false) {
  CptOptions options;
  options.frame = frame_for_resolution(mesh.bounds(), resolution, band);
  options.closest_points = closest;
  return closest_point_transform(mesh, options);
}

// Every active voxel holds the exact distance (double brute force, |error| <= 1e-5 h), every
// voxel within the band is active, and the closest points lie at that distance.
void expect_exact_band(const TriangleMesh& mesh, const CptResult& r, int stride) {
  const NarrowBand& band = r.band;
  const double h = band.voxel_size(), limit = band.half_width() * h;
  std::size_t i = 0, checked = 0;
  band.for_each_active_world([&](const Coord&, const Vec3d& p, float v) {
    const std::size_t k = i++;
    if (k % stride != 0) return;
    ++checked;
    const double ref = brute_force_distance(mesh, p);
    ASSERT_LE(std::abs(std::abs(double(v)) - ref), 1e-5 * h) << p.x << " " << p.y << " " << p.z;
    ASSERT_LE(ref, limit * (1 + 1e-9));
    if (!r.closest_points.empty()) {
      const Vec3f q = r.closest_points[k];
      const Vec3d qd{q.x, q.y, q.z};
      ASSERT_NEAR(length(p - qd), ref, 1e-5 * h + 1e-6 * length(qd));
      ASSERT_LE(brute_force_distance(mesh, qd), 1e-5 * h + 1e-6 * length(qd));
    }
  });
  EXPECT_GT(checked, 100u);
  // Completeness: voxels near the surface but comfortably inside the band are active.
  std::mt19937_64 rng(2);
  const BBox box = mesh.bounds();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int tested = 0;
  for (int s = 0; s < 20000 && tested < 2000; ++s) {
    Coord c;
    for (int a = 0; a < 3; ++a)
      c[a] = int(std::floor(((box.min[a] - limit) + u(rng) * (box.max[a] - box.min[a] + 2 * limit) -
                             band.origin()[a]) / h));
    const double ref = brute_force_distance(mesh, band.world(c));
    if (ref > limit * 0.999) continue;
    ++tested;
    ASSERT_TRUE(band.is_active(c)) << "voxel at distance " << ref / h << " h is missing";
  }
  EXPECT_GT(tested, 500);
}

TEST(ClosestPointTransform, BoxMeshGivesTheAnalyticBoxDistance) {
  const Vec3d lo{-1.0, -0.5, -0.25}, hi{1.0, 0.5, 0.25};
  const TriangleMesh mesh = box_mesh(lo, hi);
  const CptResult r = run_cpt(mesh, 96, 3.0, true);
  expect_exact_band(mesh, r, 7);
  const Vec3d c = (lo + hi) * 0.5, e = (hi - lo) * 0.5;
  r.band.for_each_active_world([&](const Coord&, const Vec3d& p, float v) {
    const Vec3d d = p - c;
    const Vec3d q{std::abs(d.x) - e.x, std::abs(d.y) - e.y, std::abs(d.z) - e.z};
    const double sdf = length(max(q, Vec3d{0, 0, 0})) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
    ASSERT_NEAR(v, sdf, 1e-5 * r.band.voxel_size());
  });
}

// Faces exactly on voxel planes (CGAL's corner.off case): voxels on the surface have distance
// 0, and their sign must come from the inside mask, never -0 (which reads as outside) nor a
// sign left to the rounding of the distance: all voxels on one planar face agree.
TEST(ClosestPointTransform, FacesOnVoxelPlanesGetOneSignPerFace) {
  const double h = 0.125;
  const Vec3d lo{0.5, 0.5, 0.5}, hi{2.0, 1.0, 1.5};
  CptOptions options;
  options.frame = GridFrame{h, Vec3d{0.0, 0.0, 0.0}, 3.0};
  const CptResult r = closest_point_transform(box_mesh(lo, hi), options);
  std::size_t on_face[6][2] = {};  // [face][negative]
  r.band.for_each_active_world([&](const Coord&, const Vec3d& p, float v) {
    ASSERT_FALSE(v == 0.0f && std::signbit(v)) << "-0 at " << p.x << " " << p.y << " " << p.z;
    if (std::abs(v) > std::numeric_limits<float>::min()) return;
    for (int a = 0; a < 3; ++a) {
      const bool in_face = [&] {
        for (int b = 0; b < 3; ++b)
          if (b != a && (p[b] <= lo[b] || p[b] >= hi[b])) return false;  // face interiors only
        return true;
      }();
      if (!in_face) continue;
      if (p[a] == lo[a]) ++on_face[2 * a][v < 0.0f];
      if (p[a] == hi[a]) ++on_face[2 * a + 1][v < 0.0f];
    }
  });
  for (int f = 0; f < 6; ++f) {
    EXPECT_GT(on_face[f][0] + on_face[f][1], 10u) << "face " << f << " is not on a voxel plane";
    EXPECT_TRUE(on_face[f][0] == 0 || on_face[f][1] == 0)
        << "face " << f << ": " << on_face[f][0] << " voxels outside, " << on_face[f][1] << " inside";
  }
}

TEST(ClosestPointTransform, SphereMeshWithinItsOwnApproximationError) {
  const double radius = 1.0;
  const TriangleMesh mesh = icosphere(4, radius, {0.1, -0.2, 0.3});  // 5120 faces
  // Largest gap between the sphere and its inscribed mesh (sagitta of the longest edge).
  double longest = 0;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, length(mesh.vertices[t[k]] - mesh.vertices[t[(k + 1) % 3]]));
  const double sagitta = radius - std::sqrt(radius * radius - longest * longest / 3.0);
  const CptResult r = run_cpt(mesh, 80);
  expect_exact_band(mesh, r, 5);
  r.band.for_each_active_world([&](const Coord&, const Vec3d& p, float v) {
    ASSERT_NEAR(v, length(p - Vec3d{0.1, -0.2, 0.3}) - radius, sagitta + 1e-6);
  });
}

TEST(ClosestPointTransform, IdenticalForOneAndTwoThreads) {
  const TriangleMesh mesh = icosphere(3, 1.0, {0, 0, 0});
  CptResult one, two;
  tbb::task_arena(1).execute([&] { one = run_cpt(mesh, 100, 3.0, true); });
  tbb::task_arena(2).execute([&] { two = run_cpt(mesh, 100, 3.0, true); });
  EXPECT_TRUE(one.band.identical(two.band));
  ASSERT_EQ(one.closest_points.size(), two.closest_points.size());
  EXPECT_EQ(std::memcmp(one.closest_points.data(), two.closest_points.data(),
                        one.closest_points.size() * sizeof(Vec3f)), 0);
}

TEST(ClosestPointTransform, FlippingHalfTheFacesChangesNothing) {
  const TriangleMesh mesh = icosphere(3, 1.0, {0, 0, 0});
  TriangleMesh flipped = mesh;
  std::mt19937 rng(4);
  for (auto& t : flipped.triangles)
    if (rng() % 2) std::swap(t[1], t[2]);
  const CptResult a = run_cpt(mesh, 72), b = run_cpt(flipped, 72);
  EXPECT_GT(b.faces_flipped, 0u);
  EXPECT_TRUE(a.band.identical(b.band));
}

TEST(ClosestPointTransform, DegenerateFacesAndDuplicatesDoNotChangeTheField) {
  const TriangleMesh clean = icosphere(2, 1.0, {0, 0, 0});
  TriangleMesh dirty = clean;
  const auto n = std::uint32_t(dirty.vertices.size());
  dirty.vertices.push_back(dirty.vertices[dirty.triangles[0][0]]);  // repeated vertex
  dirty.triangles.push_back(dirty.triangles[5]);                    // duplicate face
  const auto f0 = dirty.triangles[0];
  dirty.triangles.push_back({f0[0], f0[0], f0[1]});                 // repeated index (an edge)
  dirty.triangles.push_back({n, f0[1], f0[2]});                     // face 0 via the repeated vertex
  const auto e0 = dirty.triangles[9][0], e1 = dirty.triangles[9][1];  // an edge of the mesh
  dirty.vertices.push_back((dirty.vertices[e0] + dirty.vertices[e1]) * 0.5);
  dirty.triangles.push_back({e0, e1, n + 1});                      // collinear: zero area
  const CptResult r_clean = run_cpt(clean, 64), r_dirty = run_cpt(dirty, 64);
  ASSERT_EQ(r_clean.band.active_voxel_count(), r_dirty.band.active_voxel_count());
  // Same voxels, same signs; distances equal up to the rounding of a different but
  // equivalent closest feature (a degenerate face's edge instead of the face's own edge).
  const auto va = r_clean.band.values(), vb = r_dirty.band.values();
  const double h = r_clean.band.voxel_size();
  for (std::size_t i = 0; i < va.size(); ++i) {
    ASSERT_EQ(va[i] < 0, vb[i] < 0) << i;
    ASSERT_NEAR(va[i], vb[i], 1e-6 * h) << i;
  }
  for (std::uint32_t b = 0; b < r_clean.band.brick_count(); ++b)
    ASSERT_EQ(r_clean.band.inside_mask(b), r_dirty.band.inside_mask(b)) << b;
}

TEST(ClosestPointTransform, RejectsBadMeshes) {
  auto expect_code = [](const TriangleMesh& m, ErrorCode code, double voxel = 0.05) {
    CptOptions options;
    options.frame = GridFrame{voxel, {-2, -2, -2}, 3};
    try {
      closest_point_transform(m, options);
      ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), code) << e.what();
    }
  };
  expect_code(TriangleMesh{}, ErrorCode::InvalidArgument);
  TriangleMesh nan_mesh = box_mesh({0, 0, 0}, {1, 1, 1});
  nan_mesh.vertices[4].y = std::nan("");
  expect_code(nan_mesh, ErrorCode::NonFinite);
  TriangleMesh bad_index = box_mesh({0, 0, 0}, {1, 1, 1});
  bad_index.triangles[2][1] = 99;
  expect_code(bad_index, ErrorCode::InvalidArgument);
  try {
    CptOptions options;
    options.frame = GridFrame{1e-6, {0, 0, 0}, 3};
    closest_point_transform(box_mesh({0, 0, 0}, {10, 10, 10}), options);
    ADD_FAILURE() << "accepted a 10^7-voxel-wide grid";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
    EXPECT_NE(std::string(e.reason()).find("voxel budget"), std::string::npos) << e.what();
  }
}

const Vec3d kRay = Vec3d{0.5773, 0.6123, 0.5401} / length(Vec3d{0.5773, 0.6123, 0.5401});

std::filesystem::path cgal_mesh(const char* name) {
  return std::filesystem::path(LEVELSET_CGAL_DATA) / "meshes" / name;
}

TEST(ClosestPointTransform, CgalKnotSignAgreesWithRayParity) {
  const auto path = cgal_mesh("knot.off");
  ASSERT_TRUE(std::filesystem::exists(path))
      << "CGAL data not installed: " << path << " (install-deps.sh installs it)";
  const TriangleMesh mesh = read_mesh(path).mesh;
  const CptResult r = run_cpt(mesh, 128);
  expect_exact_band(mesh, r, 29);
  std::mt19937_64 rng(8);
  const BBox box = mesh.bounds();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int inside = 0, checked = 0;
  for (int s = 0; s < 3000; ++s) {
    Coord c;
    for (int a = 0; a < 3; ++a)
      c[a] = int(((box.min[a] + u(rng) * (box.max[a] - box.min[a])) - r.band.origin()[a]) / r.band.voxel_size());
    const Vec3d p = r.band.world(c);
    if (brute_force_distance(mesh, p) < 1e-3 * r.band.voxel_size()) continue;  // on the surface
    const bool ref = ray_parity_inside(mesh, p, kRay);
    ASSERT_EQ(r.band.is_inside(c), ref) << p.x << " " << p.y << " " << p.z;
    inside += ref;
    ++checked;
  }
  EXPECT_GT(inside, 50);
  EXPECT_GT(checked - inside, 50);
}

TEST(ClosestPointTransform, CgalElephantWithHolesDeepInsideAndFarOutside) {
  const auto path = cgal_mesh("elephant-with-holes.off");
  ASSERT_TRUE(std::filesystem::exists(path))
      << "CGAL data not installed: " << path << " (install-deps.sh installs it)";
  const TriangleMesh mesh = read_mesh(path).mesh;
  const CptResult r = run_cpt(mesh, 128);
  // Reference: the elephant without holes is CGAL's elephant.off; deep inside = inside it and
  // far from its surface.
  const TriangleMesh closed = read_mesh(cgal_mesh("elephant.off")).mesh;
  std::mt19937_64 rng(12);
  const BBox box = mesh.bounds();
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  const double h = r.band.voxel_size();
  int deep = 0, far = 0;
  for (int s = 0; s < 4000; ++s) {
    Coord c;
    for (int a = 0; a < 3; ++a)
      c[a] = int(((box.min[a] + u(rng) * (box.max[a] - box.min[a])) - r.band.origin()[a]) / h);
    const Vec3d p = r.band.world(c);
    const double d = brute_force_distance(closed, p);
    if (d < 6 * h) continue;
    if (ray_parity_inside(closed, p, kRay)) {
      ++deep;
      ASSERT_TRUE(r.band.is_inside(c)) << "deep inside point reported outside";
    } else {
      ++far;
      ASSERT_FALSE(r.band.is_inside(c)) << "far outside point reported inside";
    }
  }
  EXPECT_GT(deep, 30);
  EXPECT_GT(far, 300);
}

}  // namespace
}  // namespace levelset

namespace levelset {
namespace {

TEST(UniqueFaces, DuplicatesAddUpByOrientation) {
  TriangleMesh m = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const std::size_t n = m.triangles.size();
  m.triangles.push_back(m.triangles[0]);                                            // same copy
  m.triangles.push_back({m.triangles[1][1], m.triangles[1][2], m.triangles[1][0]});  // rotated copy
  m.triangles.push_back({m.triangles[2][0], m.triangles[2][2], m.triangles[2][1]});  // opposite copy
  m.vertices.push_back(m.vertices[0]);                                              // welded twin
  m.triangles.push_back({std::uint32_t(m.vertices.size() - 1), 0, 1});             // degenerate
  const UniqueFacesResult r = unique_faces(m);
  ASSERT_EQ(r.mesh.triangles.size(), m.triangles.size());  // indices preserved
  auto collapsed = [&](std::size_t f) {
    const auto& t = r.mesh.triangles[f];
    return t[0] == t[1] && t[1] == t[2];
  };
  EXPECT_FALSE(collapsed(0));
  EXPECT_FALSE(collapsed(1));
  EXPECT_TRUE(collapsed(2));      // face 2 and its opposite copy cancel: both go
  EXPECT_TRUE(collapsed(n + 2));
  EXPECT_TRUE(collapsed(n));      // repeats of faces 0 and 1 go
  EXPECT_TRUE(collapsed(n + 1));
  EXPECT_TRUE(collapsed(n + 3));  // degenerate after welding
  EXPECT_EQ(r.degenerate_removed, 1u);
  EXPECT_EQ(r.duplicates_removed, 4u);
  for (std::size_t f = 3; f < n; ++f) EXPECT_EQ(r.mesh.triangles[f], m.triangles[f]);
}

}  // namespace
}  // namespace levelset
