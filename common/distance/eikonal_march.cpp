#include "distance/eikonal_march.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "distance/eikonal_trial_queue.hpp"
#include "distance/eikonal_update.hpp"

namespace levelset::detail {

namespace {

// Face neighbour of voxel n of brick b in direction dir (Face order); false outside.
inline bool step(const RedistanceDomain& w, std::uint32_t& b, int& n, int dir) {
  const int shift = 3 * (dir >> 1);
  const int c = (n >> shift) & 7;
  if (c == ((dir & 1) ? 7 : 0)) {
    b = w.nbr[b][dir];
    n ^= 7 << shift;
    return b != kNoBrick;
  }
  n += (dir & 1) ? (1 << shift) : -(1 << shift);
  return true;
}

// During the march w.dist holds, per voxel: its distance once fixed or accepted (>= 0), minus its
// tentative value while it is in the trial set (< 0), +inf otherwise: one array, so that a pop
// touches one cache line per voxel rather than two (the march's cost is its cache misses: it
// visits the front in value order, all over the surface).
// (signbit: a tentative value of 0 is stored as -0.)
inline bool tentative(float v) { return std::signbit(v); }
inline bool known(float v) { return !std::signbit(v) && v < kInf; }

// Upwind update from the accepted neighbours on the voxel's
// own side of the interface or fixed. (Only a band whose sign changes outside its active voxels
// has a free neighbour of the other side; skipping it keeps the two sides' marches apart.)
inline float known_update(const RedistanceDomain& w, std::uint32_t b, int n, bool second_order) {
  const bool inside = w.inside[b].test(n);
  AxisTerm terms[3];
  for (int a = 0; a < 3; ++a) {
    float m1 = kInf, m2 = kInf;
    for (int s = 0; s < 2; ++s) {
      std::uint32_t b1 = b;
      int n1 = n;
      if (!step(w, b1, n1, 2 * a + s)) continue;
      if (w.inside[b1].test(n1) != inside && !w.fixed[b1].test(n1)) continue;
      const float v1 = w.values(b1)[n1];
      if (!known(v1) || !(v1 < m1)) continue;
      m1 = v1;
      m2 = kInf;
      if (second_order && step(w, b1, n1, 2 * a + s) && (w.inside[b1].test(n1) == inside || w.fixed[b1].test(n1))) {
        const float v2 = w.values(b1)[n1];
        if (known(v2)) m2 = w.inside[b1].test(n1) == inside ? v2 : -v2;
      }
    }
    terms[a] = axis_term(m1, m2, second_order && std::abs(m2) < kInf);
  }
  return solve_terms(terms[0], terms[1], terms[2]);
}

// Accepts the voxels of one side (inside or not) smallest tentative value first.
void march_side(RedistanceDomain& w, TrialQueue& trial, bool inside, bool second, const ProgressHook& progress) {
  std::uint64_t pops = 0;
  HeapEntry e;
  while (trial.pop(e)) {
    if ((++pops & 0xffff) == 0) progress.check("redistance march");
    if (!tentative(w.dist[e.id])) continue;  // accepted earlier with a smaller value
    w.dist[e.id] = e.value;
    if (const HeapEntry* next = trial.peek()) {  // its voxel's line and masks arrive meanwhile
      __builtin_prefetch(&w.dist[next->id]);
      __builtin_prefetch(&w.inside[next->id / kBrickVoxels]);
    }
    const std::uint32_t b = e.id / kBrickVoxels;
    const int v = int(e.id % kBrickVoxels);
    for (int dir = 0; dir < 6; ++dir) {
      std::uint32_t b2 = b;
      int n2 = v;
      if (!step(w, b2, n2, dir) || !w.domain[b2].test(n2) || w.inside[b2].test(n2) != inside) continue;
      const std::uint32_t id2 = b2 * std::uint32_t(kBrickVoxels) + std::uint32_t(n2);
      const float d = w.dist[id2];
      if (known(d)) continue;  // fixed or accepted
      const float t = known_update(w, b2, n2, second);
      if (d == kInf || t < -d) {
        w.dist[id2] = -t;
        trial.push({t, id2});
      }
    }
  }
}

}  // namespace

void march(RedistanceDomain& w, int order, double limit, const ProgressHook& progress) {
  const std::size_t n = w.size();
  const bool second = order == 2;
  // Initial front: free voxels next to an interface voxel, per brick in parallel.
  std::vector<std::vector<HeapEntry>> front(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t bi = r.begin(); bi != r.end(); ++bi) {
      const auto b = std::uint32_t(bi);
      const float* own = w.values(b);
      w.domain[b].for_each_set([&](int v) {
        if (own[v] < kInf) return;  // interface voxel
        bool near = false;
        for (int dir = 0; dir < 6 && !near; ++dir) {
          std::uint32_t b2 = b;
          int n2 = v;
          near = step(w, b2, n2, dir) && w.values(b2)[n2] < kInf;
        }
        if (!near) return;
        front[b].push_back({known_update(w, b, v, second), b * std::uint32_t(kBrickVoxels) + std::uint32_t(v)});
      });
    }
  });
  // The two sides of the interface march apart (each reads only its own side and the fixed
  // interface voxels: a free voxel next to the other side would be an interface voxel), so
  // they run in parallel and give what one march over both gives.
  TrialQueue trial[2] = {TrialQueue(limit), TrialQueue(limit)};
  {
    std::vector<HeapEntry> sides[2];
    for (const auto& f : front)
      for (const HeapEntry& e : f) {
        // Marked tentative only now: the front's updates above read the fixed voxels alone.
        if (e.value < kInf) w.dist[e.id] = -e.value;
        sides[w.inside[e.id / kBrickVoxels].test(int(e.id % kBrickVoxels)) ? 1 : 0].push_back(e);
      }
    front = {};
    trial[0].assign(sides[0]);
    trial[1].assign(sides[1]);
  }
  tbb::parallel_invoke([&] { march_side(w, trial[0], false, second, progress); },
                       [&] { march_side(w, trial[1], true, second, progress); });
  // Voxels left in the trial set (beyond the limit) are unknown.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, w.dist.size(), 1 << 16),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        if (tentative(w.dist[i])) w.dist[i] = kInf;
                    });
}

}  // namespace levelset::detail
