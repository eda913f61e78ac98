// Actions: what every control does, as plain functions the panel's buttons, the keyboard and
// --script all call. Each reads the panel's values on the UI thread, then does its work
// through the daemon's API on a worker thread and reports back through the Inbox (never
// waiting here). Server errors become readable lines in the error box; a formula error keeps
// the server's column for the caret under the formula box.
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include "app_state.hpp"
#include "connection_monitor.hpp"
#include "event_streams.hpp"
#include "io/triangle_mesh.hpp"
#include "net_worker.hpp"

namespace levelset::gui {

class SceneView;

struct ActionContext {
  AppState& state;
  ApiHolder& api;
  Inbox& inbox;
  Worker& commands;  // requests that change things, in order
  Worker& fetches;   // meshes, bands, view updates (never behind a long upload)
  EventStreams& streams;
  ConnectionMonitor& monitor;
};

class Actions {
 public:
  explicit Actions(ActionContext c) : c_(c) {}

  // Beyond the thesis: server, sessions, jobs, job files.
  void connect(const std::string& server, const std::string& token);
  void select_session(const std::string& id);
  void create_primitive();
  void rename_session();
  void delete_session(const std::string& id);
  void snapshot();
  void refresh_snapshots();
  void restore(const std::string& snapshot_id);
  void cancel_job(const std::string& job_id);
  void stop_job(const std::string& job_id);
  void run_job_file();

  // Thesis table 4.1.
  void load_mesh();          // C: upload the mesh file (and show it)
  void save_mesh();          // C: download the surface at the iso value
  void compute_distance();   // B: a session from the uploaded mesh (CPT) with the band width; with
                             //    the ROI option its field becomes the shown session's region of influence
  void store_roi();          // B: the shown session's own field becomes its region of influence
  void clear_roi();          // B: the shown session has no region of influence any more
  void extract();            // F: show the isosurface at the entered value
  void evolve();             // G: start
  void stop_evolution();     // G: stop the running evolution, keeping the state reached
  void redistance();         // H
  void load_points();        // J: upload a point cloud and show it with the session
  void reconstruct();        // beyond: a session reconstructed from the uploaded points
  void request_screenshot(); // K
  void quit();               // L

  // The local copy of the mesh file C loaded (SceneView gets it through the inbox).
  std::function<void(TriangleMesh)> on_local_mesh;
  std::function<void(PointCloud)> on_local_points;
  std::string screenshot_request;  // a path the frame loop writes after drawing

 private:
  void submit_job(const nlohmann::json& body, const std::string& what);
  void adopt_job(const nlohmann::json& job, bool select_created, EventStreams::JobThen then = {});
  // A session's new description (from a worker thread) replaces the one shown if it is that
  // session's, or is shown anyway with `select`.
  void show_session(const nlohmann::json& description, const std::string& log_line, bool select = false);
  void report(const std::exception& e, const std::string& what);
  std::shared_ptr<const client::Api> api_or_complain();
  ActionContext c_;
};

}  // namespace levelset::gui
