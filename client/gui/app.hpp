// App: one window of levelset-gui. It owns the state, the network threads (workers, connection
// monitor, event streams, frame stream) and the two view modes, and draws one frame at a time:
// apply what the network threads sent, lay out the panel (ImGui), draw the scene (local
// geometry with levelset_render, or the remote frame as a texture), then the panel over it.
// The window's GL context must be current on the calling thread for the App's whole life.
#pragma once

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "actions.hpp"
#include "app_state.hpp"
#include "camera_control.hpp"
#include "connection_monitor.hpp"
#include "event_streams.hpp"
#include "frame_texture.hpp"
#include "net_worker.hpp"
#include "panels.hpp"
#include "remote_view.hpp"
#include "scene_view.hpp"
#include "settings_store.hpp"
#include "view_loader.hpp"
#include "widget_registry.hpp"

struct GLFWwindow;

namespace levelset::gui {

class ScriptRunner;

class App {
 public:
  App(GLFWwindow* window, const Settings& settings);
  ~App();

  // One frame; false once the window should close. `script` (optional) injects input before
  // the frame and runs its next commands after it.
  bool frame(ScriptRunner* script);

  AppState& state() { return state_; }
  Actions& actions() { return actions_; }
  CameraControl& camera() { return camera_; }
  const WidgetRegistry& widgets() const { return widgets_; }
  bool network_idle() const { return commands_.idle() && fetches_.idle(); }
  std::uint64_t frame_count() const { return frames_; }
  nlohmann::json dump() const;          // the state as JSON (--dump-state, the script's dump)
  void write_screenshot(const std::string& path);  // the frame just drawn (before the swap)
  Settings settings() const;            // what to remember

 private:
  void sync_streams();
  void select_newest_once();
  void push_view_if_changed(const render::ViewSettings& view);
  void draw_scene(const render::ViewSettings& view, int scene_x, int fb_w, int fb_h);
  void count_fps();
  void handle_shortcuts();

  GLFWwindow* window_;
  AppState state_;
  Inbox inbox_;
  ApiHolder api_;
  render::GlFunctions gl_;
  SceneView scene_;
  FrameTexture texture_;
  RemoteView remote_;
  Worker commands_{"commands"}, fetches_{"fetches"};
  ConnectionMonitor monitor_;
  EventStreams streams_;
  ViewLoader loader_;
  Actions actions_;
  CameraControl camera_;
  WidgetRegistry widgets_;
  PanelContext panel_;
  std::string watched_;           // the session whose events are followed
  bool auto_selected_ = false;    // the newest session was shown at the first connection
  nlohmann::json pushed_view_;    // the view last sent with PUT .../view
  std::string pushed_session_;
  std::shared_ptr<std::atomic<bool>> view_in_flight_ = std::make_shared<std::atomic<bool>>(false);
  std::uint64_t frames_ = 0;
  double fps_window_start_ = 0;
  double last_frame_at_ = 0, longest_frame_ = 0;  // seconds: the UI thread's longest stall
  std::uint64_t fps_window_frames_ = 0;
};

}  // namespace levelset::gui
