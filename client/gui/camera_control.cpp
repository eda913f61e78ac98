#include "camera_control.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>

namespace levelset::gui {

void CameraControl::reset() {
  camera = render::Camera{};
  changed = true;
}

void CameraControl::handle_input(PanelState& panel, float scene_x) {
  ImGuiIO& io = ImGui::GetIO();
  const bool over_scene = io.MousePos.x >= scene_x && !io.WantCaptureMouse;
  const bool was_moving = moving;
  if (over_scene && ImGui::IsMouseDown(ImGuiMouseButton_Left) && (io.MouseDelta.x != 0 || io.MouseDelta.y != 0)) {
    camera.yaw = std::fmod(camera.yaw - io.MouseDelta.x * 0.4, 360.0);
    camera.pitch = std::clamp(camera.pitch + io.MouseDelta.y * 0.4, -89.0, 89.0);
    moving = changed = true;
  }
  if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) moving = false;
  if (was_moving != moving) changed = true;
  if (over_scene && io.MouseWheel != 0) {
    camera.zoom = std::clamp(camera.zoom + io.MouseWheel * 0.1 * (1 + camera.zoom), -0.9, 50.0);
    changed = true;
  }
  if (io.WantCaptureKeyboard) return;
  auto pressed = [](int key) { return ImGui::IsKeyPressed(key); };
  if (pressed(GLFW_KEY_LEFT)) camera.yaw -= 5, changed = true;
  if (pressed(GLFW_KEY_RIGHT)) camera.yaw += 5, changed = true;
  if (pressed(GLFW_KEY_UP)) camera.pitch = std::min(89.0, camera.pitch + 5), changed = true;
  if (pressed(GLFW_KEY_DOWN)) camera.pitch = std::max(-89.0, camera.pitch - 5), changed = true;
  if (pressed(GLFW_KEY_EQUAL) || pressed(GLFW_KEY_KP_ADD)) camera.zoom = std::min(50.0, camera.zoom + 0.1 * (1 + camera.zoom)), changed = true;
  if (pressed(GLFW_KEY_MINUS) || pressed(GLFW_KEY_KP_SUBTRACT)) camera.zoom = std::max(-0.9, camera.zoom - 0.1 * (1 + camera.zoom)), changed = true;
  if (pressed(GLFW_KEY_HOME)) reset();
  for (int i = 0; i < 5; ++i)
    if (pressed(GLFW_KEY_1 + i)) panel.shading = i, changed = true;
}

render::ViewSettings view_from_panel(const PanelState& p, const CameraControl& control, int width, int height) {
  render::ViewSettings v;
  v.width = std::clamp(width, render::kMinSize, render::kMaxSize);
  v.height = std::clamp(height, render::kMinSize, render::kMaxSize);
  v.camera = control.camera;
  v.moving = control.moving;
  static const render::Shading shadings[] = {render::Shading::None, render::Shading::Points, render::Shading::Wireframe,
                                             render::Shading::Flat, render::Shading::Smooth};
  v.shading = shadings[std::clamp(p.shading, 0, 4)];
  v.field = p.field == 1;
  v.vectors = p.field == 2;
  v.curvature = p.field == 3;
  v.boundary = p.field == 4;
  v.roi = p.field == 5;
  if (!p.whole_range && p.range_min <= p.range_max) {
    v.range_min = p.range_min;
    v.range_max = p.range_max;
  }
  static const render::SliceAxis axes[] = {render::SliceAxis::None, render::SliceAxis::X, render::SliceAxis::Y,
                                           render::SliceAxis::Z};
  v.slice = axes[std::clamp(p.slice, 0, 3)];
  v.slice_position = std::clamp(double(p.slice_position), 0.0, 1.0);
  v.volume = p.volume;
  v.cloud = p.cloud == 1;
  v.cloud_size = std::clamp(double(p.cloud_size), 1.0, 32.0);
  return v;
}

}  // namespace levelset::gui
