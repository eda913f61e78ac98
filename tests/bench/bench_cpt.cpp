// bench_cpt: our closest point transform against OpenVDB's meshToLevelSet on the same mesh,
// voxel size and band half-width (W = 3), with 1 and 2 threads. Prints both times, the ratio
// ours / OpenVDB (target < 1 on every row) and both active voxel counts.
// Usage: bench_cpt [--quick]   (--quick: knot.off at R = 64 only, for the ctest smoke run)
// Exit code 1 if a mesh is missing in the full run or the two sides disagree grossly on the
// band (active voxel counts more than 5% apart: OpenVDB's band is not exact, ours is).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>

#include "bench_support.hpp"
#include "distance/closest_point_transform.hpp"
#include "grid/build_from_sdf.hpp"
#include "io/mesh_reader.hpp"

namespace {

using namespace levelset;

bool bench_mesh(const std::string& path, const std::vector<int>& resolutions, int runs) {
  const TriangleMesh mesh = read_mesh(path).mesh;
  const bench::VdbMesh vdb_input = bench::vdb_mesh(mesh);
  bool ok = true;
  for (int res : resolutions) {
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      CptOptions options;
      options.frame = frame_for_resolution(mesh.bounds(), res, 3.0);
      std::uint64_t ours_active = 0, vdb_active = 0;
      const double ours = bench::best_of(runs, [&] {
        ours_active = closest_point_transform(mesh, options).band.active_voxel_count();
      });
      auto xf = openvdb::math::Transform::createLinearTransform(options.frame.voxel_size);
      const double vdb = bench::best_of(runs, [&] {
        vdb_active = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xf, vdb_input.points,
                                                                        vdb_input.triangles, 3.0f)
                         ->activeVoxelCount();
      });
      std::printf("%-14s %5d %3d %9.3f %9.3f %7.3fx %10llu %10llu  %s\n",
                  std::filesystem::path(path).filename().c_str(), res, threads, ours, vdb, ours / vdb,
                  (unsigned long long)ours_active, (unsigned long long)vdb_active,
                  ours < vdb ? "faster" : "SLOWER");
      std::fflush(stdout);
      const double diff = std::abs(double(ours_active) - double(vdb_active)) / double(vdb_active);
      ok &= diff < 0.05;
    }
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = bench::is_quick(argc, argv);
  openvdb::initialize();
  const std::string data = std::string(LEVELSET_CGAL_DATA) + "/meshes/";
  std::printf("bench_cpt: closest point transform vs OpenVDB %s meshToLevelSet, W = 3, best of %d\n",
              openvdb::getLibraryAbiVersionString(), quick ? 1 : 3);
  std::printf("%-14s %5s %3s %9s %9s %8s %10s %10s\n", "mesh", "R", "thr", "ours_s", "vdb_s",
              "ratio", "our_active", "vdb_active");
  return bench::run_bench("bench_cpt", nullptr, [&] {
    bool ok = true;
    for (const char* name : {"knot.off", "bunny00.off"}) {
      const std::string path = data + name;
      if (!std::filesystem::exists(path)) {
        std::printf("%-14s missing: %s (run deploy/install-deps.sh)\n", name, path.c_str());
        if (!quick) ok = false;
        continue;
      }
      ok &= bench_mesh(path, quick ? std::vector<int>{64} : std::vector<int>{256, 512}, quick ? 1 : 3);
      if (quick) break;
    }
    return ok;
  });
}
