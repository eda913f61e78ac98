// ScriptRunner: --script FILE, UI actions for headless tests (Xvfb). One command a line, words
// split like a shell (double or single quotes), a line starting with '#' is a comment. Commands run after a
// frame is drawn; a wait_* command holds the script (frames keep coming) until its condition
// holds or its deadline (last word, seconds; default 60) passes, which fails the script.
//
//   connect URL [TOKEN]          set FIELD VALUE (a panel field, settings_store.cpp's names)
//   press ACTION                 the function a button calls: load_mesh compute_distance
//       evolve stop redistance extract save_mesh load_points reconstruct screenshot quit
//       create_primitive rename delete snapshot restore (the newest snapshot) run_job_file
//   click LABEL                  injected ImGui mouse click at the centre of a labelled control
//   drag DX DY                   injected left-button drag over the scene (the trackball)
//   type TEXT                    injected characters (into the focused text box)
//   key ctrl+a|enter|backspace|home|f12   an injected key press (ctrl+ any letter)
//   camera YAW PITCH ZOOM        select SESSION_ID
//   wait_connected / wait_disconnected / wait_session / wait_idle / wait_surface [S]
//   wait_running [S]             a job of this window runs
//   wait_error TEXT [S]          an error containing TEXT is shown
//   wait_formula_error [S]       the formula box shows a server error with its column
//   frames N                     let N frames pass
//   screenshot PATH              dump PATH (the state as JSON)
//   expect_no_errors             clear_errors             quit
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include <imgui.h>

namespace levelset::gui {

class App;

class ScriptRunner {
 public:
  explicit ScriptRunner(const std::string& file);  // throws std::runtime_error naming the line

  void inject(ImGuiIO& io);   // before ImGui::NewFrame (after the backend's NewFrame)
  void after_frame(App& app); // runs commands until one waits
  bool finished() const { return next_ >= lines_.size() || failed_; }
  bool failed() const { return failed_; }
  const std::string& failure() const { return failure_; }

 private:
  enum class Step { Done, Wait, Fail };
  struct Line {
    int number = 0;
    std::vector<std::string> words;
  };
  Step run(const Line& line, App& app);
  Step run_wait(const Line& line, App& app);
  Step wait_for(bool condition, const Line& line, const std::string& what);
  Step settle(bool condition, const Line& line, const std::string& what);  // held for 3 frames
  Step click(const Line& line, App& app);
  Step drag(const Line& line, App& app);
  Step press(const std::string& action, App& app);
  void fail(const Line& line, const std::string& why);

  std::string file_;
  std::vector<Line> lines_;
  std::size_t next_ = 0;
  bool failed_ = false;
  std::string failure_;
  std::chrono::steady_clock::time_point started_;  // of the current command
  bool started_set_ = false;
  std::uint64_t frames_wanted_ = 0;
  int held_ = 0;  // consecutive frames a settle condition held (results posted late still land)
  // Injected input: a click is move (1 frame), press (1 frame), release.
  int click_phase_ = 0;
  ImVec2 mouse_{-1, -1};
  int drag_phase_ = 0;  // 1: over the scene, 2..11: pressed and moving, 12: released
  ImVec2 drag_step_{0, 0};
  std::string typed_, key_;
  int key_phase_ = 0;
};

}  // namespace levelset::gui
