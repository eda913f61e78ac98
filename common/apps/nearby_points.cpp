#include "apps/nearby_points.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace levelset::apps {

namespace {
constexpr int kMaxK = 256;  // PointIndex's own bound on k
// More candidates than this fall back to the tree: the cost of prepare stays bounded where
// the k nearest of the centre are far while many points lie just beyond them (a sparse
// patch next to a dense cluster; typical neighbourhoods hold 3-6 k).
constexpr std::size_t kCandidatesPerNeighbour = 32, kMinCandidateCap = 2048;
// Candidate positions are kept in 16 bits (k_nearest's bound).
static_assert(kCandidatesPerNeighbour * kMaxK <= 65536 && kMinCandidateCap <= 65536);
}  // namespace

void NearbyPoints::prepare(const Vec3d& centre, double reach, int k) {
  centre_ = centre;
  reach_ = -1.0;
  k_ = std::clamp(k, 1, kMaxK);
  candidates_.clear();
  if (!(reach >= 0.0) || !std::isfinite(reach)) return;
  std::array<std::uint32_t, kMaxK> idx{};
  std::array<double, kMaxK> d2{};
  const int got = index_->k_nearest(centre, k_, idx.data(), d2.data());
  if (got == 0) return;
  // Every point when the set has fewer than k; the radius otherwise (see the header). The
  // radius is widened by a relative 1e-12 so that rounding cannot drop a point at its edge.
  const double radius = (std::sqrt(d2[std::size_t(got - 1)]) + 2.0 * reach) * (1.0 + 1e-12);
  if (got < k_) {
    found_.clear();
    for (std::uint32_t i = 0; i < std::uint32_t(index_->size()); ++i) found_.push_back({i, 0.0});
  } else if (!index_->within(
                 centre, radius,
                 std::max<std::size_t>(kMinCandidateCap, kCandidatesPerNeighbour * std::size_t(k_)),
                 found_)) {
    return;  // a neighbourhood this crowded (points far denser than the k nearest suggest): the
             // tree
  }
  const std::vector<Vec3d>& points = index_->points();
  candidates_.reserve(found_.size());
  for (const auto& [i, unused] : found_) {
    const Vec3d& p = points[i];
    candidates_.push_back({length(p - centre), p.x, p.y, p.z, i});
  }
  std::sort(candidates_.begin(), candidates_.end(), [](const Candidate& a, const Candidate& b) {
    return a.centre_distance < b.centre_distance ||
           (a.centre_distance == b.centre_distance && a.index < b.index);
  });
  last_.clear();
  reach_ = reach;
}

int NearbyPoints::k_nearest(const Vec3d& x, int k, std::uint32_t* indices,
                            double* distances_squared) const {
  const double offset = length(x - centre_);
  if (!(reach_ >= 0.0) || k > k_ || !(offset <= reach_))
    return index_->k_nearest(x, k, indices, distances_squared);
  if (k <= 0) return 0;
  if (k < k_ || candidates_.size() < std::size_t(k))
    return k_nearest_running(x, offset, k, indices, distances_squared);
  return k_nearest_bounded(x, offset, k, indices, distances_squared);
}

namespace {
double distance_squared(const Vec3d& x, double cx, double cy, double cz) {
  double d = 0.0, diff = x.x - cx;
  d += diff * diff;
  diff = x.y - cy;
  d += diff * diff;
  diff = x.z - cz;
  d += diff * diff;
  return d;
}
}  // namespace

int NearbyPoints::k_nearest_bounded(const Vec3d& x, double offset, int k, std::uint32_t* indices,
                                    double* distances_squared) const {
  // The bound: the farthest of k known points (the last such query's k nearest, else the
  // centre's), so r_k(x)^2 <= bound. Every point within it is gathered from the candidates
  // (none beyond centre_distance - offset > sqrt(bound) can be), then sorted by (distance,
  // index): bucketed by the squared distance (uniform on [0, bound] for points on a surface),
  // then an insertion pass over the buckets' order, which moves few entries.
  double bound = 0.0;
  if (last_.size() == std::size_t(k)) {
    for (const std::uint16_t s : last_) {
      const Candidate& c = candidates_[s];
      bound = std::max(bound, distance_squared(x, c.x, c.y, c.z));
    }
  } else {
    for (std::size_t s = 0; s < std::size_t(k); ++s) {
      const Candidate& c = candidates_[s];
      bound = std::max(bound, distance_squared(x, c.x, c.y, c.z));
    }
  }
  const double stop = bound * (1.0 + 1e-9);
  // Raw pointers: the compiler cannot tell the mutable scratch from the candidates.
  const Candidate* const cand = candidates_.data();
  const std::size_t size = candidates_.size();
  gathered_.resize(size);
  Gathered* const gathered = gathered_.data();
  std::size_t m = 0;  // >= k at the end: the k known points are among them (each within the bound)
  for (std::size_t i = 0; i < size; ++i) {
    const Candidate& c = cand[i];
    const double gap = c.centre_distance - offset;
    if (gap > 0.0 && gap * gap > stop) break;
    const double d = distance_squared(x, c.x, c.y, c.z);
    gathered[m] = {d, c.index, std::uint16_t(i)};
    m += d <= bound ? 1 : 0;
  }
  if (m < std::size_t(k))
    return k_nearest_running(x, offset, k, indices, distances_squared);  // (rounding: never seen)
  bucket_start_.assign(m + 1, 0u);
  std::uint32_t* const start = bucket_start_.data();
  const double per_bucket = bound > 0.0 ? double(m) / bound : 0.0;
  auto bucket = [&](double d) { return std::min(m - 1, std::size_t(d * per_bucket)); };
  for (std::size_t i = 0; i < m; ++i) ++start[bucket(gathered[i].d) + 1];
  for (std::size_t b = 0; b < m; ++b) start[b + 1] += start[b];
  sorted_.resize(m);
  Gathered* const sorted = sorted_.data();
  for (std::size_t i = 0; i < m; ++i) sorted[start[bucket(gathered[i].d)]++] = gathered[i];
  for (std::size_t i = 1; i < m; ++i) {
    const Gathered g = sorted[i];
    std::size_t at = i;
    while (at > 0 && (sorted[at - 1].d > g.d ||
                      (sorted[at - 1].d == g.d && sorted[at - 1].index > g.index))) {
      sorted[at] = sorted[at - 1];
      --at;
    }
    sorted[at] = g;
  }
  last_.resize(std::size_t(k));
  for (std::size_t i = 0; i < std::size_t(k); ++i) {
    indices[i] = sorted[i].index;
    distances_squared[i] = sorted[i].d;
    last_[i] = sorted[i].at;
  }
  return k;
}

int NearbyPoints::k_nearest_running(const Vec3d& x, double offset, int k, std::uint32_t* indices,
                                    double* distances_squared) const {
  // The running k best, sorted by (distance, index), as the tree's result set keeps them.
  int count = 0;
  for (const Candidate& c : candidates_) {
    if (count == k) {
      // No later candidate is closer than centre_distance - offset to x.
      const double bound = c.centre_distance - offset;
      if (bound > 0.0 && bound * bound > distances_squared[k - 1] * (1.0 + 1e-9)) break;
    }
    const double d = distance_squared(x, c.x, c.y, c.z);
    if (count == k && !(d < distances_squared[k - 1] ||
                        (d == distances_squared[k - 1] && c.index < indices[k - 1])))
      continue;
    int at = count < k ? count++ : k - 1;
    while (at > 0 && (distances_squared[at - 1] > d ||
                      (distances_squared[at - 1] == d && indices[at - 1] > c.index))) {
      distances_squared[at] = distances_squared[at - 1];
      indices[at] = indices[at - 1];
      --at;
    }
    distances_squared[at] = d;
    indices[at] = c.index;
  }
  return count;
}

}  // namespace levelset::apps
