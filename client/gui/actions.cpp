// Actions for the server, sessions and jobs (the thesis panel's are in actions_thesis.cpp).
#include "actions.hpp"

#include "lib/client_error.hpp"

namespace levelset::gui {

using nlohmann::json;
using client::Api;

namespace {

std::string session_path(const std::string& id) { return "/api/v1/sessions/" + Api::encode(id); }
}  // namespace

std::shared_ptr<const Api> Actions::api_or_complain() {
  auto api = c_.api.get();
  if (!api) c_.state.add_error("not connected: give a server URL and press Connect");
  return api;
}

void Actions::report(const std::exception& e, const std::string& what) {
  std::string text = what + ": " + describe_error(e);
  FormulaError fe;
  if (const auto* ce = dynamic_cast<const client::ClientError*>(&e)) {
    const json& d = ce->details();
    const std::string field = d.is_object() ? d.value("field", "") : "";
    if ((field == "speed" || field == "formula") && d.value("column", 0) > 0) {
      fe.column = d.value("column", 0);
      fe.message = d.value("message", ce->message());
    }
  }
  c_.inbox.post([text, fe](AppState& s) {
    s.add_error(text);
    if (fe.column > 0) {
      s.formula_error = fe;
      s.formula_error.formula = s.panel.formula;
    }
  });
}

void Actions::connect(const std::string& server, const std::string& token) {
  try {
    c_.api.set(std::make_shared<const Api>(server, token));
    if (server != c_.state.server) {  // another server: nothing shown belongs to it
      select_session("");
      c_.state.sessions = json::array();
      c_.state.jobs.clear();
      c_.state.mesh_upload.clear();
      c_.state.points_upload.clear();
      c_.state.before_file.clear();
    }
    c_.state.server = server;
    c_.state.token = token;
    c_.state.connected = false;
    c_.state.banner.clear();
    c_.state.add_log("connecting to " + server);
    c_.monitor.poke();
  } catch (const std::exception& e) {
    c_.state.add_error("connect: " + describe_error(e));
  }
}

void Actions::select_session(const std::string& id) {
  c_.state.current = id;
  c_.state.session = json();
  c_.state.snapshots = json::array();
  c_.state.formula_error = {};
}

// A job was accepted: list it, follow its events, and show what it creates when it ends.
void Actions::adopt_job(const json& job, bool select_created, EventStreams::JobThen then) {
  JobRow row;
  row.id = job.value("id", "");
  row.op = job.value("op", "");
  row.session = job.contains("session") && job["session"].is_string() ? job["session"].get<std::string>() : "";
  row.state = job.value("state", "queued");
  row.mine = true;
  c_.inbox.post([row, select_created](AppState& s) {
    bool known = false;
    for (JobRow& j : s.jobs)
      if (j.id == row.id) j.mine = known = true;
    if (!known) s.jobs.push_back(row);
    if (select_created) s.select_after_job = row.id;
    s.add_log("job " + row.id + " (" + row.op + ") queued");
  });
  c_.inbox.post([this, id = row.id, then = std::move(then)](AppState&) { c_.streams.follow_job(id, then); });
}

void Actions::show_session(const json& description, const std::string& log_line, bool select) {
  c_.inbox.post([description, log_line, select](AppState& s) {
    if (select) s.current = description.value("id", "");
    if (s.current == description.value("id", "")) s.session = description;
    if (!log_line.empty()) s.add_log(log_line);
  });
}

void Actions::submit_job(const json& body, const std::string& what) {
  auto api = api_or_complain();
  if (!api) return;
  if (c_.state.current.empty()) {
    c_.state.add_error(what + ": no session (load a mesh and compute its distance field, or create one)");
    return;
  }
  const std::string path = session_path(c_.state.current) + "/jobs";
  c_.commands.post([this, api, path, body, what] {
    try {
      adopt_job(api->post(path, body), false);
    } catch (const std::exception& e) {
      report(e, what);
    }
  });
}

void Actions::create_primitive() {
  auto api = api_or_complain();
  if (!api) return;
  const json body = {{"primitive", c_.state.panel.primitive},
                     {"raster", {{"resolution", c_.state.panel.resolution}, {"band", c_.state.panel.band}}}};
  c_.commands.post([this, api, body] {
    try {
      const json s = api->post("/api/v1/sessions", body);
      c_.inbox.post([s](AppState& st) {
        st.current = s.value("id", "");
        st.session = s;
        st.add_log("session " + st.current + " created from " + s["source"].value("primitive", std::string("?")));
      });
    } catch (const std::exception& e) {
      report(e, "create session");
    }
  });
}

void Actions::rename_session() {
  auto api = api_or_complain();
  if (!api || c_.state.current.empty()) return;
  const std::string path = session_path(c_.state.current);
  const json body = {{"name", c_.state.panel.new_name}};
  c_.commands.post([this, api, path, body] {
    try {
      const json s = api->patch(path, body);
      c_.inbox.post([s](AppState& st) {
        if (st.current == s.value("id", "")) st.session = s;
      });
    } catch (const std::exception& e) {
      report(e, "rename");
    }
  });
}

void Actions::delete_session(const std::string& id) {
  auto api = api_or_complain();
  if (!api || id.empty()) return;
  c_.commands.post([this, api, id] {
    try {
      api->del(session_path(id));
      c_.inbox.post([id](AppState& s) {
        if (s.current == id) s.current.clear(), s.session = json();
        s.add_log("session " + id + " deleted");
      });
      c_.monitor.poke();
    } catch (const std::exception& e) {
      report(e, "delete " + id);
    }
  });
}

void Actions::snapshot() {
  auto api = api_or_complain();
  if (!api || c_.state.current.empty()) return;
  const std::string path = session_path(c_.state.current) + "/snapshots";
  const json body = {{"name", c_.state.panel.snapshot_name}};
  c_.commands.post([this, api, path, body] {
    try {
      const json snap = api->post(path, body);
      c_.inbox.post([snap](AppState& s) { s.add_log("snapshot " + snap.value("id", "") + " taken"); });
    } catch (const std::exception& e) {
      report(e, "snapshot");
    }
  });
  refresh_snapshots();
}

void Actions::refresh_snapshots() {
  auto api = c_.api.get();
  if (!api || c_.state.current.empty()) return;
  const std::string id = c_.state.current;
  c_.commands.post([this, api, id] {
    try {
      const json list = api->get(session_path(id) + "/snapshots").value("snapshots", json::array());
      c_.inbox.post([id, list](AppState& s) {
        if (s.current == id) s.snapshots = list;
      });
    } catch (const std::exception& e) {
      report(e, "snapshots");
    }
  });
}

void Actions::restore(const std::string& snapshot_id) {
  auto api = api_or_complain();
  if (!api || c_.state.current.empty()) return;
  const std::string path = session_path(c_.state.current) + "/snapshots/" + Api::encode(snapshot_id) + "/restore";
  c_.commands.post([this, api, path, snapshot_id] {
    try {
      const json s = api->post(path, json::object());
      c_.inbox.post([s, snapshot_id](AppState& st) {
        if (st.current == s.value("id", "")) st.session = s;
        st.add_log("restored snapshot " + snapshot_id);
      });
    } catch (const std::exception& e) {
      report(e, "restore");
    }
  });
}

void Actions::cancel_job(const std::string& job_id) {
  auto api = api_or_complain();
  if (!api) return;
  c_.commands.post([this, api, job_id] {
    try {
      api->del("/api/v1/jobs/" + Api::encode(job_id));
    } catch (const std::exception& e) {
      report(e, "cancel " + job_id);
    }
  });
}

void Actions::stop_job(const std::string& job_id) {
  auto api = api_or_complain();
  if (!api) return;
  c_.commands.post([this, api, job_id] {
    try {
      api->post("/api/v1/jobs/" + Api::encode(job_id) + "/stop", json::object());
    } catch (const std::exception& e) {
      report(e, "stop " + job_id);
    }
  });
}

void Actions::stop_evolution() {
  for (const JobRow& j : c_.state.jobs)
    if (j.session == c_.state.current && (j.state == "running" || j.state == "queued")) stop_job(j.id);
}

void Actions::request_screenshot() { screenshot_request = c_.state.panel.screenshot_file; }

void Actions::quit() { c_.state.quit = true; }

}  // namespace levelset::gui
