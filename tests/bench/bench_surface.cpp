// bench_surface: our marching cubes and surface nets against OpenVDB's volumeToMesh
// (isovalue 0, adaptivity 0) on the same band: the CPT band of CGAL's knot.off and
// bunny00.off at R = 256 and 512 (W = 3), copied into an OpenVDB grid voxel for voxel.
// Prints times (best of 7 rounds that run the three extractors in turn: this project's virtual
// machines vary by 2x within minutes, and in turn each side of a ratio sees the same phases), the
// ratio ours / OpenVDB (target < 1) and triangle counts (OpenVDB's quads count as two
// triangles), with 1 and 2 threads. Then the cold figure (the daemon re-extracts after every
// evolution step, and a batch `levelsetd mesh` extracts once):
// marching cubes as the first extraction of a fresh process (`levelsetd mesh` on the band
// saved to a scratch .lsg: read, extract, write; its stats' extract phase), best of 5 such
// processes, against the warm in-process figure; target cold / warm <= 1.5. CGAL's armadillo
// at R = 256 joins the full run (the case the cold figure was first measured on).
// Usage: bench_surface [--quick]   (--quick: knot.off at R = 64, one run, for ctest)
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/global_control.h>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include "bench_support.hpp"
#include "grid/lsg_file.hpp"
#include "distance/closest_point_transform.hpp"
#include "grid/build_from_sdf.hpp"
#include "io/mesh_reader.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/surface_nets.hpp"

namespace {

constexpr int kRuns = 7;

using namespace levelset;
using levelset::bench::best_of;

// The extract phase of a fresh `levelsetd mesh` process on the band (seconds; < 0 on failure).
double cold_extract(const NarrowBand& band, int threads) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("bench_surface_cold_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  save_lsg(band, dir / "band.lsg");
  const std::string cmd = std::string(LEVELSET_LEVELSETD) + " mesh '" + (dir / "band.lsg").string() + "' -o '" +
                          (dir / "mesh.ply").string() + "' --threads " + std::to_string(threads) + " --stats '" +
                          (dir / "stats.json").string() + "' > /dev/null";
  double seconds = -1;
  if (std::system(cmd.c_str()) == 0) {
    std::ifstream in(dir / "stats.json");
    const nlohmann::json stats = nlohmann::json::parse(in, nullptr, false);
    if (!stats.is_discarded() && stats.contains("seconds")) seconds = stats["seconds"].value("extract", -1.0);
  }
  std::filesystem::remove_all(dir);
  return seconds;
}

bool bench_mesh(const std::string& path, const std::vector<int>& resolutions, int runs, bench::RatioSummary& summary) {
  const TriangleMesh input = read_mesh(path).mesh;
  bool ok = true;
  for (int res : resolutions) {
    CptOptions options;
    options.frame = frame_for_resolution(input.bounds(), res, 3.0);
    const NarrowBand band = closest_point_transform(input, options).band;
    const auto grid = bench::vdb_from_band(band);  // same voxels and values, same index space
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      std::size_t mc_tris = 0, sn_tris = 0, vdb_tris = 0;
      // The three extractions in turn, each run's best (bench_support.hpp: the VM's speed drifts).
      const auto [mc, sn, vdb] = bench::best_of_interleaved(
          runs, [&] { mc_tris = marching_cubes(band).mesh.triangles.size(); },
          [&] { sn_tris = surface_nets(band).mesh.triangles.size(); },
          [&] {
            std::vector<openvdb::Vec3s> points;
            std::vector<openvdb::Vec3I> tris;
            std::vector<openvdb::Vec4I> quads;
            openvdb::tools::volumeToMesh(*grid, points, tris, quads, 0.0, 0.0);
            vdb_tris = tris.size() + 2 * quads.size();
          });
      const std::string name = std::filesystem::path(path).filename().string();
      double cold = 1e300;
      for (int i = 0; i < runs; ++i) cold = std::min(cold, cold_extract(band, threads));
      std::printf("%-12s %4d %3d %8.3f %8.3f %8.3f %7.3fx %7.3fx %9zu %9zu %9zu %8.3f %7.2fx\n", name.c_str(), res,
                  threads, mc, sn, vdb, mc / vdb, sn / vdb, mc_tris, sn_tris, vdb_tris, cold, cold / mc);
      std::fflush(stdout);
      const std::string row = name + " R=" + std::to_string(res) + " thr=" + std::to_string(threads);
      summary.add("marching cubes / volumeToMesh", 0.5, row, mc / vdb);
      summary.add("surface nets / volumeToMesh", 0.5, row, sn / vdb);
      summary.add("cold / warm marching cubes", 1.5, row, cold / mc);
      ok &= mc_tris > 0 && sn_tris > 0 && vdb_tris > 0 && cold > 0;
    }
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = bench::is_quick(argc, argv);
  openvdb::initialize();
  std::printf("bench_surface: extraction vs OpenVDB %s volumeToMesh (iso 0, adaptivity 0), best of %d\n",
              openvdb::getLibraryAbiVersionString(), quick ? 1 : kRuns);
  std::printf("%-12s %4s %3s %8s %8s %8s %8s %8s %9s %9s %9s %8s %8s\n", "mesh", "R", "thr", "mc_s", "nets_s",
              "vdb_s", "mc/vdb", "nets/vdb", "mc_tris", "nets_tris", "vdb_tris", "cold_s", "cold/mc");
  bench::RatioSummary summary("bench_surface");
  return bench::run_bench("bench_surface", "an extractor produced no triangles", [&] {
    bool ok = true;
    for (const char* name : {"knot.off", "bunny00.off", "armadillo.off"}) {
      const std::string path = std::string(LEVELSET_CGAL_DATA) + "/meshes/" + name;
      if (!std::filesystem::exists(path)) {
        std::printf("%-12s missing: %s (run deploy/install-deps.sh)\n", name, path.c_str());
        if (!quick) ok = false;
        continue;
      }
      const bool armadillo = std::string(name) == "armadillo.off";
      ok &= bench_mesh(path, quick ? std::vector<int>{64} : (armadillo ? std::vector<int>{256} : std::vector<int>{256, 512}),
                       quick ? 1 : kRuns, summary);
      if (quick) break;
    }
    summary.print();
    return ok;
  });
}
