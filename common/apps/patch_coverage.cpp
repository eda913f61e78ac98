#include "apps/patch_coverage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "geometry/symmetric_eigen.hpp"

namespace levelset::apps {

PatchCoverageResult patch_coverage(const PointIndex& index, const Vec3d& x, const PatchCoverageOptions& o) {
  constexpr int kMaxNeighbors = 64;
  const int k = std::clamp(o.neighbors, 3, kMaxNeighbors);
  std::array<std::uint32_t, kMaxNeighbors> ids{};
  std::array<double, kMaxNeighbors> d2{};
  const int found = index.k_nearest(x, k, ids.data(), d2.data());
  PatchCoverageResult r;
  if (found < 3) return r;
  const auto& pts = index.points();
  r.nearest = std::sqrt(d2[0]);
  Vec3d c{0, 0, 0};
  for (int i = 0; i < found; ++i) c = c + pts[ids[std::size_t(i)]];
  c = c / double(found);
  double m[6] = {0, 0, 0, 0, 0, 0};
  for (int i = 0; i < found; ++i) {
    const Vec3d v = pts[ids[std::size_t(i)]] - c;
    m[0] += v.x * v.x, m[1] += v.y * v.y, m[2] += v.z * v.z, m[3] += v.x * v.y, m[4] += v.x * v.z, m[5] += v.y * v.z;
  }
  for (double& v : m) v /= double(found);
  const double lambda = smallest_eigenvalue(m[0], m[1], m[2], m[3], m[4], m[5]);
  const Vec3d n = eigenvector_of(m[0], m[1], m[2], m[3], m[4], m[5], lambda);
  r.residual = std::sqrt(std::max(0.0, lambda));
  r.offset = std::abs(dot(x - c, n));
  // A basis (u, v) of the plane and the directions of the projections.
  const Vec3d other = std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
  Vec3d u = cross(n, other);
  u = u / length(u);
  const Vec3d w = cross(n, u);
  std::array<double, kMaxNeighbors> angle{};
  int directions = 0;
  for (int i = 0; i < found; ++i) {
    const Vec3d d = pts[ids[std::size_t(i)]] - x;
    const double a = dot(d, u), b = dot(d, w);
    if (a * a + b * b <= 1e-24 * (d2[std::size_t(i)] + 1e-300)) continue;  // straight above x: no direction
    angle[std::size_t(directions++)] = std::atan2(b, a);
  }
  if (directions < 3) return r;
  std::sort(angle.begin(), angle.begin() + directions);
  double gap = angle[0] + 2.0 * std::numbers::pi - angle[std::size_t(directions - 1)];
  for (int i = 1; i < directions; ++i) gap = std::max(gap, angle[std::size_t(i)] - angle[std::size_t(i - 1)]);
  r.angular_gap = gap;
  const double scale = o.flatness * r.nearest;
  r.inside = r.offset <= o.offset_ratio * r.nearest && r.residual <= scale && gap <= o.max_angular_gap;
  return r;
}

}  // namespace levelset::apps
