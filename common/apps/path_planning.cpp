#include "apps/path_planning.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <queue>
#include <utility>
#include <string>

#include "core/error.hpp"

namespace levelset::apps {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kStallSteps = 64;

std::string point_text(const Vec3d& p) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p.x, p.y, p.z);
  return buf;
}

// The cell of a point inside the grid: base corner and fractions.
struct CellPos {
  int base[3];
  double t[3];
};

CellPos cell_of(const DenseGrid& g, const Vec3d& p) {
  const Vec3d q = g.to_index_space(p);
  CellPos c;
  for (int a = 0; a < 3; ++a) {
    const double qa = std::clamp(q[a], 0.0, double(g.dim(a) - 1));
    c.base[a] = std::min(int(std::floor(qa)), g.dim(a) - 2);
    c.t[a] = qa - c.base[a];
  }
  return c;
}

double corner_weight(const CellPos& c, int corner) {
  const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
  return (dx ? c.t[0] : 1 - c.t[0]) * (dy ? c.t[1] : 1 - c.t[1]) * (dz ? c.t[2] : 1 - c.t[2]);
}

// Trilinear interpolation of node values over the corners with finite values.
double sample_nodes(const DenseGrid& g, const std::vector<double>& time, const Vec3d& p) {
  const CellPos c = cell_of(g, p);
  double acc = 0.0, wsum = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const double t = time[g.index(c.base[0] + (corner & 1), c.base[1] + ((corner >> 1) & 1), c.base[2] + (corner >> 2))];
    const double w = corner_weight(c, corner);
    if (w == 0.0 || !(t < kInf)) continue;
    acc += w * t;
    wsum += w;
  }
  return wsum > 0.0 ? acc / wsum : kInf;
}

// First-order Godunov update of |grad T| = c on a grid with spacing h from the smaller
// known neighbour value per axis (kInf = none).
double godunov_update(double m[3], double f) {
  std::sort(m, m + 3);
  double t = m[0] + f;
  if (t > m[1]) {
    const double b = m[0] + m[1], d = 2.0 * f * f - (m[0] - m[1]) * (m[0] - m[1]);
    t = 0.5 * (b + std::sqrt(std::max(d, 0.0)));
    if (t > m[2]) {
      const double s = m[0] + m[1] + m[2];
      const double q = m[0] * m[0] + m[1] * m[1] + m[2] * m[2] - f * f;
      t = (s + std::sqrt(std::max(s * s - 3.0 * q, 0.0))) / 3.0;
    }
  }
  return t;
}

// Arrival times continued kShellLayers layers into the obstacles (ghost values, by a
// first-order march inside the blocked nodes with twice the largest free cost; the free
// nodes' times are unchanged). The ghosts' gradients point into the obstacle, so a trace
// that grazes an obstacle between nodes blends in a push out of it (a soft wall), and it
// never runs out of descent directions there.
constexpr int kShellLayers = 2;

std::vector<double> extend_into_obstacles(const FastMarchingResult& f) {
  std::vector<double> t = f.time;
  if (f.blocked_count == 0 || f.blocked.size() != t.size()) return t;
  const DenseGrid& g = f.grid;
  const std::size_t n = t.size();
  const std::size_t stride[3] = {1, std::size_t(g.nx), std::size_t(g.nx) * std::size_t(g.ny)};
  const auto for_neighbours = [&](std::size_t v, auto&& fn) {
    const int c[3] = {int(v % stride[1]), int(v / stride[1] % std::size_t(g.ny)), int(v / stride[2])};
    for (int a = 0; a < 3; ++a) {
      if (c[a] > 0) fn(v - stride[a], a);
      if (c[a] + 1 < g.dim(a)) fn(v + stride[a], a);
    }
  };
  // Shell: blocked nodes within kShellLayers 6-steps of a reached free node.
  std::vector<std::uint8_t> shell(n, 0);
  std::vector<std::size_t> layer, next, members;
  for (std::size_t v = 0; v < n; ++v)
    if (f.blocked[v]) {
      bool touches = false;
      for_neighbours(v, [&](std::size_t w, int) { touches |= !f.blocked[w] && t[w] < kInf; });
      if (touches) shell[v] = 1, layer.push_back(v);
    }
  members = layer;
  for (int depth = 2; depth <= kShellLayers; ++depth) {
    next.clear();
    for (const std::size_t v : layer)
      for_neighbours(v, [&](std::size_t w, int) {
        if (f.blocked[w] && !shell[w]) shell[w] = std::uint8_t(depth), next.push_back(w);
      });
    members.insert(members.end(), next.begin(), next.end());
    layer.swap(next);
  }
  // March inside the shell (lazy-deletion heap; known = reached free nodes + accepted shell).
  std::vector<std::uint8_t> done(n, 0);
  const double fh = 2.0 * g.voxel_size * (f.max_cost > 0 ? f.max_cost : 1.0);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
  const auto known = [&](std::size_t w) { return f.blocked[w] ? done[w] != 0 : t[w] < kInf; };
  const auto relax = [&](std::size_t v) {
    double m[3] = {kInf, kInf, kInf};
    for_neighbours(v, [&](std::size_t w, int a) {
      if (known(w)) m[a] = std::min(m[a], t[w]);
    });
    if (!(std::min({m[0], m[1], m[2]}) < kInf)) return;
    const double u = godunov_update(m, fh);
    if (u < t[v]) {
      t[v] = u;
      heap.push({u, v});
    }
  };
  for (const std::size_t v : members)
    if (shell[v] == 1) relax(v);
  while (!heap.empty()) {
    const auto [u, v] = heap.top();
    heap.pop();
    if (done[v] || u != t[v]) continue;
    done[v] = 1;
    for_neighbours(v, [&](std::size_t w, int) {
      if (shell[w] && !done[w]) relax(w);
    });
  }
  return t;
}

// The descent direction field of a marched grid (times extended into the obstacles).
class Descent {
 public:
  explicit Descent(const FastMarchingResult& f) : f_(f), time_(extend_into_obstacles(f)), g_(f.grid) {}

  double sample(const Vec3d& p) const { return sample_nodes(g_, time_, p); }

  // grad T at node (i, j, k), which has finite T.
  Vec3d node_gradient(int i, int j, int k) const {
    const int c[3] = {i, j, k};
    const std::size_t v = g_.index(i, j, k);
    const double t0 = time_[v];
    // Free nodes see only free neighbours (one-sided at obstacles); ghosts see all.
    const bool ghost = !f_.blocked.empty() && f_.blocked[v];
    const auto value = [&](std::size_t w) { return ghost || f_.blocked.empty() || !f_.blocked[w] ? time_[w] : kInf; };
    const std::size_t stride[3] = {1, std::size_t(g_.nx), std::size_t(g_.nx) * std::size_t(g_.ny)};
    Vec3d grad;
    for (int a = 0; a < 3; ++a) {
      const double tl = c[a] > 0 ? value(v - stride[a]) : kInf;
      const double tr = c[a] + 1 < g_.dim(a) ? value(v + stride[a]) : kInf;
      const bool fl = tl < kInf, fr = tr < kInf;
      double d = 0.0;
      if (fl && fr) {
        if (tl < t0 && tr < t0) d = tl <= tr ? (t0 - tl) : (tr - t0);  // a shock: go downhill
        else d = 0.5 * (tr - tl);
      } else if (fl) {
        d = t0 - tl;
      } else if (fr) {
        d = tr - t0;
      }
      grad[a] = d / g_.voxel_size;
    }
    return grad;
  }

  // Unit descent direction at p; false where no corner is reached or the gradient vanishes.
  bool direction(const Vec3d& p, Vec3d& dir) const {
    const CellPos c = cell_of(g_, p);
    Vec3d grad;
    double wsum = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
      const int i = c.base[0] + (corner & 1), j = c.base[1] + ((corner >> 1) & 1), k = c.base[2] + (corner >> 2);
      if (!(time_[g_.index(i, j, k)] < kInf)) continue;
      const double w = corner_weight(c, corner);
      if (w == 0.0) continue;
      grad += node_gradient(i, j, k) * w;
      wsum += w;
    }
    const double len = length(grad);
    if (!(wsum > 0.0) || !(len > 1e-300)) return false;
    dir = grad * (-1.0 / len);
    return true;
  }

 private:
  const FastMarchingResult& f_;
  std::vector<double> time_;
  const DenseGrid& g_;
};

Vec3d clamp_to_grid(const DenseGrid& g, const Vec3d& p) {
  const BBox b = g.bounds();
  return {std::clamp(p.x, b.min.x, b.max.x), std::clamp(p.y, b.min.y, b.max.y), std::clamp(p.z, b.min.z, b.max.z)};
}

void validate_trace(const TraceOptions& o) {
  if (!(o.step > 0.0 && o.step <= 1.0))
    throw Error(ErrorCode::InvalidArgument, "trace step", "must be in (0, 1] voxels");
  if (!(o.stop_distance >= o.step && o.stop_distance <= 8.0))
    throw Error(ErrorCode::InvalidArgument, "trace stop_distance", "must be in [step, 8] voxels");
  if (o.rk_order != 2 && o.rk_order != 4)
    throw Error(ErrorCode::InvalidArgument, "trace rk_order", "must be 2 or 4");
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

double sample_time(const FastMarchingResult& field, const Vec3d& p) {
  if (!field.grid.contains(p))
    throw Error(ErrorCode::InvalidArgument, "sample_time", point_text(p) + " is outside the grid");
  if (field.time.size() != field.grid.voxel_count())
    throw Error(ErrorCode::InvalidArgument, "sample_time", "the field does not match its grid");
  return sample_nodes(field.grid, field.time, p);
}

TraceResult trace_path(const FastMarchingResult& field, const Vec3d& goal, const TraceOptions& options) {
  validate_trace(options);
  const DenseGrid& g = field.grid;
  if (field.time.size() != g.voxel_count() || field.seeds.empty())
    throw Error(ErrorCode::InvalidArgument, "trace_path", "the field is empty or does not match its grid");
  if (!isfinite(goal)) throw Error(ErrorCode::NonFinite, "path goal", "not finite");
  if (!g.contains(goal)) throw Error(ErrorCode::InvalidArgument, "path goal", point_text(goal) + " is outside the grid");
  {
    const Vec3d q = g.to_index_space(goal);
    const std::size_t nearest = g.index(std::clamp(int(std::lround(q.x)), 0, g.nx - 1),
                                        std::clamp(int(std::lround(q.y)), 0, g.ny - 1),
                                        std::clamp(int(std::lround(q.z)), 0, g.nz - 1));
    if (!field.blocked.empty() && field.blocked[nearest])
      throw Error(ErrorCode::InvalidArgument, "path goal", point_text(goal) + " lies in an obstacle");
    if (!(field.time[nearest] < kInf))
      throw Error(ErrorCode::InvalidArgument, "path goal",
                  point_text(goal) + " is unreachable (obstacles cut it off from the start)");
  }
  TraceResult r;
  r.arrival_time = sample_time(field, goal);
  const double h = g.voxel_size;
  const double step = options.step * h, stop = options.stop_distance * h;
  const std::uint64_t max_steps =
      options.max_steps ? options.max_steps : std::min<std::uint64_t>(4 * g.voxel_count(), 100000000);
  const Descent descent(field);

  const auto nearest_seed = [&](const Vec3d& p, double& dist) {
    std::size_t best = 0;
    dist = kInf;
    for (std::size_t s = 0; s < field.seeds.size(); ++s) {
      const double d = length(p - field.seeds[s].position);
      if (d < dist) dist = d, best = s;
    }
    return best;
  };
  const auto stall = [&](const Vec3d& p, const char* why) {
    return Error(ErrorCode::InvalidArgument, "trace_path",
                 std::string("the trace stalled at ") + point_text(p) + " after " + std::to_string(r.steps) +
                     " steps: " + why);
  };

  Vec3d x = goal;
  std::vector<Vec3d> pts{goal};
  double best_time = r.arrival_time;
  std::uint64_t best_step = 0;
  for (;;) {
    double dist;
    const std::size_t s = nearest_seed(x, dist);
    if (dist <= stop) {
      r.seed_index = s;
      r.length += dist;
      pts.push_back(field.seeds[s].position);
      break;
    }
    if (r.steps >= max_steps) throw stall(x, "max_steps reached");
    if ((r.steps & 1023) == 1023) options.progress.check("trace");
    Vec3d d1;
    if (!descent.direction(x, d1)) throw stall(x, "no descent direction");
    Vec3d next;
    if (options.rk_order == 2) {
      Vec3d d2;
      if (!descent.direction(clamp_to_grid(g, x + d1 * step), d2)) d2 = d1;
      next = x + (d1 + d2) * (0.5 * step);
    } else {
      Vec3d d2, d3, d4;
      if (!descent.direction(clamp_to_grid(g, x + d1 * (0.5 * step)), d2)) d2 = d1;
      if (!descent.direction(clamp_to_grid(g, x + d2 * (0.5 * step)), d3)) d3 = d2;
      if (!descent.direction(clamp_to_grid(g, x + d3 * step), d4)) d4 = d3;
      next = x + (d1 + d2 * 2.0 + d3 * 2.0 + d4) * (step / 6.0);
    }
    next = clamp_to_grid(g, next);
    r.length += length(next - x);
    x = next;
    pts.push_back(x);
    ++r.steps;
    const double t = descent.sample(x);
    if (t < best_time) {
      best_time = t;
      best_step = r.steps;
    } else if (r.steps - best_step > kStallSteps) {
      throw stall(x, "the arrival time stopped decreasing");
    }
  }
  r.points.assign(pts.rbegin(), pts.rend());
  return r;
}

PathResult plan_path(const PathOptions& options) {
  if (!isfinite(options.start)) throw Error(ErrorCode::NonFinite, "path start", "not finite");
  if (!isfinite(options.goal)) throw Error(ErrorCode::NonFinite, "path goal", "not finite");
  validate_trace(options.trace);
  validate_grid(options.grid, options.max_voxels, "path grid");
  if (!options.grid.contains(options.goal))
    throw Error(ErrorCode::InvalidArgument, "path goal", point_text(options.goal) + " is outside the grid");
  FastMarchingOptions march;
  march.grid = options.grid;
  march.seeds = {Seed{options.start, 0}};
  march.cost = options.cost;
  march.obstacles = options.obstacles;
  march.order = options.order;
  march.seed_radius = options.seed_radius;
  march.max_voxels = options.max_voxels;
  march.progress = options.progress;
  if (!options.keep_field) march.stop_targets = {options.goal};
  FastMarchingResult field = fast_marching(march);

  const auto t0 = std::chrono::steady_clock::now();
  TraceOptions trace = options.trace;
  trace.progress = options.progress;
  TraceResult traced = trace_path(field, options.goal, trace);
  PathResult r;
  r.points = std::move(traced.points);
  r.length = traced.length;
  r.arrival_time = traced.arrival_time;
  r.steps = traced.steps;
  r.accepted = field.accepted;
  r.blocked = field.blocked_count;
  r.first_order_fallbacks = field.first_order_fallbacks;
  r.seconds_cost = field.seconds_cost;
  r.seconds_march = field.seconds_march;
  r.seconds_trace = seconds_since(t0);
  if (options.keep_field) r.field = std::move(field);
  return r;
}

}  // namespace levelset::apps
