// ViewSettings: everything a frame depends on besides the scene, as plain data (the thesis
// viewer's GUI, table 4.1 and §4.9, plus the volume rendering of §5.4).
//
// - Size: width x height pixels, each kMinSize..kMaxSize.
// - Camera: an orbit around `target` (world; unset: the centre of the scene's box) at `yaw`
//   (degrees about +y, 0 looks from +z) and `pitch` (degrees, -89.9..89.9), `distance` world
//   units away (0: fit, the distance at which the scene's bounding sphere fills the vertical
//   field of view `fov`), divided by (1 + zoom). fit_to_bounds sets target and distance
//   explicitly from a box.
// - Shading of the surface: none | points | wireframe | flat | smooth; `moving` says the view
//   is being dragged (large meshes then draw a simplified copy, scene_renderer.hpp).
// - Overlays of the band: field points coloured by value within [range_min, range_max]
//   (world distances; infinite bounds: the whole band), vectors from those voxels to their
//   closest surface point (length = |value|), the surface coloured by mean curvature, the band's
//   boundary voxels, a slice (axis x | y | z at `position`, a fraction 0..1 of the band's box)
//   coloured by a diverging map with its zero contour, and volume rendering (ray casting through
//   the band: opacity from a transfer function on the value, peaked at 0 with half-width
//   `volume_width` world units (0: 1.5 voxels) and peak `volume_opacity`, Phong from the
//   gradient).
// - The point cloud (a session's reconstruction input or an attached upload; thesis table 4.1,
//   I): shown or not, as square points `cloud_size` pixels wide in `cloud_color`.
// - The region of influence (a stored copy of a distance field; table 4.1 D, Point(ROI)): its
//   voxels within [range_min, range_max] as points coloured by value, like the field.
// - Light: direction towards the light in view space (x right, y up, z towards the viewer;
//   (0,0,1) is a headlight). Colours are linear RGB in 0..1.
//
// JSON (to_json writes every field; merge_json takes any subset, merged over what is there):
//   {"width": 800, "height": 600, "shading": "smooth", "moving": false,
//    "camera": {"yaw": 30, "pitch": 20, "zoom": 0, "distance": 0, "target": null | [x,y,z], "fov": 40},
//    "light": [0,0,1], "background": [r,g,b], "color": [r,g,b],
//    "field": {"on": false, "min": null | number, "max": null | number}, "vectors": false,
//    "curvature": false, "boundary": false, "slice": {"axis": "none", "position": 0.5},
//    "volume": {"on": false, "width": 0, "opacity": 0.5},
//    "cloud": {"on": true, "size": 2, "color": [r,g,b]}, "roi": {"on": false}}
// URL parameters (apply_query): width, height, shading, moving, yaw, pitch, zoom, distance, fov,
//   target=x,y,z, light=x,y,z, background=r,g,b, color=r,g,b, field=on|off, field_min,
//   field_max, vectors, curvature, boundary (on|off|1|0|true|false), slice=none|x|y|z,
//   slice_position, volume=on|off, volume_width, volume_opacity, cloud=on|off, cloud_size (1..32 px),
//   cloud_color=r,g,b, roi=on|off.
// Errors: Error{InvalidArgument} whose place names the setting ("view.camera.pitch") and whose
//   reason gives the accepted range; nothing is changed by a failed merge_json / apply_query.
// Cost: trivial. Threading: plain data.
#pragma once

#include <array>
#include <limits>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/bbox.hpp"

namespace levelset::render {

inline constexpr int kMinSize = 16, kMaxSize = 4096;

enum class Shading { None, Points, Wireframe, Flat, Smooth };
enum class SliceAxis { None, X, Y, Z };

struct Camera {
  double yaw = 30, pitch = 20;  // degrees
  double zoom = 0;              // > -1: the distance is divided by (1 + zoom)
  double distance = 0;          // world units; 0: fit the scene
  std::optional<Vec3d> target;  // world; unset: the scene's centre
  double fov = 40;              // vertical field of view, degrees (5..120)
};

// Target = the box's centre, distance = where its bounding sphere fills the field of view.
// An empty box leaves the camera unchanged.
void fit_to_bounds(Camera& camera, const BBox& box);

struct ViewSettings {
  int width = 800, height = 600;
  Camera camera;
  Shading shading = Shading::Smooth;
  bool moving = false;
  std::array<float, 3> light{0.0f, 0.0f, 1.0f};
  std::array<float, 3> background{0.13f, 0.13f, 0.2f};
  std::array<float, 3> color{0.85f, 0.75f, 0.55f};
  // Overlays (need a band in the scene; without one they draw nothing).
  bool field = false;
  double range_min = -std::numeric_limits<double>::infinity();
  double range_max = std::numeric_limits<double>::infinity();
  bool vectors = false;
  bool curvature = false;
  bool boundary = false;
  SliceAxis slice = SliceAxis::None;
  double slice_position = 0.5;
  bool volume = false;
  double volume_width = 0;  // world units; 0: 1.5 voxels
  double volume_opacity = 0.5;
  bool cloud = true;
  double cloud_size = 2;  // pixels
  std::array<float, 3> cloud_color{0.55f, 0.85f, 0.45f};
  bool roi = false;  // needs a region of influence in the scene
};

void merge_json(ViewSettings& view, const nlohmann::json& settings);
ViewSettings from_json(const nlohmann::json& settings);  // merged over the defaults
nlohmann::json to_json(const ViewSettings& view);
void apply_query(ViewSettings& view, const std::string& key, const std::string& value);

std::string to_string(Shading shading);
std::string to_string(SliceAxis axis);

}  // namespace levelset::render
