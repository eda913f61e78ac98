// camera_frame: the matrices of a ViewSettings camera for a scene whose GPU positions are
// stored relative to `origin` (world minus origin, in float: large coordinates keep their
// precision).
//
// Inputs: the view (camera, width, height) and the scene's world box (for the fit when
//   camera.distance is 0 or the target is unset, and for the near / far planes, which hug the
//   box's bounding sphere). An empty box is treated as the unit cube at the origin.
// Output: view and projection matrices (OpenGL conventions), the eye in the shifted frame, the
//   distance to the target. Units: world. Cost: trivial. Threading: pure function.
#pragma once

#include <glm/glm.hpp>

#include "core/bbox.hpp"
#include "render/view_settings.hpp"

namespace levelset::render {

struct CameraFrame {
  glm::mat4 view{1.0f}, projection{1.0f};
  glm::vec3 eye{0.0f};  // relative to the origin
  double distance = 1;  // eye to target, world units
};

CameraFrame camera_frame(const ViewSettings& view, const BBox& scene_bounds, const Vec3d& origin);

}  // namespace levelset::render
