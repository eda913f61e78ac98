// SceneRenderer: a triangle mesh drawn offscreen with the thesis viewer's shading modes (table
// 4.1 A: none, points, wireframe, flat, smooth), a headlight, a background and an orbit camera
// that fits the mesh: the camera looks at the centre of the mesh's box from `yaw` / `pitch`
// degrees, at the distance where the box's bounding sphere just fills the 40 degree vertical
// field of view, divided by (1 + zoom).
// ViewSettings come from JSON ({"camera": {"yaw", "pitch", "zoom"}, "shading", "background":
// [r, g, b]}) and from URL parameters (yaw=, pitch=, zoom=, shading=), each checked (Error
// {InvalidArgument} naming the setting).
// Cost: upload O(mesh) once per set_mesh; a frame O(triangles) + read-back O(pixels).
// Threading: the context's thread only.
#pragma once

#include <array>
#include <string>

#include <nlohmann/json.hpp>

#include "io/triangle_mesh.hpp"
#include "render/image_codec.hpp"
#include "render/offscreen_context.hpp"

namespace levelset::render {

enum class Shading { None, Points, Wireframe, Flat, Smooth };

struct ViewSettings {
  double yaw = 30, pitch = 20, zoom = 0;  // degrees, degrees, > -1 (0: fit)
  Shading shading = Shading::Smooth;
  std::array<float, 3> background{0.13f, 0.13f, 0.2f};
  std::array<float, 3> color{0.85f, 0.75f, 0.55f};
};

void apply_json(ViewSettings& view, const nlohmann::json& settings);  // Error naming the field
void apply_query(ViewSettings& view, const std::string& key, const std::string& value);

class SceneRenderer {
 public:
  explicit SceneRenderer(OffscreenContext& context);  // compiles the shaders
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  void set_mesh(const TriangleMesh& mesh);
  Image render(const ViewSettings& view, int width, int height);

 private:
  OffscreenContext& context_;
  unsigned program_ = 0, vao_ = 0, positions_ = 0, normals_ = 0, indices_ = 0;
  int index_count_ = 0, vertex_count_ = 0;
  std::array<double, 3> center_{0, 0, 0};
  double radius_ = 1;
};

}  // namespace levelset::render
