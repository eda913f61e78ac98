// reconstruct_surface's coarsest level: the flow from the start shell toward the points' fits
// (reconstruction_parts.hpp).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "apps/patch_coverage.hpp"
#include "apps/reconstruction_parts.hpp"
#include "distance/redistance.hpp"
#include "evolve/evolution.hpp"
#include "grid/for_each_active_parallel.hpp"
#include "grid/sign_components.hpp"
#include "grid/topology_guard.hpp"

namespace levelset::apps::detail {

namespace {

// The coarsest level's attraction: beta = -clamp(gain * offset / h): a front within
// 1 / gain voxels of its target moves a fraction 0.5 gain / (1 + 6 w) of the way per step
// (forward Euler at cfl 0.5 with the curvature's explicit limit); 3 converges in a few
// steps without overshoot for w >= 0.1.
constexpr double kAttractionGain = 3.0;
// A component whose front voxels have a point within 1.5 coarse voxels for less than this
// fraction of them is a stray (drop_unsupported_components).
constexpr double kMinSupport = 0.5;
constexpr double kSupportDistance = 1.5;
// A speck: a component of at most kSpeckVoxels voxels none of which lies kSpeckDepth voxels
// or more from the zero level (drop_unsupported_components).
constexpr std::uint64_t kSpeckVoxels = 8;
constexpr double kSpeckDepth = 0.1;
// The guard's pinned rule: a thin inside voxel with a point within this many coarse voxels.
constexpr double kPinDistance = 0.75;

// Mean front motion of the coarsest level's flow: the speed function adds |beta| of the
// voxels within one voxel of the front (fixed point, so the sum is the same in any order:
// deterministic for any thread count); stop_when turns it into voxels per step.
struct MotionMeter {
  static constexpr double kScale = 1048576.0;
  std::atomic<std::uint64_t> sum{0};
  std::atomic<std::uint64_t> count{0};
  double take_mean() {
    const std::uint64_t n = count.exchange(0);
    const std::uint64_t s = sum.exchange(0);
    return n > 0 ? double(s) / kScale / double(n) : 0.0;
  }
};

// The coarsest level's speed (see the header), reading the cached fits (on the fly off the
// cache).
evolve::SpeedFunction fit_speed(const NarrowBand& cache, const std::vector<LocalFit>& fits, const PointIndex& index,
                                int neighbors, double weight, MotionMeter& meter) {
  const double h = cache.voxel_size();
  const Vec3d origin = cache.origin();
  evolve::SpeedFunction s;
  s.name = "point-attraction";
  s.needs = evolve::kNeedsPosition | evolve::kNeedsNormal | evolve::kNeedsMean;
  s.has_advective = true;
  s.has_parabolic = weight > 0.0;
  s.diffusion = weight * h;
  s.eval = [&cache, &fits, &index, &meter, neighbors, weight, h, origin](const evolve::SpeedBatch& b,
                                                                           const evolve::SpeedOutput& out) {
    BandAccessor acc(cache);
    std::uint64_t sum = 0, count = 0;
    for (int i = 0; i < b.count; ++i) {
      const Coord c{int(std::lround((double(b.x[i]) - origin.x) / h)), int(std::lround((double(b.y[i]) - origin.y) / h)),
                    int(std::lround((double(b.z[i]) - origin.z) / h))};
      const std::uint32_t br = acc.locate(brick_of(c));
      LocalFit fit;
      const int n = local_index(c);
      if (br != kNoBrick && cache.bricks()[br].active.test(n)) {
        const Brick& brick = cache.bricks()[br];
        fit = fits[brick.value_offset + brick.slot(n)];
      } else {
        fit = local_fit(index, cache.world(c), neighbors);
      }
      const Vec3d nrm{double(b.nx[i]), double(b.ny[i]), double(b.nz[i])};
      const double H = std::clamp(double(b.mean[i]), -1.0 / h, 1.0 / h);
      const double u = double(b.d[i]);
      // No curvature correction here: with the evolving front's own H it is a backward heat
      // term (+ (g rho^2 / 4 h) H in beta, rho^2 the fit's tangential spread, larger than the
      // w d H smoothing for k >~ 12), which grew wrinkles and spurious handles and kept the
      // flow from converging (knot, 20k points, k = 24: genus 2-8 after 120 steps; without
      // it genus 1 in 20 steps). The snaps apply it with the coarse level's fixed H.
      const double front_offset = fit.signed_offset(nrm, H, 0.0) - u;
      const double advective = -std::clamp(kAttractionGain * front_offset / h, -1.0, 1.0);
      const double parabolic = -weight * std::min(double(fit.d), h) * H;
      out.advective[i] = float(advective);
      out.parabolic[i] = float(parabolic);
      if (std::abs(u) < h) {
        sum += std::uint64_t(std::lround(std::min(std::abs(advective + parabolic), 4.0) * MotionMeter::kScale));
        ++count;
      }
    }
    meter.sum.fetch_add(sum, std::memory_order_relaxed);
    meter.count.fetch_add(count, std::memory_order_relaxed);
  };
  return s;
}

}  // namespace

// Stray components and specks turned (reconstruction_parts.hpp).
std::uint64_t drop_unsupported_components(NarrowBand& band, const PointIndex& index, double support,
                                          const ProgressHook& progress) {
  SignComponentsOptions sco;
  sco.progress = progress;
  sco.inside_connectivity = 6;  // a piece joined by an edge or a corner only may be drawn apart
  const SignComponentsResult comps = sign_components(band, sco);
  std::size_t largest = comps.components.size();  // the inside component with the largest front
  for (std::size_t c = 0; c < comps.components.size(); ++c)
    if (comps.components[c].inside &&
        (largest == comps.components.size() || comps.components[c].front.size() > comps.components[largest].front.size()))
      largest = c;
  // deep[c]: component c has a voxel kSpeckDepth voxels or more from the zero level.
  std::vector<std::uint8_t> deep(comps.components.size(), 0);
  const float speck_depth = float(kSpeckDepth * band.voxel_size());
  for (std::uint32_t b = 0; b < band.brick_count(); ++b)
    band.for_each_active_in_brick(b, [&](const Coord& c, float v) {
      if (std::abs(v) >= speck_depth) deep[std::size_t(comps.label[comps.index_of(c)])] = 1;
    });
  std::vector<std::uint8_t> drop(comps.components.size(), 0);
  std::uint64_t dropped = 0;
  for (std::size_t c = 0; c < comps.components.size(); ++c) {
    const SignComponent& comp = comps.components[c];
    if (c == largest || comp.touches_box || !comp.all_active || comp.front.empty()) continue;
    if (comp.voxels <= kSpeckVoxels && !deep[c]) {
      drop[c] = 1;
      ++dropped;
      continue;
    }
    std::size_t near = 0;
    for (const Coord& f : comp.front)
      if (index.nearest(band.world(f)).distance <= support) ++near;
    if (double(near) < kMinSupport * double(comp.front.size())) {
      drop[c] = 1;
      ++dropped;
    }
  }
  if (dropped == 0) return 0;
  std::vector<float> values(band.values().begin(), band.values().end());
  const float eps = float(1e-3 * band.voxel_size());
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) {
    std::size_t slot = band.bricks()[b].value_offset;
    band.for_each_active_in_brick(b, [&](const Coord& c, float v) {
      const std::size_t i = slot++;
      if (!drop[std::size_t(comps.label[comps.index_of(c)])]) return;
      values[i] = v < 0.0f ? std::max(-v, eps) : std::min(-v, -eps);
    });
  }
  band.swap_values(values);
  return dropped;
}

LevelOutput flow_level(NarrowBand band, const PointIndex& index, const ReconstructionOptions& o, int levels,
                       ReconstructionStage stage) {
  const double W = o.half_width, h = stage.voxel_size;
  // Cache of fits: the voxels within W + 2 of the start front.
  RedistanceOptions grow;
  grow.half_width = W + 2.0;
  grow.order = 1;  // only its voxel set is used (where fits are cached): the cheaper update
  grow.progress = o.progress;
  const NarrowBand cache = redistance(band, grow).band;
  PointFitFieldOptions fit_options;
  fit_options.neighbors = o.neighbors;
  fit_options.progress = o.progress;
  const auto t_fit = Clock::now();
  const std::vector<LocalFit> fits = point_fit_field(index, cache, fit_options).fits;
  stage.seconds_fit = seconds_since(t_fit);
  stage.fit_voxels = fits.size();
  MotionMeter meter;
  evolve::EvolutionOptions ev;
  ev.speed = fit_speed(cache, fits, index, o.neighbors, o.curvature_weight, meter);
  ev.steps = 1;
  ev.drift_tolerance = 0.1;  // the speed is constant along normals near the data: rare
  ev.progress.cancel = o.progress.cancel;
  ev.progress.stop = o.progress.stop;
  // One step per evolve call: between steps, sign changes that are not simple are
  // refused and ambiguous faces keep their decision (grid/topology_guard.hpp): the start shell's
  // topology is the result's (a part thinner than a coarse voxel, the bunny's ears,
  // otherwise broke off or grew handles depending on the sample set).
  const auto t_flow = Clock::now();
  if (!o.guard_flow) {
    // Unguarded: one evolve call, stopped by the mean |beta| near the front.
    ev.steps = o.max_steps;
    ev.stop_when = [&](const evolve::StepInfo& si) {
      stage.last_change = meter.take_mean() * si.dt / h;
      o.progress.step(0.5 * double(si.step) / o.max_steps / levels, "reconstruct");
      return stage.last_change < o.tolerance;
    };
    evolve::EvolutionResult r = evolve::evolve(band, ev);
    evolve::throw_if_stopped(r, "reconstruct");
    stage.steps = r.steps;
    stage.seconds_redistance = r.seconds.redistance;
    band = std::move(r.band);
  }
  for (int step = 1; o.guard_flow && step <= o.max_steps; ++step) {
    evolve::EvolutionResult r = evolve::evolve(band, ev);
    evolve::throw_if_stopped(r, "reconstruct");
    // A stop request ends each level's flow where it is; the remaining stages still run.
    if (r.stop == evolve::StopReason::Stopped) break;
    stage.seconds_redistance += r.seconds.redistance;
    TopologyGuardOptions guard;
    guard.eps = 1e-3 * h;
    guard.progress = o.progress;
    const double free_distance = o.free_distance * h;
    // Far from every point, and not in a gap between the samples of a patch (apps/patch_coverage.hpp).
    guard.free = [&](const Coord& c) {
      const Vec3d x = r.band.world(c);
      return index.nearest(x).distance > free_distance && !patch_coverage(index, x).inside;
    };
    // A thin inside voxel holding data inside a sampled patch stays inside: a sampled sheet
    // (an open scan, a part thinner than a coarse voxel) otherwise erodes from its rim by
    // simple flips to a scrap. Not where the data are two sheets or an edge (bridges).
    guard.pinned = [&](const Coord& c) {
      const Vec3d x = r.band.world(c);
      return index.nearest(x).distance <= kPinDistance * h && patch_coverage(index, x).inside;
    };
    TopologyGuardResult kept =
        guard_topology(band, r.band, std::vector<float>(r.band.values().begin(), r.band.values().end()), guard);
    const std::uint64_t refused = kept.refused_flips;
    r.band.swap_values(kept.values);
    if (refused > 0) {
      // Refused voxels hold the front where the band upkeep had moved on: redistance on
      // the domain grown by one voxel, as after a snap.
      stage.refused_flips += refused;
      const auto t_redistance = Clock::now();
      RedistanceOptions redo;
      redo.half_width = W;
      redo.progress = o.progress;
      r.band = redistance(reframed(r.band, {}, W - 1.0), redo).band;
      stage.seconds_redistance += seconds_since(t_redistance);
    }
    // Convergence: the mean motion of the voxels within one voxel of the front, measured
    // on the values after the topology control (the speed's own |beta| stays high where a
    // refused voxel pins the front).
    double moved = 0.0;
    std::uint64_t near = 0;
    {
      BandAccessor old_acc(band);
      for (std::uint32_t b = 0; b < r.band.brick_count(); ++b)
        r.band.for_each_active_in_brick(b, [&](const Coord& c, float u) {
          if (!(std::abs(double(u)) < h)) return;
          const std::optional<float> was = old_acc.probe(c);
          if (!was) return;
          moved += std::min(std::abs(double(u) - double(*was)), h);
          ++near;
        });
    }
    meter.take_mean();
    band = std::move(r.band);
    stage.steps = step;
    stage.last_change = near > 0 ? moved / double(near) / h : 0.0;
    o.progress.step(0.5 * double(step) / o.max_steps / levels, "reconstruct");
    if (stage.last_change < o.tolerance) break;
  }
  stage.seconds_flow = seconds_since(t_flow);
  stage.dropped_components = drop_unsupported_components(band, index, kSupportDistance * h, o.progress);
  if (stage.dropped_components > 0) {
    const auto t_redistance = Clock::now();
    RedistanceOptions redo;
    redo.progress = o.progress;
    band = redistance(band, redo).band;
    stage.seconds_redistance += seconds_since(t_redistance);
  }
  stage.converged = stage.last_change < o.tolerance;
  return {std::move(band), std::move(stage)};
}

}  // namespace levelset::apps::detail
