// Operations: what a job does, as plain C++ over levelset_core. The request names the op and
// its parameters with the names of the CLI and the job files:
//   {"op": "evolve", "speed": "-(k1+k2)", "steps": 100, "scheme": "weno5", ...}
//   {"op": "reconstruct", "input": {"points": "<upload id>"}, "raster": {"resolution": 128}}
// The applications (evolve offset fair minmax csg reconstruct segment) run through the job
// mapping (jobs/), fed a config tree built from the JSON (so every key, range and message is
// the job file's, with places "body.evolve.speed"); redistance, cpt, mesh and measure call the
// core directly. Inputs named by upload id resolve inside the uploads directory only.
//
// run_operation: runs `request` on `input` (the session's band; null for ops that create one)
// and returns the band to commit (if any), the result JSON and the files it left in work_dir.
// Errors: levelset::Error (typed; the HTTP layer maps it), ApiError for unknown ops.
// Threading: called from a job worker inside its TBB arena.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.hpp"
#include "evolve/evolution.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::service {

struct OperationContext {
  nlohmann::json request;
  std::shared_ptr<const NarrowBand> input;           // the session's band (null: creates one)
  std::shared_ptr<const PointCloud> points;          // the session's point cloud (speed field dist), or null
  std::shared_ptr<const NarrowBand> roi;             // the session's region of influence (field roi), or null
  std::filesystem::path uploads_dir;                 // where upload ids resolve
  std::filesystem::path work_dir;                    // the job's own directory (log, artifacts)
  std::function<std::string(const std::string&)> session_band_path;  // csg operand {"session": id}
  std::function<void(const std::string& line)> log;
  std::function<void(const evolve::StepInfo& step)> on_step;
  ProgressHook progress;
  int max_formula_length = 4096;
  std::uint64_t max_domain_voxels = 0;  // grid box budget of bands built from shapes and meshes
};

struct OperationResult {
  std::optional<NarrowBand> band;  // the new state (commit, or a new session)
  nlohmann::json result = nlohmann::json::object();
  std::vector<std::string> files;  // artifacts in work_dir (names)
  bool stopped = false;            // ended early on a stop request (the state reached)
};

// The ops, and whether each needs a session's band, creates one, or leaves it unchanged.
struct OperationInfo {
  std::string name;
  enum Kind { Modifies, Creates, Reads } kind;
  bool evolution_like;  // stop ends it at a step boundary
  std::string summary;
};
const std::vector<OperationInfo>& operations();
const OperationInfo* find_operation(const std::string& name);

OperationResult run_operation(const OperationContext& context);

}  // namespace levelset::service
