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
  reach_ = reach;
}

int NearbyPoints::k_nearest(const Vec3d& x, int k, std::uint32_t* indices,
                            double* distances_squared) const {
  const double offset = length(x - centre_);
  if (!(reach_ >= 0.0) || k > k_ || !(offset <= reach_))
    return index_->k_nearest(x, k, indices, distances_squared);
  if (k <= 0) return 0;
  // The running k best, sorted by (distance, index), as the tree's result set keeps them.
  int count = 0;
  for (const Candidate& c : candidates_) {
    if (count == k) {
      // No later candidate is closer than centre_distance - offset to x.
      const double bound = c.centre_distance - offset;
      if (bound > 0.0 && bound * bound > distances_squared[k - 1] * (1.0 + 1e-9)) break;
    }
    double d = 0.0, diff = x.x - c.x;
    d += diff * diff;
    diff = x.y - c.y;
    d += diff * diff;
    diff = x.z - c.z;
    d += diff * diff;
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
