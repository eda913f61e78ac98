#include "scene_view.hpp"

namespace levelset::gui {

SceneView::SceneView(const render::GlFunctions& gl)
    : gl_(gl), renderer_(std::make_unique<render::SceneRenderer>(gl, options())) {}

SceneView::~SceneView() = default;

void SceneView::set_mesh(TriangleMesh mesh, std::shared_ptr<const std::vector<std::uint32_t>> simplified) {
  scene_.mesh = std::move(mesh);
  // Kept with the mesh: a later part (band, points, ROI) re-uploads without simplifying again.
  scene_.simplified = simplified ? std::move(simplified)
                                 : std::make_shared<const std::vector<std::uint32_t>>(
                                       render::motion_indices(scene_.mesh, options()));
  dirty_ = true;
}

void SceneView::set_band(std::shared_ptr<const NarrowBand> band) {
  scene_.band = std::move(band);
  dirty_ = true;
}

void SceneView::set_points(PointCloud points) {
  scene_.points = std::move(points);
  dirty_ = true;
}

void SceneView::set_roi(std::shared_ptr<const NarrowBand> roi) {
  scene_.roi = std::move(roi);
  dirty_ = true;
}

void SceneView::clear() {
  scene_ = render::SceneData{};
  dirty_ = true;
}

void SceneView::upload() {
  // set_scene takes its own copy: the parts stay here so the next part can be added to them.
  renderer_->set_scene(scene_);
  dirty_ = false;
}

void SceneView::draw(const render::ViewSettings& view, int x, int y, int w, int h) {
  if (dirty_) upload();
  if (w < render::kMinSize || h < render::kMinSize) return;
  gl_.Viewport(x, y, w, h);
  renderer_->draw(view);
}

}  // namespace levelset::gui
