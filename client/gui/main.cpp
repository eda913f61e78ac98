// levelset-gui: the desktop client of levelsetd (thesis table 4.1's control panel over the REST
// API). Start-up order matters: the embedded daemon is forked before any thread or GL context
// exists (a fork after Mesa's context hangs the child).
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <thread>

#include "app.hpp"
#include "local_daemon.hpp"
#include "options.hpp"
#include "script_runner.hpp"
#include "settings_store.hpp"

namespace {

using namespace levelset::gui;

volatile std::sig_atomic_t g_signal = 0;
void on_signal(int sig) { g_signal = sig; }

GLFWwindow* open_window(int width, int height) {
  glfwSetErrorCallback([](int code, const char* text) { std::fprintf(stderr, "levelset-gui: GLFW %d: %s\n", code, text); });
  if (!glfwInit()) return nullptr;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWwindow* window = glfwCreateWindow(width, height, "levelset-gui", nullptr, nullptr);
  if (window == nullptr) return nullptr;
  glfwMakeContextCurrent(window);
  glfwSwapInterval(0);  // the loop paces itself (--fps); vsync under Xvfb is meaningless
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // the layout is the code's: deterministic for tests
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
  return window;
}

void close_window(GLFWwindow* window) {
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
}

// The frame loop; returns the exit code (3 when the script failed).
int run_loop(App& app, ScriptRunner* script, const Options& o) {
  using Clock = std::chrono::steady_clock;
  bool shot_taken = false;
  for (;;) {
    const auto start = Clock::now();
    if (g_signal != 0) app.state().quit = true;
    const bool go_on = app.frame(script);
    if (script != nullptr && script->failed()) {
      std::fprintf(stderr, "levelset-gui: script %s\n", script->failure().c_str());
      if (!o.screenshot.empty()) app.write_screenshot(o.screenshot);
      return 3;
    }
    const bool script_done = script != nullptr && script->finished();
    // Without a script, --screenshot waits for the shown session's surface (or a few frames when
    // the server has no session), then quits.
    const AppState& st = app.state();
    const bool surface_shown = script == nullptr && st.connected && app.network_idle() &&
                               (st.current.empty() ? app.frame_count() > 30 : st.mesh_version == st.version() || st.frames_received > 0);
    if (!o.screenshot.empty() && !shot_taken && (script_done || surface_shown)) {
      app.write_screenshot(o.screenshot);
      shot_taken = true;
      if (script == nullptr) app.state().quit = true;
    }
    if (!go_on || script_done) return 0;
    if (o.fps_limit > 0) std::this_thread::sleep_until(start + std::chrono::duration<double>(1.0 / o.fps_limit));
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse_options(argc, argv);
  const std::string settings_path = o.settings.empty() ? default_settings_path() : o.settings;
  Settings settings = load_settings(settings_path);
  if (!o.server.empty()) settings.server = o.server, settings.token = o.token;
  if (o.width > 0) settings.width = o.width;
  if (o.height > 0) settings.height = o.height;
  std::unique_ptr<ScriptRunner> script;
  std::unique_ptr<LocalDaemon> daemon;
  try {
    if (!o.script.empty()) script = std::make_unique<ScriptRunner>(o.script);
    if (o.server.empty() && (o.embedded || settings.server.empty())) {
      const std::string binary = o.levelsetd.empty() ? find_levelsetd("/proc/self/exe") : o.levelsetd;
      if (binary.empty()) throw std::runtime_error("no levelsetd beside levelset-gui or on PATH (give --levelsetd or --server)");
      const std::string log = default_daemon_log();
      daemon = std::make_unique<LocalDaemon>(binary, o.data_dir, log);
      std::fprintf(stderr, "levelset-gui: started %s serve (pid %d) on %s; its log: %s\n", binary.c_str(),
                   int(daemon->pid()), daemon->url().c_str(), log.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "levelset-gui: %s\n", e.what());
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);
  GLFWwindow* window = open_window(settings.width, settings.height);
  if (window == nullptr) {
    std::fprintf(stderr, "levelset-gui: cannot open an OpenGL 3.3 window (is DISPLAY set?)\n");
    return 2;
  }
  int code = 0;
  {
    Settings start = settings;
    if (daemon) start.server = daemon->url(), start.token.clear();
    App app(window, start);
    if (daemon) app.state().daemon_pid = int(daemon->pid());
    code = run_loop(app, script.get(), o);
    Settings keep = app.settings();
    if (daemon && keep.server == daemon->url()) {  // the embedded daemon's port is not worth keeping
      keep.server = o.embedded ? settings.server : "";
      keep.token = o.embedded ? settings.token : "";
    }
    if (!save_settings(settings_path, keep)) std::fprintf(stderr, "levelset-gui: cannot write %s\n", settings_path.c_str());
    if (!o.dump.empty()) std::ofstream(o.dump) << app.dump().dump(2) << "\n";
  }
  close_window(window);
  if (daemon) daemon->stop();
  return code;
}
