#include "apps/point_sampling.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "geometry/symmetric_eigen.hpp"

namespace levelset::apps {

namespace {

double median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

SamplingEstimate estimate_sampling(const PointIndex& index, const SamplingEstimateOptions& o) {
  if (o.neighbors < 8 || o.neighbors > 64)
    throw Error(ErrorCode::InvalidArgument, "estimate_sampling", "neighbors must be in [8, 64]");
  const std::size_t n = index.size();
  if (n < 4) throw Error(ErrorCode::InvalidArgument, "estimate_sampling", "need at least 4 points, got " + std::to_string(n));
  // Small clouds: fewer neighbours (the spacing from the j-th nearest, j = min(8, k)).
  const int k = int(std::min<std::size_t>(std::size_t(o.neighbors), n - 1)) + 1;  // the point itself comes first
  const int j = std::min(8, k - 1);
  const std::size_t count = std::max<std::size_t>(1, std::min(n, o.samples));
  const std::size_t stride = n / count;
  std::vector<double> d8, spread;
  d8.reserve(count);
  spread.reserve(count);
  std::vector<std::uint32_t> ids(std::size_t(k), 0);
  std::vector<double> dist2(std::size_t(k), 0.0);
  const std::vector<Vec3d>& pts = index.points();
  for (std::size_t s = 0; s < count; ++s) {
    if ((s & 255) == 0) o.progress.check("estimate sampling");
    const Vec3d x = pts[s * stride];
    const int found = index.k_nearest(x, k, ids.data(), dist2.data());
    if (found < k) continue;
    d8.push_back(std::sqrt(dist2[std::size_t(j)]));
    Vec3d c{0, 0, 0};
    for (int i = 0; i < found; ++i) c = c + pts[ids[std::size_t(i)]];
    c = c / double(found);
    std::array<double, 6> m{};
    for (int i = 0; i < found; ++i) {
      const Vec3d v = pts[ids[std::size_t(i)]] - c;
      m[0] += v.x * v.x, m[1] += v.y * v.y, m[2] += v.z * v.z, m[3] += v.x * v.y, m[4] += v.x * v.z, m[5] += v.y * v.z;
    }
    for (double& v : m) v /= double(found);
    spread.push_back(std::sqrt(std::max(0.0, smallest_eigenvalue(m[0], m[1], m[2], m[3], m[4], m[5]))));
  }
  SamplingEstimate e;
  e.samples = d8.size();
  e.spacing = std::sqrt(std::numbers::pi / double(j)) * median(d8);
  e.noise = median(spread);
  return e;
}

}  // namespace levelset::apps
