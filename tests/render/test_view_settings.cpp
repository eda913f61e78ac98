#include <gtest/gtest.h>

#include "core/error.hpp"
#include "render/camera.hpp"
#include "render/view_settings.hpp"

using namespace levelset;
using namespace levelset::render;

namespace {

std::string error_place(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    return e.where();
  }
  ADD_FAILURE() << "no error";
  return "";
}

}  // namespace

TEST(ViewSettings, JsonRoundTripKeepsEveryField) {
  ViewSettings v;
  v.width = 320, v.height = 200, v.shading = Shading::Wireframe, v.moving = true;
  v.camera.yaw = -45, v.camera.pitch = 10, v.camera.zoom = 0.5, v.camera.distance = 7, v.camera.fov = 60;
  v.camera.target = Vec3d{1, 2, 3};
  v.light = {1, 0, 0};
  v.field = true, v.range_min = -0.1, v.vectors = true, v.curvature = true, v.boundary = true;
  v.slice = SliceAxis::Y, v.slice_position = 0.25, v.volume = true, v.volume_width = 0.2, v.volume_opacity = 0.3;
  v.cloud = false, v.cloud_size = 4, v.cloud_color = {0.5f, 0.25f, 1.0f};
  const ViewSettings w = from_json(to_json(v));
  EXPECT_EQ(to_json(w), to_json(v));
  EXPECT_EQ(w.camera.target->z, 3);
  EXPECT_TRUE(std::isinf(w.range_max));
  EXPECT_EQ(to_json(from_json(nlohmann::json::object())), to_json(ViewSettings{}));
}

TEST(ViewSettings, MergesSubsetsAndTheDaemonsCameraForm) {
  ViewSettings v;
  merge_json(v, {{"camera", {{"yaw", 90}, {"zoom", "0.5"}}}, {"slice", "z"}, {"volume", {{"on", true}}}});
  EXPECT_EQ(v.camera.yaw, 90);
  EXPECT_EQ(v.camera.zoom, 0.5);
  EXPECT_EQ(v.camera.pitch, 20);
  EXPECT_EQ(v.slice, SliceAxis::Z);
  EXPECT_TRUE(v.volume);
}

TEST(ViewSettings, QueryParameters) {
  ViewSettings v;
  apply_query(v, "shading", "flat");
  apply_query(v, "target", "1,2,3");
  apply_query(v, "light", "0,1,0");
  apply_query(v, "field", "on");
  apply_query(v, "field_min", "-0.5");
  apply_query(v, "field_max", "inf");
  apply_query(v, "slice", "x");
  apply_query(v, "slice_position", "0.75");
  apply_query(v, "moving", "1");
  apply_query(v, "width", "1024");
  apply_query(v, "cloud", "off");
  apply_query(v, "cloud_size", "6");
  apply_query(v, "cloud_color", "1,0,0");
  EXPECT_EQ(v.shading, Shading::Flat);
  EXPECT_EQ(v.camera.target->y, 2);
  EXPECT_EQ(v.light[1], 1);
  EXPECT_TRUE(v.field);
  EXPECT_EQ(v.range_min, -0.5);
  EXPECT_TRUE(std::isinf(v.range_max));
  EXPECT_EQ(v.slice, SliceAxis::X);
  EXPECT_TRUE(v.moving);
  EXPECT_EQ(v.width, 1024);
  EXPECT_FALSE(v.cloud);
  EXPECT_EQ(v.cloud_size, 6);
  EXPECT_EQ(v.cloud_color[0], 1.0f);
}

TEST(ViewSettings, ErrorsNameTheSettingAndChangeNothing) {
  ViewSettings v;
  EXPECT_EQ(error_place([&] { apply_query(v, "pitch", "95"); }), "view.pitch");
  EXPECT_EQ(error_place([&] { apply_query(v, "shading", "glossy"); }), "view.shading");
  EXPECT_EQ(error_place([&] { apply_query(v, "width", "5000"); }), "view.width");
  EXPECT_EQ(error_place([&] { apply_query(v, "light", "0,0,0"); }), "view.light");
  EXPECT_EQ(error_place([&] { apply_query(v, "colour", "1"); }), "view.colour");
  EXPECT_EQ(error_place([&] { merge_json(v, {{"camera", {{"pitch", "x"}}}}); }), "view.camera.pitch");
  EXPECT_EQ(error_place([&] { merge_json(v, {{"camera", {{"shading", "flat"}}}}); }), "view.camera.shading");
  EXPECT_EQ(error_place([&] { merge_json(v, {{"slice", {{"position", 2}}}}); }), "view.slice.position");
  EXPECT_EQ(error_place([&] { merge_json(v, {{"background", {1, 2}}}); }), "view.background");
  EXPECT_EQ(error_place([&] { merge_json(v, {{"cloud", {{"size", 0}}}}); }), "view.cloud.size");
  EXPECT_EQ(error_place([&] { merge_json(v, {{"cloud", {{"shape", "disc"}}}}); }), "view.cloud.shape");
  EXPECT_EQ(error_place([&] { merge_json(v, {{"yaw", 10}, {"volume", {{"opacity", -1}}}}); }), "view.volume.opacity");
  EXPECT_EQ(to_json(v), to_json(ViewSettings{}));  // the yaw of the failed merge did not stick
  try {
    apply_query(v, "pitch", "95");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.reason()).find("-89.9"), std::string::npos) << e.reason();
  }
}

TEST(ViewSettings, FitToBoundsFillsTheFieldOfView) {
  Camera c;
  BBox box;
  box.extend({-1, -1, -1});
  box.extend({3, 1, 1});
  fit_to_bounds(c, box);
  EXPECT_EQ(c.target->x, 1);
  EXPECT_NEAR(c.distance, std::sqrt(6.0) / std::sin(20 * M_PI / 180), 1e-9);
  ViewSettings v;
  v.camera = c;
  v.camera.yaw = 0, v.camera.pitch = 0;
  const CameraFrame f = camera_frame(v, box, {1, 0, 0});  // eye on +z from the target
  EXPECT_NEAR(f.eye.x, 0, 1e-5);
  EXPECT_NEAR(f.eye.z, c.distance, 1e-4);
}
