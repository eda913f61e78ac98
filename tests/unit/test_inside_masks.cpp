#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include <tbb/task_arena.h>

#include "core/error.hpp"
#include "distance/brick_triangle_lists.hpp"
#include "distance/exact_predicates.hpp"
#include "distance/inside_masks.hpp"
#include "distance/orient_faces.hpp"
#include "distance/winding_number.hpp"
#include "distance_test_meshes.hpp"
#include "geometry/point_triangle.hpp"

namespace levelset {
namespace {

struct Masks {
  BrickTriangleLists lists;
  InsideMasksResult result;
  GridFrame frame;

  // f(world position, grid coordinates, inside bit) for every voxel of every brick.
  template <typename F>
  void for_each_voxel(F&& f) const {
    for (std::size_t i = 0; i < lists.bricks.size(); ++i) {
      const Coord o = brick_origin(lists.bricks[i]);
      for (int n = 0; n < kBrickVoxels; ++n) {
        const Coord g = o + local_coord(n);
        const Vec3d p =
            frame.origin + Vec3d{double(g.x), double(g.y), double(g.z)} * frame.voxel_size;
        f(p, g, result.inside[i].test(n));
      }
    }
  }
};

BrickTriangleLists lists_for(const TriangleMesh& mesh, const GridFrame& frame, double margin) {
  BinTrianglesOptions bin;
  bin.frame = frame;
  bin.margin = margin;
  return bin_triangles_to_bricks(mesh, bin);
}

Masks compute(const TriangleMesh& oriented, double h, Vec3d origin, double margin_voxels = 3.0) {
  Masks m;
  m.frame.voxel_size = h;
  m.frame.origin = origin;
  m.lists = lists_for(oriented, m.frame, margin_voxels * h);
  const WindingNumberTree tree = build_winding_tree(oriented);
  InsideMasksOptions options;
  options.frame = m.frame;
  m.result = compute_inside_masks(oriented, tree, m.lists, options);
  EXPECT_EQ(m.result.inside.size(), m.lists.bricks.size());
  if (m.result.open_edges == 0) {
    // Closed: exact rays and jumps, no tree query; the per-brick tree path (one query per
    // brick) agrees on every voxel.
    EXPECT_EQ(m.result.winding_queries, 0u);
    EXPECT_GE(m.result.ray_queries, m.lists.bricks.empty() ? 0u : 1u);
    InsideMasksOptions by_tree = options;
    by_tree.closed_by_rays = false;
    const InsideMasksResult t = compute_inside_masks(oriented, tree, m.lists, by_tree);
    EXPECT_EQ(t.winding_queries, m.lists.bricks.size());
    EXPECT_EQ(t.direct_bricks, 0u);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < m.lists.bricks.size(); ++i) differ += !(t.inside[i] == m.result.inside[i]);
    EXPECT_EQ(differ, 0u) << "bricks where rays and tree disagree";
  } else {
    // One query per brick, 512 (minus voxels on the surface) per brick near open edges.
    EXPECT_GE(m.result.winding_queries, m.lists.bricks.size());
    EXPECT_LE(m.result.winding_queries, m.lists.bricks.size() + 511 * m.result.direct_bricks);
  }
  return m;
}

// Maps a mesh given in grid coordinates to world coordinates (exactly, for dyadic h and origin).
TriangleMesh to_world(TriangleMesh m, double h, Vec3d origin) {
  for (auto& v : m.vertices) v = origin + v * h;
  return m;
}

TEST(InsideMasks, IcosphereMatchesThePointInPolyhedronOnEveryVoxel) {
  const Vec3d centre{0.0137, -0.0291, 0.0419};
  const TriangleMesh sphere = test::icosphere(4, 1.2, centre);  // 5120 faces, radius 12 voxels
  ASSERT_EQ(sphere.triangles.size(), 5120u);
  const Masks m = compute(sphere, 0.1, {0.0, 0.0, 0.0});
  ASSERT_GT(m.lists.bricks.size(), 50u);
  // The icosphere is convex: inside iff behind every face plane (no voxel lies near one at this
  // generic offset), checked on every voxel; the brute-force winding number on a sample.
  std::vector<std::pair<Vec3d, Vec3d>> planes;  // (point, outward normal)
  for (const auto& f : sphere.triangles) {
    const Vec3d& a = sphere.vertices[f[0]];
    planes.push_back({a, cross(sphere.vertices[f[1]] - a, sphere.vertices[f[2]] - a)});
  }
  std::mt19937 rng(1);
  std::size_t checked = 0, exact_checked = 0, inside = 0;
  m.for_each_voxel([&](const Vec3d& p, const Coord&, bool bit) {
    bool behind_all = true;
    for (const auto& [a, n] : planes)
      if (!(dot(n, p - a) < 0.0)) {
        behind_all = false;
        break;
      }
    ASSERT_EQ(bit, behind_all) << p.x << " " << p.y << " " << p.z;
    if (rng() % 64 == 0) {
      ASSERT_EQ(bit, winding_number_exact(sphere, p) > 0.5);
      ++exact_checked;
    }
    ++checked;
    inside += bit;
  });
  EXPECT_GT(inside, checked / 10);
  EXPECT_LT(inside, checked * 9 / 10);
  EXPECT_GT(exact_checked, 300u);
}

TEST(InsideMasks, KnotMatchesRayParityOnRandomVoxels) {
  const TriangleMesh knot = orient_faces(test::load_cgal_mesh("knot.off"), {}).mesh;
  const BBox box = knot.bounds();
  const double h = box.longest_side() / 128.0;
  const Masks m = compute(knot, h, box.min - Vec3d{0.37 * h, 0.71 * h, 0.13 * h});
  const Vec3d dir = Vec3d{0.5377, 0.8243, 0.1791} / length(Vec3d{0.5377, 0.8243, 0.1791});
  std::mt19937 rng(2);
  int checked = 0, inside = 0;
  m.for_each_voxel([&](const Vec3d& p, const Coord&, bool bit) {
    if (rng() % 200 != 0) return;
    ASSERT_EQ(bit, test::ray_parity_inside(knot, p, dir)) << p.x << " " << p.y << " " << p.z;
    ++checked;
    inside += bit;
  });
  EXPECT_GT(checked, 2000);
  EXPECT_GT(inside, checked / 20);
}

// Grid-aligned adversarial input: faces on voxel-centre planes, edges and vertices on grid
// lines. Points on the surface follow the documented convention: inside iff the point moved
// infinitesimally by -x (then -y, then -z) is inside.
TEST(InsideMasks, GridAlignedBoxHasNoSpecklesAndFollowsTheSurfaceConvention) {
  const double h = 0.5;
  const Vec3d origin{-2.0, -1.5, -3.0};
  const std::array<int, 3> lo{3, 8, -2}, hi{23, 14, 30};
  for (int step : {1, 3}) {
    const TriangleMesh box = to_world(test::grid_box(lo, hi, step), h, origin);
    const Masks m = compute(box, h, origin);
    std::size_t on_surface = 0;
    m.for_each_voxel([&](const Vec3d&, const Coord& g, bool bit) {
      bool expected = true;
      for (int a = 0; a < 3; ++a) expected = expected && lo[a] < g[a] && g[a] <= hi[a];
      ASSERT_EQ(bit, expected) << "step " << step << " voxel " << g.x << " " << g.y << " " << g.z;
      bool on = false;
      for (int a = 0; a < 3; ++a) on = on || g[a] == lo[a] || g[a] == hi[a];
      on_surface += on;
    });
    EXPECT_GT(on_surface, 1000u);
  }
}

// Large triangles (one pair per face) whose edges and corners lie exactly on voxel centres and
// grid lines, at several positions relative to the brick boundaries (faces on the first, last
// and middle voxels of a brick, boxes spanning one or many bricks).
TEST(InsideMasks, CoarseGridAlignedBoxesFollowTheSurfaceConventionEverywhere) {
  const double h = 0.25;
  const Vec3d origin{-1.0, 0.5, -2.0};
  const std::vector<std::pair<std::array<int, 3>, std::array<int, 3>>> boxes = {
      {{3, 3, 3}, {125, 125, 125}}, {{0, 0, 0}, {7, 7, 7}},     {{7, 8, 15}, {16, 23, 24}},
      {{-8, -1, 1}, {8, 15, 6}},    {{1, 6, 7}, {2, 7, 8}},     {{-5, 3, 0}, {40, 31, 39}},
      {{8, 8, 8}, {9, 40, 17}},     {{3, -9, 4}, {60, 5, 13}}};
  for (const auto& [lo, hi] : boxes)
    for (int step : {1000, 5}) {
      const TriangleMesh box = to_world(test::grid_box(lo, hi, step), h, origin);
      const Masks m = compute(box, h, origin);
      ASSERT_EQ(m.result.open_edges, 0u);
      std::size_t wrong = 0;
      m.for_each_voxel([&](const Vec3d&, const Coord& g, bool bit) {
        bool expected = true;
        for (int a = 0; a < 3; ++a) expected = expected && lo[a] < g[a] && g[a] <= hi[a];
        if (bit != expected && ++wrong <= 5)
          ADD_FAILURE() << "box " << lo[0] << " " << lo[1] << " " << lo[2] << " .. " << hi[0]
                        << " " << hi[1] << " " << hi[2] << " step " << step << " voxel " << g.x
                        << " " << g.y << " " << g.z << " bit " << bit;
      });
      EXPECT_EQ(wrong, 0u);
    }
}

// CGAL's cheese-box.off: an axis-aligned cube of half side 0.066550000931700007; at the frame
// the server uses for -r 128 (voxel size 0.1331 / 122, cube from voxel 3 to 125) its faces lie
// on voxel planes and its corners on voxel centres (up to the rounding of (v - origin) / h, so
// only voxels at least 1e-6 voxels off the surface are checked).
TEST(InsideMasks, CheeseBoxOnVoxelCentresMatchesTheAnalyticBox) {
  const std::string path = std::string(LEVELSET_CGAL_DATA) + "/meshes/cheese-box.off";
  ASSERT_TRUE(std::ifstream(path).good()) << "missing " << path << " (install-deps.sh installs it)";
  const TriangleMesh mesh = orient_faces(test::load_cgal_mesh("cheese-box.off"), {}).mesh;
  ASSERT_EQ(mesh.triangles.size(), 12u);
  Vec3d lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const Vec3d& v : mesh.vertices)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], v[a]);
      hi[a] = std::max(hi[a], v[a]);
    }
  const double h = (hi.x - lo.x) / 122.0;
  const Vec3d origin = lo - Vec3d{3.0, 3.0, 3.0} * h;
  const Masks m = compute(mesh, h, origin);
  std::size_t wrong = 0, checked = 0;
  m.for_each_voxel([&](const Vec3d&, const Coord& g, bool bit) {
    double sd = -1e300;  // signed distance to the box in voxels (> 0 outside)
    for (int a = 0; a < 3; ++a) {
      const double c = (origin[a] + double(g[a]) * h - 0.5 * (lo[a] + hi[a])) / h;
      sd = std::max(sd, std::abs(c) - 0.5 * (hi[a] - lo[a]) / h);
    }
    if (std::abs(sd) < 1e-6) return;
    ++checked;
    if (bit != (sd < 0.0) && ++wrong <= 5)
      ADD_FAILURE() << "voxel " << g.x << " " << g.y << " " << g.z << " bit " << bit;
  });
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(checked, 10000u);
}

TEST(InsideMasks, GridAlignedOctahedronFollowsTheSymbolicPerturbation) {
  const double h = 0.25;
  const Vec3d origin{1.0, -2.0, 0.5};
  const std::array<int, 3> c{12, 9, 10};
  const int r = 10;
  const TriangleMesh oct = to_world(test::grid_octahedron(c, r), h, origin);
  const Masks m = compute(oct, h, origin);
  std::size_t on_surface = 0;
  m.for_each_voxel([&](const Vec3d&, const Coord& g, bool bit) {
    // The perturbation p - (e1, e2, e3), e1 >> e2 >> e3, emulated with 1e-3, 1e-6, 1e-9 (exact
    // enough for unit normals and integer positions).
    const double x = g.x - c[0] - 1e-3, y = g.y - c[1] - 1e-6, z = g.z - c[2] - 1e-9;
    const bool expected = std::abs(x) + std::abs(y) + std::abs(z) < r;
    ASSERT_EQ(bit, expected) << g.x << " " << g.y << " " << g.z;
    on_surface += std::abs(g.x - c[0]) + std::abs(g.y - c[1]) + std::abs(g.z - c[2]) == r;
  });
  EXPECT_EQ(on_surface, 4u * r * r + 2u);  // lattice points on the surface
}

TEST(InsideMasks, SphereSnappedToGridPointsFollowsTheSymbolicPerturbation) {
  // Every vertex on a voxel centre: faces, edges and vertices through voxel centres in all
  // directions, folds and zero-area faces from the snapping. Reference: the exact winding
  // number at p - (e1, e2, e3) emulated with (1e-4, 1e-8, 1e-12) voxels, faithful here because
  // normals are small integer vectors (|n_i| <= 2 * 16^2) and plane offsets integers.
  for (double radius : {6.3, 9.7}) {
    TriangleMesh m = test::icosphere(2, radius, {8.2, 7.9, 8.4});
    for (auto& v : m.vertices) v = Vec3d{std::round(v.x), std::round(v.y), std::round(v.z)};
    const Masks masks = compute(m, 1.0, {0, 0, 0});
    std::size_t on_surface = 0;
    masks.for_each_voxel([&](const Vec3d& p, const Coord&, bool bit) {
      const Vec3d q = p - Vec3d{1e-4, 1e-8, 1e-12};
      ASSERT_EQ(bit, winding_number_exact(m, q) > 0.5)
          << radius << ": " << p.x << " " << p.y << " " << p.z;
      for (const auto& f : m.triangles)
        if (closest_point_on_triangle(p, m.vertices[f[0]], m.vertices[f[1]], m.vertices[f[2]])
                .distance_squared == 0.0) {
          ++on_surface;
          break;
        }
    });
    EXPECT_GT(on_surface, 40u);
  }
}

TEST(InsideMasks, OverlappingSpheresSoupIsTheirUnion) {
  // Two closed spheres as one self-intersecting soup: winding number 2 where they overlap.
  const Vec3d ca{0.02, 0.01, -0.03}, cb{0.83, 0.21, 0.07};
  TriangleMesh soup = test::icosphere(3, 1.0, ca);
  const TriangleMesh b = test::icosphere(3, 0.8, cb);
  test::append_mesh(soup, b);
  const TriangleMesh a = test::icosphere(3, 1.0, ca);
  const WindingNumberTree ta = build_winding_tree(a), tb = build_winding_tree(b);
  const Masks m = compute(soup, 0.08, {0, 0, 0});
  std::size_t twice = 0;
  m.for_each_voxel([&](const Vec3d& p, const Coord&, bool bit) {
    const bool in_a = winding_number(ta, p) > 0.5, in_b = winding_number(tb, p) > 0.5;
    ASSERT_EQ(bit, in_a || in_b);
    twice += in_a && in_b;
  });
  EXPECT_GT(twice, 100u);
}

// Closed soups whose bricks fall into separate face-connected groups: a hollow ball (outer
// sphere outward, inner sphere inward: inside only between them), a separate sphere far away,
// and a sphere overlapping the ball (winding number 2). Each group is anchored by its own exact
// ray; with no ray budget the tree path takes over and gives the same masks.
TEST(InsideMasks, ClosedSoupsInSeparateGroupsAndTheRayBudget) {
  TriangleMesh soup;
  auto append = [&](const TriangleMesh& part, bool inward) { test::append_mesh(soup, part, inward); };
  const Vec3d c{0.013, -0.021, 0.017}, far{5.03, 0.11, -0.07}, over{0.97, 0.05, 0.02};
  append(test::icosphere(3, 1.0, c), false);
  append(test::icosphere(3, 0.5, c), true);
  append(test::icosphere(3, 0.6, far), false);
  append(test::icosphere(3, 0.4, over), false);
  const Masks m = compute(soup, 0.05, {0, 0, 0}, 1.0);  // also checks rays == tree path
  ASSERT_EQ(m.result.open_edges, 0u);
  EXPECT_GE(m.result.ray_queries, 2u);  // the far sphere's bricks touch no other group
  std::size_t checked = 0, shell = 0, twice = 0;
  m.for_each_voxel([&](const Vec3d& p, const Coord&, bool bit) {
    const double rc = length(p - c), rf = length(p - far), ro = length(p - over);
    // Away from the faceted surfaces (0.01 covers the icospheres' chord error), the analytic
    // answer: w = [rc < 1] - [rc < 0.5] + [rf < 0.6] + [ro < 0.4].
    const double margin = 0.01;
    if (std::abs(rc - 1.0) < margin || std::abs(rc - 0.5) < margin || std::abs(rf - 0.6) < margin ||
        std::abs(ro - 0.4) < margin)
      return;
    const int w = (rc < 1.0) - (rc < 0.5) + (rf < 0.6) + (ro < 0.4);
    ASSERT_EQ(bit, w >= 1) << p.x << " " << p.y << " " << p.z;
    ++checked;
    shell += rc > 0.5 && rc < 1.0;
    twice += w == 2;
  });
  EXPECT_GT(checked, 10000u);
  EXPECT_GT(shell, 1000u);
  EXPECT_GT(twice, 100u);

  InsideMasksOptions options;
  options.frame = m.frame;
  options.max_ray_work = 0.0;
  const InsideMasksResult fallback = compute_inside_masks(soup, build_winding_tree(soup), m.lists, options);
  EXPECT_EQ(fallback.ray_queries, 0u);
  EXPECT_EQ(fallback.winding_queries, m.lists.bricks.size());
  EXPECT_EQ(fallback.inside, m.result.inside);
}

// 70 nested cubes, all outward, inside one brick: winding numbers up to 70 there. Exact by the
// ray path (its bricks keep their winding numbers rather than 70 masks); the tree path's error
// grows with the number of shells, and next to the outermost cube it reads w > 1/2 outside.
TEST(InsideMasks, DeeplyNestedShellsAreExact) {
  TriangleMesh soup;
  for (int k = 0; k < 70; ++k) {
    const double r = 0.3 + 0.04 * k;
    test::append_mesh(soup, test::box_mesh({3.5 - r, 3.52 - r, 3.54 - r}, {3.5 + r, 3.52 + r, 3.54 + r}));
  }
  GridFrame frame;
  frame.voxel_size = 1.0;
  const BrickTriangleLists lists = lists_for(soup, frame, 1.0);
  InsideMasksOptions options;
  options.frame = frame;
  const InsideMasksResult r = compute_inside_masks(soup, build_winding_tree(soup), lists, options);
  EXPECT_EQ(r.open_edges, 0u);
  EXPECT_GE(r.ray_queries, 1u);
  EXPECT_EQ(r.winding_queries, 0u);
  const double outer = 0.3 + 0.04 * 69;
  int inside = 0;
  for (std::size_t i = 0; i < lists.bricks.size(); ++i) {
    const Coord o = brick_origin(lists.bricks[i]);
    for (int n = 0; n < kBrickVoxels; ++n) {
      const Coord g = o + local_coord(n);
      const bool in = std::abs(g.x - 3.5) < outer && std::abs(g.y - 3.52) < outer && std::abs(g.z - 3.54) < outer;
      ASSERT_EQ(r.inside[i].test(n), in) << g.x << " " << g.y << " " << g.z;
      inside += in;
    }
  }
  EXPECT_GT(inside, 100);
}

// The ray path's exact integers against an independent reference: soups of random closed
// tetrahedra (some inverted, some flat on a line, some repeated) with corners on the half-integer
// lattice, so that voxel centres fall on faces, edges and corners. Reference: per tetrahedron,
// whether the voxel centre displaced by -(e1, e2, e3), e1 >> e2 >> e3 > 0 (the crossings'
// convention), is behind all four faces (exact orient3d; a zero decided by the perturbation,
// which adds e . ((b - a) x (c - a))), counted with the tetrahedron's orientation.
TEST(InsideMasks, RandomTetrahedraOnTheLatticeMatchAPointInTetrahedronReference) {
  auto behind = [](const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& p) {
    const int s = orient3d_sign(a, b, c, p);
    if (s != 0) return s > 0;
    // The perturbation's terms: the normal's components, x first (exact signs by orient2d).
    const int nx = orient2d_sign(a.y, a.z, b.y, b.z, c.y, c.z);
    const int ny = orient2d_sign(a.z, a.x, b.z, b.x, c.z, c.x);
    const int nz = orient2d_sign(a.x, a.y, b.x, b.y, c.x, c.y);
    return (nx != 0 ? nx : (ny != 0 ? ny : nz)) > 0;
  };
  std::mt19937 rng(21);
  std::uniform_int_distribution<int> L(0, 24);  // half-integer lattice over [0, 12]
  std::size_t checked = 0, inside_total = 0, deep = 0;
  for (int trial = 0; trial < 12; ++trial) {
    struct Tet {
      Vec3d v[4];
      int orientation;
    };
    std::vector<Tet> tets;
    for (int i = 0; i < 25; ++i) {
      Tet t;
      for (auto& v : t.v) v = {0.5 * L(rng), 0.5 * L(rng), 0.5 * L(rng)};
      if (i % 9 == 4) {  // flat: all corners on one line (every face without area)
        t.v[2] = (t.v[0] + t.v[1]) * 0.5;
        t.v[3] = t.v[0] * 2.0 - t.v[1];
      }
      // Positive orientation: v3 behind face (v0, v1, v2) (swap two corners otherwise).
      if (orient3d_sign(t.v[0], t.v[1], t.v[2], t.v[3]) < 0) std::swap(t.v[1], t.v[2]);
      t.orientation = (rng() % 4 == 0) ? -1 : 1;
      tets.push_back(t);
      if (i % 7 == 3) tets.push_back(t);  // repeated
    }
    TriangleMesh soup;
    for (const Tet& t : tets) {
      const auto base = std::uint32_t(soup.vertices.size());
      for (const auto& v : t.v) soup.vertices.push_back(v);
      // Faces turning counterclockwise seen from outside (the opposite corner behind them).
      const std::array<std::array<std::uint32_t, 3>, 4> faces = {{{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {0, 2, 3}}};
      for (auto f : faces) {
        if (t.orientation < 0) std::swap(f[1], f[2]);
        soup.triangles.push_back({base + f[0], base + f[1], base + f[2]});
      }
    }
    const Masks m = compute(soup, 1.0, {0, 0, 0}, 1.0);
    ASSERT_EQ(m.result.open_edges, 0u) << trial;
    m.for_each_voxel([&](const Vec3d& p, const Coord&, bool bit) {
      int w = 0;
      for (const Tet& t : tets) {
        const Vec3d* v = t.v;
        const bool in = behind(v[0], v[1], v[2], p) && behind(v[0], v[3], v[1], p) &&
                        behind(v[1], v[3], v[2], p) && behind(v[0], v[2], v[3], p);
        w += in ? t.orientation : 0;
      }
      ASSERT_EQ(bit, w >= 1) << "trial " << trial << " at " << p.x << " " << p.y << " " << p.z << " w " << w;
      ++checked;
      inside_total += bit;
      deep += w >= 2;
    });
  }
  EXPECT_GT(checked, 50000u);
  EXPECT_GT(inside_total, 1000u);
  EXPECT_GT(deep, 50u);
}

TEST(InsideMasks, FlippedFacesAfterOrientationGiveIdenticalMasks) {
  for (const char* name : {"knot.off", "blobby.off"}) {
    const TriangleMesh original = test::load_cgal_mesh(name);
    TriangleMesh scrambled = original;
    test::flip_random_half(scrambled, 17);
    const BBox box = original.bounds();
    const double h = box.longest_side() / 80.0;
    const Masks a = compute(orient_faces(original, {}).mesh, h, box.min);
    const Masks b = compute(orient_faces(scrambled, {}).mesh, h, box.min);
    ASSERT_EQ(a.lists.bricks, b.lists.bricks) << name;
    ASSERT_EQ(a.result.inside, b.result.inside) << name;
    std::size_t inside = 0;
    for (const auto& mask : a.result.inside) inside += std::size_t(mask.count());
    EXPECT_GT(inside, 1000u) << name;
  }
}

TEST(InsideMasks, ElephantWithHolesIsInsideDeepInAndOutsideFarOut) {
  // 1353 open edges: every brick lies near a hole and is evaluated voxel by voxel.
  const TriangleMesh holes = orient_faces(test::load_cgal_mesh("elephant-with-holes.off"), {}).mesh;
  const TriangleMesh closed = orient_faces(test::load_cgal_mesh("elephant.off"), {}).mesh;
  const BBox box = closed.bounds();
  const double h = box.longest_side() / 64.0;
  const Masks m = compute(holes, h, box.min);
  EXPECT_EQ(m.result.open_edges, 1353u);
  EXPECT_GT(m.result.direct_bricks, 0u);
  const WindingNumberTree closed_tree = build_winding_tree(closed);
  const WindingNumberTree holes_tree = build_winding_tree(holes);
  std::size_t deep = 0, far = 0, agree = 0, total = 0, wrong = 0;
  m.for_each_voxel([&](const Vec3d& p, const Coord&, bool bit) {
    const double wc = winding_number(closed_tree, p);
    const double wh = winding_number(holes_tree, p);
    // Where the holed surface's own winding number is unambiguous it decides.
    if (wh > 0.6) {
      wrong += !bit;
      deep += wc > 0.5;
    }
    if (wh < 0.4) {
      wrong += bit;
      far += wc < 0.5;
    }
    ++total;
    agree += bit == (wc > 0.5);
  });
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(deep, 1000u);
  EXPECT_GT(far, 10000u);
  // And it is mostly the closed elephant's inside.
  EXPECT_GT(double(agree), 0.95 * double(total));
}

// Open surfaces, where the cones of the nearby open edges carry the winding number's
// continuous part (brick_winding.hpp): every voxel whose exact winding number is not within
// 0.02 of 1/2 gets its side, with far fewer queries than one per voxel near the rims.
TEST(InsideMasks, OpenSurfacesMatchTheExactWindingNumberAwayFromOneHalf) {
  TriangleMesh holed = test::icosphere(2);
  std::erase_if(holed.triangles, [&](const auto& f) {  // two holes
    const Vec3d c = (holed.vertices[f[0]] + holed.vertices[f[1]] + holed.vertices[f[2]]) / 3.0;
    return c.z > 0.75 || c.x > 0.8;
  });
  TriangleMesh cap = test::hemisphere(8, 32, 0.9);
  for (Vec3d& v : cap.vertices) v = Vec3d{0.8 * v.x - 0.6 * v.z, v.y, 0.6 * v.x + 0.8 * v.z};
  for (const auto& [name, mesh] : {std::pair<const char*, TriangleMesh>{"holed sphere", holed},
                                   {"tilted hemisphere", cap}}) {
    SCOPED_TRACE(name);
    const Masks m = compute(mesh, 1.0 / 24.0, Vec3d{-1.3137, -1.2718, -1.2941});
    ASSERT_GT(m.result.open_edges, 0u);
    ASSERT_GT(m.result.direct_bricks, 0u);
    std::size_t checked = 0, wrong = 0;
    m.for_each_voxel([&](const Vec3d& p, const Coord&, bool bit) {
      const double w = winding_number_exact(mesh, p);
      if (std::abs(w - 0.5) <= 0.02) return;
      ++checked;
      wrong += bit != (w > 0.5);
    });
    EXPECT_GT(checked, 10000u);
    EXPECT_EQ(wrong, 0u);
    EXPECT_LT(m.result.winding_queries, m.result.direct_bricks * kBrickVoxels / 4);
  }
}

TEST(InsideMasks, DeterministicForAnyThreadCount) {
  const TriangleMesh knot = orient_faces(test::load_cgal_mesh("knot.off"), {}).mesh;
  const BBox box = knot.bounds();
  const double h = box.longest_side() / 100.0;
  Masks one, two;
  tbb::task_arena(1).execute([&] { one = compute(knot, h, box.min); });
  tbb::task_arena(2).execute([&] { two = compute(knot, h, box.min); });
  EXPECT_EQ(one.result.inside, two.result.inside);
}

TEST(InsideMasks, CancelsAndRejectsInconsistentInput) {
  const TriangleMesh sphere = test::icosphere(3);
  GridFrame frame;
  frame.voxel_size = 0.05;
  const BrickTriangleLists lists = lists_for(sphere, frame, 0.15);
  const WindingNumberTree tree = build_winding_tree(sphere);
  InsideMasksOptions options;
  options.frame = frame;
  auto token = std::make_shared<CancelToken>();
  token->cancel();
  options.progress.cancel = token;
  auto expect_code = [&](auto&& call, ErrorCode code) {
    try {
      call();
      ADD_FAILURE() << "expected an error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), code) << e.what();
    }
  };
  expect_code([&] { (void)compute_inside_masks(sphere, tree, lists, options); },
              ErrorCode::Cancelled);
  options.progress = {};
  const WindingNumberTree other = build_winding_tree(test::icosphere(1));
  expect_code([&] { (void)compute_inside_masks(sphere, other, lists, options); },
              ErrorCode::InvalidArgument);
  BrickTriangleLists broken = lists;
  broken.triangles[0] = 1u << 30;
  expect_code([&] { (void)compute_inside_masks(sphere, tree, broken, options); },
              ErrorCode::InvalidArgument);
  options.frame.voxel_size = 0.0;
  expect_code([&] { (void)compute_inside_masks(sphere, tree, lists, options); },
              ErrorCode::InvalidArgument);
  // No bricks: no masks.
  options.frame.voxel_size = 0.05;
  EXPECT_TRUE(compute_inside_masks(sphere, tree, BrickTriangleLists{}, options).inside.empty());
}

}  // namespace
}  // namespace levelset
