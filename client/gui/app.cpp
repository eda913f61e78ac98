#include "app.hpp"

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <chrono>

#include "script_runner.hpp"

namespace levelset::gui {

using nlohmann::json;

namespace {

void* glfw_proc(const char* name) { return reinterpret_cast<void*>(glfwGetProcAddress(name)); }

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

App::App(GLFWwindow* window, const Settings& settings)
    : window_(window),
      gl_(render::load_gl_functions(glfw_proc)),
      scene_(gl_),
      texture_(gl_, glfw_proc),
      remote_(api_, inbox_),
      monitor_(api_, inbox_),
      streams_(api_, inbox_),
      loader_(api_, inbox_, fetches_, scene_, remote_),
      actions_(ActionContext{state_, api_, inbox_, commands_, fetches_, streams_, monitor_}),
      panel_{state_, actions_, settings.server, settings.token} {
  state_.panel = settings.panel;
  // Files read on a worker reach the scene through the inbox (the scene is the UI thread's).
  actions_.on_local_mesh = [this](TriangleMesh mesh) {
    auto shared = std::make_shared<TriangleMesh>(std::move(mesh));
    auto simplified = std::make_shared<const std::vector<std::uint32_t>>(
        render::motion_indices(*shared, SceneView::options()));  // here, on the worker thread
    inbox_.post([this, shared, simplified](AppState& s) {
      // C shows the loaded mesh (as the thesis does) until B makes a session of it.
      if (!s.current.empty()) s.before_file = s.current;
      actions_.select_session("");
      scene_.clear();
      s.mesh_triangles = shared->triangles.size();
      s.mesh_version = -1;
      scene_.set_mesh(std::move(*shared), simplified);
    });
  };
  actions_.on_local_points = [this](PointCloud points) {
    auto shared = std::make_shared<PointCloud>(std::move(points));
    inbox_.post([this, shared](AppState& s) {
      s.cloud_points = shared->points.size();
      scene_.set_points(std::move(*shared));
    });
  };
  if (!settings.server.empty()) actions_.connect(settings.server, settings.token);
}

App::~App() = default;

Settings App::settings() const {
  Settings s;
  s.server = state_.server;
  s.token = state_.token;
  glfwGetWindowSize(window_, &s.width, &s.height);
  s.panel = state_.panel;
  return s;
}

// At the first connection with nothing shown, the most recently updated session is shown.
void App::select_newest_once() {
  if (auto_selected_ || !state_.connected) return;
  auto_selected_ = true;
  if (!state_.current.empty() || !state_.sessions.is_array() || state_.sessions.empty()) return;
  const json* newest = nullptr;
  for (const json& s : state_.sessions)
    if (newest == nullptr || s.value("updated", "") > newest->value("updated", "")) newest = &s;
  actions_.select_session(newest->value("id", ""));
}

void App::sync_streams() {
  streams_.reap();
  if (state_.current != watched_) {
    watched_ = state_.current;
    streams_.watch_session(watched_);
    actions_.refresh_snapshots();
  }
  if (!state_.connected) return;
  for (const JobRow& j : state_.jobs)  // progress bars from each running job's events
    if ((j.state == "running" || j.state == "queued") && (j.mine || j.session == state_.current))
      streams_.follow_job(j.id);
}

// The camera and display settings go to the session's view (PUT, merged), so the daemon's frames
// and the remote view show what the panel says. One request at a time; the newest view wins.
void App::push_view_if_changed(const render::ViewSettings& view) {
  if (!state_.connected || state_.current.empty() || view_in_flight_->load()) return;
  const json body = render::to_json(view);
  if (body == pushed_view_ && state_.current == pushed_session_) return;
  auto api = api_.get();
  if (!api) return;
  pushed_view_ = body;
  pushed_session_ = state_.current;
  *view_in_flight_ = true;
  const std::string path = "/api/v1/sessions/" + client::Api::encode(state_.current) + "/view";
  fetches_.post([this, api, path, body, flag = view_in_flight_] {
    try {
      api->put(path, body);
    } catch (const std::exception& e) {
      inbox_.post([why = describe_error(e)](AppState& s) { s.add_error("view: " + why); });
    }
    *flag = false;
  });
}

void App::draw_scene(const render::ViewSettings& view, int scene_x, int fb_w, int fb_h) {
  gl_.Viewport(0, 0, fb_w, fb_h);
  gl_.ClearColor(view.background[0], view.background[1], view.background[2], 1);
  gl_.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (!state_.remote && !scene_.empty()) {
    scene_.draw(view, scene_x, 0, fb_w - scene_x, fb_h);
    gl_.Viewport(0, 0, fb_w, fb_h);
  }
}

// K and L from the keyboard: F12 screenshot, Ctrl+Q quit (not while typing into a box).
void App::handle_shortcuts() {
  const ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureKeyboard) return;
  if (ImGui::IsKeyPressed(GLFW_KEY_F12, false)) actions_.request_screenshot();
  if (io.KeyCtrl && ImGui::IsKeyPressed(GLFW_KEY_Q, false)) actions_.quit();
}

void App::count_fps() {
  ++frames_;
  ++fps_window_frames_;
  const double t = now_seconds();
  if (last_frame_at_ > 0) longest_frame_ = std::max(longest_frame_, t - last_frame_at_);
  last_frame_at_ = t;
  if (fps_window_start_ == 0) fps_window_start_ = t;
  if (t - fps_window_start_ >= 1.0) {
    state_.fps = double(fps_window_frames_) / (t - fps_window_start_);
    fps_window_start_ = t;
    fps_window_frames_ = 0;
  }
}

bool App::frame(ScriptRunner* script) {
  glfwPollEvents();
  if (glfwWindowShouldClose(window_)) state_.quit = true;
  inbox_.apply(state_);
  select_newest_once();
  sync_streams();
  // ImGui lays out in window coordinates, GL draws in framebuffer pixels (more on a HiDPI screen).
  int fb_w = 0, fb_h = 0, win_w = 0, win_h = 0;
  glfwGetFramebufferSize(window_, &fb_w, &fb_h);
  glfwGetWindowSize(window_, &win_w, &win_h);
  const float scale = win_w > 0 ? float(fb_w) / float(win_w) : 1.0f;
  const int scene_x = int(kPanelWidth * scale);
  const int scene_w = std::max(render::kMinSize, fb_w - scene_x), scene_h = std::max(render::kMinSize, fb_h);
  loader_.update(state_, scene_w, scene_h);
  if (auto image = remote_.take_frame()) {
    texture_.upload(*image);
    ++state_.frames_received;
  }

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  if (script != nullptr) script->inject(ImGui::GetIO());
  ImGui::NewFrame();
  ui::registry = &widgets_;
  widgets_.begin_frame();
  camera_.handle_input(state_.panel, kPanelWidth);
  handle_shortcuts();
  draw_panel(panel_, float(win_h));
  draw_overlay(state_, kPanelWidth, float(win_w) - kPanelWidth);
  if (state_.remote && texture_.id() != 0 && state_.frames_received > 0)
    ImGui::GetBackgroundDrawList()->AddImage(reinterpret_cast<ImTextureID>(std::intptr_t(texture_.id())),
                                             ImVec2(kPanelWidth, 0), ImVec2(float(win_w), float(win_h)));
  ImGui::Render();

  const render::ViewSettings view = view_from_panel(state_.panel, camera_, scene_w, scene_h);
  push_view_if_changed(view);
  draw_scene(view, scene_x, fb_w, fb_h);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  if (!actions_.screenshot_request.empty()) {
    write_screenshot(actions_.screenshot_request);
    actions_.screenshot_request.clear();
  }
  if (script != nullptr) script->after_frame(*this);
  glfwSwapBuffers(window_);
  count_fps();
  return !state_.quit;
}

void App::write_screenshot(const std::string& path) {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  try {
    write_png(read_window(gl_, w, h), path);
    state_.add_log("screenshot " + path);
  } catch (const std::exception& e) {
    state_.add_error("screenshot " + path + ": " + describe_error(e));
  }
}

json App::dump() const {
  json jobs = json::array();
  for (const JobRow& j : state_.jobs)
    jobs.push_back({{"id", j.id}, {"op", j.op}, {"state", j.state}, {"fraction", j.fraction}, {"mine", j.mine}});
  json widgets = json::object();
  for (const auto& [label, r] : widgets_.all()) widgets[label] = {r.x0, r.y0, r.x1, r.y1};
  return {{"server", state_.server},
          {"daemon_pid", state_.daemon_pid},
          {"connected", state_.connected},
          {"banner", state_.banner},
          {"errors", state_.errors},
          {"formula_error", {{"column", state_.formula_error.column}, {"message", state_.formula_error.message},
                             {"formula", state_.formula_error.formula}}},
          {"session", state_.current},
          {"version", state_.version()},
          {"roi", state_.session.is_object() ? state_.session.value("roi", json()) : json()},
          {"jobs", jobs},
          {"view", {{"remote", state_.remote}, {"triangles", state_.mesh_triangles}, {"mesh_version", state_.mesh_version},
                    {"frames_received", state_.frames_received}, {"fps", state_.fps},
                    {"band_loaded", state_.band_loaded}, {"roi_loaded", state_.roi_loaded},
                    {"cloud_points", state_.cloud_points}}},
          {"frames", frames_},
          {"longest_frame_ms", 1000 * longest_frame_},
          {"camera", {{"yaw", camera_.camera.yaw}, {"pitch", camera_.camera.pitch}, {"zoom", camera_.camera.zoom}}},
          {"panel", panel_to_json(state_.panel)},
          {"widgets", widgets},
          {"log", std::vector<std::string>(state_.log.begin(), state_.log.end())}};
}

}  // namespace levelset::gui
