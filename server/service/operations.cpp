#include "service/operations.hpp"

#include <system_error>

#include "core/error.hpp"
#include "distance/redistance.hpp"
#include "io/mesh_writer.hpp"
#include "jobs/job.hpp"
#include "jobs/job_context.hpp"
#include "jobs/measures_json.hpp"
#include "service/api_error.hpp"
#include "service/ids.hpp"
#include "service/json_config.hpp"
#include "surface/iso_range.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/mesh_measures.hpp"
#include "surface/surface_nets.hpp"

namespace levelset::service {

namespace fs = std::filesystem;
using nlohmann::json;

const std::vector<OperationInfo>& operations() {
  static const std::vector<OperationInfo> list = {
      {"evolve", OperationInfo::Modifies, true, "move the surface with a speed formula (thesis 4.7)"},
      {"redistance", OperationInfo::Modifies, false, "restore the distance property (fast sweeping or marching)"},
      {"offset", OperationInfo::Modifies, true, "offset surface by a signed distance (thesis 5.1.1)"},
      {"fair", OperationInfo::Modifies, true, "fairing by curvature flows (thesis 5.1.2)"},
      {"minmax", OperationInfo::Modifies, true, "min/max flow to a steady state (thesis 3.3)"},
      {"csg", OperationInfo::Modifies, true, "union, intersection, difference with another level set (thesis 3.5)"},
      {"reconstruct", OperationInfo::Creates, true, "surface from an uploaded point cloud (thesis 5.1.3)"},
      {"segment", OperationInfo::Creates, true, "shape detection in an uploaded 3D image (thesis 3.4)"},
      {"cpt", OperationInfo::Creates, false, "closest point transform of an uploaded mesh (thesis 4.5)"},
      {"mesh", OperationInfo::Reads, false, "extract the surface as a mesh artifact, with its measures"},
      {"measure", OperationInfo::Reads, false, "area, volume, genus, components of the surface"},
  };
  return list;
}

const OperationInfo* find_operation(const std::string& name) {
  for (const OperationInfo& o : operations())
    if (o.name == name) return &o;
  return nullptr;
}

namespace {

// Upload ids named anywhere in the request become hard links in the job's directory, so the
// job's inputs resolve there and nowhere else (confine_inputs).
void link_uploads(const json& v, const OperationContext& ctx) {
  if (v.is_object() || v.is_array()) {
    for (const json& item : v) link_uploads(item, ctx);
    return;
  }
  if (!v.is_string()) return;
  const std::string id = v.get<std::string>();
  if (!is_valid_id(id, 'u')) return;
  const fs::path from = ctx.uploads_dir / id, to = ctx.work_dir / id;
  std::error_code ec;
  if (!fs::exists(from, ec)) throw not_found("upload", id);
  if (fs::exists(to, ec)) return;
  fs::create_hard_link(from, to, ec);
  if (ec) fs::copy_file(from, to, ec);
  if (ec) throw Error(ErrorCode::IoError, id, "cannot stage the upload for the job: " + ec.message());
}

jobs::JobOptions job_options(const OperationContext& ctx, std::optional<NarrowBand>& final_band) {
  jobs::JobOptions o;
  o.output_dir = ctx.work_dir.string();
  o.base_dir = ctx.work_dir.string();
  o.name = "job";
  o.confine_inputs = true;
  o.progress = ctx.progress;
  o.input_band = ctx.input;
  o.points = ctx.points;
  o.roi = ctx.roi;
  o.max_domain_voxels = ctx.max_domain_voxels;
  o.on_step = ctx.on_step;
  if (ctx.log) o.log = [log = ctx.log](std::string_view line) { log(std::string(line)); };
  o.band_sink = [&final_band](const NarrowBand& band, std::string_view suffix) {
    if (suffix.empty()) final_band = band;
  };
  return o;
}

void check_formulas(const json& request, int max_length) {
  for (const char* key : {"speed", "formula", "cost"}) {
    if (request.contains(key) && request[key].is_string() && int(request[key].get<std::string>().size()) > max_length)
      throw ApiError(413, "payload_too_large",
                     std::string("body.") + key + ": the formula has " +
                         std::to_string(request[key].get<std::string>().size()) + " characters, more than max_formula_length (" +
                         std::to_string(max_length) + ")");
  }
}

// An application of jobs/ run on a config tree built from the request.
OperationResult run_application(const OperationContext& ctx, const std::string& op) {
  json body = ctx.request;
  body.erase("op");
  config::Set root;
  add_word(root, "job", op);
  config::Set app;
  for (const auto& [key, value] : body.items()) {
    if (key == "input" || key == "raster") {
      add_entry(root, key, value, "body." + key);
    } else if (key == "queue" || key == "name" || key == "output") {
      continue;
    } else if (op == "csg" && key == "operation") {
      add_entry(app, "op", value, "body.operation");
    } else if (op == "csg" && key == "operand" && value.is_object() && value.contains("session")) {
      if (!value["session"].is_string() || !ctx.session_band_path)
        throw Error(ErrorCode::InvalidArgument, "body.operand.session", "expected a session id");
      const fs::path band = ctx.session_band_path(value["session"].get<std::string>());
      std::error_code ec;
      const fs::path staged = ctx.work_dir / "operand.lsg";
      fs::create_hard_link(band, staged, ec);
      if (ec) fs::copy_file(band, staged, ec);
      add_entry(app, "operand", json{{"lsg", "operand.lsg"}}, "body.operand");
    } else {
      add_entry(app, key, value, "body." + key);
    }
  }
  config::Entry set_entry;
  set_entry.key = op;
  set_entry.is_set = true;
  set_entry.set = std::move(app);
  set_entry.override_text = "body";
  root.entries.push_back(std::move(set_entry));
  config::Entry output;
  output.key = "output";
  output.is_set = true;
  add_word(output.set, "mesh", "none");
  add_word(output.set, "lsg", "no");
  root.entries.push_back(std::move(output));

  OperationResult r;
  std::optional<NarrowBand> band;
  const jobs::JobResult jr = jobs::run_job(root, job_options(ctx, band));
  r.band = std::move(band);
  r.result = jr.stats;
  r.result.erase("outputs");
  r.stopped = ctx.progress.stop_requested();
  return r;
}

json surface_measures(const SurfaceResult& s) { return jobs::measures_json(measure_mesh(s.mesh)); }

SurfaceResult extract(const NarrowBand& band, const json& request) {
  const double iso = request.value("iso", 0.0);
  check_iso_in_band(band, iso, "body.iso");
  const std::string method = request.value("method", "mc");
  if (method == "nets") {
    SurfaceNetsOptions o;
    o.iso = iso;
    return surface_nets(band, o);
  }
  if (method != "mc") throw Error(ErrorCode::InvalidArgument, "body.method", "expected mc or nets");
  MarchingCubesOptions o;
  o.iso = iso;
  return marching_cubes(band, o);
}

OperationResult run_redistance(const OperationContext& ctx) {
  RedistanceOptions o;
  const std::string method = ctx.request.value("method", "sweep");
  if (method != "sweep" && method != "march") throw Error(ErrorCode::InvalidArgument, "body.method", "expected sweep or march");
  o.method = method == "march" ? RedistanceMethod::March : RedistanceMethod::Sweep;
  o.order = ctx.request.value("order", 2);
  o.half_width = ctx.request.value("band", 0.0);
  o.progress = ctx.progress;
  RedistanceResult rr = redistance(*ctx.input, o);
  OperationResult r;
  r.result = {{"method", method},
              {"interface_voxels", rr.interface_voxels},
              {"sweep_iterations", rr.sweep_iterations},
              {"march_rounds", rr.march_rounds},
              {"seconds", rr.seconds},
              {"active_voxels", rr.band.active_voxel_count()}};
  r.band = std::move(rr.band);
  return r;
}

// A band from an input set ({"mesh": upload} for cpt, {"shape": name} for primitives).
OperationResult run_input_band(const OperationContext& ctx) {
  config::Set root;
  if (ctx.request.contains("input")) add_entry(root, "input", ctx.request["input"], "body.input");
  if (ctx.request.contains("raster")) add_entry(root, "raster", ctx.request["raster"], "body.raster");
  std::optional<NarrowBand> unused;
  jobs::JobOptions options = job_options(ctx, unused);
  options.input_band.reset();
  jobs::JobContext job(root, options);
  static const config::Set empty;
  const config::Entry* input = root.find("input");
  OperationResult r;
  r.band = job.input_band(input != nullptr && input->is_set ? input->set : empty);
  r.result = {{"active_voxels", r.band->active_voxel_count()}, {"voxel_size", r.band->voxel_size()}};
  return r;
}

OperationResult run_mesh(const OperationContext& ctx, bool write) {
  const SurfaceResult s = extract(*ctx.input, ctx.request);
  OperationResult r;
  r.result = surface_measures(s);
  if (write) {
    const std::string format = ctx.request.value("format", "ply");
    const std::string file = "surface." + format;
    write_mesh(s.mesh, ctx.work_dir / file);
    r.files.push_back(file);
  }
  return r;
}

}  // namespace

OperationResult run_operation(const OperationContext& ctx) {
  if (!ctx.request.is_object() || !ctx.request.contains("op") || !ctx.request["op"].is_string())
    throw ApiError(400, "bad_request", "the body needs \"op\": one of the operations (GET /api/v1 lists them)");
  const std::string op = ctx.request["op"].get<std::string>();
  const OperationInfo* info = find_operation(op);
  if (info == nullptr) throw unprocessable("body.op", "unknown operation '" + op.substr(0, 40) + "'");
  check_formulas(ctx.request, ctx.max_formula_length);
  if (info->kind != OperationInfo::Creates && !ctx.input)
    throw unprocessable("body.op", "'" + op + "' works on a session's band");
  link_uploads(ctx.request, ctx);
  if (op == "redistance") return run_redistance(ctx);
  if (op == "cpt") return run_input_band(ctx);
  if (op == "mesh") return run_mesh(ctx, true);
  if (op == "measure") return run_mesh(ctx, false);
  return run_application(ctx, op);
}

}  // namespace levelset::service
