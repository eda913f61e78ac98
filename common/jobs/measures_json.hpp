// JSON forms of the measures the jobs and subcommands report (stats files, --stats).
#pragma once

#include <nlohmann/json.hpp>

#include "apps/shape_measures.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::jobs {

// Area, volume, counts, topology and closedness of a mesh.
nlohmann::json measures_json(const MeshMeasures& m);
// The shape measures: size, topology, sphere fit and mean-curvature statistics.
nlohmann::json shape_json(const apps::ShapeMeasures& m);

}  // namespace levelset::jobs
