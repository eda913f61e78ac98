// The trackball camera of both view modes: drag with the left button in the scene to orbit,
// the wheel (or +/-) to zoom, arrows to turn by 5 degrees, Home to reset; digits 1..5 pick the
// shading (A). Input the panel uses (io.WantCapture*) never moves the camera.
// view_from_panel: the renderer's ViewSettings from the panel's values and the camera.
#pragma once

#include "app_state.hpp"
#include "render/view_settings.hpp"

namespace levelset::gui {

struct CameraControl {
  render::Camera camera;
  bool moving = false;  // a drag is in progress (large meshes draw their simplified copy)
  bool changed = false; // since the last take_changed()

  // UI thread, between ImGui::NewFrame and Render; the scene covers x >= scene_x.
  void handle_input(PanelState& panel, float scene_x);
  void reset();
  bool take_changed() {
    const bool c = changed;
    changed = false;
    return c;
  }
};

render::ViewSettings view_from_panel(const PanelState& panel, const CameraControl& control, int width, int height);

}  // namespace levelset::gui
