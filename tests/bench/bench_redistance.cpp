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
// Figures: seconds (best of 3), active input voxels per second, ratio "vs VDB sw" (OpenVDB
// sdfToSdf time / ours at the same thread count, > 1: we are faster); from the 1-thread run:
// |grad|-1 = max ||grad d| - 1| by central differences at voxels at least 1.5 voxels from
// the zero level whose 6 neighbours are active (distorted input shown for scale), x-shift =
// max displacement (voxels) of the zero crossing along the input's sign-change edges (linear
// interpolation, edges whose ends the result keeps active), signs = input voxels whose sign
// the result flipped (ours: or dropped within one voxel of the zero level).
// Ours runs with order 2 (default) and order 1 (the thesis's first-order update).
// Usage: bench_redistance [--quick]   (--quick: R = 128 only, one run, for the ctest smoke run;
// R = 64 would put the knot's tube axis, where |grad d| is undefined, inside the band)
// Exit code 1 if one of our results fails a sanity bound (gradient error, crossing shift,
// signs).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/LevelSetTracker.h>
#include <tbb/task_arena.h>

#include "bench_support.hpp"
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

// probe(c, v): the value at voxel c if the result holds it active.
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
// input's sign-change edges whose two ends the result holds, with opposite signs.
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
      if ((dc < 0) == (de < 0)) continue;  // a sign flipped: counted by sign_errors
      const double before = double(u) / (double(u) - double(*ue));
      const double after = double(dc) / (double(dc) - double(de));
      worst = std::max(worst, std::abs(after - before));
    }
  });
  return worst;
}

// Voxels of `in` whose sign the result flipped.
std::uint64_t sign_errors_vdb(const NarrowBand& in, const openvdb::FloatGrid& grid) {
  auto acc = grid.getConstAccessor();
  std::uint64_t bad = 0;
  in.for_each_active([&](const Coord& c, float v) {
    const openvdb::Coord oc(c.x, c.y, c.z);
    bad += (acc.getValue(oc) < 0) != (v < 0);
  });
  return bad;
}

struct Quality {
  bool measured = false;       // only for the 1-thread run
  double grad_error = 0;       // max ||grad d| - 1|
  double crossing_shift = 0;   // max zero-crossing displacement, voxels
  std::uint64_t sign_errors = 0;
};

void row(const char* what, int res, int threads, std::uint64_t voxels, double seconds, double reference,
         const Quality& q, const std::string& note) {
  char ratio[16] = "-", quality[48] = "        -         -      -";
  if (reference > 0) std::snprintf(ratio, sizeof ratio, "%.2fx", reference / seconds);
  if (q.measured)
    std::snprintf(quality, sizeof quality, "%9.4f %9.4f %6llu", q.grad_error, q.crossing_shift,
                  (unsigned long long)q.sign_errors);
  std::printf("%-24s %4d %3d %9llu %8.4f %7.2f %9s %s  %s\n", what, res, threads, (unsigned long long)voxels,
              seconds, double(voxels) / seconds / 1e6, ratio, quality, note.c_str());
}

bool run_case(int res, int runs, bench::RatioSummary& summary) {
  const auto knot = make_builtin_shape("knot");
  SdfBuildOptions build;
  build.frame = frame_for_resolution(knot->bounds(), res, 3.0);
  const NarrowBand exact =
      build_from_sdf([&](const Vec3d& p) { return knot->distance(p); }, knot->bounds(), build).band;
  const NarrowBand in = distort(exact);
  const std::uint64_t voxels = in.active_voxel_count();
  std::printf("%-24s %4d %3s %9llu %8s %7s %9s %9.4f\n", "input (distorted)", res, "-", (unsigned long long)voxels,
              "-", "-", "-", ours_gradient_error(in));

  // OpenVDB on the same voxels; quality from the 1-thread run.
  double vdb_sweep_seconds[3] = {0, 0, 0};  // by thread count
  for (int threads : {1, 2}) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      const auto grid = bench::vdb_from_band(in);
      openvdb::FloatGrid::Ptr out;
      auto quality = [&](bool measure) {
        Quality q;
        if (!measure) return q;
        q.measured = true;
        q.grad_error = vdb_gradient_error(*out);
        q.crossing_shift = crossing_shift(in, vdb_probe(*out));
        q.sign_errors = sign_errors_vdb(in, *out);
        return q;
      };
      const double t = bench::best_of(runs, [&] { out = openvdb::tools::sdfToSdf(*grid, 0.0f, 1); });
      vdb_sweep_seconds[threads] = t;
      row("openvdb sdfToSdf", res, threads, voxels, t, 0, quality(threads == 1), "FastSweeping, 1 iteration");
      const double tr = bench::best_of(runs, [&] { out = openvdb::tools::levelSetRebuild(*grid, 0.0f, 3.0f); });
      row("openvdb levelSetRebuild", res, threads, voxels, tr, 0, quality(threads == 1),
          "mesh + rescan, " + std::to_string(out->activeVoxelCount()) + " active");
      double tn = 1e30;
      for (int i = 0; i < runs; ++i) {
        out = grid->deepCopy();
        openvdb::tools::LevelSetTracker<openvdb::FloatGrid> tracker(*out);
        tn = std::min(tn, bench::best_of(1, [&] { tracker.normalize(); }));
      }
      row("openvdb normalize()", res, threads, voxels, tn, 0, quality(threads == 1), "3 HJWENO5 steps");
    });
  }
  // Ours (identical results for any thread count). The ratio compares with OpenVDB's
  // sdfToSdf at the same thread count.
  bool ok = true;
  for (int order : {2, 1}) {
    for (RedistanceMethod method : {RedistanceMethod::Sweep, RedistanceMethod::March}) {
      for (int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        RedistanceResult r;
        RedistanceOptions o;
        o.method = method;
        o.order = order;
        const double t = arena.execute([&] { return bench::best_of(runs, [&] { r = redistance(in, o); }); });
        Quality q;
        if (threads == 1) {
          q.measured = true;
          q.grad_error = ours_gradient_error(r.band);
          q.crossing_shift = crossing_shift(in, band_probe(r.band));
          BandAccessor acc(r.band);
          in.for_each_active([&](const Coord& c, float v) {
            const auto w = acc.probe(c);
            q.sign_errors += w.has_value() ? ((*w < 0) != (v < 0)) : std::abs(v) < in.voxel_size();
          });
          ok &= q.grad_error < (order == 2 ? 0.05 : 0.1) && q.crossing_shift < 0.05 && q.sign_errors == 0;
        }
        const std::string what = std::string(method == RedistanceMethod::Sweep ? "ours sweep" : "ours march") +
                                 (order == 2 ? "" : " (order 1)");
        summary.add(what + " / sdfToSdf", 0.5, "R=" + std::to_string(res) + " thr=" + std::to_string(threads),
                    t / vdb_sweep_seconds[threads]);
        row(what.c_str(), res, threads, voxels, t, vdb_sweep_seconds[threads], q,
            method == RedistanceMethod::Sweep ? std::to_string(r.sweep_iterations) + " iterations"
                                              : std::to_string(r.march_rounds) + " rounds");
      }
    }
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = bench::is_quick(argc, argv);
  openvdb::initialize();
  const std::vector<int> res = quick ? std::vector<int>{128} : std::vector<int>{256, 512};
  std::printf("bench_redistance: distorted torus knot, W = 3, OpenVDB %s; seconds = best of %d\n",
              openvdb::getLibraryAbiVersionString(), quick ? 1 : 3);
  std::printf("%-24s %4s %3s %9s %8s %7s %9s %9s %9s %6s\n", "method", "R", "thr", "voxels", "seconds", "Mvox/s",
              "vs VDB sw", "|grad|-1", "x-shift", "signs");
  return bench::run_bench("bench_redistance", "a result failed its sanity bound", [&] {
    bool ok = true;
    bench::RatioSummary summary("bench_redistance");
    for (int r : res) ok &= run_case(r, quick ? 1 : 3, summary);
    summary.print();
    return ok;
  });
}
