#include "distance/eikonal_march.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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

// Upwind update from the accepted neighbours (w.dist holds +inf for all others).
inline float known_update(const RedistanceDomain& w, std::uint32_t b, int n, bool second_order) {
  const bool inside = w.inside[b].test(n);
  AxisTerm terms[3];
  for (int a = 0; a < 3; ++a) {
    float m1 = kInf, m2 = kInf;
    for (int s = 0; s < 2; ++s) {
      std::uint32_t b1 = b;
      int n1 = n;
      if (!step(w, b1, n1, 2 * a + s)) continue;
      const float v1 = w.values(b1)[n1];
      if (!(v1 < m1)) continue;
      m1 = v1;
      m2 = kInf;
      if (second_order && step(w, b1, n1, 2 * a + s)) {
        const float v2 = w.values(b1)[n1];
        if (v2 < kInf) m2 = w.inside[b1].test(n1) == inside ? v2 : -v2;
      }
    }
    terms[a] = axis_term(m1, m2, second_order && std::abs(m2) < kInf);
  }
  return solve_terms(terms[0], terms[1], terms[2]);
}

struct HeapEntry {
  float value;
  std::uint32_t id;  // brick * 512 + voxel
};
struct HeapAfter {
  bool operator()(const HeapEntry& a, const HeapEntry& b) const {
    return a.value > b.value || (a.value == b.value && a.id > b.id);
  }
};

// The trial set: binary min-heaps, one per slice of the value range [0, limit] (a global
// heap over the whole front misses the cache on every level). The march only ever pops the
// smallest value, and every pushed value lands in the current slice or a later one, so the
// pop order is exactly that of one global heap. Values above the limit are never accepted
// and are not stored.
class TrialQueue {
 public:
  explicit TrialQueue(double limit)
      : limit_(limit),
        slices_(std::size_t(std::clamp(std::ceil(limit * kSlicesPerVoxel), 1.0, double(kMaxSlices)))),
        per_unit_(double(slices_.size()) / limit) {}

  void push(const HeapEntry& e) {
    if (!(double(e.value) <= limit_)) return;
    std::vector<HeapEntry>& h = slices_[slice_of(e.value)];
    h.push_back(e);
    std::push_heap(h.begin(), h.end(), HeapAfter{});
  }
  // Bulk insertion of the initial front.
  void assign(const std::vector<HeapEntry>& entries) {
    for (const HeapEntry& e : entries)
      if (double(e.value) <= limit_) slices_[slice_of(e.value)].push_back(e);
    for (auto& h : slices_) std::make_heap(h.begin(), h.end(), HeapAfter{});
  }
  bool pop(HeapEntry& e) {
    while (current_ < slices_.size() && slices_[current_].empty()) {
      slices_[current_].shrink_to_fit();
      ++current_;
    }
    if (current_ == slices_.size()) return false;
    std::vector<HeapEntry>& h = slices_[current_];
    std::pop_heap(h.begin(), h.end(), HeapAfter{});
    e = h.back();
    h.pop_back();
    return true;
  }

 private:
  static constexpr double kSlicesPerVoxel = 256.0;
  static constexpr std::size_t kMaxSlices = 1 << 16;
  std::size_t slice_of(float v) const {
    const double k = std::floor(double(v) * per_unit_);
    const std::size_t last = slices_.size() - 1;
    const std::size_t s = k <= 0.0 ? 0 : (k >= double(last) ? last : std::size_t(k));
    return std::max(s, current_);  // below the current slice (rounding): still the minimum
  }
  double limit_;
  std::vector<std::vector<HeapEntry>> slices_;
  double per_unit_;
  std::size_t current_ = 0;
};

}  // namespace

void march(RedistanceDomain& w, int order, double limit, const ProgressHook& progress) {
  const std::size_t n = w.size();
  const bool second = order == 2;
  std::vector<float> tentative(w.dist.size(), kInf);
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
        const float t = known_update(w, b, v, second);
        tentative[std::size_t(b) * kBrickVoxels + v] = t;
        front[b].push_back({t, b * std::uint32_t(kBrickVoxels) + std::uint32_t(v)});
      });
    }
  });
  TrialQueue trial(limit);
  {
    std::vector<HeapEntry> all;
    for (auto& f : front) all.insert(all.end(), f.begin(), f.end());
    front = {};
    trial.assign(all);
  }
  std::uint64_t pops = 0;
  HeapEntry e;
  while (trial.pop(e)) {
    if ((++pops & 0xffff) == 0) progress.check("redistance march");
    if (w.dist[e.id] < kInf) continue;  // accepted earlier with a smaller value
    w.dist[e.id] = e.value;
    const std::uint32_t b = e.id / kBrickVoxels;
    const int v = int(e.id % kBrickVoxels);
    for (int dir = 0; dir < 6; ++dir) {
      std::uint32_t b2 = b;
      int n2 = v;
      if (!step(w, b2, n2, dir) || !w.domain[b2].test(n2)) continue;
      const std::uint32_t id2 = b2 * std::uint32_t(kBrickVoxels) + std::uint32_t(n2);
      if (w.dist[id2] < kInf) continue;
      const float t = known_update(w, b2, n2, second);
      if (t < tentative[id2]) {
        tentative[id2] = t;
        trial.push({t, id2});
      }
    }
  }
}

}  // namespace levelset::detail
