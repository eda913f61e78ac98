#include "apps/minmax_flow.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "distance/redistance.hpp"

namespace levelset::apps {

namespace {

// Avg_R(u) - u for every active voxel of `band`, in band value order: per brick a dense tile with an
// R-voxel halo, then three separable 1D box sums.
std::vector<float> box_averages(const NarrowBand& band, int R) {
  std::vector<float> avg(band.values().begin(), band.values().end());
  const int n = kBrickDim + 2 * R;
  const double inv = 1.0 / double((2 * R + 1) * (2 * R + 1) * (2 * R + 1));
  parallel_for_bricks(band, [&](std::uint32_t b) {
    BandAccessor acc(band);
    const Coord o = brick_origin(band.bricks()[b].coord) - Coord{R, R, R};
    std::vector<double> t(std::size_t(n) * n * n), u(t.size());
    auto at = [n](int x, int y, int z) { return std::size_t(x + n * (y + n * z)); };
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) t[at(x, y, z)] = acc.value(o + Coord{x, y, z});
    // x pass into u, y pass into t, z pass into u (only the ranges later passes read).
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = R; x < n - R; ++x) {
          double s = 0;
          for (int d = -R; d <= R; ++d) s += t[at(x + d, y, z)];
          u[at(x, y, z)] = s;
        }
    for (int z = 0; z < n; ++z)
      for (int y = R; y < n - R; ++y)
        for (int x = R; x < n - R; ++x) {
          double s = 0;
          for (int d = -R; d <= R; ++d) s += u[at(x, y + d, z)];
          t[at(x, y, z)] = s;
        }
    auto u_z = [&](const Coord& l, int d) { return t[at(l.x, l.y, l.z + d)]; };
    float* out = avg.data() + band.bricks()[b].value_offset;
    band.bricks()[b].active.for_each_set([&](int i) {
      const Coord l = local_coord(i) + Coord{R, R, R};
      double s = 0;
      for (int d = -R; d <= R; ++d) s += u_z(l, d);
      *out = float(s * inv - double(*out));  // Avg_R(u) - u
      ++out;
    });
  });
  return avg;
}

struct Change {
  double mean = 0, max = 0;  // voxels (whole chunk)
};

// |new - old| over the voxels within one voxel of the old zero level, active in both.
Change change_near_front(const NarrowBand& before, const NarrowBand& after) {
  const double h = before.voxel_size();
  std::vector<double> sum(before.brick_count(), 0.0), mx(before.brick_count(), 0.0);
  std::vector<std::uint64_t> count(before.brick_count(), 0);
  parallel_for_bricks(before, [&](std::uint32_t b) {
    BandAccessor acc(after);
    before.for_each_active_in_brick(b, [&](const Coord& c, float v) {
      if (std::abs(v) > h) return;
      const std::optional<float> w = acc.probe(c);
      if (!w) return;
      const double d = std::abs(double(*w) - double(v)) / h;
      sum[b] += d;
      mx[b] = std::max(mx[b], d);
      ++count[b];
    });
  });
  Change c;
  double s = 0;
  std::uint64_t k = 0;
  for (std::size_t b = 0; b < sum.size(); ++b) {
    s += sum[b];
    k += count[b];
    c.max = std::max(c.max, mx[b]);
  }
  c.mean = k ? s / double(k) : 0.0;
  return c;
}

}  // namespace

double box_average(BandAccessor& accessor, const Coord& c, int R) {
  double s = 0;
  for (int z = -R; z <= R; ++z)
    for (int y = -R; y <= R; ++y)
      for (int x = -R; x <= R; ++x) s += accessor.value(c + Coord{x, y, z});
  return s / double((2 * R + 1) * (2 * R + 1) * (2 * R + 1));
}

MinMaxResult minmax_flow(const NarrowBand& band, const MinMaxOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (o.radius < 1 || o.radius > 16) throw Error(ErrorCode::InvalidArgument, "minmax radius", "must be in [1, 16] voxels");
  if (!(std::isfinite(o.tolerance) && o.tolerance > 0))
    throw Error(ErrorCode::InvalidArgument, "minmax tolerance", "must be finite and > 0");
  if (o.update_every < 1 || o.max_steps < 1 || o.patience < 1 || o.redistance_every < 0)
    throw Error(ErrorCode::InvalidArgument, "minmax", "update_every, max_steps, patience must be >= 1, redistance_every >= 0");

  MinMaxResult result;
  if (o.measure) result.before = measure_shape(band);

  // The speed reads Avg_R(u) - u in the roi slot and picks the branch (see the header).
  evolve::EvolutionOptions eo;
  eo.speed.name = "minmax";
  eo.speed.needs = evolve::kNeedsMean | evolve::kNeedsRoi;
  eo.speed.has_advective = false;
  eo.speed.has_parabolic = true;
  eo.speed.diffusion = 1.0;
  eo.speed.eval = [](const evolve::SpeedBatch& s, const evolve::SpeedOutput& out) {
    for (int i = 0; i < s.count; ++i) {
      const float H = s.mean[i];
      out.advective[i] = 0.0f;
      const bool shrink_convex = s.roi[i] < 0.0f;  // roi = Avg_R(u) - G, G = u
      out.parabolic[i] = shrink_convex ? -std::max(H, 0.0f) : -std::min(H, 0.0f);
    }
  };
  eo.cfl = o.cfl;

  NarrowBand current = band;
  int steps = 0, calm = 0, since_redistance = 0;
  double time = 0;
  while (steps < o.max_steps) {
    o.progress.step(double(steps) / o.max_steps, "minmax");
    // Avg_R of the state at the start of the chunk.
    NarrowBand averages = current;
    std::vector<float> avg = box_averages(current, o.radius);
    averages.swap_values(avg);
    const NarrowBand& snapshot = current;
    const int R = o.radius;
    eo.fields.roi = [&averages, &snapshot, R](const Vec3d& p) -> double {
      const Vec3d q = snapshot.to_index_space(p);
      const Coord c{int(std::lround(q.x)), int(std::lround(q.y)), int(std::lround(q.z))};
      BandAccessor acc(averages);
      if (const std::optional<float> v = acc.probe(c)) return *v;
      BandAccessor cur(snapshot);  // activated during the chunk: from the same snapshot
      return box_average(cur, c, R) - cur.value(c);
    };
    eo.steps = std::min(o.update_every, o.max_steps - steps);
    eo.progress = o.progress;
    evolve::EvolutionResult er = evolve::evolve(current, eo);
    evolve::throw_if_stopped(er, "minmax");
    if (er.stop == evolve::StopReason::Stopped) {
      current = std::move(er.band);
      steps += er.steps;
      time += er.time;
      break;
    }
    const Change change = change_near_front(current, er.band);
    steps += er.steps;
    time += er.time;
    since_redistance += er.steps;
    const double per_step = 1.0 / std::max(1, er.steps);
    result.history.push_back({steps, time, change.mean * per_step, change.max * per_step});
    current = std::move(er.band);
    if (o.redistance_every > 0 && since_redistance >= o.redistance_every) {
      RedistanceOptions ro;
      ro.progress = o.progress;
      current = redistance(current, ro).band;
      since_redistance = 0;
    }
    calm = change.mean * per_step < o.tolerance ? calm + 1 : 0;
    if (calm >= o.patience) {
      result.steady = true;
      result.steady_step = steps;
      break;
    }
  }
  result.steps = steps;
  result.time = time;
  result.band = std::move(current);
  if (o.measure) result.after = measure_shape(result.band);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace levelset::apps
