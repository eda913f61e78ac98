// Test helper: the narrow band of a builtin analytic shape at a given resolution.
#pragma once

#include <memory>
#include <string>

#include "geometry/analytic_shapes.hpp"
#include "grid/build_from_sdf.hpp"

namespace levelset::test {

struct ShapeBand {
  std::unique_ptr<AnalyticShape> shape;
  NarrowBand band;
};

inline ShapeBand make_shape_band(const std::string& name, int resolution, double half_width = 3.0) {
  ShapeBand sb{make_builtin_shape(name), {}};
  SdfBuildOptions options;
  options.frame = frame_for_resolution(sb.shape->bounds(), resolution, half_width);
  const AnalyticShape* s = sb.shape.get();
  sb.band = build_from_sdf([s](const Vec3d& p) { return s->distance(p); }, s->bounds(), options).band;
  return sb;
}

}  // namespace levelset::test
