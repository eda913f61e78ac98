// The thesis panel's actions (table 4.1, B C G H J) and job files: Actions, continued.
#include <filesystem>

#include "actions.hpp"
#include "config/config_file.hpp"
#include "core/file_io.hpp"
#include "io/mesh_reader.hpp"
#include "io/point_cloud_reader.hpp"
#include "lib/client_error.hpp"
#include "lib/job_inputs.hpp"

namespace levelset::gui {

namespace fs = std::filesystem;
using nlohmann::json;
using client::Api;

namespace {
const char* const kSchemes[] = {"godunov", "eno2", "weno5"};
std::string session_path(const std::string& id) { return "/api/v1/sessions/" + Api::encode(id); }
}  // namespace

void Actions::load_mesh() {
  auto api = api_or_complain();
  if (!api) return;
  const std::string file = c_.state.panel.mesh_file;
  c_.commands.post([this, api, file] {
    try {
      const json u = api->upload(file, client::upload_format_of(file));
      c_.inbox.post([u, file](AppState& s) {
        s.mesh_upload = u.value("id", "");
        s.add_log("uploaded " + file + " as " + s.mesh_upload);
      });
      // Shown at once, before its distance field exists (the thesis displays the loaded mesh).
      TriangleMesh mesh = read_mesh(file).mesh;
      if (on_local_mesh) on_local_mesh(std::move(mesh));
    } catch (const std::exception& e) {
      report(e, "load mesh " + file);
    }
  });
}

void Actions::compute_distance() {
  auto api = api_or_complain();
  if (!api) return;
  if (c_.state.mesh_upload.empty()) {
    c_.state.add_error("compute distance field: load a mesh first (C)");
    return;
  }
  const PanelState& p = c_.state.panel;
  // The ROI option (thesis B): the field computed becomes the region of influence of the session
  // shown (the surface being evolved; or the one shown before C's mesh file replaced it), which
  // is shown again, and the session made for it is removed; with none it is the new session's own.
  const std::string target = !p.roi ? "" : !c_.state.current.empty() ? c_.state.current : c_.state.before_file;
  json body = {{"upload", c_.state.mesh_upload},
               {"name", fs::path(p.mesh_file).stem().string() + (p.roi ? " (roi)" : "")},
               {"raster", {{"resolution", p.resolution}, {"band", p.band}}}};
  EventStreams::JobThen then;
  if (p.roi) {
    then = [this, target](const Api& a, const json& job) {
      const json result = job.value("result", json::object());
      const std::string made = result.is_object() ? result.value("session", "") : "";
      if (made.empty()) throw std::runtime_error("the job made no session");
      if (target.empty()) {
        show_session(a.put(session_path(made) + "/roi", json::object()), "region of influence of " + made + " stored");
        return;
      }
      show_session(a.put(session_path(target) + "/roi", {{"session", made}}),
                   "region of influence of " + target + " computed from " + made, true);
      a.del(session_path(made));
    };
  }
  c_.commands.post([this, api, body, target, then] {
    try {
      int status = 0;
      const json answer = api->post("/api/v1/sessions", body, &status);
      if (status == 201) {  // made at once (a band upload)
        if (then) then(*api, {{"result", {{"session", answer.value("id", "")}}}});
        if (!then || target.empty())
          c_.inbox.post([answer](AppState& s) { s.current = answer.value("id", ""), s.session = answer; });
      } else {
        adopt_job(answer, target.empty(), then);
      }
    } catch (const std::exception& e) {
      report(e, "compute distance field");
    }
  });
}

void Actions::store_roi() {
  auto api = api_or_complain();
  if (!api) return;
  if (c_.state.current.empty()) return c_.state.add_error("store region of influence: no session shown");
  const std::string id = c_.state.current;
  c_.commands.post([this, api, id] {
    try {
      show_session(api->put(session_path(id) + "/roi", json::object()), "region of influence of " + id + " stored");
    } catch (const std::exception& e) {
      report(e, "store region of influence");
    }
  });
}

void Actions::clear_roi() {
  auto api = api_or_complain();
  if (!api || c_.state.current.empty()) return;
  const std::string id = c_.state.current;
  c_.commands.post([this, api, id] {
    try {
      api->del(session_path(id) + "/roi");
      show_session(api->get(session_path(id)), "region of influence of " + id + " removed");
    } catch (const std::exception& e) {
      report(e, "clear region of influence");
    }
  });
}

void Actions::save_mesh() {
  auto api = api_or_complain();
  if (!api || c_.state.current.empty()) return;
  const std::string file = c_.state.panel.save_file;
  std::string format = fs::path(file).extension().string();
  if (!format.empty()) format = format.substr(1);
  const std::string path = session_path(c_.state.current) + "/mesh?iso=" + std::to_string(c_.state.panel.iso) +
                           "&format=" + Api::encode(format.empty() ? "ply" : format);
  c_.commands.post([this, api, path, file] {
    try {
      const std::uint64_t bytes = api->download(path, file);
      c_.inbox.post([file, bytes](AppState& s) { s.add_log("saved " + file + " (" + std::to_string(bytes) + " bytes)"); });
    } catch (const std::exception& e) {
      report(e, "save mesh " + file);
    }
  });
}

void Actions::extract() {
  c_.state.iso_shown = c_.state.panel.iso;
  c_.state.add_log("isosurface at " + std::to_string(c_.state.iso_shown));
}

void Actions::evolve() {
  const PanelState& p = c_.state.panel;
  json body = {{"op", "evolve"}, {"speed", p.formula}, {"scheme", kSchemes[std::clamp(p.scheme, 0, 2)]}};
  if (p.use_time) {
    body["time"] = p.time;
  } else {
    body["steps"] = p.steps;
  }
  c_.state.formula_error = {};
  submit_job(body, "evolve");
}

void Actions::redistance() { submit_job({{"op", "redistance"}}, "correct distance field"); }

void Actions::load_points() {
  auto api = api_or_complain();
  if (!api) return;
  const std::string file = c_.state.panel.points_file, session = c_.state.current;
  c_.commands.post([this, api, file, session] {
    try {
      const json u = api->upload(file, client::upload_format_of(file));
      const std::string id = u.value("id", "");
      if (!session.empty()) api->patch(session_path(session), {{"points", id}});
      c_.inbox.post([id, file](AppState& s) {
        s.points_upload = id;
        s.add_log("uploaded points " + file + " as " + id);
      });
      PointCloud points = read_point_cloud(file).cloud;
      if (on_local_points) on_local_points(std::move(points));
    } catch (const std::exception& e) {
      report(e, "load point cloud " + file);
    }
  });
}

void Actions::reconstruct() {
  auto api = api_or_complain();
  if (!api) return;
  if (c_.state.points_upload.empty()) {
    c_.state.add_error("reconstruct: load a point cloud first (J)");
    return;
  }
  const json body = {{"upload", c_.state.points_upload},
                     {"raster", {{"resolution", c_.state.panel.resolution}, {"band", c_.state.panel.band}}}};
  c_.commands.post([this, api, body] {
    try {
      adopt_job(api->post("/api/v1/sessions", body), true);
    } catch (const std::exception& e) {
      report(e, "reconstruct");
    }
  });
}

// A job file, as `levelsetctl run` sends it: parsed here, its input files uploaded and named by
// their upload ids, the text posted to /jobs; its final band becomes a session shown when done.
void Actions::run_job_file() {
  auto api = api_or_complain();
  if (!api) return;
  const std::string file = c_.state.panel.job_file;
  c_.commands.post([this, api, file] {
    try {
      const std::string text = read_file_bytes(file, config::Limits{}.max_bytes);
      config::ParseOptions po;
      po.name = file;
      const config::Set root = config::parse_config(text, po);
      json sets = json::array();
      for (const client::InputFile& f : client::job_input_files(root, fs::path(file).parent_path().string())) {
        if (f.path.empty()) continue;
        sets.push_back(f.key + "=" + api->upload(f.path, client::upload_format_of(f.path)).value("id", ""));
      }
      const json body = {{"config", text}, {"set", sets}, {"name", fs::path(file).filename().string()}};
      adopt_job(api->post("/api/v1/jobs", body), true);
    } catch (const std::exception& e) {
      report(e, "run job file " + file);
    }
  });
}

}  // namespace levelset::gui
