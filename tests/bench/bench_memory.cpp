// bench_memory: bytes per active voxel of our NarrowBand against OpenVDB's FloatGrid on the
// same band. Prints one row per case and the ratio ours / OpenVDB (target <= 0.40).
//
// Cases: CGAL's knot.off and bunny00.off turned into a band by OpenVDB's meshToLevelSet at
// R = 256 (and 512 in the full run), W = 3, whose active voxels are then copied into our
// NarrowBand (identical voxel sets, values and signs; bricks = OpenVDB leaves); and the
// analytic torus knot built by our build_from_sdf, copied into an OpenVDB grid.
// Usage: bench_memory [--quick]   (--quick: R = 64 only, for the ctest smoke run)
// Exit code 1 if the two sides of any row disagree on the voxel set.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>

#include "core/error.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/band_builder.hpp"
#include "grid/build_from_sdf.hpp"
#include "io/mesh_reader.hpp"

namespace {

using namespace levelset;

struct Row {
  std::string name;
  int resolution;
  std::uint64_t vdb_active, ours_active;
  std::uint64_t vdb_bytes, ours_bytes;
  std::uint64_t vdb_leaves, ours_bricks;
};

// Our band holding exactly the active voxels of an OpenVDB level set (index spaces aligned:
// origin 0, same voxel size), signs of inactive voxels from OpenVDB's values.
NarrowBand band_from_vdb(const openvdb::FloatGrid& grid, double half_width) {
  const double h = grid.voxelSize()[0];
  BandBuilder builder(GridFrame{h, {0, 0, 0}, half_width});
  std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
  for (auto it = grid.tree().cbeginLeaf(); it; ++it) leaves.push_back(&*it);
  tbb::parallel_for(std::size_t(0), leaves.size(), [&](std::size_t i) {
    const auto& leaf = *leaves[i];
    const openvdb::Coord o = leaf.origin();
    BrickMask active, inside;
    float dense[kBrickVoxels];
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
          // OpenVDB leaf offsets run z fastest; ours x fastest.
          const openvdb::Index off = leaf.coordToOffset(o + openvdb::Coord(x, y, z));
          const int n = local_index(x, y, z);
          dense[n] = leaf.getValue(off);
          if (leaf.isValueOn(off)) active.set(n);
          if (dense[n] < 0.0f) inside.set(n);
        }
    if (!active.none()) builder.add_brick(brick_of(Coord{o.x(), o.y(), o.z()}), active, inside, dense);
  });
  return builder.finish(false);
}

openvdb::FloatGrid::Ptr vdb_from_band(const NarrowBand& band) {
  auto grid = openvdb::FloatGrid::create(band.background());
  grid->setTransform(openvdb::math::Transform::createLinearTransform(band.voxel_size()));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  auto acc = grid->getAccessor();
  band.for_each_active([&](const Coord& c, float v) { acc.setValueOn(openvdb::Coord(c.x, c.y, c.z), v); });
  openvdb::tools::signedFloodFill(grid->tree());
  return grid;
}

void print_row(const Row& r) {
  const double vdb_per = double(r.vdb_bytes) / double(r.vdb_active);
  const double ours_per = double(r.ours_bytes) / double(r.ours_active);
  std::printf("%-16s %5d %10llu %10llu %8llu %8llu %11.2f %11.2f %7.3fx  %s\n", r.name.c_str(),
              r.resolution, (unsigned long long)r.vdb_active, (unsigned long long)r.ours_active,
              (unsigned long long)r.vdb_leaves, (unsigned long long)r.ours_bricks, vdb_per, ours_per,
              ours_per / vdb_per, ours_per / vdb_per <= 0.40 ? "target met" : "TARGET MISSED");
}

bool mesh_rows(const std::string& path, const std::vector<int>& resolutions, std::vector<Row>& rows) {
  if (!std::filesystem::exists(path)) {
    std::printf("%-16s skipped: %s not found (run deploy/install-deps.sh)\n",
                std::filesystem::path(path).filename().c_str(), path.c_str());
    return true;
  }
  const TriangleMesh mesh = read_mesh(path).mesh;
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  for (const auto& v : mesh.vertices) points.emplace_back(float(v.x), float(v.y), float(v.z));
  for (const auto& t : mesh.triangles) tris.emplace_back(t[0], t[1], t[2]);
  bool ok = true;
  for (int res : resolutions) {
    const double W = 3.0;
    const GridFrame frame = frame_for_resolution(mesh.bounds(), res, W);
    auto xf = openvdb::math::Transform::createLinearTransform(frame.voxel_size);
    auto grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xf, points, tris, float(W));
    const NarrowBand band = band_from_vdb(*grid, W);
    Row r{std::filesystem::path(path).filename().string(), res, grid->activeVoxelCount(),
          band.active_voxel_count(), grid->memUsage(), band.memory_bytes(),
          grid->tree().leafCount(), band.brick_count()};
    ok &= r.vdb_active == r.ours_active;
    rows.push_back(r);
    print_row(r);
  }
  return ok;
}

bool analytic_rows(const std::vector<int>& resolutions, std::vector<Row>& rows) {
  const auto knot = make_builtin_shape("knot");
  bool ok = true;
  for (int res : resolutions) {
    SdfBuildOptions options;
    options.frame = frame_for_resolution(knot->bounds(), res, 3.0);
    const NarrowBand band =
        build_from_sdf([&](const Vec3d& p) { return knot->distance(p); }, knot->bounds(), options).band;
    auto grid = vdb_from_band(band);  // same index coordinates, so leaves = bricks
    Row r{"analytic knot", res, grid->activeVoxelCount(), band.active_voxel_count(),
          grid->memUsage(), band.memory_bytes(), grid->tree().leafCount(), band.brick_count()};
    ok &= r.vdb_active == r.ours_active;
    rows.push_back(r);
    print_row(r);
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  openvdb::initialize();
  const std::string data = LEVELSET_CGAL_DATA;
  const std::vector<int> res = quick ? std::vector<int>{64} : std::vector<int>{256, 512};
  std::printf("bench_memory: bytes per active voxel, band half-width 3, OpenVDB %s\n",
              openvdb::getLibraryAbiVersionString());
  std::printf("%-16s %5s %10s %10s %8s %8s %11s %11s %8s\n", "case", "R", "vdb_active",
              "our_active", "leaves", "bricks", "vdb_B/vox", "our_B/vox", "ratio");
  std::vector<Row> rows;
  bool ok = true;
  try {
    ok &= mesh_rows(data + "/meshes/knot.off", res, rows);
    ok &= mesh_rows(data + "/meshes/bunny00.off", res, rows);
    ok &= analytic_rows(res, rows);
  } catch (const Error& e) {
    std::fprintf(stderr, "bench_memory: %s\n", e.what());
    return 1;
  }
  if (!ok) {
    std::fprintf(stderr, "bench_memory: voxel sets differ between the two sides\n");
    return 1;
  }
  return 0;
}
