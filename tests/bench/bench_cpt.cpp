// bench_cpt: our closest point transform against OpenVDB's meshToLevelSet on the same mesh,
// voxel size and band half-width (W = 3), with 1 and 2 threads. Prints both times, the ratio
// ours / OpenVDB (target < 1 on every row) and both active voxel counts.
// Usage: bench_cpt [--quick]   (--quick: knot.off at R = 64 only, for the ctest smoke run)
// Exit code 1 if a mesh is missing in the full run or the two sides disagree grossly on the
// band (active voxel counts more than 5% apart: OpenVDB's band is not exact, ours is).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>

#include "core/error.hpp"
#include "distance/closest_point_transform.hpp"
#include "grid/build_from_sdf.hpp"
#include "io/mesh_reader.hpp"

namespace {

using namespace levelset;
using Clock = std::chrono::steady_clock;

template <typename F>
double best_of(int runs, F&& f) {
  double best = 1e300;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  return best;
}

bool bench_mesh(const std::string& path, const std::vector<int>& resolutions, int runs) {
  const TriangleMesh mesh = read_mesh(path).mesh;
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  for (const auto& v : mesh.vertices) points.emplace_back(float(v.x), float(v.y), float(v.z));
  for (const auto& t : mesh.triangles) tris.emplace_back(t[0], t[1], t[2]);
  bool ok = true;
  for (int res : resolutions) {
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      CptOptions options;
      options.frame = frame_for_resolution(mesh.bounds(), res, 3.0);
      std::uint64_t ours_active = 0, vdb_active = 0;
      const double ours = best_of(runs, [&] {
        ours_active = closest_point_transform(mesh, options).band.active_voxel_count();
      });
      auto xf = openvdb::math::Transform::createLinearTransform(options.frame.voxel_size);
      const double vdb = best_of(runs, [&] {
        vdb_active = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xf, points, tris, 3.0f)
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
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  openvdb::initialize();
  const std::string data = std::string(LEVELSET_CGAL_DATA) + "/meshes/";
  std::printf("bench_cpt: closest point transform vs OpenVDB %s meshToLevelSet, W = 3, best of %d\n",
              openvdb::getLibraryAbiVersionString(), quick ? 1 : 3);
  std::printf("%-14s %5s %3s %9s %9s %8s %10s %10s\n", "mesh", "R", "thr", "ours_s", "vdb_s",
              "ratio", "our_active", "vdb_active");
  bool ok = true;
  try {
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
  } catch (const Error& e) {
    std::fprintf(stderr, "bench_cpt: %s\n", e.what());
    return 1;
  }
  return ok ? 0 : 1;
}
