#include "render/camera.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace levelset::render {

CameraFrame camera_frame(const ViewSettings& view, const BBox& scene_bounds, const Vec3d& origin) {
  BBox box = scene_bounds;
  if (box.empty()) {
    box.extend({-0.5, -0.5, -0.5});
    box.extend({0.5, 0.5, 0.5});
  }
  Camera fitted = view.camera;
  fit_to_bounds(fitted, box);  // the fit's target and distance fill in what the view leaves unset
  const Camera& c = view.camera;
  const Vec3d target = (c.target ? *c.target : *fitted.target) - origin;
  const double distance = (c.distance > 0 ? c.distance : fitted.distance) / (1.0 + c.zoom);
  const double yaw = glm::radians(c.yaw), pitch = glm::radians(c.pitch);
  const Vec3d eye = target + Vec3d{std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)} *
                                 distance;
  CameraFrame f;
  f.eye = glm::vec3(float(eye.x), float(eye.y), float(eye.z));
  f.distance = distance;
  f.view = glm::lookAt(f.eye, glm::vec3(float(target.x), float(target.y), float(target.z)), glm::vec3(0, 1, 0));
  // Near and far planes around the scene's bounding sphere as seen from the eye.
  const Vec3d centre = box.center() - origin;
  const double radius = std::max(1e-9, 0.5 * length(box.max - box.min));
  const double to_centre = length(eye - centre);
  const double far_plane = to_centre + 1.1 * radius;
  const double near_plane = std::max(far_plane * 1e-4, to_centre - 1.1 * radius);
  f.projection = glm::perspective(float(glm::radians(c.fov)), float(view.width) / float(view.height),
                                  float(near_plane), float(far_plane));
  return f;
}

}  // namespace levelset::render
