// AppState: everything the window shows, owned by the UI thread. Other threads never touch it:
// they post closures to the Inbox (net_worker.hpp) that the UI thread applies between frames.
// PanelState is the part the controls edit and the settings file remembers.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace levelset::gui {

// The controls' values (thesis table 4.1 letters in the comments).
struct PanelState {
  int shading = 4;                   // A: none points wireframe flat smooth
  float band = 3;                    // B: narrow band half-width, voxels
  bool roi = false;                  // B: the computed field becomes the shown session's region of influence
  int resolution = 96;               // B: voxels along the longest side
  std::string mesh_file;             // C: the mesh to load
  std::string save_file = "surface.ply";  // C: where "Save mesh" writes
  int field = 0;                     // D: none points vectors curvature boundary roi(5)
  bool whole_range = true;           // E: show every value of the band
  float range_min = -0.05f, range_max = 0.05f;  // E
  float iso = 0;                     // F
  std::string formula = "-H";        // G
  bool use_time = false;             // G: evolve for a time instead of a step count
  int steps = 20;                    // G
  float time = 0.01f;                // G
  int scheme = 0;                    // G: godunov eno2 weno5
  int cloud = 1;                     // I: none points
  float cloud_size = 2;              // I
  std::string points_file;           // J
  std::string screenshot_file = "levelset-gui.png";  // K
  // Beyond the thesis
  int slice = 0;                     // none x y z
  float slice_position = 0.5f;
  bool volume = false;
  int view_mode = 0;                 // auto local remote
  int triangle_budget = 2000000;     // auto: remote frames above it
  std::string primitive = "knot";
  std::string job_file;
  std::string new_name;
  std::string snapshot_name;
};

struct JobRow {
  std::string id, op, session, state, stage;
  double fraction = 0;
  bool mine = false;  // submitted from this window
};

// A server error under the formula box: the server's column (1-based) and its message.
struct FormulaError {
  std::string formula;  // the text it was about
  int column = 0;
  std::string message;
};

struct AppState {
  PanelState panel;
  std::string server, token;
  bool connected = false;
  bool ever_connected = false;
  std::string banner;               // non-empty while the connection is lost
  std::vector<std::string> errors;  // readable server / local errors, newest last
  FormulaError formula_error;
  std::deque<std::string> log;      // the live log (job log lines, notices)

  nlohmann::json sessions = nlohmann::json::array();  // GET /sessions
  std::string current;              // the session shown
  nlohmann::json session;           // its description (GET /sessions/{id}, SSE "state")
  nlohmann::json snapshots = nlohmann::json::array();
  std::vector<JobRow> jobs;
  std::string mesh_upload;          // C: the uploaded mesh B computes from
  std::string before_file;          // C: the session shown before a loaded mesh file replaced it
  std::string points_upload;        // J
  std::string select_after_job;     // a job creating a session: show that session when it ends

  // The view
  float iso_shown = 0;              // F: the iso value of the surface shown (set by Extract)
  bool remote = false;              // remote frames (else local geometry)
  std::uint64_t mesh_triangles = 0;
  std::int64_t mesh_version = -1;   // the session version the local mesh shows
  std::uint64_t frames_received = 0;
  bool band_loaded = false;         // the band of the shown session is here (D's overlays)
  bool roi_loaded = false;          // its region of influence is here (D's Point(ROI))
  std::size_t cloud_points = 0;     // the point cloud shown (I), local or the session's
  double fps = 0;
  bool quit = false;
  int daemon_pid = 0;               // the embedded levelsetd (0: none)

  void add_log(const std::string& line) {
    log.push_back(line);
    while (log.size() > 500) log.pop_front();
  }
  void add_error(const std::string& text) {
    errors.push_back(text);
    if (errors.size() > 20) errors.erase(errors.begin());
    add_log("error: " + text);
  }
  int version() const { return session.is_object() ? session.value("version", 0) : 0; }
  bool job_running() const {
    for (const JobRow& j : jobs)
      if (j.mine && (j.state == "queued" || j.state == "running")) return true;
    return false;
  }
};

}  // namespace levelset::gui
