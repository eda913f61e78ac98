#include "render/view_settings.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/error.hpp"
#include "core/text.hpp"

namespace levelset::render {

namespace {

using nlohmann::json;

[[noreturn]] void bad(const std::string& place, const std::string& expected, const json& found) {
  const std::string text = found.is_string() ? found.get<std::string>() : found.dump();
  throw Error(ErrorCode::InvalidArgument, place, expected + ", found '" + sanitize_utf8(text.substr(0, 40)) + "'");
}

// A number from a JSON number or a string (URL parameters arrive as strings).
double number(const std::string& place, const json& v, double lo, double hi) {
  double x = std::nan("");
  if (v.is_number()) {
    x = v.get<double>();
  } else if (v.is_string()) {
    const std::string s = v.get<std::string>();
    char* end = nullptr;
    x = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || *end != 0) x = std::nan("");
  }
  if (!std::isfinite(x) || x < lo || x > hi)
    bad(place, "expected a number from " + format_number(lo) + " to " + format_number(hi), v);
  return x;
}

// A range bound: a number, or null / "" / "inf" for no bound.
double bound(const std::string& place, const json& v, double infinity) {
  if (v.is_null() || (v.is_string() && (v.get<std::string>().empty() || v.get<std::string>() == "inf")))
    return infinity;
  return number(place, v, -1e30, 1e30);
}

bool boolean(const std::string& place, const json& v) {
  if (v.is_boolean()) return v.get<bool>();
  if (v.is_number_integer() && (v.get<long long>() == 0 || v.get<long long>() == 1)) return v.get<long long>() == 1;
  if (v.is_string()) {
    const std::string s = v.get<std::string>();
    if (s == "on" || s == "1" || s == "true" || s == "yes") return true;
    if (s == "off" || s == "0" || s == "false" || s == "no") return false;
  }
  bad(place, "expected on or off (true, false, 1, 0)", v);
}

// [x, y, z] or "x,y,z".
Vec3d triple(const std::string& place, const json& v, double lo, double hi) {
  json items = v;
  if (v.is_string()) {
    items = json::array();
    std::stringstream in(v.get<std::string>());
    std::string part;
    while (std::getline(in, part, ',')) items.push_back(part);
  }
  if (!items.is_array() || items.size() != 3) bad(place, "expected three numbers [x, y, z] (or x,y,z)", v);
  return {number(place, items[0], lo, hi), number(place, items[1], lo, hi), number(place, items[2], lo, hi)};
}

std::array<float, 3> rgb(const std::string& place, const json& v) {
  const Vec3d c = triple(place, v, 0, 1);
  return {float(c.x), float(c.y), float(c.z)};
}

Shading shading_of(const std::string& place, const json& v) {
  const std::string s = v.is_string() ? v.get<std::string>() : "";
  if (s == "none") return Shading::None;
  if (s == "points") return Shading::Points;
  if (s == "wireframe") return Shading::Wireframe;
  if (s == "flat") return Shading::Flat;
  if (s == "smooth") return Shading::Smooth;
  bad(place, "expected none, points, wireframe, flat or smooth", v);
}

SliceAxis axis_of(const std::string& place, const json& v) {
  const std::string s = v.is_string() ? v.get<std::string>() : "";
  if (s == "none" || s == "off") return SliceAxis::None;
  if (s == "x") return SliceAxis::X;
  if (s == "y") return SliceAxis::Y;
  if (s == "z") return SliceAxis::Z;
  bad(place, "expected none, x, y or z", v);
}

constexpr const char* kFlatKeys =
    "width, height, shading, moving, yaw, pitch, zoom, distance, fov, target, light, background, color, field, "
    "field_min, field_max, vectors, curvature, boundary, slice, slice_position, volume, volume_width, volume_opacity, "
    "cloud, cloud_size, cloud_color, roi";

// One setting by its flat (URL) name; `place` names it in errors.
void set_flat(ViewSettings& view, const std::string& key, const json& v, const std::string& place) {
  Camera& c = view.camera;
  if (key == "width") view.width = int(number(place, v, kMinSize, kMaxSize));
  else if (key == "height") view.height = int(number(place, v, kMinSize, kMaxSize));
  else if (key == "shading") view.shading = shading_of(place, v);
  else if (key == "moving") view.moving = boolean(place, v);
  else if (key == "yaw") c.yaw = number(place, v, -36000, 36000);
  else if (key == "pitch") c.pitch = number(place, v, -89.9, 89.9);
  else if (key == "zoom") c.zoom = number(place, v, -0.9, 100);
  else if (key == "distance") c.distance = number(place, v, 0, 1e12);
  else if (key == "fov") c.fov = number(place, v, 5, 120);
  else if (key == "target") c.target = v.is_null() ? std::nullopt : std::optional<Vec3d>(triple(place, v, -1e12, 1e12));
  else if (key == "light") {
    const Vec3d l = triple(place, v, -1e6, 1e6);
    if (length(l) < 1e-9) bad(place, "expected a non-zero direction", v);
    view.light = {float(l.x), float(l.y), float(l.z)};
  } else if (key == "background") view.background = rgb(place, v);
  else if (key == "color") view.color = rgb(place, v);
  else if (key == "field") view.field = boolean(place, v);
  else if (key == "field_min") view.range_min = bound(place, v, -std::numeric_limits<double>::infinity());
  else if (key == "field_max") view.range_max = bound(place, v, std::numeric_limits<double>::infinity());
  else if (key == "vectors") view.vectors = boolean(place, v);
  else if (key == "curvature") view.curvature = boolean(place, v);
  else if (key == "boundary") view.boundary = boolean(place, v);
  else if (key == "slice") view.slice = axis_of(place, v);
  else if (key == "slice_position") view.slice_position = number(place, v, 0, 1);
  else if (key == "volume") view.volume = boolean(place, v);
  else if (key == "volume_width") view.volume_width = number(place, v, 0, 1e12);
  else if (key == "volume_opacity") view.volume_opacity = number(place, v, 0, 1);
  else if (key == "cloud") view.cloud = boolean(place, v);
  else if (key == "cloud_size") view.cloud_size = number(place, v, 1, 32);
  else if (key == "cloud_color") view.cloud_color = rgb(place, v);
  else if (key == "roi") view.roi = boolean(place, v);
  else throw Error(ErrorCode::InvalidArgument, place, std::string("unknown view setting (") + kFlatKeys + ")");
}

// A nested object ("camera", "field", "slice", "volume", "cloud", "roi"): its keys mapped to flat names.
void set_group(ViewSettings& view, const std::string& group, const json& object) {
  for (const auto& [k, v] : object.items()) {
    const std::string place = "view." + group + "." + sanitize_utf8(k.substr(0, 40));
    std::string flat;
    if (group == "camera") flat = k;
    else if (k == "on") flat = group;
    else if (group == "field" && (k == "min" || k == "max")) flat = "field_" + k;
    else if (group == "slice" && k == "axis") flat = "slice";
    else if (group == "slice" && k == "position") flat = "slice_position";
    else if (group == "volume" && (k == "width" || k == "opacity")) flat = "volume_" + k;
    else if (group == "cloud" && (k == "size" || k == "color")) flat = "cloud_" + k;
    const bool camera_key = flat == "yaw" || flat == "pitch" || flat == "zoom" || flat == "distance" ||
                            flat == "fov" || flat == "target";
    if (flat.empty() || (group == "camera" && !camera_key))
      throw Error(ErrorCode::InvalidArgument, place, "unknown setting in view." + group);
    set_flat(view, flat, v, place);
  }
}

json optional_bound(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

}  // namespace

void fit_to_bounds(Camera& camera, const BBox& box) {
  if (box.empty()) return;
  const double radius = std::max(1e-9, 0.5 * length(box.max - box.min));
  camera.target = box.center();
  camera.distance = radius / std::sin(camera.fov * M_PI / 360.0);
}

std::string to_string(Shading shading) {
  switch (shading) {
    case Shading::None: return "none";
    case Shading::Points: return "points";
    case Shading::Wireframe: return "wireframe";
    case Shading::Flat: return "flat";
    case Shading::Smooth: return "smooth";
  }
  return "smooth";
}

std::string to_string(SliceAxis axis) {
  switch (axis) {
    case SliceAxis::None: return "none";
    case SliceAxis::X: return "x";
    case SliceAxis::Y: return "y";
    case SliceAxis::Z: return "z";
  }
  return "none";
}

void merge_json(ViewSettings& view, const json& settings) {
  if (!settings.is_object()) throw Error(ErrorCode::InvalidArgument, "view", "expected an object of view settings");
  ViewSettings next = view;  // all or nothing
  for (const auto& [key, value] : settings.items()) {
    const bool group =
        key == "camera" || key == "field" || key == "slice" || key == "volume" || key == "cloud" || key == "roi";
    if (group && value.is_object()) set_group(next, key, value);
    else if (key == "camera") throw Error(ErrorCode::InvalidArgument, "view.camera", "expected an object");
    else set_flat(next, key, value, "view." + sanitize_utf8(key.substr(0, 40)));
  }
  view = next;
}

ViewSettings from_json(const json& settings) {
  ViewSettings view;
  merge_json(view, settings);
  return view;
}

json to_json(const ViewSettings& v) {
  const Camera& c = v.camera;
  return {{"width", v.width},
          {"height", v.height},
          {"shading", to_string(v.shading)},
          {"moving", v.moving},
          {"camera",
           {{"yaw", c.yaw},
            {"pitch", c.pitch},
            {"zoom", c.zoom},
            {"distance", c.distance},
            {"target", c.target ? json::array({c.target->x, c.target->y, c.target->z}) : json(nullptr)},
            {"fov", c.fov}}},
          {"light", v.light},
          {"background", v.background},
          {"color", v.color},
          {"field", {{"on", v.field}, {"min", optional_bound(v.range_min)}, {"max", optional_bound(v.range_max)}}},
          {"vectors", v.vectors},
          {"curvature", v.curvature},
          {"boundary", v.boundary},
          {"slice", {{"axis", to_string(v.slice)}, {"position", v.slice_position}}},
          {"volume", {{"on", v.volume}, {"width", v.volume_width}, {"opacity", v.volume_opacity}}},
          {"cloud", {{"on", v.cloud}, {"size", v.cloud_size}, {"color", v.cloud_color}}},
          {"roi", {{"on", v.roi}}}};
}

void apply_query(ViewSettings& view, const std::string& key, const std::string& value) {
  ViewSettings next = view;
  set_flat(next, key, json(value), "view." + sanitize_utf8(key.substr(0, 40)));
  view = next;
}

}  // namespace levelset::render
