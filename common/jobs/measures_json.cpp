#include "jobs/measures_json.hpp"

namespace levelset::jobs {

nlohmann::json measures_json(const MeshMeasures& m) {
  return {{"area", m.area},
          {"volume", m.volume},
          {"vertices", m.vertices},
          {"triangles", m.faces},
          {"components", m.components},
          {"genus", m.genus},
          {"euler_characteristic", m.euler_characteristic},
          {"watertight", m.watertight},
          {"manifold", m.manifold},
          {"oriented", m.oriented},
          {"bounds_min", {m.bounds.min.x, m.bounds.min.y, m.bounds.min.z}},
          {"bounds_max", {m.bounds.max.x, m.bounds.max.y, m.bounds.max.z}}};
}

nlohmann::json shape_json(const apps::ShapeMeasures& m) {
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

}  // namespace levelset::jobs
