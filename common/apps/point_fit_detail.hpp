// Internals the point fits share (point_distance.cpp, sheet_fit.cpp): the neighbour cap and
// the moments a plane (centroid) fit is made from. Internal to levelset_core.
#pragma once

#include <algorithm>

#include "apps/point_distance.hpp"

namespace levelset::apps::detail {

inline constexpr int kMaxNeighbors = 256;

// First and second moments of offsets v = x - p, divided into a LocalFit (d set by the caller).
struct Moments {
  Vec3d a{};
  double s[6] = {0, 0, 0, 0, 0, 0};
  int n = 0;
  void add(const Vec3d& v) {
    a += v;
    s[0] += v.x * v.x;
    s[1] += v.x * v.y;
    s[2] += v.x * v.z;
    s[3] += v.y * v.y;
    s[4] += v.y * v.z;
    s[5] += v.z * v.z;
    ++n;
  }
  LocalFit fit(double distance) const {
    LocalFit f;
    const double inv = 1.0 / std::max(n, 1);
    f.d = float(distance);
    f.ax = float(a.x * inv);
    f.ay = float(a.y * inv);
    f.az = float(a.z * inv);
    f.sxx = float(s[0] * inv);
    f.sxy = float(s[1] * inv);
    f.sxz = float(s[2] * inv);
    f.syy = float(s[3] * inv);
    f.syz = float(s[4] * inv);
    f.szz = float(s[5] * inv);
    return f;
  }
};

}  // namespace levelset::apps::detail
