// evolve(): the step loop (time step, Runge-Kutta stages, land mines, the edge layer, band
// upkeep, redistancing, stop rules); the spatial operator is in evolution_operator.cpp.
#include "evolve/evolution.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/text.hpp"
#include "distance/redistance.hpp"
#include "evolve/band_tracking.hpp"
#include "evolve/evolution_operator.hpp"

namespace levelset::evolve {

// The observer of every evolution on this thread (StepObserverScope); null when none.
thread_local const std::function<void(const StepInfo&)>* t_step_observer = nullptr;

namespace {

using namespace detail;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
constexpr double kSqrt3 = 1.7320508075688772;

void check_options(const NarrowBand& band, const EvolutionOptions& o) {
  auto bad = [](const std::string& why) { throw Error(ErrorCode::InvalidArgument, "evolve", why); };
  if (!has_speed(o) && !has_velocity(o)) bad("no motion: give a speed or a velocity");
  if (o.velocity.kind == Velocity::Kind::Field && !o.velocity.field) bad("velocity field without a function");
  if (o.velocity.kind == Velocity::Kind::Constant && !isfinite(o.velocity.constant)) bad("velocity must be finite");
  if ((o.steps > 0) == (o.time > 0)) bad("give exactly one of steps > 0 or time > 0");
  if (o.steps < 0 || !(o.time >= 0) || !std::isfinite(o.time)) bad("steps and time must be >= 0 and finite");
  if (!(o.cfl >= 0 && o.cfl <= 1)) bad("cfl must be in (0, 1] (0: the default)");
  if (o.rk_order != 1 && o.rk_order != 3) bad("rk_order must be 1 or 3");
  if (o.redistance_every < 0 || !(o.drift_tolerance >= 0) || o.max_steps < 1) bad("negative redistance_every, drift_tolerance or max_steps");
  if (has_speed(o) && (!std::isfinite(o.speed.diffusion) || o.speed.diffusion < 0)) bad("speed diffusion bound must be >= 0");
  if (band.half_width() < 2.0) bad("the band half-width must be at least 2 voxels");
  if (has_speed(o)) {
    const std::uint32_t n = o.speed.needs;
    const SpeedFields& f = o.fields;
    auto missing = [&](std::uint32_t bit, bool given, const char* name) {
      if ((n & bit) && !given) bad(std::string("the speed reads the field '") + name + "', which was not given");
    };
    missing(kNeedsDist, bool(f.dist), "dist");
    missing(kNeedsDistGradient, bool(f.dist_gradient), "dgx/dgy/dgz/dn (the gradient of dist)");
    missing(kNeedsImage, bool(f.image), "img");
    missing(kNeedsEdge, bool(f.edge), "edge");
    missing(kNeedsRoi, bool(f.roi), "roi");
  }
  if (!(o.track_distance > 0 && o.track_distance <= 1)) bad("track_distance must be in (0, 1] voxels");
  if (!(o.band_growth_limit == 0 || (o.band_growth_limit >= 1 && o.band_growth_limit <= 1e6)))
    bad("band_growth_limit must be 0 (off) or in [1, 1e6]");
}

// f(i) for i in [0, n), in parallel (the RK combinations and checks over all values).
template <typename F>
void for_each_value(std::size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
  });
}

// First non-finite value, as "voxel (x, y, z)"; empty when all are finite.
std::string first_non_finite(const NarrowBand& band, const std::vector<float>& values) {
  std::atomic<std::size_t> at{std::numeric_limits<std::size_t>::max()};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, values.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      if (!std::isfinite(values[i])) {
        std::size_t cur = at.load();
        while (i < cur && !at.compare_exchange_weak(cur, i)) {
        }
        break;
      }
  });
  const std::size_t i = at.load();
  if (i == std::numeric_limits<std::size_t>::max()) return {};
  std::size_t k = 0;
  std::string where;
  band.for_each_active([&](const Coord& c, float) {
    if (k++ == i) where = "voxel (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " + std::to_string(c.z) + ")";
  });
  return where;
}

void add_phases(EvolutionResult& result, const OperatorOutput& op) {
  result.seconds.gradient_cpu += op.seconds.gradient;
  result.seconds.curvature_cpu += op.seconds.curvature;
  result.seconds.speed_cpu += op.seconds.speed;
  result.seconds.rates_cpu += op.seconds.rates;
}

// One time step's values from `cur` and its rates `op` (forward Euler, or TVD-RK3 with two
// more operator evaluations), retried with half the step while a sign changes in the edge
// layer (a land mine: the band's edge holds no PDE), at most 5 times. `cur` holds u0 again on
// return; the stages swap their values in and out (no copies). finite: every new value is.
struct Advanced {
  std::vector<float> values;
  bool mine = false, finite = true;
  double dt = 0;
};

// next[i] = value(i) for every i, in parallel; whether a sign changed against u0 at an edge
// voxel (a land mine) and whether every value is finite, in the same pass.
template <typename Value>
void finish_stage(const float* u0, const std::vector<std::uint8_t>& edge, std::vector<float>& next, Value&& value,
                  bool& mine, bool& finite) {
  std::atomic<bool> fired{false}, bad{false};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, next.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    bool f = false, nf = false;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const float v = value(i);
      next[i] = v;
      f |= edge[i] && ((u0[i] < 0.0f) != (v < 0.0f));
      nf |= !std::isfinite(v);
    }
    if (f) fired.store(true, std::memory_order_relaxed);
    if (nf) bad.store(true, std::memory_order_relaxed);
  });
  mine = fired.load();
  finite = !bad.load();
}

Advanced advance(NarrowBand& cur, const OperatorOutput& op, const OperatorSetup& setup, double dt, int rk_order,
                 EvolutionResult& result) {
  const double t = setup.time;
  std::vector<float> next(cur.active_voxel_count());
  bool mine = false, finite = true;
  for (int attempt = 0; attempt < 5; ++attempt) {
    auto t1 = Clock::now();
    const float* u0 = cur.values().data();
    if (rk_order == 1) {
      finish_stage(u0, op.edge, next, [&](std::size_t i) { return float(double(u0[i]) + dt * double(op.rate[i])); },
                   mine, finite);
    } else {
      for_each_value(next.size(), [&](std::size_t i) { next[i] = float(double(u0[i]) + dt * double(op.rate[i])); });
      // Stages are evaluated on `cur` with its values swapped out and back (no band copy).
      OperatorSetup s2 = setup;
      s2.want_edges = false;
      s2.want_betas = false;
      s2.want_stats = false;
      cur.swap_values(next);  // cur holds u1, next holds u0
      s2.time = t + dt;
      auto t2 = Clock::now();
      OperatorOutput o1 = run_operator(cur, s2);
      cur.swap_values(next);  // back: next holds u1
      add_phases(result, o1);
      const UninitializedVector<float> r1 = std::move(o1.rate);
      result.seconds.operator_eval += since(t2);
      std::vector<float> u2(next.size());
      for_each_value(next.size(), [&](std::size_t i) {
        u2[i] = float(0.75 * u0[i] + 0.25 * (double(next[i]) + dt * double(r1[i])));
      });
      cur.swap_values(u2);  // cur holds u2
      s2.time = t + 0.5 * dt;
      t2 = Clock::now();
      OperatorOutput o2 = run_operator(cur, s2);
      cur.swap_values(u2);  // back
      add_phases(result, o2);
      const UninitializedVector<float> r2 = std::move(o2.rate);
      result.seconds.operator_eval += since(t2);
      finish_stage(u0, op.edge, next,
                   [&](std::size_t i) { return float(u0[i] / 3.0 + 2.0 / 3.0 * (double(u2[i]) + dt * double(r2[i]))); },
                   mine, finite);
    }
    result.seconds.update += since(t1);
    if (!mine || attempt == 4) break;
    ++result.landmine_count;
    dt *= 0.5;
  }
  return {std::move(next), mine, finite, dt};
}

// The edge layer from the new interior values (EdgeStencil), on its own side only: every
// stencil's value from `next` first (into the stencil), then all are written.
void extrapolate_edge_layer(const NarrowBand& cur, OperatorOutput& op, std::vector<float>& next) {
  const double h = cur.voxel_size();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, op.edge_stencils.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b)
      for (EdgeStencil& e : op.edge_stencils[b]) {
        e.value = next[e.target];
        double v = 0;
        for (int k = 0; k < e.count; ++k) v += double(e.coef[std::size_t(k)]) * double(next[e.source[std::size_t(k)]]);
        const bool inside = cur.values()[e.target] < 0.0f;
        if (inside != (v < 0.0)) continue;
        double lo = 0.0, hi = std::numeric_limits<double>::infinity();
        for (int k = 0; k < e.neighbors; ++k) {
          const double un = next[e.neighbor[std::size_t(k)]];
          if ((un < 0.0) != inside) continue;
          lo = std::max(lo, std::abs(un) - h);
          hi = std::min(hi, std::abs(un) + h);
        }
        const double mag = std::clamp(std::abs(v), lo, std::max(lo, hi));
        e.value = float(inside ? -mag : mag);
      }
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, op.edge_stencils.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b)
      for (const EdgeStencil& e : op.edge_stencils[b]) next[e.target] = e.value;
  });
}

// Band upkeep (band_tracking.hpp): voxels within W h of the front activated, the others
// retired; counted in the result.
NarrowBand upkeep(const NarrowBand& band, double half_width, bool extrapolate_edge, EvolutionResult& result) {
  TrackOptions track;
  track.half_width = half_width;
  track.extrapolate_edge = extrapolate_edge;
  TrackResult tracked = track_band(band, track);
  result.activated += tracked.activated;
  result.retired += tracked.retired;
  ++result.band_updates;
  return std::move(tracked.band);
}

// What observers see after a step (result.steps, time and grad_drift already updated).
StepInfo step_info(const EvolutionResult& result, const OperatorOutput& op, const NarrowBand& band, double dt,
                   double elapsed) {
  StepInfo info;
  info.step = result.steps;
  info.time = result.time;
  info.dt = dt;
  info.active_voxels = band.active_voxel_count();
  info.max_speed = op.max_speed;
  info.redistance_count = result.redistance_count;
  info.landmine_count = result.landmine_count;
  info.grad_drift = result.grad_drift;
  info.elapsed_seconds = elapsed;
  info.crossings = op.crossings;
  info.band = &band;
  return info;
}

}  // namespace

EvolutionResult evolve(const NarrowBand& band, const EvolutionOptions& options) {
  check_options(band, options);
  const auto start = Clock::now();
  const double h = band.voxel_size();
  const double half_width = band.half_width();
  const double diffusion = has_speed(options) && options.speed.has_parabolic ? options.speed.diffusion : 0.0;
  const double cfl = options.cfl > 0 ? options.cfl : (options.rk_order == 3 ? 0.9 : 0.5);
  EvolutionResult result;
  result.band = band;
  NarrowBand& cur = result.band;
  double t = 0, motion = 0;
  int steps_since_redistance = 0;
  // Band growth guard: active voxels per crossing of a fresh band (measured at the first step
  // and after each redistance, within what a fresh band can hold: 2W / sqrt(3) for a plane
  // along a cube diagonal to 2W + 1 along an axis); 0: measure at the next step.
  double fresh_ratio = 0;
  for (int step = 1; step <= options.max_steps; ++step) {
    if (options.steps > 0 && step > options.steps) break;
    if (options.time > 0 && t >= options.time) break;
    if (options.progress.cancelled()) {
      result.stop = StopReason::Cancelled;
      result.message = "cancelled after " + std::to_string(result.steps) + " steps";
      break;
    }
    if (options.progress.stop_requested()) {
      result.stop = StopReason::Stopped;
      result.message = "stopped on request after " + std::to_string(result.steps) + " steps";
      break;
    }
    // Stage 1 (and the speeds, extended when asked).
    auto t0 = Clock::now();
    OperatorSetup setup{options};
    setup.time = t;
    setup.want_edges = true;
    setup.want_betas = options.extension && has_speed(options);
    if (has_speed(options) && (options.speed.needs & kNeedsMeanAverage)) setup.kavg = mean_curvature_average(cur);
    OperatorOutput op = run_operator(cur, setup);
    add_phases(result, op);
    if (setup.want_betas) {
      extend_speeds(cur, op.beta_a, op.beta_p);
      OperatorSetup ext = setup;
      ext.beta_a_override = op.beta_a.data();
      ext.beta_p_override = op.beta_p.data();
      std::vector<std::uint8_t> edge = std::move(op.edge);
      op = run_operator(cur, ext);
      add_phases(result, op);
      op.edge = std::move(edge);
    }
    result.seconds.operator_eval += since(t0);
    // No sign change left in the band, or none with any volume on one side (the inside, or
    // the outside, only touches the zero level: a sphere redistanced at the moment it shrinks
    // to a point holds one voxel at -1e-37 among neighbours at h, and its exactly symmetric
    // stencil has no gradient to move it): the surface vanished (or was never there).
    const float flat = float(1e-3 * h);
    if (op.crossings == 0 || op.min_value > -flat || op.max_value < flat) {
      // Nothing can move any more; the band is emptied with the remaining sign everywhere.
      result.stop = StopReason::Vanished;
      result.message = "the surface vanished after " + std::to_string(result.steps) + " steps (t = " +
                       format_number(t) + ")";
      const bool inside = cur.active_voxel_count() > 0 ? op.max_value < flat : cur.far_inside();
      cur = NarrowBand(cur.frame());
      cur.set_far_inside(inside);
      motion = 0;
      break;
    }
    if (fresh_ratio == 0)
      fresh_ratio = std::clamp(double(cur.active_voxel_count()) / double(op.crossings), 2.0 * half_width / kSqrt3,
                               2.0 * half_width + 1.0);
    const double grad_drift = op.drift_count ? op.drift_sum / double(op.drift_count) : 0.0;
    const double rate_limit = op.max_hyperbolic / h + 6.0 * diffusion / (h * h);
    double dt = rate_limit > 0 ? cfl / rate_limit : cfl * h;
    if (options.time > 0) dt = std::min(dt, options.time - t);

    // RK stages; land mines halve dt and retry.
    Advanced adv = advance(cur, op, setup, dt, options.rk_order, result);
    std::vector<float> next = std::move(adv.values);
    const bool mine = adv.mine;
    dt = adv.dt;
    const std::string bad = adv.finite ? std::string() : first_non_finite(cur, next);
    if (!bad.empty()) {
      result.stop = StopReason::NonFinite;
      std::ostringstream msg;
      msg << "a non-finite value at " << bad << " in step " << step << " (t = " << t << ", dt = " << dt
          << "); the band is the state after step " << result.steps;
      result.message = msg.str();
      break;
    }
    auto t3 = Clock::now();
    extrapolate_edge_layer(cur, op, next);
    // Band upkeep once the front may have moved track_distance voxels since the last one.
    motion += op.max_front_speed * dt;
    cur.swap_values(next);
    TrackResult tracked;
    if (mine || motion >= options.track_distance * h) {
      tracked.band = upkeep(cur, half_width, false, result);  // the edge layer: done above, every step
      motion = 0;
    } else {
      tracked.band = std::move(cur);
    }
    result.seconds.tracking += since(t3);
    ++steps_since_redistance;
    const bool overgrown = options.band_growth_limit > 0 &&
                           double(tracked.band.active_voxel_count()) >
                               options.band_growth_limit * fresh_ratio * double(op.crossings);
    const bool due = mine || overgrown ||
                     (options.redistance_every > 0 && steps_since_redistance >= options.redistance_every) ||
                     (options.drift_tolerance > 0 && grad_drift > options.drift_tolerance);
    if (due) {
      result.growth_redistance_count += overgrown;
      fresh_ratio = 0;
      auto t4 = Clock::now();
      RedistanceOptions ro;
      ro.half_width = half_width;
      tracked.band = redistance(tracked.band, ro).band;
      ++result.redistance_count;
      steps_since_redistance = 0;
      result.seconds.redistance += since(t4);
    }
    cur = std::move(tracked.band);
    t += dt;
    result.steps = step;
    result.time = t;
    result.grad_drift = grad_drift;
    const StepInfo info = step_info(result, op, cur, dt, since(start));
    if (options.on_step) options.on_step(info);
    if (t_step_observer != nullptr) (*t_step_observer)(info);
    if (options.progress.on_progress) {
      const double f = options.steps > 0 ? double(step) / options.steps : t / options.time;
      options.progress.on_progress(std::min(1.0, f), "evolve");
    }
    if (options.stop_when && options.stop_when(info)) {
      result.message = "stopped by stop_when after " + std::to_string(step) + " steps";
      break;
    }
  }
  if (motion > 0) {
    // Leave a tidy band: every value within W h, every voxel within W h of the front active.
    auto t5 = Clock::now();
    cur = upkeep(cur, half_width, true, result);
    result.seconds.tracking += since(t5);
  }
  result.seconds.total = since(start);
  return result;
}

StepObserverScope::StepObserverScope(std::function<void(const StepInfo&)> observer)
    : observer_(std::move(observer)), previous_(t_step_observer) {
  t_step_observer = &observer_;
}

StepObserverScope::~StepObserverScope() { t_step_observer = previous_; }

void throw_if_stopped(const EvolutionResult& result, const std::string& where) {
  if (result.stop == StopReason::Cancelled) throw Error(ErrorCode::Cancelled, where, "operation cancelled");
  if (result.stop == StopReason::NonFinite) throw Error(ErrorCode::NonFinite, where, result.message);
}

std::string_view to_string(StopReason reason) {
  switch (reason) {
    case StopReason::Completed: return "completed";
    case StopReason::Cancelled: return "cancelled";
    case StopReason::NonFinite: return "non-finite";
    case StopReason::Vanished: return "vanished";
    case StopReason::Stopped: return "stopped";
  }
  return "?";
}

Scheme scheme_from_name(std::string_view name) {
  if (name == "godunov") return Scheme::Upwind1;
  if (name == "eno2") return Scheme::Eno2;
  if (name == "weno5") return Scheme::Weno5;
  throw Error(ErrorCode::InvalidArgument, "scheme", "unknown scheme '" + std::string(name) + "' (known: godunov, eno2, weno5)");
}

}  // namespace levelset::evolve
