// bench_evolve: our evolution steps against OpenVDB's on the same band (the CPT band of
// CGAL's knot.off at R = 256, W = 3, copied voxel for voxel), with 1 and 2 threads:
//   mean curvature: 10 steps of our mean-curvature flow (forward Euler, band upkeep and the
//     edge-layer extrapolation included) against 10 calls of LevelSetFilter::meanCurvature()
//     (one Euler step + its tracker each); seconds per step and the ratio.
//   advection: WENO5 in space, TVD-RK3 in time, constant velocity (0.5, 0.3, -0.2), over the
//     same simulated time as 10 of our CFL-0.5 steps, against LevelSetAdvection with
//     HJWENO5_BIAS / TVD_RK3 (CFL 0.5, its default tracker); total seconds, steps taken by
//     each and the ratio of seconds per unit of simulated time.
// Target: ratio <= 1 / 1.5 (at least 1.5x faster). Best of 3.
// Usage: bench_evolve [--quick]   (--quick: R = 64, one run, for ctest)
#include <cstdio>
#include <filesystem>
#include <string>

#include <openvdb/tools/LevelSetAdvect.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <tbb/global_control.h>

#include "bench_support.hpp"
#include "distance/closest_point_transform.hpp"
#include "evolve/evolution.hpp"
#include "grid/build_from_sdf.hpp"
#include "io/mesh_reader.hpp"

namespace {

using namespace levelset;
using levelset::bench::best_of;

// OpenVDB's velocity-field interface for a constant velocity (world units per time).
struct ConstantField {
  using ValueType = float;
  using VectorType = openvdb::math::Vec3<float>;
  VectorType v;
  openvdb::math::Transform transform() const { return openvdb::math::Transform(); }
  VectorType operator()(const openvdb::Vec3d&, ValueType) const { return v; }
  VectorType operator()(const openvdb::Coord&, ValueType) const { return v; }
};

bool bench_band(const NarrowBand& band, int runs, int steps) {
  const auto grid = bench::vdb_from_band(band);
  const Vec3d velocity{0.5, 0.3, -0.2};
  bool ok = true;
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    // Mean curvature.
    evolve::EvolutionOptions mcf;
    mcf.speed = evolve::mean_curvature_flow();
    mcf.steps = steps;
    int upkeeps = 0;
    const double ours = best_of(runs, [&] { upkeeps = evolve::evolve(band, mcf).band_updates; }) / steps;
    const double vdb = best_of(runs, [&] {
      auto g = grid->deepCopy();
      openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*g);
      for (int i = 0; i < steps; ++i) filter.meanCurvature();
    }) / steps;
    std::printf("%-14s %3d %10.4f %10.4f %7.3fx %6d/%d upkeeps\n", "mean-curvature", threads, ours, vdb, ours / vdb,
                upkeeps, steps);
    ok &= ours > 0 && vdb > 0;
    // WENO5 / RK3 advection over the time of `steps` of our steps.
    evolve::EvolutionOptions adv;
    adv.velocity.kind = evolve::Velocity::Kind::Constant;
    adv.velocity.constant = velocity;
    adv.scheme = evolve::Scheme::Weno5;
    adv.rk_order = 3;
    adv.steps = steps;
    double sim_time = 0;
    int our_steps = 0;
    const double ours_adv = best_of(runs, [&] {
      const auto r = evolve::evolve(band, adv);
      sim_time = r.time;
      our_steps = r.steps;
    });
    std::size_t vdb_steps = 0;
    const double vdb_adv = best_of(runs, [&] {
      auto g = grid->deepCopy();
      ConstantField field{{float(velocity.x), float(velocity.y), float(velocity.z)}};
      openvdb::tools::LevelSetAdvection<openvdb::FloatGrid, ConstantField> advect(*g, field);
      advect.setSpatialScheme(openvdb::math::HJWENO5_BIAS);
      advect.setTemporalScheme(openvdb::math::TVD_RK3);
      advect.setNormCount(1);
      vdb_steps = advect.advect(0.0, sim_time);
    });
    std::printf("%-14s %3d %10.4f %10.4f %7.3fx %6d / %zu steps over t = %.4g\n", "weno5-rk3 adv", threads, ours_adv,
                vdb_adv, ours_adv / vdb_adv, our_steps, vdb_steps, sim_time);
    std::fflush(stdout);
    ok &= ours_adv > 0 && vdb_adv > 0;
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = bench::is_quick(argc, argv);
  openvdb::initialize();
  const int runs = quick ? 1 : 3, steps = quick ? 2 : 10, res = quick ? 64 : 256;
  std::printf("bench_evolve: evolution steps vs OpenVDB %s, knot.off R = %d, W = 3, best of %d\n",
              openvdb::getLibraryAbiVersionString(), res, runs);
  std::printf("%-14s %3s %10s %10s %8s\n", "case", "thr", "ours_s", "vdb_s", "ratio");
  return bench::run_bench("bench_evolve", "a run failed", [&] {
    const std::string path = std::string(LEVELSET_CGAL_DATA) + "/meshes/knot.off";
    if (!std::filesystem::exists(path)) {
      std::printf("knot.off missing: %s (run deploy/install-deps.sh)\n", path.c_str());
      return quick;
    }
    const TriangleMesh input = read_mesh(path).mesh;
    CptOptions options;
    options.frame = frame_for_resolution(input.bounds(), res, 3.0);
    return bench_band(closest_point_transform(input, options).band, runs, steps);
  });
}
