// The control panel, one section per file: the thesis's table 4.1 (panel_thesis.cpp, A-L),
// server and sessions (panel_sessions.cpp), jobs and the live log (panel_jobs.cpp), and what is
// drawn over the scene: the connection banner, errors, the status line (panel_overlay.cpp).
// Every control calls Actions; none talks to the network itself.
#pragma once

#include "actions.hpp"
#include "app_state.hpp"
#include "widget_registry.hpp"

namespace levelset::gui {

inline constexpr float kPanelWidth = 420;

struct PanelContext {
  AppState& s;
  Actions& a;
  std::string server_input, token_input;  // the server box's text until Connect
};

void draw_panel(PanelContext& c, float height);       // the left window with its tabs
void draw_thesis_controls(PanelContext& c);          // A-L
void draw_view_controls(PanelContext& c);            // slice, volume, view mode, camera keys
void draw_server_and_sessions(PanelContext& c);
void draw_jobs_and_log(PanelContext& c);
void draw_overlay(const AppState& s, float scene_x, float width);  // banner, errors, status
void draw_formula_box(PanelContext& c);               // G's formula with the error caret

}  // namespace levelset::gui
