// bench_reconstruct: levelset's reconstruction (apps/reconstruction.hpp, no normals) against
// Open3D's screened Poisson (tests/bench/poisson_reference.py: normals estimated and oriented,
// depth 8) on points sampled by area (seeded) from CGAL's knot.off and bunny00.off, 20k and
// 100k points, noise 0 and 0.2% of the bounding-box diagonal, resolution 256.
// Prints per case, side by side: Chamfer and Hausdorff to the true mesh (exact point-to-mesh
// distances of 200k area samples each way; in units of the bbox diagonal and of our voxel),
// watertight, genus, seconds. --quick: the knot, 20k clean points, resolution 96, no Poisson.
// Development switches (any order after the program name): --ours (no Poisson), --mesh NAME
// (knot.off or bunny00.off), --points N, --noise F (fraction of the diagonal): one case;
// --log: the reconstruction's per-level lines on stderr; --seeds A B: the sampling seeds A..B
// (default 5 only); --levels L, --neighbors K: reconstruction options; --topology: no
// distances, only watertight / genus / components per case (fast sample-set sweeps).
// --sweep: every closed manifold CGAL mesh at several densities, noises and seeds with default
// options (bench_reconstruct_sweep.cpp, issue 19).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/mesh_distance.hpp"
#include "apps/reconstruction.hpp"
#include "apps/sample_points.hpp"
#include "bench_support.hpp"
#include "reconstruct_scoring.hpp"
#include "core/file_io.hpp"
#include "io/mesh_reader.hpp"
#include "surface/mesh_measures.hpp"

namespace {

using namespace levelset;

using bench::Row;
using bench::score;
using bench::gross_threshold;

}  // namespace

int main(int argc, char** argv) {
  for (int a = 1; a < argc; ++a)
    if (std::string(argv[a]) == "--sweep") return bench::run_reconstruct_sweep(argc, argv);
  const bool quick = bench::is_quick(argc, argv);
  bool ours_only = quick;
  bool log_stages = false;
  std::string only_mesh;
  long only_points = -1;
  double only_noise = -1.0;
  unsigned long seed_first = 5, seed_last = 5;
  int levels = 0, neighbors = 0;
  bool topology_only = false;
  bool guard_flow = true, guard_snaps = true;
  double free_distance = -1.0;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--ours") ours_only = true;
    if (arg == "--log") log_stages = true;
    if (a + 1 < argc && arg == "--mesh") only_mesh = argv[a + 1];
    if (a + 1 < argc && arg == "--points") only_points = std::atol(argv[a + 1]);
    if (a + 1 < argc && arg == "--noise") only_noise = std::atof(argv[a + 1]);
    if (a + 2 < argc && arg == "--seeds") {
      seed_first = std::strtoul(argv[a + 1], nullptr, 10);
      seed_last = std::max(seed_first, std::strtoul(argv[a + 2], nullptr, 10));
    }
    if (a + 1 < argc && arg == "--levels") levels = std::atoi(argv[a + 1]);
    if (a + 1 < argc && arg == "--neighbors") neighbors = std::atoi(argv[a + 1]);
    if (arg == "--topology") topology_only = true;
    if (arg == "--no-guard-flow") guard_flow = false;
    if (arg == "--no-guard-snaps") guard_snaps = false;
    if (a + 1 < argc && arg == "--free-distance") free_distance = std::atof(argv[a + 1]);
  }
  return bench::run_bench("bench_reconstruct", "a reconstruction is not watertight", [&] {
    bool ok = true;
    const std::string dir = std::string(LEVELSET_CGAL_DATA) + "/meshes/";
    std::printf("%-10s %7s %6s | %-9s %9s %9s %9s %9s %3s %5s %7s\n", "mesh", "points", "noise", "method", "chamfer/D",
                "chamfer/h", "hausd/D", "hausd/h", "wt", "genus", "seconds");
    for (const char* name : {"knot.off", "bunny00.off"}) {
      if (quick && std::string(name) != "knot.off") continue;
      if (!only_mesh.empty() && only_mesh != name) continue;
      const TriangleMesh truth = read_mesh(dir + name).mesh;
      const double diag = length(truth.bounds().extent());
      apps::SurfaceSampleOptions ts;
      ts.count = 200000;
      ts.seed = 11;
      const std::vector<Vec3d> truth_samples = apps::sample_mesh_surface(truth, ts);
      for (std::size_t count : {std::size_t(20000), std::size_t(100000)}) {
        for (double noise : {0.0, 0.002}) {
          if (quick && (count != 20000 || noise > 0)) continue;
          if (only_points >= 0 && std::size_t(only_points) != count) continue;
          if (only_noise >= 0.0 && std::abs(only_noise - noise) > 1e-12) continue;
          for (unsigned long seed = seed_first; seed <= seed_last; ++seed) {
          apps::SurfaceSampleOptions ps;
          ps.count = count;
          ps.noise = noise * diag;
          ps.seed = seed;
          const std::vector<Vec3d> points = apps::sample_mesh_surface(truth, ps);
          apps::ReconstructionOptions o;
          o.resolution = quick ? 96 : 256;
          if (neighbors > 0) o.neighbors = neighbors;
          if (levels > 0) o.levels = levels;
          o.guard_flow = guard_flow;
          o.guard_snaps = guard_snaps;
          if (free_distance >= 0.0) o.free_distance = free_distance;
          if (log_stages) o.log = [](const std::string& line) { std::fprintf(stderr, "  %s\n", line.c_str()); };
          o.log_topology = log_stages;
          const auto t0 = std::chrono::steady_clock::now();
          const apps::ReconstructionResult r = apps::reconstruct_surface(points, o);
          const double ours_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          const double h = r.voxel_size;
          auto print = [&](const char* method, const Row& row) {
            std::printf("%-10s %7zu %6.3f%% | %-9s %9.2e %9.3f %9.2e %9.3f %3s %5g %7.2f\n", name, count, noise * 100, method,
                        row.chamfer / diag, row.chamfer / h, row.hausdorff / diag, row.hausdorff / h,
                        row.watertight ? "yes" : "no", row.genus, row.seconds);
            std::fflush(stdout);
          };
          if (topology_only) {
            std::printf("%-10s %7zu %6.3f%% | seed %lu: watertight %s, genus %g, components %llu, %.2f s\n", name, count,
                        noise * 100, seed, r.measures.watertight ? "yes" : "no", r.measures.genus,
                        static_cast<unsigned long long>(r.measures.components), ours_s);
            std::fflush(stdout);
            ok = ok && r.measures.watertight;
            continue;
          }
          if (seed_last > seed_first) std::printf("seed %lu\n", seed);
          const Row ours = score(truth, truth_samples, r.mesh, ours_s, gross_threshold(truth, noise));
          print("levelset", ours);
          ok = ok && ours.watertight;
          if (ours_only) continue;
          const bench::PoissonRun poisson = bench::run_poisson(points, "");
          if (!poisson.ok) {
            std::printf("%-10s %7zu %6.3f%% | poisson   (reference failed: %s)\n", name, count, noise * 100, poisson.error.c_str());
            continue;
          }
          print("poisson", score(truth, truth_samples, poisson.mesh, poisson.seconds, gross_threshold(truth, noise)));
          }
        }
      }
    }
    return ok;
  });
}
