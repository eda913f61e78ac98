// Axis-aligned bounding box in world units. Empty when min > max on any axis.
#pragma once

#include <limits>

#include "core/vec3.hpp"

namespace levelset {

struct BBox {
  Vec3d min{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
            std::numeric_limits<double>::infinity()};
  Vec3d max{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
            -std::numeric_limits<double>::infinity()};

  bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  void extend(const Vec3d& p) { min = levelset::min(min, p); max = levelset::max(max, p); }
  Vec3d extent() const { return empty() ? Vec3d{} : max - min; }
  Vec3d center() const { return (min + max) * 0.5; }
  double longest_side() const {
    Vec3d e = extent();
    return e.x > e.y ? (e.x > e.z ? e.x : e.z) : (e.y > e.z ? e.y : e.z);
  }
};

}  // namespace levelset
