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

nlohmann::json stages_json(const std::vector<apps::ReconstructionStage>& stages) {
  nlohmann::json levels = nlohmann::json::array();
  for (const apps::ReconstructionStage& s : stages)
    levels.push_back({{"level", s.level},
                      {"voxel_size", s.voxel_size},
                      {"steps", s.steps},
                      {"shell_offset", s.shell_offset},
                      {"converged", s.converged},
                      {"last_change", s.last_change},
                      {"noise", s.noise},
                      {"height_noise", s.height_noise},
                      {"smoothing", s.smoothing},
                      {"second_order", s.second_order},
                      {"height_fits", s.height_fits},
                      {"height_neighbors", s.height_neighbors},
                      {"refused_flips", s.refused_flips},
                      {"dropped_components", s.dropped_components},
                      {"buried_points", s.buried_points},
                      {"carved_regions", s.carved_regions},
                      {"pierced_regions", s.pierced_regions},
                      {"webs_cut", s.webs_cut},
                      {"sheets_cut", s.sheets_cut},
                      {"web_tunnels", s.web_tunnels},
                      {"refit_bricks", s.refit_bricks},
                      {"widened_bricks", s.widened_bricks},
                      {"facing_fits", s.facing_fits},
                      {"carved_voxels", s.carved_voxels},
                      {"active_voxels", s.active_voxels},
                      {"fit_voxels", s.fit_voxels},
                      {"fit_models", s.fit_models},
                      {"seconds", s.seconds},
                      {"seconds_start", s.seconds_start},
                      {"seconds_fit", s.seconds_fit},
                      {"seconds_flow", s.seconds_flow},
                      {"seconds_redistance", s.seconds_redistance}});
  return levels;
}

}  // namespace levelset::jobs
