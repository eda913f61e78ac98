// JSON forms of the measures the jobs and subcommands report (stats files, --stats).
#pragma once

#include <nlohmann/json.hpp>

#include <vector>

#include "apps/reconstruction.hpp"
#include "apps/shape_measures.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::jobs {

// Area, volume, counts, topology and closedness of a mesh.
nlohmann::json measures_json(const MeshMeasures& m);
// The shape measures: size, topology, sphere fit and mean-curvature statistics.
nlohmann::json shape_json(const apps::ShapeMeasures& m);
// The reconstruction's levels: voxel size, steps, convergence, voxels, seconds per phase.
nlohmann::json stages_json(const std::vector<apps::ReconstructionStage>& stages);

}  // namespace levelset::jobs
