#include "distance/collinear_segments.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <numeric>
#include <utility>

namespace levelset {

namespace {

struct LineKey {
  std::array<std::int64_t, 6> q{};
  auto operator<=>(const LineKey&) const = default;
};

// The line's direction (its largest component made positive) and the foot of the perpendicular
// from the origin, quantised: collinear segments share a key unless they straddle a cell edge.
Vec3d canonical_direction(const std::array<Vec3d, 2>& s) {
  Vec3d d = s[1] - s[0];
  if (!(length(d) > 0)) return {1, 0, 0};  // a point: on no line (kept whole below)
  d = d / length(d);
  int big = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(d[a]) > std::abs(d[big])) big = a;
  return d[big] < 0 ? d * -1.0 : d;
}

LineKey line_key(const std::array<Vec3d, 2>& s, double tolerance) {
  const Vec3d d = canonical_direction(s);
  const Vec3d foot = s[0] - d * dot(s[0], d);
  const double direction_step = 1.0 / 65536.0, foot_step = 1e4 * tolerance;
  LineKey key;
  for (int a = 0; a < 3; ++a) {
    key.q[a] = std::llround(d[a] / direction_step);
    key.q[3 + a] = std::llround(foot[a] / foot_step);
  }
  return key;
}

double off_line(const Vec3d& p, const Vec3d& origin, const Vec3d& d) {
  const Vec3d r = p - origin;
  return length(r - d * dot(r, d));
}

using Parts = std::vector<std::pair<double, double>>;
using Union = std::map<double, double>;  // disjoint intervals [start, end], by start

// [lo, hi] less the union, then the union grows by [lo, hi]. O(log k) plus the intervals it
// meets, each of which it merges away: O(n log n) over n inserts, also for a line dashed
// into many disjoint pieces.
Parts subtract_and_insert(Union& covered, double lo, double hi) {
  Parts parts;
  auto it = covered.upper_bound(lo);
  if (it != covered.begin() && std::prev(it)->second > lo) --it;  // the interval holding lo
  double cursor = lo, start = lo, end = hi;
  while (it != covered.end() && it->first < hi) {
    if (it->first > cursor) parts.push_back({cursor, it->first});
    cursor = std::max(cursor, it->second);
    start = std::min(start, it->first);
    end = std::max(end, it->second);
    it = covered.erase(it);
  }
  if (cursor < hi) parts.push_back({cursor, hi});
  covered.emplace(start, end);
  return parts;
}

}  // namespace

SegmentParts uncovered_segment_parts(std::span<const std::array<Vec3d, 2>> segments, double tolerance) {
  const std::size_t n = segments.size();
  std::vector<LineKey> keys(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = line_key(segments[i], tolerance);
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return keys[a] != keys[b] ? keys[a] < keys[b] : a < b;
  });
  // (segment, part) in group order, then laid out in segment order (counting sort; a
  // segment's parts stay in their order along it).
  std::vector<std::pair<std::uint32_t, std::array<Vec3d, 2>>> found;
  found.reserve(n);
  for (std::size_t g = 0; g < n;) {
    std::size_t end = g + 1;
    while (end < n && keys[order[end]] == keys[order[g]]) ++end;
    const std::array<Vec3d, 2>& first = segments[order[g]];
    const Vec3d d = canonical_direction(first);
    Union covered;
    for (std::size_t m = g; m < end; ++m) {
      const std::uint32_t i = order[m];
      const std::array<Vec3d, 2>& s = segments[i];
      if (!(length(s[1] - s[0]) > 0) || !(length(first[1] - first[0]) > 0) ||
          !(off_line(s[0], first[0], d) <= tolerance && off_line(s[1], first[0], d) <= tolerance)) {
        found.push_back({i, s});  // near the group's line but not on it: alone
        continue;
      }
      const double ta = dot(s[0] - first[0], d), tb = dot(s[1] - first[0], d);
      if (!(ta != tb)) {
        found.push_back({i, s});
        continue;
      }
      // Along the segment itself, so that each part lies on it.
      auto at = [&](double t) { return s[0] + (s[1] - s[0]) * ((t - ta) / (tb - ta)); };
      for (const auto& [t0, t1] : subtract_and_insert(covered, std::min(ta, tb), std::max(ta, tb)))
        found.push_back({i, {at(t0), at(t1)}});
    }
    g = end;
  }
  SegmentParts out;
  out.offsets.assign(n + 1, 0);
  for (const auto& [i, part] : found) ++out.offsets[i + 1];
  for (std::size_t i = 0; i < n; ++i) out.offsets[i + 1] += out.offsets[i];
  out.parts.resize(found.size());
  std::vector<std::uint32_t> fill(out.offsets.begin(), out.offsets.end() - 1);
  for (const auto& [i, part] : found) out.parts[fill[i]++] = part;
  return out;
}

}  // namespace levelset
