// Test helpers for render_tests: known scenes (analytic shapes through build_from_sdf and
// marching cubes) and pixel measures on RGB8 images.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <set>
#include <string>

#include "geometry/analytic_shapes.hpp"
#include "grid/build_from_sdf.hpp"
#include "render/image_codec.hpp"
#include "render/offscreen_context.hpp"
#include "render/scene.hpp"
#include "render/scene_renderer.hpp"
#include "render/view_settings.hpp"
#include "surface/marching_cubes.hpp"

namespace levelset::test {

// The band and surface of a builtin shape ("sphere": radius 1 at the origin, "knot").
inline render::SceneData shape_scene(const std::string& name, int resolution) {
  const auto shape = make_builtin_shape(name);
  SdfBuildOptions options;
  options.frame = frame_for_resolution(shape->bounds(), resolution, 3.0);
  const AnalyticShape* s = shape.get();
  auto band = std::make_shared<NarrowBand>(
      build_from_sdf([s](const Vec3d& p) { return s->distance(p); }, s->bounds(), options).band);
  render::SceneData scene;
  scene.mesh = marching_cubes(*band).mesh;
  scene.band = band;
  return scene;
}

inline bool is_background(const render::Image& img, std::size_t pixel, const std::array<float, 3>& bg) {
  for (int c = 0; c < 3; ++c)
    if (std::abs(int(img.rgb[3 * pixel + c]) - int(std::lround(bg[c] * 255))) > 12) return false;
  return true;
}

inline std::size_t foreground(const render::Image& img, const std::array<float, 3>& bg = render::ViewSettings{}.background) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < std::size_t(img.width) * img.height; ++i) n += !is_background(img, i, bg);
  return n;
}

inline std::size_t distinct_colours(const render::Image& img) {
  std::set<int> colours;
  for (std::size_t i = 0; i < img.rgb.size(); i += 3) colours.insert(img.rgb[i] << 16 | img.rgb[i + 1] << 8 | img.rgb[i + 2]);
  return colours.size();
}

// Radius in pixels of a sphere of radius r at distance d (centre on the axis), vertical fov.
inline double projected_radius(double r, double d, double fov_degrees, int height) {
  const double half = fov_degrees * M_PI / 360.0;
  return (height / 2.0) * std::tan(std::asin(r / d)) / std::tan(half);
}

inline const char* kind_name(render::ContextKind kind) { return kind == render::ContextKind::Egl ? "Egl" : "OsMesa"; }

}  // namespace levelset::test

namespace levelset::test {
// With LEVELSET_RENDER_DUMP=DIR set, writes the image to DIR/name.png (for looking at failures).
inline void dump(const render::Image& img, const std::string& name) {
  if (const char* dir = std::getenv("LEVELSET_RENDER_DUMP")) {
    const std::string png = render::encode_png(img);
    if (FILE* f = std::fopen((std::string(dir) + "/" + name + ".png").c_str(), "wb")) {
      std::fwrite(png.data(), 1, png.size(), f);
      std::fclose(f);
    }
  }
}
}  // namespace levelset::test

namespace levelset::test {

// A context of the parameter's kind (creation throws: the test fails, never skips) and a
// renderer on it, for the render test suites.
class RenderFixture : public ::testing::TestWithParam<render::ContextKind> {
 protected:
  void SetUp() override {
    context = render::create_offscreen_context(GetParam());
    renderer = std::make_unique<render::SceneRenderer>(context->gl());
  }
  void TearDown() override {
    renderer.reset();
    context.reset();
  }
  std::unique_ptr<render::OffscreenContext> context;
  std::unique_ptr<render::SceneRenderer> renderer;
};

// The analytic sphere at resolution 64, built once per test binary.
inline const render::SceneData& sphere_scene() {
  static const render::SceneData s = shape_scene("sphere", 64);
  return s;
}

}  // namespace levelset::test
