// The band's overlays through EGL and OSMesa: field points within a range, vectors to the
// closest point, boundary voxels, curvature colours, the slice's zero contour on the analytic
// circle, and the volume rendering's silhouette.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "render/band_samples.hpp"
#include "render/scene_renderer.hpp"
#include "render_scenes.hpp"

using namespace levelset;
using namespace levelset::render;
using levelset::test::foreground;

namespace {

class Overlays : public test::RenderFixture {};

const SceneData& sphere() { return test::sphere_scene(); }

SceneData band_only(const SceneData& s) { return SceneData{{}, {}, s.band, nullptr, nullptr}; }

ViewSettings front_view(int w, int h) {  // looking down -z at the scene's centre
  ViewSettings v;
  v.width = w, v.height = h, v.camera.yaw = 0, v.camera.pitch = 0, v.shading = Shading::None;
  return v;
}

}  // namespace

TEST(BandSamples, ClosestPointsLieOnTheSphere) {
  const BandPoints s = sample_band_points(*sphere().band, {0, 0, 0}, 0 + 10000000);
  ASSERT_EQ(s.values.size(), sphere().band->active_voxel_count());
  double worst = 0;
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    const double r = std::hypot(s.closest[3 * i], s.closest[3 * i + 1], s.closest[3 * i + 2]);
    if (std::abs(s.values[i]) < 0.08) worst = std::max(worst, std::abs(r - 1.0));
  }
  EXPECT_LT(worst, 0.01);
  EXPECT_GT(s.boundary.size(), 0u);
  EXPECT_LT(s.boundary.size() / 3, s.values.size());
  const BandPoints few = sample_band_points(*sphere().band, {0, 0, 0}, 1000);
  EXPECT_LE(few.values.size(), 1000u);
  const DenseVolume v = sample_dense_volume(*sphere().band, 32);
  EXPECT_LE(std::max({v.nx, v.ny, v.nz}), 32);
  EXPECT_EQ(v.values.size(), std::size_t(v.nx) * v.ny * v.nz);
}

TEST_P(Overlays, FieldPointsWithinTheRange) {
  renderer->set_scene(sphere());
  ViewSettings v = front_view(320, 240);
  v.field = true;
  v.range_min = -0.03, v.range_max = 0.03;
  test::dump(renderer->render(v), std::string("field_") + test::kind_name(GetParam()));
  v.range_min = -1e30, v.range_max = 1e30;
  const std::size_t all = foreground(renderer->render(v));
  v.range_min = -0.03, v.range_max = 0.03;
  const std::size_t near = foreground(renderer->render(v));
  v.range_min = 5, v.range_max = 6;  // beyond the band
  const std::size_t none = foreground(renderer->render(v));
  EXPECT_GT(all, near);
  EXPECT_GT(near, 1000u);
  EXPECT_EQ(none, 0u);
  v.field = false, v.vectors = true, v.range_min = -1e30, v.range_max = 1e30;
  EXPECT_GT(foreground(renderer->render(v)), 1000u);
  v.vectors = false, v.boundary = true;
  EXPECT_GT(foreground(renderer->render(v)), 1000u);
}

TEST_P(Overlays, RegionOfInfluencePoints) {
  // Table 4.1 D, Point(ROI): the stored field's points, independent of the current band. The
  // scene's band is the sphere, its ROI the knot: roi=on draws points where only the knot is.
  SceneData scene = sphere();
  scene.roi = test::shape_scene("knot", 48).band;
  renderer->set_scene(scene);
  ViewSettings v = front_view(320, 240);
  EXPECT_EQ(foreground(renderer->render(v)), 0u);  // shading none, no overlay
  v.roi = true;
  const std::size_t shown = foreground(renderer->render(v));
  EXPECT_GT(shown, 1000u);
  v.range_min = -1e30, v.range_max = -1e29;  // no value in range
  EXPECT_EQ(foreground(renderer->render(v)), 0u);
  scene.roi = nullptr;  // without one, roi=on draws nothing
  renderer->set_scene(scene);
  v.range_min = -1e30, v.range_max = 1e30;
  EXPECT_EQ(foreground(renderer->render(v)), 0u);
}

TEST_P(Overlays, CurvatureColoursTheSphereUniformly) {
  renderer->set_scene(sphere());
  ViewSettings v = front_view(256, 256);
  v.shading = Shading::Wireframe;  // unlit: the colours are the map's
  v.curvature = true;
  const Image img = renderer->render(v);
  // H = 2 everywhere > 0: the positive end of the map (blue), no red.
  std::size_t blue = 0, red = 0;
  for (std::size_t i = 0; i < img.rgb.size(); i += 3) {
    if (test::is_background(img, i / 3, v.background)) continue;
    blue += img.rgb[i + 2] > img.rgb[i] + 60;
    red += img.rgb[i] > img.rgb[i + 2] + 60;
  }
  EXPECT_GT(blue, 2000u);
  EXPECT_EQ(red, 0u);
  // The knot's tube (radius 0.15) bends along the curve: H varies around 1 / 0.15, all positive.
  renderer->set_scene(test::shape_scene("knot", 96));
  const Image knot = renderer->render(v);
  test::dump(knot, std::string("curvature_") + test::kind_name(GetParam()));
  red = 0;
  for (std::size_t i = 0; i < knot.rgb.size(); i += 3)
    if (!test::is_background(knot, i / 3, v.background)) red += knot.rgb[i] > knot.rgb[i + 2] + 60;
  EXPECT_EQ(red, 0u);
  EXPECT_GT(test::distinct_colours(knot), 20u);
}

TEST_P(Overlays, SliceZeroContourIsTheAnalyticCircle) {
  renderer->set_scene(band_only(sphere()));
  ViewSettings v = front_view(400, 400);
  v.slice = SliceAxis::Z;
  v.slice_position = 0.5;
  const Image img = renderer->render(v);
  test::dump(img, std::string("slice_") + test::kind_name(GetParam()));
  // The plane z = 0 (the band's box is symmetric) is `distance` from the eye: the circle of
  // radius 1 there has this radius in pixels.
  Camera c = v.camera;
  fit_to_bounds(c, renderer->bounds());
  const double f = (v.height / 2.0) / std::tan(c.fov * M_PI / 360.0);
  const double expected = f * 1.0 / c.distance;
  std::vector<double> radii;
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x) {
      const unsigned char* p = img.rgb.data() + 3 * (std::size_t(y) * v.width + x);
      if (p[0] + p[1] + p[2] < 40) radii.push_back(std::hypot(x + 0.5 - 200, y + 0.5 - 200));
    }
  ASSERT_GT(radii.size(), std::size_t(2 * M_PI * expected));  // a closed line, about a pixel wide
  std::sort(radii.begin(), radii.end());
  EXPECT_NEAR(radii[radii.size() / 2], expected, 0.02 * expected);
  EXPECT_GT(radii[radii.size() / 20], 0.95 * expected);
  EXPECT_LT(radii[radii.size() * 19 / 20], 1.05 * expected);
  // Inside the circle is the negative end of the map (red), outside the positive (blue).
  const unsigned char* centre = img.rgb.data() + 3 * (200 * 400 + 200);
  EXPECT_GT(int(centre[0]), int(centre[2]) + 60);
  const int out = int(200 + 1.06 * expected);
  const unsigned char* outside = img.rgb.data() + 3 * (200 * 400 + out);
  EXPECT_GT(int(outside[2]), int(outside[0]) + 20);
}

TEST_P(Overlays, VolumeRenderingShowsTheSphere) {
  renderer->set_scene(sphere());
  ViewSettings v = front_view(256, 256);
  v.volume = true;
  v.volume_opacity = 0.6;
  const Image img = renderer->render(v);
  test::dump(img, std::string("volume_") + test::kind_name(GetParam()));
  Camera c = v.camera;
  fit_to_bounds(c, renderer->bounds());
  const double rho = test::projected_radius(1.0, c.distance, c.fov, v.height);
  const double disc = M_PI * rho * rho;
  // The transfer function peaks at the zero level (half-width w = 1.5 voxels, zero beyond 2 w):
  // the silhouette is the sphere's, at most 2 w wider.
  const double wider = 1 + 2 * 1.5 * sphere().band->voxel_size();
  EXPECT_GT(double(foreground(img)), 0.97 * disc);
  EXPECT_LT(double(foreground(img)), wider * wider * disc);
  // Phong from the gradient with the headlight: the centre is brighter than the rim.
  auto brightness = [&](int x, int y) {
    const unsigned char* p = img.rgb.data() + 3 * (std::size_t(y) * 256 + x);
    return p[0] + p[1] + p[2];
  };
  EXPECT_GT(brightness(128, 128), brightness(int(128 + 0.9 * rho), 128));
}

INSTANTIATE_TEST_SUITE_P(Contexts, Overlays, ::testing::Values(ContextKind::Egl, ContextKind::OsMesa),
                         [](const auto& info) { return std::string(test::kind_name(info.param)); });
