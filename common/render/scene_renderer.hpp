// SceneRenderer: draws a SceneData (scene.hpp) with ViewSettings (view_settings.hpp): the
// surface in the thesis viewer's shading modes (table 4.1: none, points, wireframe, flat,
// smooth) lit from view.light, the point cloud, and the band's overlays (field points, vectors
// to the closest point, curvature colours, boundary voxels, a slice with its zero contour,
// volume rendering; thesis §4.9, §5.4).
//
// It takes a GL function table, not a context: an OffscreenContext (offscreen_context.hpp) or
// a window's context (the desktop client, table loaded from glfwGetProcAddress) work alike.
// - set_scene: uploads the mesh (and its simplified copy, when above the triangle budget) and the
//   point cloud once; the band's overlays are prepared on first use (band_samples.hpp) and kept
//   until the next set_scene.
// - draw: into the bound framebuffer, viewport already set by the caller (a window).
// - render: into an own offscreen framebuffer of view.width x view.height, read back as RGB8,
//   top row first; `timing` (optional) gets the draw (GPU work up to glFinish) and read-back
//   times.
// While view.moving is true, a mesh above SceneOptions::moving_triangle_budget draws its
// simplified copy. The volume is composited over the surface (no depth interplay).
// Errors: Error{InvalidArgument} for a size outside kMinSize..kMaxSize or a bad mesh index;
// Error{IoError} from shader compilation or the framebuffer.
// Cost: set_scene O(mesh + points) (+ ~1 s per 1M triangles to simplify); a frame
// O(triangles drawn + pixels); the first frame with a slice / volume samples the band densely
// (~0.3 s for 256^3). Threading: the context's thread only; the renderer must be destroyed
// while that context is current.
#pragma once

#include <memory>

#include "render/gl_functions.hpp"
#include "render/image_codec.hpp"
#include "render/scene.hpp"
#include "render/view_settings.hpp"

namespace levelset::render {

struct FrameTiming {
  double draw_ms = 0, read_ms = 0;
};

class SceneRenderer {
 public:
  explicit SceneRenderer(const GlFunctions& gl, SceneOptions options = {});  // compiles the shaders
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  void set_scene(SceneData scene);
  const SceneData& scene() const;
  BBox bounds() const;                           // what the camera fits (scene_bounds)
  std::size_t simplified_triangles() const;      // 0 when the mesh has no simplified copy

  void draw(const ViewSettings& view);
  Image render(const ViewSettings& view, FrameTiming* timing = nullptr);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace levelset::render
