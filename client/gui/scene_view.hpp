// SceneView: the local-geometry view mode. levelset_render's SceneRenderer draws, in the
// window's own context, the surface fetched from the server (or a mesh file loaded before its
// distance field exists), the band for the overlays and the point cloud. Parts arrive one at a
// time from the network threads (through the Inbox) and replace what was shown.
#pragma once

#include <memory>

#include "render/gl_functions.hpp"
#include "render/scene_renderer.hpp"

namespace levelset::gui {

class SceneView {
 public:
  explicit SceneView(const render::GlFunctions& gl);  // the window's context is current
  ~SceneView();

  // `simplified`: render::motion_indices(mesh, options()) made off the UI thread, or null (then
  // the next draw makes it, about 0.35 s per million triangles above the budget).
  void set_mesh(TriangleMesh mesh, std::shared_ptr<const std::vector<std::uint32_t>> simplified = nullptr);
  static render::SceneOptions options() { return {}; }
  void set_band(std::shared_ptr<const NarrowBand> band);
  void set_points(PointCloud points);
  void set_roi(std::shared_ptr<const NarrowBand> roi);  // null: none
  void clear();
  std::size_t triangles() const { return scene_.mesh.triangles.size(); }
  bool has_band() const { return scene_.band != nullptr; }
  bool empty() const { return scene_.mesh.triangles.empty() && scene_.points.points.empty() && !scene_.band; }

  // Draws into the window's framebuffer, in the rectangle (x, y from the bottom-left, w x h).
  void draw(const render::ViewSettings& view, int x, int y, int w, int h);

 private:
  void upload();
  const render::GlFunctions& gl_;
  render::SceneData scene_;
  std::unique_ptr<render::SceneRenderer> renderer_;
  bool dirty_ = false;
};

}  // namespace levelset::gui
