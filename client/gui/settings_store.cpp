#include "settings_store.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace levelset::gui {

namespace fs = std::filesystem;
using nlohmann::json;

std::string default_settings_path() {
  const char* xdg = std::getenv("XDG_CONFIG_HOME");
  const char* home = std::getenv("HOME");
  fs::path base = xdg != nullptr && *xdg != '\0' ? fs::path(xdg) : fs::path(home != nullptr ? home : ".") / ".config";
  return (base / "levelset" / "gui.json").string();
}

// One list of the panel's fields for both directions.
#define LEVELSET_PANEL_FIELDS(X)                                                                     \
  X(shading) X(band) X(roi) X(resolution) X(mesh_file) X(save_file) X(field) X(whole_range) X(range_min)    \
  X(range_max) X(iso) X(formula) X(use_time) X(steps) X(time) X(scheme) X(cloud) X(cloud_size)       \
  X(points_file) X(screenshot_file) X(slice) X(slice_position) X(volume) X(view_mode)                \
  X(triangle_budget) X(primitive) X(job_file) X(new_name) X(snapshot_name)

json panel_to_json(const PanelState& p) {
  json j;
#define X(name) j[#name] = p.name;
  LEVELSET_PANEL_FIELDS(X)
#undef X
  return j;
}

void panel_from_json(PanelState& p, const json& j) {
  if (!j.is_object()) return;
  // A value of the wrong type keeps the default (a hand-edited file must not stop the window).
#define X(name)                                                     \
  if (j.contains(#name)) try {                                      \
      p.name = j[#name].get<decltype(p.name)>();                    \
    } catch (const json::exception&) {                              \
    }
  LEVELSET_PANEL_FIELDS(X)
#undef X
}

Settings load_settings(const std::string& path) {
  Settings s;
  std::ifstream in(path);
  if (!in) return s;
  std::stringstream text;
  text << in.rdbuf();
  const json j = json::parse(text.str(), nullptr, false);
  if (!j.is_object()) return s;
  if (j.contains("server") && j["server"].is_string()) s.server = j["server"];
  if (j.contains("token") && j["token"].is_string()) s.token = j["token"];
  if (j.contains("window") && j["window"].is_array() && j["window"].size() == 2 && j["window"][0].is_number_integer() &&
      j["window"][1].is_number_integer()) {
    s.width = std::clamp(j["window"][0].get<int>(), 320, 8192);
    s.height = std::clamp(j["window"][1].get<int>(), 240, 8192);
  }
  panel_from_json(s.panel, j.value("panel", json::object()));
  return s;
}

bool save_settings(const std::string& path, const Settings& s) {
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  const json j = {{"server", s.server}, {"token", s.token}, {"window", {s.width, s.height}}, {"panel", panel_to_json(s.panel)}};
  const std::string temp = path + ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(temp, std::ios::trunc);
    if (!out) return false;
    fs::permissions(temp, fs::perms::owner_read | fs::perms::owner_write, ec);  // it may hold a token
    out << j.dump(2) << "\n";
    if (!out) return false;
  }
  fs::rename(temp, path, ec);
  if (ec) fs::remove(temp, ec);
  return !ec;
}

}  // namespace levelset::gui
