#include "apps/unique_points.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numeric>

#include "core/error.hpp"

namespace levelset::apps {

namespace {

// A point's cell as three 64-bit integers: floor(x / t) where that fits comfortably, else
// the coordinate's bit pattern (exact comparison; order does not matter, only equality).
using CellKey = std::array<std::int64_t, 3>;

CellKey cell_of(const Vec3d& p, double tolerance) {
  CellKey key{};
  for (int a = 0; a < 3; ++a) {
    const double x = p[a];
    const double scaled = tolerance > 0.0 ? std::floor(x / tolerance) : 0.0;
    if (tolerance > 0.0 && std::abs(scaled) < 4.0e18) {
      key[std::size_t(a)] = std::int64_t(scaled);
    } else {
      const double exact = x == 0.0 ? 0.0 : x;  // -0 and +0 are one coordinate
      std::memcpy(&key[std::size_t(a)], &exact, sizeof exact);
    }
  }
  return key;
}

}  // namespace

UniquePointsResult unique_points(const std::vector<Vec3d>& points, const UniquePointsOptions& options) {
  if (!std::isfinite(options.tolerance) || options.tolerance < 0.0)
    throw Error(ErrorCode::InvalidArgument, "unique_points", "tolerance must be a finite number >= 0");
  std::vector<CellKey> keys(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) keys[i] = cell_of(points[i], options.tolerance);
  std::vector<std::size_t> order(points.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
  std::vector<std::uint8_t> keep(points.size(), 0);
  for (std::size_t k = 0; k < order.size(); ++k)
    if (k == 0 || keys[order[k]] != keys[order[k - 1]]) keep[order[k]] = 1;
  UniquePointsResult r;
  r.points.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    if (keep[i]) r.points.push_back(points[i]);
  r.merged = points.size() - r.points.size();
  return r;
}

}  // namespace levelset::apps
