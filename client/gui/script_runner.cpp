#include "script_runner.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "app.hpp"
#include "panels.hpp"
#include "core/file_io.hpp"

namespace levelset::gui {

using nlohmann::json;

namespace {

std::vector<std::string> split_words(const std::string& text, int number) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (char ch : text) {
    if (quote != 0) {
      if (ch == quote) {
        quote = 0;
      } else {
        word += ch;
      }
    } else if (ch == '"' || ch == '\'') {
      quote = ch;
      in_word = true;
    } else if (ch == '#' && !in_word && words.empty()) {  // a comment line (labels may start with '#')
      break;
    } else if (ch == ' ' || ch == '\t') {
      if (in_word) words.push_back(word), word.clear(), in_word = false;
    } else {
      word += ch;
      in_word = true;
    }
  }
  if (quote != 0) throw std::runtime_error("line " + std::to_string(number) + ": unterminated quote");
  if (in_word) words.push_back(word);
  return words;
}

const std::map<std::string, int>& known_commands() {  // name -> the fewest words after it
  static const std::map<std::string, int> m = {
      {"connect", 1}, {"set", 2}, {"press", 1}, {"click", 1}, {"drag", 2}, {"type", 1}, {"key", 1}, {"camera", 3}, {"select", 1},
      {"wait_connected", 0}, {"wait_disconnected", 0}, {"wait_session", 0}, {"wait_idle", 0}, {"wait_surface", 0}, {"wait_running", 0},
      {"wait_error", 1}, {"wait_formula_error", 0}, {"frames", 1}, {"screenshot", 1}, {"dump", 1},
      {"expect_no_errors", 0}, {"clear_errors", 0}, {"quit", 0}};
  return m;
}

}  // namespace

ScriptRunner::ScriptRunner(const std::string& file) : file_(file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read the script " + file);
  std::string text;
  for (int number = 1; std::getline(in, text); ++number) {
    Line line{number, split_words(text, number)};
    if (line.words.empty()) continue;
    auto it = known_commands().find(line.words[0]);
    if (it == known_commands().end())
      throw std::runtime_error(file + ":" + std::to_string(number) + ": unknown command '" + line.words[0] + "'");
    if (int(line.words.size()) - 1 < it->second)
      throw std::runtime_error(file + ":" + std::to_string(number) + ": '" + line.words[0] + "' needs " +
                               std::to_string(it->second) + " argument(s)");
    lines_.push_back(std::move(line));
  }
}

void ScriptRunner::inject(ImGuiIO& io) {
  if (click_phase_ > 0) {
    io.MousePos = mouse_;
    io.MouseDown[0] = click_phase_ == 2;
  }
  if (drag_phase_ > 0) {
    if (drag_phase_ > 2 && drag_phase_ < 12) mouse_ = ImVec2(mouse_.x + drag_step_.x, mouse_.y + drag_step_.y);
    io.MousePos = mouse_;
    io.MouseDown[0] = drag_phase_ >= 2 && drag_phase_ < 12;
  }
  if (!typed_.empty()) {
    io.AddInputCharactersUTF8(typed_.c_str());
    typed_.clear();
  }
  if (key_phase_ > 0) {
    const bool down = key_phase_ == 1;
    const bool ctrl = key_.rfind("ctrl+", 0) == 0;
    const std::string name = ctrl ? key_.substr(5) : key_;
    int key = GLFW_KEY_UNKNOWN;
    if (name.size() == 1 && name[0] >= 'a' && name[0] <= 'z') key = GLFW_KEY_A + (name[0] - 'a');
    if (name == "enter") key = GLFW_KEY_ENTER;
    if (name == "backspace") key = GLFW_KEY_BACKSPACE;
    if (name == "home") key = GLFW_KEY_HOME;
    if (name.size() >= 2 && name[0] == 'f' && std::isdigit(static_cast<unsigned char>(name[1])))
      key = GLFW_KEY_F1 + std::clamp(std::atoi(name.c_str() + 1), 1, 25) - 1;
    if (key != GLFW_KEY_UNKNOWN) io.KeysDown[key] = down;
    io.KeyCtrl = ctrl && down;
  }
}

void ScriptRunner::fail(const Line& line, const std::string& why) {
  failed_ = true;
  failure_ = file_ + ":" + std::to_string(line.number) + ": " + line.words[0] + ": " + why;
}

ScriptRunner::Step ScriptRunner::wait_for(bool condition, const Line& line, const std::string& what) {
  if (condition) return Step::Done;
  double limit = 60;
  if (line.words.size() > 1) {
    char* end = nullptr;
    const double v = std::strtod(line.words.back().c_str(), &end);
    if (end != nullptr && *end == '\0' && v > 0) limit = v;
  }
  if (std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count() > limit) {
    fail(line, "timed out after " + std::to_string(int(limit)) + " s waiting for " + what);
    return Step::Fail;
  }
  return Step::Wait;
}

ScriptRunner::Step ScriptRunner::settle(bool condition, const Line& line, const std::string& what) {
  held_ = condition ? held_ + 1 : 0;
  const Step step = wait_for(held_ >= 3, line, what);
  if (step != Step::Wait) held_ = 0;
  return step;
}

ScriptRunner::Step ScriptRunner::click(const Line& line, App& app) {
  if (click_phase_ == 0) {
    const WidgetRect* r = app.widgets().find(line.words[1]);
    if (r == nullptr) return wait_for(false, line, "a control labelled '" + line.words[1] + "'");
    mouse_ = ImVec2((r->x0 + r->x1) / 2, (r->y0 + r->y1) / 2);
    click_phase_ = 1;
    return Step::Wait;
  }
  if (click_phase_ < 3) {
    ++click_phase_;
    return Step::Wait;
  }
  click_phase_ = 0;
  return Step::Done;
}

ScriptRunner::Step ScriptRunner::drag(const Line& line, App& app) {
  if (drag_phase_ == 0) {
    const ImVec2 size = ImGui::GetIO().DisplaySize;
    mouse_ = ImVec2((kPanelWidth + size.x) / 2, size.y / 2);  // the scene's centre
    drag_step_ = ImVec2(float(std::stod(line.words[1])) / 9, float(std::stod(line.words[2])) / 9);
    drag_phase_ = 1;
    (void)app;
    return Step::Wait;
  }
  if (drag_phase_ < 12) {
    ++drag_phase_;
    return Step::Wait;
  }
  drag_phase_ = 0;
  return Step::Done;
}

ScriptRunner::Step ScriptRunner::press(const std::string& action, App& app) {
  Actions& a = app.actions();
  static const std::map<std::string, void (Actions::*)()> table = {
      {"load_mesh", &Actions::load_mesh},     {"compute_distance", &Actions::compute_distance},
      {"evolve", &Actions::evolve},           {"stop", &Actions::stop_evolution},
      {"redistance", &Actions::redistance},   {"extract", &Actions::extract},
      {"save_mesh", &Actions::save_mesh},     {"load_points", &Actions::load_points},
      {"reconstruct", &Actions::reconstruct}, {"screenshot", &Actions::request_screenshot},
      {"quit", &Actions::quit},               {"create_primitive", &Actions::create_primitive},
      {"snapshot", &Actions::snapshot},       {"run_job_file", &Actions::run_job_file},
      {"store_roi", &Actions::store_roi},     {"clear_roi", &Actions::clear_roi}};
  if (action == "rename") return a.rename_session(), Step::Done;
  if (action == "delete") return a.delete_session(app.state().current), Step::Done;
  if (action == "restore") {
    const json& snaps = app.state().snapshots;
    if (snaps.empty()) return Step::Fail;
    return a.restore(snaps.back().value("id", "")), Step::Done;
  }
  auto it = table.find(action);
  if (it == table.end()) return Step::Fail;
  (a.*(it->second))();
  return Step::Done;
}

}  // namespace levelset::gui

namespace levelset::gui {

namespace {

// `set FIELD VALUE`: the value takes the field's type (text fields keep VALUE as written).
bool set_panel_field(PanelState& panel, const std::string& field, const std::string& value) {
  const json current = panel_to_json(panel);
  if (!current.contains(field)) return false;
  json v = current[field].is_string() ? json(value) : json::parse(value, nullptr, false);
  if (v.is_discarded() || (current[field].is_number() && !v.is_number()) ||
      (current[field].is_boolean() && !v.is_boolean()))
    return false;
  panel_from_json(panel, json{{field, v}});
  return true;
}

bool write_text(const std::string& path, const std::string& text) {
  try {
    write_file_atomically(path, text);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

ScriptRunner::Step ScriptRunner::run(const Line& line, App& app) {
  const std::string& cmd = line.words[0];
  const auto arg = [&](std::size_t i) { return i < line.words.size() ? line.words[i] : std::string(); };
  AppState& s = app.state();
  if (cmd == "connect") return app.actions().connect(arg(1), arg(2)), Step::Done;
  if (cmd == "set") {
    if (set_panel_field(s.panel, arg(1), arg(2))) return Step::Done;
    fail(line, "no panel field '" + arg(1) + "' taking '" + arg(2) + "'");
    return Step::Fail;
  }
  if (cmd == "press") {
    if (press(arg(1), app) == Step::Done) return Step::Done;
    fail(line, "unknown action '" + arg(1) + "' (or nothing to act on)");
    return Step::Fail;
  }
  if (cmd == "click") return click(line, app);
  if (cmd == "drag") return drag(line, app);
  if (cmd == "type") {
    if (key_phase_ == 0 && typed_.empty() && !started_set_) {
      typed_ = arg(1);
      return Step::Wait;  // inject() hands it to ImGui before the next frame
    }
    return typed_.empty() ? Step::Done : Step::Wait;
  }
  if (cmd == "key") {
    if (key_phase_ == 0) key_ = arg(1), key_phase_ = 1;
    else if (key_phase_ == 1) key_phase_ = 2;
    else return key_phase_ = 0, Step::Done;
    return Step::Wait;
  }
  if (cmd == "camera") {
    app.camera().camera.yaw = std::stod(arg(1));
    app.camera().camera.pitch = std::stod(arg(2));
    app.camera().camera.zoom = std::stod(arg(3));
    return Step::Done;
  }
  if (cmd == "select") return app.actions().select_session(arg(1)), Step::Done;
  if (cmd == "frames") {
    if (frames_wanted_ == 0) frames_wanted_ = app.frame_count() + std::stoull(arg(1));
    if (app.frame_count() < frames_wanted_) return Step::Wait;
    frames_wanted_ = 0;
    return Step::Done;
  }
  if (cmd == "screenshot") return app.write_screenshot(arg(1)), Step::Done;
  if (cmd == "dump") {
    if (write_text(arg(1), app.dump().dump(2))) return Step::Done;
    fail(line, "cannot write " + arg(1));
    return Step::Fail;
  }
  if (cmd == "clear_errors") return s.errors.clear(), s.formula_error = {}, Step::Done;
  if (cmd == "quit") return app.actions().quit(), Step::Done;
  return run_wait(line, app);
}

ScriptRunner::Step ScriptRunner::run_wait(const Line& line, App& app) {
  const std::string& cmd = line.words[0];
  AppState& s = app.state();
  if (cmd == "expect_no_errors") {
    if (s.errors.empty()) return Step::Done;
    fail(line, "errors shown: " + json(s.errors).dump());
    return Step::Fail;
  }
  if (cmd == "wait_connected") return wait_for(s.connected, line, "a connection");
  if (cmd == "wait_disconnected") return wait_for(!s.banner.empty(), line, "the connection-lost banner");
  if (cmd == "wait_session") return wait_for(!s.current.empty() && s.version() > 0, line, "a session");
  if (cmd == "wait_idle")
    return settle(app.network_idle() && !s.job_running() && s.select_after_job.empty(), line, "the jobs to end");
  if (cmd == "wait_running") {
    bool running = false;
    for (const JobRow& j : s.jobs) running = running || (j.mine && j.state == "running");
    return wait_for(running, line, "a running job");
  }
  if (cmd == "wait_surface") {
    const bool shown = s.remote ? s.frames_received > 0
                                : s.mesh_version == s.version() && s.mesh_triangles > 0 && app.network_idle();
    return settle(!s.current.empty() && shown, line, "the surface of the session's version");
  }
  if (cmd == "wait_error") {
    bool found = false;
    for (const std::string& e : s.errors) found = found || e.find(line.words[1]) != std::string::npos;
    return wait_for(found, line, "an error containing '" + line.words[1] + "'");
  }
  if (cmd == "wait_formula_error") return wait_for(s.formula_error.column > 0, line, "a formula error");
  fail(line, "unknown command");
  return Step::Fail;
}

void ScriptRunner::after_frame(App& app) {
  while (!failed_ && next_ < lines_.size()) {
    const Line& line = lines_[next_];
    if (!started_set_) started_ = std::chrono::steady_clock::now();
    const Step step = run(line, app);
    if (step == Step::Wait) {
      started_set_ = true;
      return;
    }
    started_set_ = false;
    if (step == Step::Fail) return;
    ++next_;
  }
}

}  // namespace levelset::gui
