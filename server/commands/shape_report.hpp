// The shape measures (apps/shape_measures.hpp) as JSON and as one summary line, for the
// --stats output of the shape-operation subcommands (offset, fair, minmax, csg).
#pragma once

#include <cstdio>

#include <nlohmann/json.hpp>

#include "apps/shape_measures.hpp"
#include "jobs/measures_json.hpp"

namespace levelset::cli {

using jobs::shape_json;


inline void print_shape(std::FILE* out, const char* label, const apps::ShapeMeasures& m) {
  std::fprintf(out, "  %s: area %.6g volume %.6g components %llu genus %g; sphere fit r %.6g rms %.3g; H mean %.4g var %.4g max|H| %.4g\n",
               label, m.area, m.volume, (unsigned long long)m.components, m.genus, m.sphere.radius,
               m.sphere.rms_deviation, m.curvature.mean, m.curvature.variance, m.curvature.max_abs);
}

}  // namespace levelset::cli
