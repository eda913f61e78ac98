#include "apps/fast_marching.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.hpp"

namespace levelset::apps {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::int32_t kFar = -1, kKnown = -2, kBlocked = -3;  // node states (>= 0: heap slot)
constexpr std::size_t kMaxSeeds = std::size_t{1} << 20;

std::string point_text(const Vec3d& p) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p.x, p.y, p.z);
  return buf;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Term {
  double beta;
  double alpha2;
};

// Largest admissible root of sum alpha2 (T - beta)^2 = f^2 over the terms taken in
// increasing beta while the root stays above the next beta; NaN when a system has no real
// root (possible only with second-order terms). Relative to the smallest beta for precision.
double solve_terms(Term* terms, int n, double f) {
  std::sort(terms, terms + n, [](const Term& a, const Term& b) { return a.beta < b.beta; });
  const double b0 = terms[0].beta;
  double A = 0, B = 0, C = -f * f, t = kInf;
  for (int k = 0; k < n; ++k) {
    const double b = terms[k].beta - b0;
    A += terms[k].alpha2;
    B += terms[k].alpha2 * b;
    C += terms[k].alpha2 * b * b;
    const double disc = B * B - A * C;
    if (disc < 0) return std::numeric_limits<double>::quiet_NaN();
    t = (B + std::sqrt(disc)) / A;
    if (k + 1 < n && t > terms[k + 1].beta - b0) continue;
    break;
  }
  return b0 + t;
}

// The marching state over one grid.
class Marcher {
 public:
  Marcher(const DenseGrid& g, const std::vector<double>& cost, int order, FastMarchingResult& r)
      : g_(g), cost_(cost), order_(order), r_(r), state_(cost.size(), kFar) {
    stride_[0] = 1;
    stride_[1] = std::ptrdiff_t(g.nx);
    stride_[2] = std::ptrdiff_t(g.nx) * g.ny;
    for (std::size_t v = 0; v < cost.size(); ++v)
      if (cost[v] == kInf) state_[v] = kBlocked;
  }

  bool free(std::size_t v) const { return state_[v] != kBlocked; }
  bool known(std::size_t v) const { return state_[v] == kKnown; }

  void fix(std::size_t v) {  // a seed node: accepted at its initial time
    if (state_[v] >= 0) remove_from_heap(v);
    state_[v] = kKnown;
  }

  // Updates the not yet accepted free neighbours of accepted node (i, j, k).
  void relax_neighbours(int i, int j, int k) {
    const int c[3] = {i, j, k};
    for (int a = 0; a < 3; ++a)
      for (int side = -1; side <= 1; side += 2) {
        const int ca = c[a] + side;
        if (ca < 0 || ca >= g_.dim(a)) continue;
        int n[3] = {i, j, k};
        n[a] = ca;
        const std::size_t v = g_.index(n[0], n[1], n[2]);
        if (state_[v] == kKnown || state_[v] == kBlocked) continue;
        std::int32_t label = -1;
        const double t = update(v, n, label);
        if (t < r_.time[v]) {
          r_.time[v] = t;
          r_.label[v] = label;
          if (state_[v] == kFar) {
            push(v);
          } else {
            heap_[std::size_t(state_[v])].t = t;
            sift_up(std::size_t(state_[v]));
          }
        }
      }
  }

  bool heap_empty() const { return heap_.empty(); }
  std::size_t pop() {
    const std::size_t v = heap_[0].v;
    const Entry last = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) {
      place(0, last);
      sift_down(0);
    }
    state_[v] = kKnown;
    return v;
  }
  // Drops the trial nodes (after a stop_time cut): back to +inf, unlabelled.
  void clear_trial() {
    for (const Entry& e : heap_) {
      const std::uint32_t v = e.v;
      r_.time[v] = kInf;
      r_.label[v] = -1;
      state_[v] = kFar;
    }
    heap_.clear();
  }

 private:
  double update(std::size_t v, const int* c, std::int32_t& label) {
    Term terms[3];
    int n = 0;
    double smallest = kInf;
    bool second = false;
    for (int a = 0; a < 3; ++a) {
      const std::ptrdiff_t s = stride_[a];
      double m1 = kInf;
      int side = 0;
      if (c[a] > 0 && known(v - s)) m1 = r_.time[v - s], side = -1;
      if (c[a] + 1 < g_.dim(a) && known(v + s) && r_.time[v + s] < m1) m1 = r_.time[v + s], side = 1;
      if (side == 0) continue;
      const std::size_t n1 = std::size_t(std::ptrdiff_t(v) + side * s);
      if (m1 < smallest) smallest = m1, label = r_.label[n1];
      Term t{m1, 1.0};
      const int c2 = c[a] + 2 * side;
      if (order_ == 2 && c2 >= 0 && c2 < g_.dim(a)) {
        const std::size_t n2 = std::size_t(std::ptrdiff_t(v) + 2 * side * s);
        if (known(n2) && r_.time[n2] <= m1) {
          t = {(4.0 * m1 - r_.time[n2]) / 3.0, 2.25};
          second = true;
        }
      }
      first_[n] = m1;
      terms[n++] = t;
    }
    const double f = g_.voxel_size * cost_[v];
    if (second) {
      const double t = solve_terms(terms, n, f);
      if (!std::isnan(t)) {
        ++r_.second_order_updates;
        return t;
      }
      ++r_.first_order_fallbacks;
    }
    for (int q = 0; q < n; ++q) terms[q] = {first_[q], 1.0};
    ++r_.first_order_updates;
    return solve_terms(terms, n, f);
  }

  // Heap entries carry their key, so sifting never reads the (large, cold) time array.
  struct Entry {
    double t;
    std::uint32_t v;
  };
  static bool less(const Entry& a, const Entry& b) {
    return a.t < b.t || (a.t == b.t && a.v < b.v);  // ties by node index: deterministic
  }
  void place(std::size_t slot, const Entry& e) {
    heap_[slot] = e;
    state_[e.v] = std::int32_t(slot);
  }
  void push(std::size_t v) {
    heap_.push_back({r_.time[v], std::uint32_t(v)});
    state_[v] = std::int32_t(heap_.size() - 1);
    sift_up(heap_.size() - 1);
  }
  void sift_up(std::size_t slot) {
    const Entry e = heap_[slot];
    while (slot > 0) {
      const std::size_t parent = (slot - 1) / 2;
      if (!less(e, heap_[parent])) break;
      place(slot, heap_[parent]);
      slot = parent;
    }
    place(slot, e);
  }
  void sift_down(std::size_t slot) {
    const Entry e = heap_[slot];
    const std::size_t n = heap_.size();
    for (;;) {
      const std::size_t l = 2 * slot + 1, r = l + 1;
      if (l >= n) break;
      const std::size_t c = r < n && less(heap_[r], heap_[l]) ? r : l;
      if (!less(heap_[c], e)) break;
      place(slot, heap_[c]);
      slot = c;
    }
    place(slot, e);
  }
  void remove_from_heap(std::size_t v) {
    const std::size_t slot = std::size_t(state_[v]);
    const Entry last = heap_.back();
    heap_.pop_back();
    state_[v] = kFar;
    if (slot < heap_.size()) {
      place(slot, last);
      sift_up(slot);
      sift_down(std::size_t(state_[last.v]));
    }
  }

  const DenseGrid& g_;
  const std::vector<double>& cost_;
  int order_;
  FastMarchingResult& r_;
  std::vector<std::int32_t> state_;
  std::vector<Entry> heap_;
  std::ptrdiff_t stride_[3];
  double first_[3] = {};
};

void validate_options(const FastMarchingOptions& o) {
  if (o.max_voxels > std::uint64_t(std::numeric_limits<std::int32_t>::max()))
    throw Error(ErrorCode::InvalidArgument, "fast_marching max_voxels", "at most 2^31 - 1 nodes (32-bit heap indices)");
  validate_grid(o.grid, o.max_voxels, "fast_marching grid");
  if (o.order != 1 && o.order != 2)
    throw Error(ErrorCode::InvalidArgument, "fast_marching order", "must be 1 or 2");
  if (!(o.seed_radius >= 0.0 && o.seed_radius <= 16.0))
    throw Error(ErrorCode::InvalidArgument, "fast_marching seed_radius", "must be in [0, 16] voxels");
  if (std::isnan(o.stop_time)) throw Error(ErrorCode::NonFinite, "fast_marching stop_time", "is NaN");
  if (o.seeds.empty()) throw Error(ErrorCode::InvalidArgument, "fast_marching seeds", "no seed given");
  if (o.seeds.size() > kMaxSeeds)
    throw Error(ErrorCode::LimitExceeded, "fast_marching seeds", "more than 2^20 seeds");
  for (std::size_t s = 0; s < o.seeds.size(); ++s) {
    const Seed& seed = o.seeds[s];
    const std::string at = "seed " + std::to_string(s + 1);
    if (!isfinite(seed.position)) throw Error(ErrorCode::NonFinite, at, "position is not finite");
    if (!o.grid.contains(seed.position))
      throw Error(ErrorCode::InvalidArgument, at, point_text(seed.position) + " is outside the grid");
    if (seed.label < 0) throw Error(ErrorCode::InvalidArgument, at, "labels must be >= 0");
  }
  if (o.stop_targets.size() > kMaxSeeds)
    throw Error(ErrorCode::LimitExceeded, "fast_marching stop_targets", "more than 2^20 targets");
  for (const Vec3d& p : o.stop_targets) {
    if (!isfinite(p)) throw Error(ErrorCode::NonFinite, "fast_marching stop target", "not finite");
    if (!o.grid.contains(p))
      throw Error(ErrorCode::InvalidArgument, "fast_marching stop target", point_text(p) + " is outside the grid");
  }
}

}  // namespace

FastMarchingResult fast_marching(const FastMarchingOptions& options) {
  validate_options(options);
  const DenseGrid& g = options.grid;
  const auto t0 = std::chrono::steady_clock::now();
  CostGrid costs = build_cost_grid(g, options.cost, options.obstacles, options.progress);

  FastMarchingResult r;
  r.grid = g;
  r.seeds = options.seeds;
  r.min_cost = costs.min_cost;
  r.max_cost = costs.max_cost;
  r.blocked_count = costs.blocked;
  r.seconds_cost = seconds_since(t0);
  const auto t1 = std::chrono::steady_clock::now();
  const std::size_t n = costs.cost.size();
  r.time.assign(n, kInf);
  r.label.assign(n, -1);
  r.blocked.assign(n, 0);
  for (std::size_t v = 0; v < n; ++v) r.blocked[v] = costs.cost[v] == kInf;

  Marcher m(g, costs.cost, options.order, r);

  // 1. Seed layers: straight-segment travel times, smallest over seeds.
  std::vector<std::size_t> seed_nodes;
  const double h = g.voxel_size;
  for (std::size_t s = 0; s < options.seeds.size(); ++s) {
    const Seed& seed = options.seeds[s];
    const double cs = cost_at(costs, seed.position);
    if (cs == kInf)
      throw Error(ErrorCode::InvalidArgument, "seed " + std::to_string(s + 1),
                  point_text(seed.position) + " lies in an obstacle");
    const Vec3d q = g.to_index_space(seed.position);
    int lo[3], hi[3], cell[3];
    for (int a = 0; a < 3; ++a) {
      const double qa = std::clamp(q[a], 0.0, double(g.dim(a) - 1));
      cell[a] = std::min(int(std::floor(qa)), g.dim(a) - 2);
      lo[a] = std::max(0, int(std::floor(qa - options.seed_radius)));
      hi[a] = std::min(g.dim(a) - 1, int(std::ceil(qa + options.seed_radius)));
      lo[a] = std::min(lo[a], cell[a]);
      hi[a] = std::max(hi[a], cell[a] + 1);
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          const std::size_t v = g.index(i, j, k);
          if (!m.free(v)) continue;
          const Vec3d x = g.world(i, j, k);
          const double d = length(x - seed.position);
          const bool corner = i - cell[0] >= 0 && i - cell[0] <= 1 && j - cell[1] >= 0 && j - cell[1] <= 1 &&
                              k - cell[2] >= 0 && k - cell[2] <= 1;
          if (!corner && d > options.seed_radius * h) continue;
          const double cm = cost_at(costs, (x + seed.position) * 0.5);
          const double cx = costs.cost[v];
          const double t = cm == kInf ? d * 0.5 * (cs + cx) : d * (cs + 4.0 * cm + cx) / 6.0;
          if (r.time[v] == kInf) seed_nodes.push_back(v);
          if (t < r.time[v]) {
            r.time[v] = t;
            r.label[v] = seed.label;
          }
        }
  }
  std::sort(seed_nodes.begin(), seed_nodes.end());
  for (const std::size_t v : seed_nodes) m.fix(v);
  r.seed_nodes = seed_nodes.size();
  r.accepted = seed_nodes.size();
  const auto coords = [&](std::size_t v, int& i, int& j, int& k) {
    i = int(v % std::size_t(g.nx));
    j = int((v / std::size_t(g.nx)) % std::size_t(g.ny));
    k = int(v / (std::size_t(g.nx) * std::size_t(g.ny)));
  };
  for (const std::size_t v : seed_nodes) {
    int i, j, k;
    coords(v, i, j, k);
    m.relax_neighbours(i, j, k);
  }

  // The free corner nodes of the stop targets' cells not accepted yet.
  std::vector<std::size_t> pending;
  for (const Vec3d& p : options.stop_targets) {
    const Vec3d q = g.to_index_space(p);
    int base[3];
    for (int a = 0; a < 3; ++a)
      base[a] = std::min(int(std::floor(std::clamp(q[a], 0.0, double(g.dim(a) - 1)))), g.dim(a) - 2);
    for (int c = 0; c < 8; ++c) {
      const std::size_t v = g.index(base[0] + (c & 1), base[1] + ((c >> 1) & 1), base[2] + (c >> 2));
      if (m.free(v) && !m.known(v)) pending.push_back(v);
    }
  }
  std::sort(pending.begin(), pending.end());
  pending.erase(std::unique(pending.begin(), pending.end()), pending.end());
  std::size_t pending_left = pending.size();
  double stop_time = options.stop_time;
  if (!options.stop_targets.empty() && pending_left == 0)
    stop_time = std::min(stop_time, 3.0 * h * costs.max_cost + [&] {
      double t = 0;  // all target cells lie in the seed layers
      for (const std::size_t v : seed_nodes) t = std::max(t, r.time[v]);
      return t;
    }());

  // 2. March.
  const double free_nodes = double(n - costs.blocked);
  while (!m.heap_empty()) {
    const std::size_t v = m.pop();
    ++r.accepted;
    if (pending_left > 0 && std::binary_search(pending.begin(), pending.end(), v) && --pending_left == 0)
      stop_time = std::min(stop_time, r.time[v] + 3.0 * h * costs.max_cost);
    if (r.time[v] > stop_time) {
      r.time[v] = kInf;
      r.label[v] = -1;
      r.complete = false;
      m.clear_trial();
      break;
    }
    int i, j, k;
    coords(v, i, j, k);
    m.relax_neighbours(i, j, k);
    if ((r.accepted & 16383) == 0) {
      if (options.progress.on_progress) options.progress.step(double(r.accepted) / free_nodes, "march");
      else options.progress.check("march");
    }
  }
  if (!r.complete) --r.accepted;
  if (options.progress.on_progress) options.progress.step(1.0, "march");
  r.seconds_march = seconds_since(t1);
  return r;
}

}  // namespace levelset::apps
