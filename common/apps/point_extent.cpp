#include "apps/point_extent.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <vector>

namespace levelset::apps {

PointExtentResult point_extent(const PointIndex& index, const PointExtentOptions& options) {
  const std::vector<Vec3d>& points = index.points();
  const std::size_t n = points.size();
  PointExtentResult r;
  for (const Vec3d& p : points) r.box.extend(p);
  const int k = std::clamp(options.neighbors, 1, 255);
  r.gap = sample_gap(index, k, 0.9, 4000);
  if (n < std::size_t(k) + 2) return r;
  const double limit = options.factor * r.gap;
  if (!(limit > 0.0)) return r;  // duplicates: no spacing to judge by
  // The k-th nearest other point (the point itself is its own nearest).
  std::array<std::uint32_t, 256> idx;
  std::array<double, 256> d2;
  auto isolated = [&](std::uint32_t i) {
    const int got = index.k_nearest(points[i], k + 1, idx.data(), d2.data());
    return got == k + 1 && std::sqrt(d2[std::size_t(k)]) > limit;
  };
  // The usual cloud: no point on the raw box's faces is isolated.
  bool any = false;
  for (int a = 0; a < 3 && !any; ++a) {
    const auto [lo, hi] = std::minmax_element(points.begin(), points.end(),
                                              [a](const Vec3d& p, const Vec3d& q) { return p[a] < q[a]; });
    any = isolated(std::uint32_t(lo - points.begin())) || isolated(std::uint32_t(hi - points.begin()));
  }
  if (!any) return r;
  std::vector<std::uint8_t> state(n, 0);  // 0 untested, 1 isolated, 2 data
  auto is_isolated = [&](std::uint32_t i) {
    if (state[i] == 0) state[i] = isolated(i) ? 1 : 2;
    return state[i] == 1;
  };
  std::vector<std::uint32_t> order(n);
  BBox box;
  for (int a = 0; a < 3; ++a) {
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
      return points[i][a] < points[j][a] || (points[i][a] == points[j][a] && i < j);
    });
    std::size_t lo = 0, hi = n;
    while (lo < hi && is_isolated(order[lo])) ++lo;
    while (hi > lo && is_isolated(order[hi - 1])) --hi;
    if (lo == hi) return r;  // every point isolated: keep the raw box
    box.min[a] = points[order[lo]][a];
    box.max[a] = points[order[hi - 1]][a];
  }
  // A sparse point near the data (a thinly sampled tail of the surface) is isolated too, but
  // leaving it outside the grids would cut the surface there: points within the limit of the
  // box join it, as long as any does.
  std::vector<std::uint32_t> outside;
  auto distance_to_box = [&](const Vec3d& p) {
    Vec3d d{};
    for (int a = 0; a < 3; ++a) d[a] = std::max({box.min[a] - p[a], 0.0, p[a] - box.max[a]});
    return length(d);
  };
  for (std::uint32_t i = 0; i < n; ++i)
    if (distance_to_box(points[i]) > 0.0) outside.push_back(i);
  for (bool grew = true; grew && !outside.empty();) {
    grew = false;
    std::size_t kept = 0;
    for (const std::uint32_t i : outside) {
      if (distance_to_box(points[i]) <= limit) {
        box.extend(points[i]);
        grew = true;
      } else {
        outside[kept++] = i;
      }
    }
    outside.resize(kept);
  }
  r.box = box;
  r.isolated = outside.size();
  return r;
}

}  // namespace levelset::apps
