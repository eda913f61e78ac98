// Issue 14: the closest point transform of an open mesh closes its holes. The sign changes
// where the winding number crosses 1/2 away from the mesh (a hole's membrane) lie in the band,
// valued by the distance to the membrane, so marching cubes gives a closed surface: every open
// mesh of CGAL's data (those with open edges, found by open_edges), at a resolution from a voxel
// budget; an open box against the exact answer; degenerate inputs give a clear result.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "distance/closest_point_transform.hpp"
#include "distance/open_edges.hpp"
#include "distance/orient_faces.hpp"
#include "distance/unique_faces.hpp"
#include "distance_test_meshes.hpp"
#include "grid/build_from_sdf.hpp"
#include "io/mesh_reader.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset {
namespace {

namespace fs = std::filesystem;

// Open edges of the mesh the CPT signs with (every face once, consistently oriented): the
// meshes whose winding number is not piecewise constant.
std::size_t open_edge_count(const TriangleMesh& mesh) {
  const TriangleMesh sign_mesh = orient_faces(unique_faces(mesh).mesh, OrientOptions{}).mesh;
  std::vector<bool> counts(sign_mesh.triangles.size());
  for (std::size_t t = 0; t < counts.size(); ++t) {
    const auto& f = sign_mesh.triangles[t];
    const Vec3d n = cross(sign_mesh.vertices[f[1]] - sign_mesh.vertices[f[0]],
                          sign_mesh.vertices[f[2]] - sign_mesh.vertices[f[0]]);
    counts[t] = n.x != 0.0 || n.y != 0.0 || n.z != 0.0;
  }
  return open_edges(sign_mesh, weld_exact(sign_mesh.vertices), counts).size();
}

// Resolution from a voxel budget on the mesh's bounding box (flat boxes get more voxels along
// their long sides), between 32 and 192.
int resolution_for(const BBox& box, double voxels) {
  const Vec3d e = box.extent();
  const double longest = std::max(box.longest_side(), 1e-30);
  double fill = 1.0;
  for (int a = 0; a < 3; ++a) fill *= std::max(e[a] / longest, 0.05);
  return int(std::clamp(std::cbrt(voxels / fill), 32.0, 192.0));
}

CptOptions options_at(const TriangleMesh& mesh, int resolution) {
  CptOptions o;
  o.frame = frame_for_resolution(mesh.bounds(), resolution, 3.0);
  return o;
}

// Band invariant: two 6-adjacent voxels of opposite sign are both active.
std::uint64_t invariant_violations(const NarrowBand& band) {
  std::uint64_t bad = 0;
  band.for_each_active([&](const Coord& c, float v) {
    for (int a = 0; a < 3; ++a)
      for (int s : {-1, 1}) {
        Coord n = c;
        n[a] += s;
        if (!band.is_active(n) && band.is_inside(n) != (v < 0.0f)) ++bad;
      }
  });
  return bad;
}

TEST(MembraneBand, EveryOpenCgalMeshGivesAClosedSurface) {
  const fs::path dir = test::cgal_meshes_dir();
  ASSERT_TRUE(fs::is_directory(dir))
      << "CGAL data meshes not installed: " << dir << " (install-deps.sh installs it)";
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  struct Outcome {
    std::string name;
    bool open = false;
    int resolution = 0;
    CptResult cpt;
    MeshMeasures out;
    std::uint64_t violations = 0;
    double seconds = 0.0;
    std::string error;
  };
  std::vector<Outcome> outcomes(files.size());
  const auto t0 = std::chrono::steady_clock::now();
  tbb::parallel_for(std::size_t{0}, files.size(), [&](std::size_t i) {
    Outcome& o = outcomes[i];
    o.name = files[i].filename().string();
    TriangleMesh mesh;
    try {
      mesh = read_mesh(files[i]).mesh;
    } catch (const std::exception&) {
      return;  // unreadable files are test_cgal_data's business
    }
    if (mesh.triangles.empty() || open_edge_count(mesh) == 0) return;
    o.open = true;
    const auto start = std::chrono::steady_clock::now();
    try {
      o.resolution = resolution_for(mesh.bounds(), 1.5e6);
      o.cpt = closest_point_transform(mesh, options_at(mesh, o.resolution));
      o.out = measure_mesh(marching_cubes(o.cpt.band).mesh);
      o.violations = invariant_violations(o.cpt.band);
    } catch (const std::exception& ex) {
      o.error = ex.what();
    }
    o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int open = 0, with_membrane = 0;
  bool saw_cube = false, saw_elephant = false;
  for (const Outcome& o : outcomes) {
    if (!o.open) continue;
    ++open;
    EXPECT_TRUE(o.error.empty()) << o.name << ": " << o.error;
    if (!o.error.empty()) continue;
    with_membrane += o.cpt.membrane_voxels > 0;
    std::ostringstream msg;
    msg << o.name << " R=" << o.resolution << ": open edges " << o.cpt.open_edges << ", membrane voxels "
        << o.cpt.membrane_voxels << " (+" << o.cpt.membrane_bricks_added << " bricks) -> genus " << o.out.genus
        << ", components " << o.out.components << ", watertight " << o.out.watertight << ", manifold "
        << o.out.manifold << " (" << o.seconds << " s)";
    std::cout << "[ open     ] " << msg.str() << "\n";
    EXPECT_TRUE(o.out.watertight && o.out.manifold && o.out.oriented) << msg.str();
    EXPECT_EQ(o.violations, 0u) << msg.str();
    EXPECT_EQ(o.cpt.membrane_truncated_bricks, 0u) << msg.str();
    if (o.name == "cube-ouvert.off") {
      saw_cube = true;
      EXPECT_EQ(o.out.genus, 0.0) << msg.str();
      EXPECT_EQ(o.out.components, 1u) << msg.str();
      EXPECT_NEAR(o.out.volume, 8.0, 0.05) << msg.str();  // the closed cube [-1, 1]^3
    }
    if (o.name == "elephant-with-holes.off") {
      saw_elephant = true;
      // The closed elephant through the same pipeline and frame.
      const TriangleMesh closed = read_mesh(dir / "elephant.off").mesh;
      CptOptions same = options_at(read_mesh(dir / o.name).mesh, o.resolution);
      const MeshMeasures ref = measure_mesh(marching_cubes(closest_point_transform(closed, same).band).mesh);
      EXPECT_EQ(o.out.genus, ref.genus) << msg.str();
      EXPECT_EQ(o.out.components, ref.components) << msg.str();
      EXPECT_NEAR(o.out.volume, ref.volume, 0.03 * ref.volume) << msg.str();
    }
  }
  std::cout << "[ open     ] " << open << " open meshes, " << with_membrane << " with membranes beyond the mesh; "
            << total << " s\n";
  EXPECT_GE(open, 30);
  EXPECT_TRUE(saw_cube && saw_elephant);
}

// A box [0, 1]^2 x [0, top] without its top face: w = 1/2 exactly on the opening, so the band
// holds the signed distance to the closed box: z - top near the opening's centre.
TEST(MembraneBand, OpenBoxIsTheClosedBoxNearTheOpening) {
  const double top = 0.9913;
  TriangleMesh closed = test::box_mesh({0, 0, 0}, {1, 1, top});
  TriangleMesh open = closed;
  open.triangles.erase(open.triangles.begin() + 2, open.triangles.begin() + 4);  // the z = top face
  ASSERT_EQ(open_edge_count(open), 4u);
  ASSERT_EQ(open_edge_count(closed), 0u);
  const CptOptions o = options_at(closed, 96);
  const CptResult a = closest_point_transform(open, o);
  const CptResult b = closest_point_transform(closed, o);
  EXPECT_GT(a.membrane_voxels, 1000u);
  EXPECT_EQ(b.membrane_voxels, 0u);
  EXPECT_EQ(invariant_violations(a.band), 0u);
  const double h = a.band.voxel_size();
  double worst = 0.0;
  std::uint64_t checked = 0;
  a.band.for_each_active_world([&](const Coord& c, const Vec3d& p, float v) {
    // Away from the rim (there the mesh is nearer): the opening's plane is the nearest surface.
    if (p.x < 0.3 || p.x > 0.7 || p.y < 0.3 || p.y > 0.7 || std::abs(p.z - top) > 0.25) return;
    ++checked;
    worst = std::max(worst, std::abs(double(v) - (p.z - top)));
    const auto ref = b.band.value(c);
    if (ref) {
      EXPECT_EQ(std::signbit(*ref), std::signbit(v));
    }
  });
  std::cout << "[ open box ] " << checked << " voxels near the opening: |value - (z - top)| <= " << worst / h
            << " h\n";
  EXPECT_GT(checked, 1000u);
  EXPECT_LE(worst, 0.1 * h);
  // Same surface as the closed box.
  const MeshMeasures ma = measure_mesh(marching_cubes(a.band).mesh);
  const MeshMeasures mb = measure_mesh(marching_cubes(b.band).mesh);
  EXPECT_TRUE(ma.watertight && ma.manifold);
  EXPECT_EQ(ma.genus, 0.0);
  EXPECT_NEAR(ma.volume, mb.volume, 1e-3 * mb.volume);
}

// Closest points of membrane voxels lie on the opening's plane.
TEST(MembraneBand, ClosestPointsOfMembraneVoxelsLieOnTheMembrane) {
  const double top = 0.9913;
  TriangleMesh open = test::box_mesh({0, 0, 0}, {1, 1, top});
  open.triangles.erase(open.triangles.begin() + 2, open.triangles.begin() + 4);
  CptOptions o = options_at(open, 64);
  o.closest_points = true;
  const CptResult r = closest_point_transform(open, o);
  ASSERT_EQ(r.closest_points.size(), r.band.active_voxel_count());
  const double h = r.band.voxel_size();
  std::size_t k = 0, checked = 0;
  r.band.for_each_active_world([&](const Coord&, const Vec3d& p, float v) {
    const Vec3f q = r.closest_points[k++];
    ASSERT_NEAR(length(p - Vec3d{q.x, q.y, q.z}), std::abs(double(v)), 0.05 * h);
    if (p.x < 0.3 || p.x > 0.7 || p.y < 0.3 || p.y > 0.7 || std::abs(p.z - top) > 0.2) return;
    ++checked;
    EXPECT_NEAR(q.z, top, 0.1 * h);
  });
  EXPECT_GT(checked, 100u);
}

// Degenerate inputs: no crash, a definite band. A single triangle or a flat patch has no
// inside (w <= 1/2 everywhere); a non-manifold fan and a self-intersecting open pair get a
// closed surface or none.
TEST(MembraneBand, DegenerateOpenInputsGiveAClearResult) {
  TriangleMesh triangle;
  triangle.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  triangle.triangles = {{0, 1, 2}};
  TriangleMesh fan;  // three triangles on one edge (non-manifold), open
  fan.vertices = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {-0.5, 0.8, 0}, {-0.5, -0.8, 0}};
  fan.triangles = {{0, 1, 2}, {0, 1, 3}, {1, 0, 4}};
  TriangleMesh crossing = test::box_mesh({0, 0, 0}, {1, 1, 1});  // open box through another
  crossing.triangles.erase(crossing.triangles.begin() + 2, crossing.triangles.begin() + 4);
  TriangleMesh other = test::box_mesh({0.5, 0.3, 0.2}, {1.6, 0.8, 1.4});
  other.triangles.erase(other.triangles.begin() + 10, other.triangles.end());  // no +x face
  for (const auto& t : other.triangles)
    crossing.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  crossing.vertices.insert(crossing.vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const auto& [name, mesh] : {std::pair<const char*, TriangleMesh>{"triangle", triangle},
                                   {"fan", fan},
                                   {"crossing", crossing}}) {
    SCOPED_TRACE(name);
    CptResult r;
    ASSERT_NO_THROW(r = closest_point_transform(mesh, options_at(mesh, 64)));
    EXPECT_GT(r.band.active_voxel_count(), 0u);
    EXPECT_EQ(invariant_violations(r.band), 0u);
    const MeshMeasures m = measure_mesh(marching_cubes(r.band).mesh);
    EXPECT_TRUE(m.faces == 0 || (m.watertight && m.manifold)) << m.faces << " faces";
    if (std::string(name) == "triangle") {
      EXPECT_EQ(m.faces, 0u);
      EXPECT_EQ(r.membrane_voxels, 0u);
    }
    if (std::string(name) == "crossing") {
      EXPECT_GT(m.faces, 0u);
      EXPECT_EQ(m.components, 1u);
    }
  }
}

}  // namespace
}  // namespace levelset
