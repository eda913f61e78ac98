// bench_redistance: throughput of redistance() (Sweep and March, 1 and 2 threads) against
// OpenVDB's reinitialisation of the same voxels.
//
// Case: the analytic torus knot built by build_from_sdf at R = 256 and 512, W = 3, its values
// multiplied by 1 + 0.5 sin(3x) sin(3y) sin(3z) (zero level and signs kept, |grad u| in
// about [0.5, 1.5]). The same distorted voxels are copied into an openvdb::FloatGrid (active
// voxels = our band's, signedFloodFill for the rest; leaves = bricks) and reinitialised by
//   - tools::sdfToSdf (FastSweeping.h, 1 iteration = 8 sweeps): Eikonal solve on the active
//     voxels, the same job as ours; the ratio column compares against it;
//   - tools::levelSetRebuild (mesh the zero level, re-scan a W = 3 band): the thesis's
//     reinitialisation (4.4), exact to the polygonised surface;
//   - tools::LevelSetTracker::normalize() with its defaults (HJWENO5, TVD-RK1, 3 pseudo-time
//     steps): OpenVDB's in-place renormalisation during tracking, which only reduces the
//     distortion.
// Figures: seconds (best of 3), active input voxels per second, ratio (OpenVDB sdfToSdf time /
// ours, > 1: we are faster), and the max ||grad d| - 1| by central differences at voxels at
// least 1.5 voxels from the zero level whose 6 neighbours are active (distorted input shown
// for scale).
// Usage: bench_redistance [--quick]   (--quick: R = 128 only, one run, for the ctest smoke run;
// R = 64 would put the knot's tube axis, where |grad d| is undefined, inside the band)
// Exit code 1 if a result fails a sanity bound (gradient error, lost or wrong-sign voxels).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/LevelSetTracker.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/task_arena.h>

#include "core/error.hpp"
#include "distance/redistance.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/band_accessor.hpp"
#include "grid/build_from_sdf.hpp"

namespace {

using namespace levelset;

double wobble(const Vec3d& p) { return 1.0 + 0.5 * std::sin(3 * p.x) * std::sin(3 * p.y) * std::sin(3 * p.z); }

NarrowBand distort(const NarrowBand& band) {
  NarrowBand out = band;
  parallel_for_bricks(out, [&](std::uint32_t b) {
    const Coord o = brick_origin(out.bricks()[b].coord);
    out.update_active_in_brick(b, [&](int n, float v) { return float(double(v) * wobble(out.world(o + local_coord(n)))); });
  });
  return out;
}

// Same index space (origin 0 in OpenVDB's transform = our origin), so leaves = bricks.
openvdb::FloatGrid::Ptr vdb_from_band(const NarrowBand& band) {
  auto grid = openvdb::FloatGrid::create(band.background());
  grid->setTransform(openvdb::math::Transform::createLinearTransform(band.voxel_size()));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  auto acc = grid->getAccessor();
  band.for_each_active([&](const Coord& c, float v) { acc.setValueOn(openvdb::Coord(c.x, c.y, c.z), v); });
  openvdb::tools::signedFloodFill(grid->tree());
  return grid;
}

// Max ||grad| - 1| at voxels with |v| >= 1.5h whose 6 neighbours are active.
template <typename Probe>
double gradient_error(double h, const std::function<void(const std::function<void(const Coord&, float)>&)>& each,
                      Probe probe) {
  double worst = 0;
  each([&](const Coord& c, float v) {
    if (std::abs(v) < 1.5 * h) return;
    double g2 = 0;
    for (int a = 0; a < 3; ++a) {
      Coord d{0, 0, 0};
      d[a] = 1;
      float p, m;
      if (!probe(c + d, p) || !probe(c - d, m)) return;
      const double g = (double(p) - double(m)) / (2 * h);
      g2 += g * g;
    }
    worst = std::max(worst, std::abs(std::sqrt(g2) - 1.0));
  });
  return worst;
}

double ours_gradient_error(const NarrowBand& band) {
  return gradient_error(band.voxel_size(), [&](const auto& f) { band.for_each_active(f); }, band_probe(band));
}

auto vdb_probe(const openvdb::FloatGrid& grid) {
  return [acc = grid.getConstAccessor()](const Coord& c, float& v) mutable {
    const openvdb::Coord oc(c.x, c.y, c.z);
    v = acc.getValue(oc);
    return acc.isValueOn(oc);
  };
}

auto band_probe(const NarrowBand& band) {
  return [acc = BandAccessor(band)](const Coord& c, float& v) mutable {
    const auto p = acc.probe(c);
    if (p) v = *p;
    return p.has_value();
  };
}

double vdb_gradient_error(const openvdb::FloatGrid& grid) {
  return gradient_error(
      grid.voxelSize()[0],
      [&](const auto& f) {
        for (auto it = grid.cbeginValueOn(); it; ++it) {
          const openvdb::Coord c = it.getCoord();
          f(Coord{c.x(), c.y(), c.z()}, *it);
        }
      },
      vdb_probe(grid));
}

// Largest displacement (in voxels) of the zero crossing, by linear interpolation, along the
// input's sign-change edges whose two ends the result holds.
template <typename Probe>
double crossing_shift(const NarrowBand& in, Probe probe) {
  BandAccessor acc(in);
  double worst = 0;
  in.for_each_active([&](const Coord& c, float u) {
    for (int a = 0; a < 3; ++a) {
      Coord e = c;
      e[a] += 1;
      const auto ue = acc.probe(e);
      float dc, de;
      if (!ue || (*ue < 0) == (u < 0) || !probe(c, dc) || !probe(e, de)) continue;
      const double before = double(u) / (double(u) - double(*ue));
      const double after = double(dc) / (double(dc) - double(de));
      worst = std::max(worst, std::abs(after - before));
    }
  });
  return worst;
}

// Voxels of `in` whose sign the result lost or flipped (the result must keep every one).
std::uint64_t sign_errors_vdb(const NarrowBand& in, const openvdb::FloatGrid& grid) {
  auto acc = grid.getConstAccessor();
  std::uint64_t bad = 0;
  in.for_each_active([&](const Coord& c, float v) {
    const openvdb::Coord oc(c.x, c.y, c.z);
    bad += (acc.getValue(oc) < 0) != (v < 0);
  });
  return bad;
}

template <typename F>
double best_seconds(int runs, F&& f) {
  double best = 1e30;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

void row(const char* what, int res, int threads, std::uint64_t voxels, double seconds, double reference,
         double grad_error, const std::string& note) {
  std::printf("%-22s %4d %3d %10llu %9.4f %9.2f %8s %9.4f  %s\n", what, res, threads, (unsigned long long)voxels,
              seconds, double(voxels) / seconds / 1e6,
              reference > 0 ? (std::to_string(reference / seconds).substr(0, 5) + "x").c_str() : "-", grad_error,
              note.c_str());
}

bool run_case(int res, int runs) {
  const auto knot = make_builtin_shape("knot");
  SdfBuildOptions build;
  build.frame = frame_for_resolution(knot->bounds(), res, 3.0);
  const NarrowBand exact =
      build_from_sdf([&](const Vec3d& p) { return knot->distance(p); }, knot->bounds(), build).band;
  const NarrowBand in = distort(exact);
  const std::uint64_t voxels = in.active_voxel_count();
  bool ok = true;
  std::printf("%-22s %4d %3s %10llu %9s %9s %8s %9.4f\n", "input (distorted)", res, "-", (unsigned long long)voxels,
              "-", "-", "-", ours_gradient_error(in));

  // OpenVDB on the same voxels.
  double vdb_sweep_seconds[3] = {0, 0, 0};  // by thread count
  for (int threads : {1, 2}) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      const auto grid = vdb_from_band(in);
      openvdb::FloatGrid::Ptr out;
      const double t = best_seconds(runs, [&] { out = openvdb::tools::sdfToSdf(*grid, 0.0f, 1); });
      vdb_sweep_seconds[threads] = t;
      row("openvdb sdfToSdf", res, threads, voxels, t, 0, vdb_gradient_error(*out),
          "sign errors " + std::to_string(sign_errors_vdb(in, *out)));
      const double tr = best_seconds(runs, [&] { out = openvdb::tools::levelSetRebuild(*grid, 0.0f, 3.0f); });
      row("openvdb levelSetRebuild", res, threads, voxels, tr, 0, vdb_gradient_error(*out),
          "active " + std::to_string(out->activeVoxelCount()));
      double tn = 1e30;
      for (int i = 0; i < runs; ++i) {
        out = grid->deepCopy();
        openvdb::tools::LevelSetTracker<openvdb::FloatGrid> tracker(*out);
        tn = std::min(tn, best_seconds(1, [&] { tracker.normalize(); }));
      }
      row("openvdb normalize()", res, threads, voxels, tn, 0, vdb_gradient_error(*out), "3 HJWENO5 steps");
    });
  }
  // Ours. The ratio compares with OpenVDB's sdfToSdf at the same thread count.
  for (RedistanceMethod method : {RedistanceMethod::Sweep, RedistanceMethod::March}) {
    for (int threads : {1, 2}) {
      tbb::task_arena arena(threads);
      RedistanceResult r;
      RedistanceOptions o;
      o.method = method;
      const double t = arena.execute([&] { return best_seconds(runs, [&] { r = redistance(in, o); }); });
      const double g = ours_gradient_error(r.band);
      std::uint64_t lost = 0;
      BandAccessor acc(r.band);
      in.for_each_active([&](const Coord& c, float v) {
        const auto w = acc.probe(c);
        lost += w.has_value() ? ((*w < 0) != (v < 0)) : std::abs(v) < in.voxel_size();
      });
      ok &= g < 0.05 && lost == 0;
      row(method == RedistanceMethod::Sweep ? "ours sweep" : "ours march", res, threads, voxels, t,
          vdb_sweep_seconds[threads], g,
          "iterations " + std::to_string(r.sweep_iterations) + ", sign errors " + std::to_string(lost));
    }
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  openvdb::initialize();
  const std::vector<int> res = quick ? std::vector<int>{128} : std::vector<int>{256, 512};
  std::printf("bench_redistance: distorted torus knot, W = 3, OpenVDB %s; seconds = best of %d\n",
              openvdb::getLibraryAbiVersionString(), quick ? 1 : 3);
  std::printf("%-22s %4s %3s %10s %9s %9s %8s %9s\n", "method", "R", "thr", "voxels", "seconds", "Mvox/s",
              "vs sdfToSdf", "|grad|-1");
  bool ok = true;
  try {
    for (int r : res) ok &= run_case(r, quick ? 1 : 3);
  } catch (const Error& e) {
    std::fprintf(stderr, "bench_redistance: %s\n", e.what());
    return 1;
  }
  if (!ok) {
    std::fprintf(stderr, "bench_redistance: a result failed its sanity bound\n");
    return 1;
  }
  return 0;
}
