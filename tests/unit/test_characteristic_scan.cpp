// The characteristic scan (CptMethod::characteristic: prisms, wedges and cones) against the slab
// scan (CptMethod::slab_scan, which the brute-force tests in test_closest_point_transform also
// check): the same band and values within 1e-5 h on every CGAL mesh at W = 3, 6 and 12, on meshes
// subdivided until there is about one triangle per surface voxel, on separate sheets whose
// polyhedra overlap, and on open sheets whose wide wedges and cones overlap at W = 12; the same
// result for any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "core/error.hpp"
#include "distance/closest_point_transform.hpp"
#include "distance_test_meshes.hpp"
#include "grid/build_from_sdf.hpp"
#include "io/mesh_reader.hpp"
#include "mesh_subdivide.hpp"
#include "surface/marching_cubes.hpp"

namespace levelset {
namespace {

namespace fs = std::filesystem;

CptResult run(const TriangleMesh& mesh, const GridFrame& frame, CptMethod method, bool closest = false) {
  CptOptions options;
  options.frame = frame;
  options.method = method;
  options.closest_points = closest;
  return closest_point_transform(mesh, options);
}

struct Comparison {
  std::uint64_t voxels = 0, missing = 0, extra = 0, wrong = 0, sign_flips = 0;
  double worst = 0;  // largest |difference| in units of h
};

// The characteristic scan's band against the slab scan's on the same frame. A voxel exactly on
// the band's rim (|value| = W h up to rounding) is a tie either way: not counted.
Comparison compare_methods(const TriangleMesh& mesh, const GridFrame& frame) {
  const CptResult a = run(mesh, frame, CptMethod::characteristic);
  const CptResult b = run(mesh, frame, CptMethod::slab_scan);
  const double h = frame.voxel_size, rim = frame.half_width * h * (1 - 1e-6);
  Comparison c;
  b.band.for_each_active([&](const Coord& voxel, float ref) {
    ++c.voxels;
    const auto v = a.band.value(voxel);
    if (!v) {
      c.missing += std::abs(ref) < rim;
      return;
    }
    c.sign_flips += std::signbit(*v) != std::signbit(ref);
    const double diff = std::abs(double(*v) - double(ref)) / h;
    c.worst = std::max(c.worst, diff);
    c.wrong += diff > 1e-5;
  });
  a.band.for_each_active([&](const Coord& voxel, float v) { c.extra += !b.band.is_active(voxel) && std::abs(v) < rim; });
  return c;
}

void expect_same(const std::string& what, const Comparison& c) {
  EXPECT_GT(c.voxels, 100u) << what;
  EXPECT_EQ(c.wrong + c.missing + c.extra + c.sign_flips, 0u)
      << what << ": " << c.wrong << " values differ (worst " << c.worst << " h), " << c.missing << " missing, "
      << c.extra << " extra, " << c.sign_flips << " signs";
}

std::vector<fs::path> cgal_mesh_files() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(test::cgal_meshes_dir())) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Every CGAL mesh our readers take: scans with noise and holes, CAD parts with sharp edges and
// flat fans, soups, non-manifold and degenerate inputs; open meshes with their membranes too.
TEST(CharacteristicScan, EqualsTheSlabScanOnEveryCgalMesh) {
  int meshes = 0;
  for (const fs::path& path : cgal_mesh_files()) {
    TriangleMesh mesh;
    try {
      mesh = read_mesh(path.string()).mesh;
    } catch (const Error&) {
      continue;  // not a mesh our readers take (test_cgal_data covers the reasons)
    }
    if (mesh.triangles.empty() || mesh.triangles.size() > 200000) continue;
    ++meshes;
    for (const double w : {3.0, 6.0})
      expect_same(path.filename().string() + " W=" + std::to_string(int(w)),
                  compare_methods(mesh, frame_for_resolution(mesh.bounds(), 64, w)));
  }
  EXPECT_GT(meshes, 40);
}

// Wide bands: W = 12 on a selection (the slab scan is slow there: that is the point).
TEST(CharacteristicScan, EqualsTheSlabScanForAWideBand) {
  for (const char* name : {"knot.off", "fandisk.off", "elephant.off", "cube.off", "oblong.off", "turbine.off"})
    expect_same(std::string(name) + " W=12",
                compare_methods(test::load_cgal_mesh(name),
                                frame_for_resolution(test::load_cgal_mesh(name).bounds(), 80, 12.0)));
}

// Scans and meshes extracted from grids have about one triangle per surface voxel; subdivided
// meshes also have flat facets split into triangles far smaller than a voxel.
TEST(CharacteristicScan, EqualsTheSlabScanOnDenseMeshes) {
  // degtri_sliding.off: collinear faces, subdivided into many (their shorter edges unscanned).
  for (const char* name : {"knot.off", "bunny00.off", "fandisk.off", "degtri_sliding.off"}) {
    const TriangleMesh coarse = test::load_cgal_mesh(name);
    const TriangleMesh dense = test::densify(coarse, frame_for_resolution(coarse.bounds(), 96, 3.0).voxel_size);
    for (const double w : {3.0, 12.0})
      expect_same(std::string(name) + " dense (" + std::to_string(dense.triangles.size()) + " triangles) W=" +
                      std::to_string(int(w)),
                  compare_methods(dense, frame_for_resolution(dense.bounds(), 96, w)));
  }
  const TriangleMesh sphere = test::icosphere(6, 1.0, {0.1, -0.2, 0.3});  // 81920 faces
  expect_same("icosphere 6 W=6", compare_methods(sphere, frame_for_resolution(sphere.bounds(), 128, 6.0)));
  // A mesh extracted by marching cubes, transformed again on its own grid: every vertex on a
  // grid line, voxel centres exactly on the surface, slivers (bench_cpt's headline row).
  const BBox box{{-1, -1, -1}, {1, 1, 1}};
  SdfBuildOptions build;
  build.frame = frame_for_resolution(box, 96, 3.0);
  const TriangleMesh extracted =
      marching_cubes(build_from_sdf([](const Vec3d& p) { return length(p) - 0.8; }, box, build).band).mesh;
  for (const double w : {3.0, 6.0}) {
    GridFrame same_grid = build.frame;
    same_grid.half_width = w;
    expect_same("marching cubes sphere W=" + std::to_string(int(w)), compare_methods(extracted, same_grid));
  }
}

// A sphere inside a box, a thin slab, a torus: polyhedra of separate sheets overlap in the band.
TEST(CharacteristicScan, SeparateSheetsAndThinParts) {
  TriangleMesh mesh = test::icosphere(4, 0.3, {0, 0, 0});
  test::append_mesh(mesh, test::box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}));
  for (const double w : {3.0, 12.0})
    expect_same("sphere in box W=" + std::to_string(int(w)),
                compare_methods(mesh, frame_for_resolution(mesh.bounds(), 80, w)));
  const TriangleMesh slab = test::box_mesh({-1.0, -1.0, -0.02}, {1.0, 1.0, 0.02});
  expect_same("thin slab W=6", compare_methods(slab, frame_for_resolution(slab.bounds(), 100, 6.0)));
  const TriangleMesh torus = test::torus(1.0, 0.35, 96, 48);
  expect_same("torus W=12", compare_methods(torus, frame_for_resolution(torus.bounds(), 96, 12.0)));
  // Two faces back to back (a double-sided sheet): at each edge the face across is folded
  // onto this one, and the edge's wedge is the half-space beyond it (its box once came out
  // thin there, and voxels beyond the edges were missing).
  TriangleMesh sheet;
  sheet.vertices = {{0, 0, 0}, {1, 0.1, 0.05}, {0.3, 0.9, 0.1}};
  sheet.triangles = {{0, 1, 2}, {0, 2, 1}};
  for (const double w : {2.0, 4.0})
    expect_same("double-sided sheet W=" + std::to_string(int(w)),
                compare_methods(sheet, frame_for_resolution(sheet.bounds(), 64, w)));
}

// Open sheets in a wide band: every border edge's wedge is a half-cylinder and every border or
// corner vertex's cone a large part of the ball around it, and across holes and between
// nearby pieces they overlap many times over, where the scan skips the voxels a wedge's line
// or a cone's vertex is already farther from than a known triangle (FeatureBound). A soup of
// small separate triangles (all wedges and cones wide), and CGAL's open meshes with holes,
// borders and many components.
TEST(CharacteristicScan, OverlappingWideWedgesAndConesOfOpenSheets) {
  TriangleMesh soup;
  std::uint32_t seed = 12345;
  auto next = [&] {  // a fixed linear congruential sequence in [0, 1)
    seed = seed * 1664525u + 1013904223u;
    return double(seed >> 8) / double(1u << 24);
  };
  for (int i = 0; i < 120; ++i) {
    const Vec3d c{next(), next(), next()};
    for (int k = 0; k < 3; ++k) soup.vertices.push_back(c + Vec3d{next(), next(), next()} * 0.08);
    const std::uint32_t b = std::uint32_t(3 * i);
    soup.triangles.push_back({b, b + 1, b + 2});
  }
  expect_same("soup of 120 small triangles W=12", compare_methods(soup, frame_for_resolution(soup.bounds(), 64, 12.0)));
  for (const char* name : {"elephant-with-holes.off", "b9_mesh.off", "mask_cone.off"})
    expect_same(std::string(name) + " W=12",
                compare_methods(test::load_cgal_mesh(name),
                                frame_for_resolution(test::load_cgal_mesh(name).bounds(), 64, 12.0)));
}

// Degenerate faces alone on a slanted line (no flat face's edge covers it), overlapping many
// times over and in disjoint pieces, beside one flat face: their band is their segments'
// cylinders, scanned once per point of the line (collinear_segments.hpp). The slab scan binned
// and sliced such faces by their cross product's rounding noise as a normal, and missed the
// nearest face at up to 0.2 h (triangle_plane: no plane for them now).
TEST(CharacteristicScan, CollinearDegenerateFacesAlone) {
  TriangleMesh mesh;
  const Vec3d a{0.1, 0.2, 0.3}, d = Vec3d{0.8, 0.5, -0.3} / length(Vec3d{0.8, 0.5, -0.3});
  auto on_line = [&](double t) {
    mesh.vertices.push_back(a + d * t);
    return std::uint32_t(mesh.vertices.size() - 1);
  };
  for (int i = 0; i < 40; ++i) {  // overlapping: [0.02 i, 0.02 i + 0.5], the third vertex inside
    const double t0 = 0.02 * i, t1 = t0 + 0.5;
    mesh.triangles.push_back({on_line(t0), on_line(t1), on_line(0.5 * (t0 + t1))});
  }
  for (int i = 0; i < 10; ++i) {  // disjoint pieces further along
    const double t0 = 1.5 + 0.1 * i;
    mesh.triangles.push_back({on_line(t0), on_line(t0 + 0.05), on_line(t0 + 0.02)});
  }
  const std::uint32_t base = std::uint32_t(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), {{-0.5, -0.5, -0.4}, {0.5, -0.5, -0.4}, {0.0, 0.5, -0.4}});
  mesh.triangles.push_back({base, base + 1, base + 2});
  for (const double w : {3.0, 6.0})
    expect_same("collinear degenerate faces W=" + std::to_string(int(w)),
                compare_methods(mesh, frame_for_resolution(mesh.bounds(), 64, w)));
}

TEST(CharacteristicScan, IdenticalForOneAndTwoThreads) {
  const TriangleMesh knot = test::load_cgal_mesh("knot.off");
  const TriangleMesh dense = test::densify(knot, frame_for_resolution(knot.bounds(), 80, 3.0).voxel_size);
  const GridFrame frame = frame_for_resolution(dense.bounds(), 80, 6.0);
  CptResult one, two;
  tbb::task_arena(1).execute([&] { one = run(dense, frame, CptMethod::characteristic, true); });
  tbb::task_arena(2).execute([&] { two = run(dense, frame, CptMethod::characteristic, true); });
  EXPECT_TRUE(one.band.identical(two.band));
  ASSERT_EQ(one.closest_points.size(), two.closest_points.size());
  EXPECT_TRUE(std::equal(one.closest_points.begin(), one.closest_points.end(), two.closest_points.begin(),
                         [](const Vec3f& a, const Vec3f& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }));
  EXPECT_GE(one.polyhedra, dense.triangles.size());  // a prism per face, wedges and cones where not flat
  // About one to two evaluations per band voxel on a smooth dense mesh.
  EXPECT_LT(double(one.evaluations), 3.0 * double(one.band.active_voxel_count()));
}

// The automatic choice: the slab scan for a narrow band around a coarse mesh, the
// characteristic scan for wide bands and dense meshes.
TEST(CharacteristicScan, AutomaticChoice) {
  const TriangleMesh knot = test::load_cgal_mesh("knot.off");
  // Very coarse against the grid (4k triangles, ~500k surface voxels): the slab scan.
  EXPECT_EQ(run(knot, frame_for_resolution(knot.bounds(), 512, 3.0), CptMethod::automatic).method, CptMethod::slab_scan);
  EXPECT_EQ(run(knot, frame_for_resolution(knot.bounds(), 128, 3.0), CptMethod::automatic).method,
            CptMethod::characteristic);
  EXPECT_EQ(run(knot, frame_for_resolution(knot.bounds(), 128, 6.0), CptMethod::automatic).method,
            CptMethod::characteristic);
  const TriangleMesh dense = test::densify(knot, frame_for_resolution(knot.bounds(), 128, 3.0).voxel_size);
  EXPECT_EQ(run(dense, frame_for_resolution(dense.bounds(), 128, 3.0), CptMethod::automatic).method,
            CptMethod::characteristic);
}

}  // namespace
}  // namespace levelset
