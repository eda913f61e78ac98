// Surface extraction over the CGAL data meshes: closest point transform at R = 128 then marching
// cubes must give a closed manifold with the input's genus; Hausdorff checks on two meshes; and
// the area-weighted mean curvature of analytic meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <mutex>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "distance/closest_point_transform.hpp"
#include "distance_test_meshes.hpp"
#include "geometry/point_triangle.hpp"
#include "grid/build_from_sdf.hpp"
#include "io/mesh_reader.hpp"
#include "shape_band.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/surface_nets.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset {
namespace {

namespace fs = std::filesystem;

constexpr int kResolution = 128;
constexpr double kHalfWidth = 3.0;
constexpr std::uint64_t kMaxTriangles = 200000;

// Closed manifold inputs whose marching cubes surface at R = 128 legitimately changes topology,
// because they have features thinner than about one voxel at that resolution (measured numbers
// in each comment).
// Thickness / gap: smallest wall thickness / gap between nearby parts from
// DISABLED_ThicknessOfExcludedMeshes, in voxels at R = 128 (h = voxel size).
const std::set<std::string> kTopologyExclusions = {
    "3torus.off",       // 14 convex ridges with a 40.9 deg dihedral angle: the wedge is thinner
                        // than a voxel within 1.34 voxels of the ridge, voxels there are
                        // 6-isolated (20 at R = 128, signs all equal to the exact winding number)
                        // -> genus 4, 7 comps; extra components at every R (R = 512: 41);
                        // making the 232 inside voxels within 1 voxel of them outside gives
                        // genus 3, 1 component. (Not a zero-value case: no band value is 0.)
    "bones.off",        // 26 components, touching bones: thickness 0.012, gap 0.0013 -> genus 14, 7 comps
    "camel.off",        // thickness 0.017, gap 0.025 (thin ears/legs) -> genus 1, 3 comps
    "cheese.off",       // genus 133, walls 0.12 voxels thick -> genus 129, 3 comps
    "cow.off",          // thickness 0.058, gap 0.035 (horns, tail) -> genus 1
    "femur.off",        // thickness 0.10, gap 0.068 -> genus 0, 7 comps (input genus 2)
    "homer.off",        // gap 0.58 voxels (arm against body) -> genus 1
    "man.off",          // thickness 0.0013, gap 0.0008 -> genus 5
    "rotor.off",        // blades 0.74 voxels thick -> genus 9 (input 1)
    "rotor_small.off",  // blades 0.43 voxels thick -> genus 8 (input 1)
};

const std::vector<std::string> kDiagnosed = {"3torus.off", "bones.off",  "camel.off", "cheese-box.off",
                                             "cheese.off",  "corner.off", "cow.off",   "femur.off",
                                             "homer.off",   "man.off",    "rotor.off", "rotor_small.off"};

bool closed_manifold(const MeshMeasures& m) { return m.watertight && m.manifold && m.oriented; }

struct Extracted {
  CptResult cpt;
  SurfaceResult surface;
};

Extracted extract(const TriangleMesh& mesh) {
  const MeshMeasures in = measure_mesh(mesh);
  CptOptions o;
  o.frame = frame_for_resolution(in.bounds, kResolution, kHalfWidth);
  Extracted e;
  e.cpt = closest_point_transform(mesh, o);
  e.surface = marching_cubes(e.cpt.band);
  return e;
}

// Largest distance from every stride-th vertex of `from` to the triangles of `to` (brute force).
double directed_hausdorff(const TriangleMesh& from, const TriangleMesh& to, std::size_t stride) {
  const std::size_t n = (from.vertices.size() + stride - 1) / stride;
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double best) {
        for (std::size_t i = r.begin(); i < r.end(); ++i)
          best = std::max(best, test::brute_force_distance(to, from.vertices[i * stride]));
        return best;
      },
      [](double a, double b) { return std::max(a, b); });
}

// Stride keeping samples * triangles under ~2e7 point-triangle queries.
std::size_t stride_for(const TriangleMesh& from, const TriangleMesh& to) {
  const double budget = 2e7;
  const double samples = std::max(1.0, budget / double(std::max<std::size_t>(1, to.triangles.size())));
  return std::max<std::size_t>(1, std::size_t(std::ceil(double(from.vertices.size()) / samples)));
}

TEST(CgalSurfaces, ClosedManifoldInputsKeepTopologyAtR128BothMethods) {
  const fs::path dir = test::cgal_meshes_dir();
  ASSERT_TRUE(fs::is_directory(dir))
      << "CGAL data meshes not installed: " << dir << " (install-deps.sh installs it)";
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".off") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty());

  struct Outcome {
    std::string name;
    enum { Unread, Open, Large, Tested } kind = Unread;
    MeshMeasures in, out, nets;
    double seconds = 0;
    std::string error;
  };
  std::vector<Outcome> outcomes(files.size());
  const auto t0 = std::chrono::steady_clock::now();
  tbb::parallel_for(std::size_t{0}, files.size(), [&](std::size_t i) {
    Outcome& o = outcomes[i];
    o.name = files[i].filename().string();
    const auto start = std::chrono::steady_clock::now();
    try {
      const TriangleMesh mesh = read_mesh(files[i]).mesh;
      o.in = measure_mesh(mesh);
      if (!closed_manifold(o.in)) { o.kind = Outcome::Open; return; }
      if (o.in.faces > kMaxTriangles) { o.kind = Outcome::Large; return; }
      o.kind = Outcome::Tested;
      const Extracted e = extract(mesh);
      o.out = measure_mesh(e.surface.mesh);
      o.nets = measure_mesh(surface_nets(e.cpt.band).mesh);
    } catch (const std::exception& ex) {
      o.error = ex.what();
    }
    o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  int unread = 0, open = 0, large = 0, tested = 0, excluded = 0, passed = 0;
  for (const Outcome& o : outcomes) {
    if (!o.error.empty() && o.kind != Outcome::Tested) { ++unread; continue; }
    if (o.kind == Outcome::Open) { ++open; continue; }
    if (o.kind == Outcome::Large) { ++large; continue; }
    ++tested;
    EXPECT_TRUE(o.error.empty()) << o.name << ": " << o.error;
    if (!o.error.empty()) continue;
    const bool ok = closed_manifold(o.out) && o.out.genus == o.in.genus;
    // Surface nets contours the same cell loops: the same topology as marching cubes, always
    // (also on the excluded meshes, where both differ from the input).
    EXPECT_TRUE(closed_manifold(o.nets)) << o.name << " surface nets";
    EXPECT_EQ(o.nets.euler_characteristic, o.out.euler_characteristic) << o.name << " surface nets";
    EXPECT_EQ(o.nets.components, o.out.components) << o.name << " surface nets";
    std::ostringstream msg;
    msg << o.name << ": input genus " << o.in.genus << " components " << o.in.components << " faces "
        << o.in.faces << "; output genus " << o.out.genus << " components " << o.out.components
        << " watertight " << o.out.watertight << " manifold " << o.out.manifold << " oriented "
        << o.out.oriented << " (" << o.seconds << " s)";
    if (kTopologyExclusions.count(o.name)) {
      ++excluded;
      std::cout << "[excluded] " << msg.str() << (ok ? "  (now passes)" : "") << "\n";
      continue;
    }
    EXPECT_TRUE(closed_manifold(o.out)) << msg.str();
    EXPECT_EQ(o.out.genus, o.in.genus) << msg.str();
    passed += ok;
  }
  std::cout << "[CgalSurfaces] " << files.size() << " .off files: " << tested << " tested (" << passed
            << " passed, " << excluded << " excluded), " << open << " not closed manifold, " << large
            << " over " << kMaxTriangles << " triangles, " << unread << " unreadable; " << total << " s\n";
  EXPECT_GT(tested, 10);
}

TEST(CgalSurfaces, HausdorffWithinOneVoxelForKnotAndBunny) {
  const fs::path dir = test::cgal_meshes_dir();
  ASSERT_TRUE(fs::is_directory(dir))
      << "CGAL data meshes not installed: " << dir << " (install-deps.sh installs it)";
  int checked = 0;
  for (const std::string name : {"knot.off", "bunny00.off"}) {
    const fs::path path = dir / name;
    if (!fs::exists(path)) continue;
    const TriangleMesh mesh = read_mesh(path).mesh;
    const MeshMeasures in = measure_mesh(mesh);
    if (!closed_manifold(in)) {
      std::cout << "[CgalSurfaces] " << name << " is not a closed manifold: skipped\n";
      continue;
    }
    const auto start = std::chrono::steady_clock::now();
    const Extracted e = extract(mesh);
    const TriangleMesh& mc = e.surface.mesh;
    const double h = e.cpt.band.frame().voxel_size;
    const double to_input = directed_hausdorff(mc, mesh, stride_for(mc, mesh));
    const double to_mc = directed_hausdorff(mesh, mc, stride_for(mesh, mc));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "[CgalSurfaces] " << name << ": MC->input " << to_input / h << " voxels, input->MC "
              << to_mc / h << " voxels (" << seconds << " s)\n";
    EXPECT_LE(to_input, h) << name;
    EXPECT_LE(to_mc, h) << name;
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

// Diagnostic for the exclusion list (run with --gtest_also_run_disabled_tests): for each listed
// mesh, the smallest wall thickness (ray from a face centroid along -normal to the first face not
// sharing a vertex) and the smallest gap (same along +normal), in voxels at R = 128.
double first_hit(const TriangleMesh& m, std::size_t f, const Vec3d& o, const Vec3d& d) {
  const auto& tf = m.triangles[f];
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t g = 0; g < m.triangles.size(); ++g) {
    const auto& t = m.triangles[g];
    bool shared = false;
    for (auto a : t)
      for (auto b : tf) shared |= a == b;
    if (shared) continue;
    const Vec3d &a = m.vertices[t[0]], e1 = m.vertices[t[1]] - a, e2 = m.vertices[t[2]] - a;
    const Vec3d p = cross(d, e2);
    const double det = dot(e1, p);
    if (std::abs(det) < 1e-300) continue;
    const Vec3d s = o - a;
    const double u = dot(s, p) / det;
    if (u < 0 || u > 1) continue;
    const Vec3d q = cross(s, e1);
    const double v = dot(d, q) / det;
    if (v < 0 || u + v > 1) continue;
    const double t_hit = dot(e2, q) / det;
    if (t_hit > 0) best = std::min(best, t_hit);
  }
  return best;
}

TEST(CgalSurfaces, DISABLED_ThicknessOfExcludedMeshes) {
  const fs::path dir = test::cgal_meshes_dir();
  if (!fs::is_directory(dir)) GTEST_SKIP();
  for (const std::string& name : kDiagnosed) {
    const TriangleMesh m = read_mesh(dir / name).mesh;
    const MeshMeasures in = measure_mesh(m);
    const double h = frame_for_resolution(in.bounds, kResolution, kHalfWidth).voxel_size;
    const std::size_t stride = std::max<std::size_t>(1, m.triangles.size() / 4000);
    std::mutex mu;
    double thick = std::numeric_limits<double>::infinity(), gap = thick;
    tbb::parallel_for(std::size_t{0}, (m.triangles.size() + stride - 1) / stride, [&](std::size_t i) {
      const std::size_t f = i * stride;
      const auto& t = m.triangles[f];
      const Vec3d n = cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]);
      if (!(length(n) > 0)) return;
      const Vec3d d = n / length(n), c = (m.vertices[t[0]] + m.vertices[t[1]] + m.vertices[t[2]]) / 3.0;
      const double a = first_hit(m, f, c, d * -1.0), b = first_hit(m, f, c, d);
      std::lock_guard lock(mu);
      thick = std::min(thick, a);
      gap = std::min(gap, b);
    });
    std::cout << name << ": h " << h << " min thickness " << thick / h << " voxels, min gap " << gap / h
              << " voxels\n";
  }
}

TEST(MeanCurvature, IcosphereRadiusTwoGivesOne) {
  const double h = area_weighted_mean_curvature(test::icosphere(5, 2.0, {0.3, -0.2, 0.1}));
  EXPECT_NEAR(h, 1.0, 0.01);
}

TEST(MeanCurvature, MarchingCubesTorusGivesOneOverMinorRadius) {
  // Torus R = 1, r = 0.35: integral of (k1 + k2) dA = 4 pi^2 R, area = 4 pi^2 R r.
  const auto sb = test::make_shape_band("torus", 128);
  const SurfaceResult s = marching_cubes(sb.band);
  EXPECT_NEAR(area_weighted_mean_curvature(s.mesh), 1.0 / 0.35, 0.02 / 0.35);
  // The analytic mesh agrees, and reversing the orientation flips the sign.
  TriangleMesh t = test::torus(1.0, 0.35, 256, 96);
  EXPECT_NEAR(area_weighted_mean_curvature(t), 1.0 / 0.35, 0.01 / 0.35);
  for (auto& tri : t.triangles) std::swap(tri[1], tri[2]);
  EXPECT_NEAR(area_weighted_mean_curvature(t), -1.0 / 0.35, 0.01 / 0.35);
}

}  // namespace
}  // namespace levelset
