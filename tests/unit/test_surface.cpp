// Surface extraction: marching cubes, surface nets and mesh measures.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>

#include <tbb/task_arena.h>

#include "core/error.hpp"
#include "distance/closest_point_transform.hpp"
#include "distance_test_meshes.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/band_builder.hpp"
#include "grid/build_from_sdf.hpp"
#include "shape_band.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/mesh_measures.hpp"
#include "surface/surface_nets.hpp"

namespace levelset {
namespace {

using test::make_shape_band;

void expect_closed_manifold(const MeshMeasures& m, const char* what) {
  EXPECT_GT(m.faces, 0u) << what;
  EXPECT_TRUE(m.watertight) << what << " boundary " << m.boundary_edges << " non-manifold " << m.non_manifold_edges;
  EXPECT_TRUE(m.manifold) << what << " non-manifold edges " << m.non_manifold_edges << " vertices "
                          << m.non_manifold_vertices;
  EXPECT_TRUE(m.oriented) << what << " misoriented " << m.misoriented_edges;
}

SurfaceResult run_mc(const NarrowBand& band, double iso = 0.0) {
  MarchingCubesOptions o;
  o.iso = iso;
  return marching_cubes(band, o);
}
SurfaceResult run_sn(const NarrowBand& band, double iso = 0.0) {
  SurfaceNetsOptions o;
  o.iso = iso;
  return surface_nets(band, o);
}

TEST(MeshMeasuresTest, BoxAndTorusMeshes) {
  const TriangleMesh box = test::box_mesh({0, 0, 0}, {1, 2, 3});
  const MeshMeasures b = measure_mesh(box);
  EXPECT_NEAR(b.area, 2 * (2 + 3 + 6), 1e-12);
  EXPECT_NEAR(b.volume, 6.0, 1e-12);
  EXPECT_EQ(b.euler_characteristic, 2);
  EXPECT_EQ(b.components, 1u);
  EXPECT_EQ(b.genus, 0.0);
  expect_closed_manifold(b, "box");
  const MeshMeasures t = measure_mesh(test::torus(1.0, 0.3, 24, 12));
  EXPECT_EQ(t.genus, 1.0);
  expect_closed_manifold(t, "torus");
  const MeshMeasures h = measure_mesh(test::hemisphere(6, 12));
  EXPECT_FALSE(h.watertight);
  EXPECT_EQ(h.boundary_edges, 12u);
  TriangleMesh flipped = box;
  std::swap(flipped.triangles[0][0], flipped.triangles[0][1]);
  const MeshMeasures f = measure_mesh(flipped);
  EXPECT_TRUE(f.watertight);
  EXPECT_FALSE(f.oriented);
}

TEST(MeshMeasuresTest, BowtieVertexIsNonManifold) {
  TriangleMesh m = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const TriangleMesh second = test::box_mesh({1, 1, 1}, {2, 2, 2});
  // Share the corner (1,1,1): vertex 7 of the first, vertex 0 of the second.
  const std::uint32_t base = std::uint32_t(m.vertices.size());
  for (const auto& v : second.vertices) m.vertices.push_back(v);
  for (auto t : second.triangles) {
    for (auto& i : t) i = i == 0 ? 7u : i + base;
    m.triangles.push_back(t);
  }
  const MeshMeasures r = measure_mesh(m);
  EXPECT_TRUE(r.watertight);
  EXPECT_EQ(r.non_manifold_vertices, 1u);
  EXPECT_FALSE(r.manifold);
}

// measure_mesh counts edges at their lower vertex; a global sort of all directed edges is
// the plain definition. Random index triples (repeated indices, edges in 1-4 triangles, both
// directions) must give the same counts.
TEST(MeshMeasuresTest, EdgeCountsMatchAGlobalSortOnMessyMeshes) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    TriangleMesh m;
    const std::uint32_t nv = 6 + std::uint32_t(trial);
    for (std::uint32_t v = 0; v < nv; ++v) m.vertices.push_back({double(v), double(v * v % 7), double(v % 3)});
    std::uniform_int_distribution<std::uint32_t> pick(0, nv - 1);
    for (int f = 0; f < 40; ++f) m.triangles.push_back({pick(rng), pick(rng), pick(rng)});
    std::vector<std::array<std::uint32_t, 3>> directed;  // lo, hi, forward
    for (const auto& t : m.triangles)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t u = t[std::size_t(k)], w = t[std::size_t((k + 1) % 3)];
        directed.push_back({std::min(u, w), std::max(u, w), u < w ? 1u : 0u});
      }
    std::sort(directed.begin(), directed.end());
    std::uint64_t edges = 0, boundary = 0, non_manifold = 0, misoriented = 0;
    for (std::size_t i = 0; i < directed.size();) {
      std::size_t j = i;
      std::uint32_t fwd = 0;
      while (j < directed.size() && directed[j][0] == directed[i][0] && directed[j][1] == directed[i][1])
        fwd += directed[j++][2];
      ++edges;
      if (j - i == 1) ++boundary;
      else if (j - i > 2) ++non_manifold;
      else if (fwd != 1) ++misoriented;
      i = j;
    }
    const MeshMeasures r = measure_mesh(m);
    EXPECT_EQ(r.edges, edges) << "trial " << trial;
    EXPECT_EQ(r.boundary_edges, boundary) << "trial " << trial;
    EXPECT_EQ(r.non_manifold_edges, non_manifold) << "trial " << trial;
    EXPECT_EQ(r.misoriented_edges, misoriented) << "trial " << trial;
  }
}

struct SphereErrors {
  double mc_area, mc_volume, sn_area, sn_volume;
};

SphereErrors sphere_errors(int resolution) {
  const auto sb = make_shape_band("sphere", resolution);
  const double area = 4 * std::numbers::pi, volume = 4.0 / 3.0 * std::numbers::pi;
  const MeshMeasures mc = measure_mesh(run_mc(sb.band).mesh);
  const MeshMeasures sn = measure_mesh(run_sn(sb.band).mesh);
  expect_closed_manifold(mc, "mc sphere");
  expect_closed_manifold(sn, "sn sphere");
  EXPECT_EQ(mc.genus, 0.0);
  EXPECT_EQ(sn.genus, 0.0);
  EXPECT_EQ(mc.components, 1u);
  EXPECT_EQ(sn.components, 1u);
  return {std::abs(mc.area - area) / area, std::abs(mc.volume - volume) / volume,
          std::abs(sn.area - area) / area, std::abs(sn.volume - volume) / volume};
}

TEST(MarchingCubesSphere, AreaAndVolumeConvergeAtSecondOrder) {
  SphereErrors e[3];
  const int res[3] = {32, 64, 128};
  for (int i = 0; i < 3; ++i) {
    e[i] = sphere_errors(res[i]);
    std::printf("R=%d  MC area %.3e vol %.3e   SN area %.3e vol %.3e\n", res[i], e[i].mc_area,
                e[i].mc_volume, e[i].sn_area, e[i].sn_volume);
  }
  for (int i = 0; i + 1 < 3; ++i) {
    EXPECT_GE(e[i].mc_area / e[i + 1].mc_area, 3.0);
    EXPECT_GE(e[i].mc_volume / e[i + 1].mc_volume, 3.0);
    EXPECT_GE(e[i].sn_area / e[i + 1].sn_area, 3.0);
    EXPECT_GE(e[i].sn_volume / e[i + 1].sn_volume, 3.0);
  }
}

TEST(MarchingCubesTopology, TorusHasGenusOneAndTwoSpheresTwoComponents) {
  const auto sb = make_shape_band("torus", 64);
  for (const SurfaceResult& r : {run_mc(sb.band), run_sn(sb.band)}) {
    const MeshMeasures m = measure_mesh(r.mesh);
    expect_closed_manifold(m, "torus");
    EXPECT_EQ(m.genus, 1.0);
    EXPECT_EQ(m.components, 1u);
  }
  auto a = make_sphere({-1.2, 0, 0}, 0.8), b = make_sphere({1.2, 0, 0}, 0.8);
  BBox box;
  box.extend({-2.0, -0.8, -0.8});
  box.extend({2.0, 0.8, 0.8});
  SdfBuildOptions o;
  o.frame = frame_for_resolution(box, 96, 3.0);
  const NarrowBand band =
      build_from_sdf([&](const Vec3d& p) { return std::min(a->distance(p), b->distance(p)); }, box, o).band;
  for (const SurfaceResult& r : {run_mc(band), run_sn(band)}) {
    const MeshMeasures m = measure_mesh(r.mesh);
    expect_closed_manifold(m, "two spheres");
    EXPECT_EQ(m.components, 2u);
    EXPECT_EQ(m.genus, 0.0);
  }
}

// A block of bricks with every voxel active and values from f(voxel).
template <typename F>
NarrowBand full_block(int bricks, F f) {
  GridFrame frame;
  frame.voxel_size = 1.0;
  frame.half_width = 3.0;
  BandBuilder builder(frame);
  for (int bz = 0; bz < bricks; ++bz)
    for (int by = 0; by < bricks; ++by)
      for (int bx = 0; bx < bricks; ++bx) {
        BrickMask active, inside;
        float dense[kBrickVoxels];
        for (int n = 0; n < kBrickVoxels; ++n) {
          const Coord c = brick_origin({bx, by, bz}) + local_coord(n);
          dense[n] = f(c);
          active.set(n);
          inside.assign(n, dense[n] < 0.0f);
        }
        builder.add_brick({bx, by, bz}, active, inside, dense);
      }
  return builder.finish(false);
}

// The block's outer layer of voxels is positive so the surface stays inside the block.
TEST(MarchingCubesAdversarial, RandomAndCheckerboardFieldsGiveClosedManifolds) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  const int n = 3 * kBrickDim;
  auto border = [&](const Coord& c) {
    return c.x == 0 || c.y == 0 || c.z == 0 || c.x == n - 1 || c.y == n - 1 || c.z == n - 1;
  };
  const NarrowBand random = full_block(3, [&](const Coord& c) { return border(c) ? 2.0f : u(rng); });
  const NarrowBand checker = full_block(3, [&](const Coord& c) {
    return border(c) ? 2.0f : (((c.x + c.y + c.z) & 1) ? 1.0f : -1.0f);
  });
  const NarrowBand checker2 = full_block(3, [&](const Coord& c) {
    return border(c) ? 1.5f : (((c.x + c.y + c.z) & 1) ? 0.5f + 0.01f * float(c.x % 5) : -1.0f + 0.02f * float(c.y % 3));
  });
  // More random fields: exact ties with iso (values in {-1, 0, 1}), isolated inside voxels,
  // and smooth noise with many ambiguous faces, several seeds each.
  std::vector<NarrowBand> more;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    std::mt19937 g(seed);
    std::uniform_int_distribution<int> tri(-1, 1);
    std::uniform_real_distribution<float> v(0.0f, 1.0f);
    more.push_back(full_block(3, [&](const Coord& c) { return border(c) ? 1.0f : float(tri(g)); }));
    more.push_back(full_block(3, [&](const Coord& c) { return border(c) || v(g) > 0.3f ? 1.0f : -v(g); }));
    more.push_back(full_block(3, [&](const Coord& c) {
      return border(c) ? 2.0f : std::sin(1.7f * float(c.x) + float(seed)) * std::cos(1.3f * float(c.y)) +
                                    std::sin(1.1f * float(c.z)) * 0.9f + 0.2f * (v(g) - 0.5f);
    }));
  }
  std::vector<const NarrowBand*> bands = {&random, &checker, &checker2};
  for (const NarrowBand& b : more) bands.push_back(&b);
  for (const NarrowBand* band : bands) {
    for (double iso : {0.0, 0.3}) {
      const SurfaceResult mc = run_mc(*band, iso);
      const MeshMeasures m = measure_mesh(mc.mesh);
      expect_closed_manifold(m, "mc adversarial");
      const SurfaceResult sn = run_sn(*band, iso);
      const MeshMeasures s = measure_mesh(sn.mesh);
      expect_closed_manifold(s, "sn adversarial");
      // Both extractors contour the same cell loops, so their surfaces are homeomorphic.
      EXPECT_EQ(s.components, m.components);
      EXPECT_EQ(s.euler_characteristic, m.euler_characteristic);
      std::printf("adversarial iso %.1f: MC %zu tris (%llu extra vertices), SN %zu tris\n", iso,
                  mc.mesh.triangles.size(), (unsigned long long)mc.extra_vertices, sn.mesh.triangles.size());
    }
  }
}

TEST(MarchingCubesDeterminism, OneAndTwoThreadsGiveIdenticalArrays) {
  const auto sb = make_shape_band("knot", 96);
  SurfaceResult mc[2], sn[2];
  for (int k = 0; k < 2; ++k) {
    tbb::task_arena arena(k + 1);
    arena.execute([&] {
      mc[k] = run_mc(sb.band);
      sn[k] = run_sn(sb.band);
    });
  }
  EXPECT_TRUE(mc[0].mesh.vertices == mc[1].mesh.vertices);
  EXPECT_TRUE(mc[0].mesh.triangles == mc[1].mesh.triangles);
  EXPECT_TRUE(mc[0].normals == mc[1].normals);
  EXPECT_TRUE(sn[0].mesh.vertices == sn[1].mesh.vertices);
  EXPECT_TRUE(sn[0].mesh.triangles == sn[1].mesh.triangles);
}

TEST(MarchingCubesNormals, AgreeWithAnalyticSphereNormals) {
  const auto sb = make_shape_band("sphere", 64);
  for (const SurfaceResult& r : {run_mc(sb.band), run_sn(sb.band)}) {
    ASSERT_EQ(r.normals.size(), r.mesh.vertices.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < r.normals.size(); ++i) {
      const Vec3d p = r.mesh.vertices[i], n{r.normals[i].x, r.normals[i].y, r.normals[i].z};
      worst = std::max(worst, std::acos(std::clamp(dot(n, p / length(p)), -1.0, 1.0)));
    }
    EXPECT_LT(worst * 180.0 / std::numbers::pi, 2.0);
  }
}

TEST(SurfaceNetsQuality, BetterMinAngleThanMarchingCubes) {
  for (const char* name : {"sphere", "knot"}) {
    const auto sb = make_shape_band(name, 96);
    const MeshMeasures mc = measure_mesh(run_mc(sb.band).mesh);
    const MeshMeasures sn = measure_mesh(run_sn(sb.band).mesh);
    std::printf("%s: mean min angle MC %.2f SN %.2f\n", name, mc.mean_min_angle_deg, sn.mean_min_angle_deg);
    EXPECT_GT(sn.mean_min_angle_deg, mc.mean_min_angle_deg) << name;
    expect_closed_manifold(sn, name);
    expect_closed_manifold(mc, name);
  }
}

TEST(MarchingCubesIso, OffsetIsoGivesOffsetSphere) {
  const auto sb = make_shape_band("sphere", 64);
  const double h = sb.band.voxel_size();
  for (double iso : {h, -h}) {
    for (const SurfaceResult& r : {run_mc(sb.band, iso), run_sn(sb.band, iso)}) {
      const MeshMeasures m = measure_mesh(r.mesh);
      const double rr = 1.0 + iso;
      EXPECT_NEAR(m.area, 4 * std::numbers::pi * rr * rr, 4 * std::numbers::pi * rr * rr * 2e-3);
      EXPECT_NEAR(m.volume, 4.0 / 3.0 * std::numbers::pi * rr * rr * rr, 4.0 * rr * rr * rr * 2e-3);
    }
  }
  EXPECT_THROW(run_mc(sb.band, 3.5 * h), Error);
  EXPECT_THROW(run_sn(sb.band, -3.5 * h), Error);
}

TEST(MarchingCubesCgal, KnotIsGenusOneWithinOneVoxel) {
  const std::filesystem::path path = std::filesystem::path(LEVELSET_CGAL_DATA) / "meshes" / "knot.off";
  ASSERT_TRUE(std::filesystem::exists(path))
      << "CGAL data not installed: " << path << " (install-deps.sh installs it)";
  const TriangleMesh input = test::load_cgal_mesh("knot.off");
  CptOptions o;
  o.frame = frame_for_resolution(input.bounds(), 128, 3.0);
  const CptResult cpt = closest_point_transform(input, o);
  const SurfaceResult mc = run_mc(cpt.band);
  const MeshMeasures m = measure_mesh(mc.mesh);
  expect_closed_manifold(m, "cgal knot");
  EXPECT_EQ(m.genus, 1.0);
  EXPECT_EQ(m.components, 1u);
  const double h = cpt.band.voxel_size();
  double d1 = 0.0, d2 = 0.0;
  for (std::size_t i = 0; i < mc.mesh.vertices.size(); i += 7)
    d1 = std::max(d1, test::brute_force_distance(input, mc.mesh.vertices[i]));
  for (const auto& v : input.vertices) d2 = std::max(d2, test::brute_force_distance(mc.mesh, v));
  std::printf("cgal knot Hausdorff: mc->input %.3f h, input->mc %.3f h\n", d1 / h, d2 / h);
  EXPECT_LE(d1, h);
  EXPECT_LE(d2, h);
}

TEST(MarchingCubesTiming, KnotBandAt256) {
  const auto sb = make_shape_band("knot", 256);
  const SurfaceResult mc = run_mc(sb.band);
  const SurfaceResult sn = run_sn(sb.band);
  const MeshMeasures m = measure_mesh(mc.mesh), s = measure_mesh(sn.mesh);
  expect_closed_manifold(m, "knot 256 mc");
  expect_closed_manifold(s, "knot 256 sn");
  EXPECT_EQ(m.genus, 1.0);
  EXPECT_EQ(s.genus, 1.0);
  std::printf("knot R=256: %zu bricks; MC %.3f s %zu verts %zu tris; SN %.3f s %zu verts %zu tris\n",
              sb.band.brick_count(), mc.seconds, mc.mesh.vertices.size(), mc.mesh.triangles.size(),
              sn.seconds, sn.mesh.vertices.size(), sn.mesh.triangles.size());
}

}  // namespace
}  // namespace levelset
