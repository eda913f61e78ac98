// Known scenes through EGL and OSMesa: the sphere's silhouette against the camera's projection,
// the shading modes, the light direction, the simplified copy while moving, the point cloud,
// and EGL and OSMesa agreeing.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "render/scene_renderer.hpp"
#include "render_scenes.hpp"

using namespace levelset;
using namespace levelset::render;
using levelset::test::foreground;

namespace {

class SceneRender : public test::RenderFixture {};

const SceneData& sphere() { return test::sphere_scene(); }

// The sphere's expected silhouette radius with the fitted camera (the mesh's box).
double sphere_rho(const SceneRenderer& r, const ViewSettings& v) {
  Camera c = v.camera;
  fit_to_bounds(c, r.bounds());
  return test::projected_radius(1.0, c.distance / (1 + v.camera.zoom), c.fov, v.height);
}

}  // namespace

TEST_P(SceneRender, NamesItsRenderer) {
  EXPECT_FALSE(context->renderer_name().empty());
  EXPECT_FALSE(context->platform().empty());
}

TEST_P(SceneRender, SphereSilhouetteMatchesTheProjectedDisc) {
  renderer->set_scene(sphere());
  for (const auto& [w, h, zoom] : {std::tuple{320, 240, 0.0}, std::tuple{400, 400, 0.8}}) {
    ViewSettings v;
    v.width = w, v.height = h, v.camera.zoom = zoom;
    const Image img = renderer->render(v);
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    ASSERT_EQ(img.rgb.size(), std::size_t(w) * h * 3);
    const double rho = sphere_rho(*renderer, v);
    const double disc = M_PI * rho * rho;
    EXPECT_NEAR(double(foreground(img)), disc, 0.03 * disc) << w << "x" << h << " zoom " << zoom;
  }
}

TEST_P(SceneRender, ShadingModes) {
  renderer->set_scene(sphere());
  std::map<Shading, std::size_t> count, shades;
  for (Shading s : {Shading::None, Shading::Points, Shading::Wireframe, Shading::Flat, Shading::Smooth}) {
    ViewSettings v;
    v.width = 320, v.height = 240, v.shading = s;
    const Image img = renderer->render(v);
    count[s] = foreground(img);
    shades[s] = test::distinct_colours(img);
  }
  ViewSettings fitted;
  fitted.width = 320, fitted.height = 240;
  const double disc = M_PI * std::pow(sphere_rho(*renderer, fitted), 2);
  EXPECT_EQ(count[Shading::None], 0u);
  for (Shading s : {Shading::Points, Shading::Wireframe, Shading::Flat, Shading::Smooth}) EXPECT_GT(count[s], 0.5 * disc);
  EXPECT_NEAR(double(count[Shading::Flat]), double(count[Shading::Smooth]), 0.02 * count[Shading::Smooth]);
  EXPECT_LE(shades[Shading::Points], 3u);  // unlit: the colour and the background
  EXPECT_LE(shades[Shading::Wireframe], 3u);
  EXPECT_GT(shades[Shading::Flat], 50u);
  EXPECT_GT(shades[Shading::Smooth], 50u);
}

TEST_P(SceneRender, LitSideIsBrighterThanTheDarkSide) {
  renderer->set_scene(sphere());
  for (const auto& [light, lit_right] : {std::pair{std::array<float, 3>{1, 0, 0.2f}, true},
                                          std::pair{std::array<float, 3>{-1, 0, 0.2f}, false}}) {
    ViewSettings v;
    v.width = 256, v.height = 256, v.light = light;
    const Image img = renderer->render(v);
    double sum[2] = {0, 0};
    std::size_t n[2] = {0, 0};
    for (int y = 0; y < v.height; ++y)
      for (int x = 0; x < v.width; ++x) {
        const std::size_t i = std::size_t(y) * v.width + x;
        if (test::is_background(img, i, v.background)) continue;
        const int side = x >= v.width / 2;
        sum[side] += img.rgb[3 * i] + img.rgb[3 * i + 1] + img.rgb[3 * i + 2];
        ++n[side];
      }
    const double left = sum[0] / double(n[0]), right = sum[1] / double(n[1]);
    if (lit_right) EXPECT_GT(right, 1.5 * left) << "light from the right: left " << left << " right " << right;
    else EXPECT_GT(left, 1.5 * right) << "light from the left: left " << left << " right " << right;
  }
  // The headlight: the centre is brighter than the rim.
  ViewSettings v;
  v.width = 256, v.height = 256;
  const Image img = renderer->render(v);
  const double rho = sphere_rho(*renderer, v);
  auto at = [&](int x, int y) {
    const unsigned char* p = img.rgb.data() + 3 * (std::size_t(y) * 256 + x);
    return p[0] + p[1] + p[2];
  };
  EXPECT_GT(at(128, 128), at(int(128 + 0.9 * rho), 128));
}

TEST_P(SceneRender, KnotInEveryMode) {
  renderer->set_scene(test::shape_scene("knot", 96));
  std::size_t smooth = 0;
  for (Shading s : {Shading::Points, Shading::Wireframe, Shading::Flat, Shading::Smooth}) {
    ViewSettings v;
    v.width = 320, v.height = 240, v.shading = s;
    const std::size_t n = foreground(renderer->render(v));
    EXPECT_GT(n, 0.05 * v.width * v.height) << to_string(s);
    EXPECT_LT(n, 0.6 * v.width * v.height) << to_string(s);
    if (s == Shading::Smooth) smooth = n;
  }
  EXPECT_GT(smooth, 0u);
}

TEST_P(SceneRender, MovingViewDrawsTheSimplifiedCopy) {
  SceneOptions options;
  options.moving_triangle_budget = 2000;
  renderer = std::make_unique<SceneRenderer>(context->gl(), options);
  renderer->set_scene(sphere());
  ASSERT_GT(sphere().mesh.triangles.size(), 10000u);
  EXPECT_GT(renderer->simplified_triangles(), 100u);
  EXPECT_LE(renderer->simplified_triangles(), 2000u);
  ViewSettings v;
  v.width = 320, v.height = 240, v.shading = Shading::Wireframe;
  const std::size_t still = foreground(renderer->render(v));
  v.moving = true;
  const std::size_t moving = foreground(renderer->render(v));
  EXPECT_LT(moving, 0.8 * still);  // fewer edges
  v.shading = Shading::Smooth;
  const std::size_t moving_area = foreground(renderer->render(v));
  v.moving = false;
  const std::size_t area = foreground(renderer->render(v));
  EXPECT_NEAR(double(moving_area), double(area), 0.03 * area);
}

// The simplified copy made beforehand (off a window's UI thread) is the one set_scene would make,
// and set_scene uses it rather than simplifying again.
TEST_P(SceneRender, SimplifiedCopyMadeBeforehand) {
  SceneOptions options;
  options.moving_triangle_budget = 2000;
  SceneData scene = sphere();
  const std::vector<std::uint32_t> made = motion_indices(scene.mesh, options);
  ASSERT_GT(made.size(), 300u);
  ASSERT_LE(made.size(), 3 * 2000u);
  EXPECT_EQ(made, prepare_mesh(scene.mesh, scene_bounds(scene).center(), options).simplified);
  EXPECT_TRUE(motion_indices(scene.mesh, SceneOptions{}).empty());  // within the default budget
  std::vector<std::uint32_t> few(made.begin(), made.begin() + 30);  // 10 triangles, recognisably not its own
  scene.simplified = std::make_shared<const std::vector<std::uint32_t>>(few);
  renderer = std::make_unique<SceneRenderer>(context->gl(), options);
  renderer->set_scene(scene);
  EXPECT_EQ(renderer->simplified_triangles(), 10u);
  few[0] = std::uint32_t(scene.mesh.vertices.size());  // out of range: refused, named
  scene.simplified = std::make_shared<const std::vector<std::uint32_t>>(few);
  EXPECT_THROW(renderer->set_scene(scene), Error);
}

TEST_P(SceneRender, PointCloud) {
  SceneData scene;
  for (int i = 0; i < 2000; ++i) {  // a Fibonacci sphere of radius 1
    const double z = 1 - 2 * (i + 0.5) / 2000, r = std::sqrt(1 - z * z), a = i * 2.399963229728653;
    scene.points.points.push_back({r * std::cos(a), r * std::sin(a), z});
  }
  renderer->set_scene(scene);
  ViewSettings v;
  v.width = 320, v.height = 240;
  const Image img = renderer->render(v);
  const std::size_t n = foreground(img);
  EXPECT_GT(n, 1000u);
  const double rho = sphere_rho(*renderer, v);
  EXPECT_LT(double(n), M_PI * rho * rho);
  for (int y = 0; y < v.height; ++y)  // every point inside the projected disc (+ point size)
    for (int x = 0; x < v.width; ++x) {
      if (!test::is_background(img, std::size_t(y) * v.width + x, v.background)) {
        ASSERT_LT(std::hypot(x + 0.5 - 160, y + 0.5 - 120), rho + 3);
      }
    }
  // Table 4.1 I: the cloud's shading. Off draws nothing; bigger points cover more; the colour
  // is the one asked for.
  v.cloud = false;
  EXPECT_EQ(foreground(renderer->render(v)), 0u);
  v.cloud = true;
  v.cloud_size = 5;
  v.cloud_color = {1.0f, 0.0f, 0.0f};
  const Image big = renderer->render(v);
  EXPECT_GT(double(foreground(big)), 1.5 * double(n));
  std::size_t red = 0;
  for (std::size_t i = 0; i + 2 < big.rgb.size(); i += 3)
    red += big.rgb[i] > 200 && big.rgb[i + 1] < 40 && big.rgb[i + 2] < 40;
  EXPECT_EQ(red, foreground(big));
}

TEST_P(SceneRender, RefusesBadSizes) {
  renderer->set_scene(sphere());
  ViewSettings v;
  v.width = 8;
  EXPECT_THROW(renderer->render(v), Error);
  v.width = 5000;
  EXPECT_THROW(renderer->render(v), Error);
}

INSTANTIATE_TEST_SUITE_P(Contexts, SceneRender, ::testing::Values(ContextKind::Egl, ContextKind::OsMesa),
                         [](const auto& info) { return std::string(test::kind_name(info.param)); });

TEST(SceneRenderContexts, EglAndOsMesaAgree) {
  ViewSettings v;
  v.width = 320, v.height = 240;
  v.field = true, v.range_min = -0.02, v.range_max = 0.02, v.slice = SliceAxis::X;
  const SceneData scene = test::shape_scene("knot", 64);
  Image images[2];
  for (ContextKind kind : {ContextKind::Egl, ContextKind::OsMesa}) {
    auto context = create_offscreen_context(kind);
    SceneRenderer renderer(context->gl());
    renderer.set_scene(scene);
    images[kind == ContextKind::OsMesa] = renderer.render(v);
  }
  double diff = 0;
  for (std::size_t i = 0; i < images[0].rgb.size(); ++i) diff += std::abs(int(images[0].rgb[i]) - int(images[1].rgb[i]));
  EXPECT_LT(diff / double(images[0].rgb.size()), 2.0);
  EXPECT_GT(foreground(images[0]), 1000u);
}
