// bench_memory: bytes per active voxel of our NarrowBand against OpenVDB's FloatGrid on the
// same band. Prints one row per case and the ratio ours / OpenVDB (target <= 0.40).
//
// Cases: CGAL's knot.off and bunny00.off turned into a band by OpenVDB's meshToLevelSet at
// R = 256 (and 512 in the full run), W = 3, whose active voxels are then copied into our
// NarrowBand (identical voxel sets, values and signs; bricks = OpenVDB leaves); and the
// analytic torus knot built by our build_from_sdf, copied into an OpenVDB grid.
// Usage: bench_memory [--quick]   (--quick: R = 64 only, for the ctest smoke run)
// Exit code 1 if the two sides of any row disagree on the voxel set.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>

#include "bench_support.hpp"
#include "geometry/analytic_shapes.hpp"
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
  const bench::VdbMesh vdb_input = bench::vdb_mesh(mesh);
  bool ok = true;
  for (int res : resolutions) {
    const double W = 3.0;
    const GridFrame frame = frame_for_resolution(mesh.bounds(), res, W);
    auto xf = openvdb::math::Transform::createLinearTransform(frame.voxel_size);
    auto grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xf, vdb_input.points,
                                                                   vdb_input.triangles, float(W));
    const NarrowBand band = bench::band_from_vdb(*grid, W);
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
    auto grid = bench::vdb_from_band(band);  // same index coordinates, so leaves = bricks
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
  const bool quick = bench::is_quick(argc, argv);
  openvdb::initialize();
  const std::string data = LEVELSET_CGAL_DATA;
  const std::vector<int> res = quick ? std::vector<int>{64} : std::vector<int>{256, 512};
  std::printf("bench_memory: bytes per active voxel, band half-width 3, OpenVDB %s\n",
              openvdb::getLibraryAbiVersionString());
  std::printf("%-16s %5s %10s %10s %8s %8s %11s %11s %8s\n", "case", "R", "vdb_active",
              "our_active", "leaves", "bricks", "vdb_B/vox", "our_B/vox", "ratio");
  std::vector<Row> rows;
  return bench::run_bench("bench_memory", "voxel sets differ between the two sides", [&] {
    bool ok = true;
    ok &= mesh_rows(data + "/meshes/knot.off", res, rows);
    ok &= mesh_rows(data + "/meshes/bunny00.off", res, rows);
    ok &= analytic_rows(res, rows);
    return ok;
  });
}
