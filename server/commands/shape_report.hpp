// The shape measures (apps/shape_measures.hpp) as JSON and as one summary line, for the
// --stats output of the shape-operation subcommands (offset, fair, minmax, csg).
#pragma once

#include <cstdio>

#include <nlohmann/json.hpp>

#include "apps/shape_measures.hpp"

namespace levelset::cli {

inline nlohmann::json shape_json(const apps::ShapeMeasures& m) {
  return {{"area", m.area},
          {"volume", m.volume},
          {"components", m.components},
          {"genus", m.genus},
          {"vertices", m.vertices},
          {"triangles", m.triangles},
          {"watertight", m.watertight},
          {"sphere_fit",
           {{"center", {m.sphere.center.x, m.sphere.center.y, m.sphere.center.z}},
            {"radius", m.sphere.radius},
            {"rms_deviation", m.sphere.rms_deviation},
            {"max_deviation", m.sphere.max_deviation}}},
          {"mean_curvature",
           {{"mean", m.curvature.mean}, {"variance", m.curvature.variance}, {"max_abs", m.curvature.max_abs}}}};
}

inline void print_shape(std::FILE* out, const char* label, const apps::ShapeMeasures& m) {
  std::fprintf(out, "  %s: area %.6g volume %.6g components %llu genus %g; sphere fit r %.6g rms %.3g; H mean %.4g var %.4g max|H| %.4g\n",
               label, m.area, m.volume, (unsigned long long)m.components, m.genus, m.sphere.radius,
               m.sphere.rms_deviation, m.curvature.mean, m.curvature.variance, m.curvature.max_abs);
}

}  // namespace levelset::cli
