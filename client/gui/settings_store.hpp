// Settings remembered between runs: the server and token, the window's size and the panel's
// values, as a small JSON file: $XDG_CONFIG_HOME/levelset/gui.json (~/.config/... without it).
// A missing or unreadable file gives the defaults; unknown keys are ignored, so files from other
// versions load. Written atomically (temp + rename) on exit, readable by its owner only (the
// token).
#pragma once

#include <string>

#include "app_state.hpp"

namespace levelset::gui {

struct Settings {
  std::string server, token;  // "" server: the embedded daemon
  int width = 1280, height = 800;
  PanelState panel;
};

std::string default_settings_path();
Settings load_settings(const std::string& path);
bool save_settings(const std::string& path, const Settings& settings);  // false when it cannot

nlohmann::json panel_to_json(const PanelState& p);
void panel_from_json(PanelState& p, const nlohmann::json& j);

}  // namespace levelset::gui
