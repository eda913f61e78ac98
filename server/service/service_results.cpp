// Service: results of a session (mesh, band, voxels), from its committed band or, while an
// evolution runs, its latest preview.
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>

#include "apps/band_curvature.hpp"
#include "core/error.hpp"
#include "grid/band_accessor.hpp"
#include "grid/lsg_file.hpp"
#include "io/mesh_writer.hpp"
#include "service/api_error.hpp"
#include "service/service.hpp"
#include "surface/iso_range.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/surface_nets.hpp"

namespace levelset::service {

using nlohmann::json;

namespace {

const char* content_type_of(const std::string& format) {
  if (format == "ply" || format == "stl") return "application/octet-stream";
  return "text/plain; charset=utf-8";
}

void append_f32(std::string& out, double v) {
  const float f = static_cast<float>(v);
  char b[4];
  std::memcpy(b, &f, 4);  // little-endian hosts only (x86-64, arm64)
  out.append(b, 4);
}

}  // namespace

Blob Service::mesh(const std::string& session_id, const MeshQuery& q) {
  auto s = sessions_->get(session_id);
  if (q.method != "mc" && q.method != "nets") throw unprocessable("method", "expected mc or nets");
  if (q.format != "ply" && q.format != "obj" && q.format != "off" && q.format != "stl")
    throw unprocessable("format", "expected ply, obj, off or stl");
  const std::uint64_t version = s->version(), serial = s->preview_serial();
  char iso[40];
  std::snprintf(iso, sizeof iso, "%.17g", q.iso);
  const std::string key = session_id + "-v" + std::to_string(version) + "-p" + std::to_string(serial) + "-" + q.method +
                          "-" + q.format + "-" + iso;
  const std::string etag = "\"" + std::to_string(std::hash<std::string>{}(key)) + "\"";
  {
    std::lock_guard lock(cache_mutex_);
    for (auto it = mesh_cache_.begin(); it != mesh_cache_.end(); ++it)
      if (it->first == key) {
        mesh_cache_.splice(mesh_cache_.begin(), mesh_cache_, it);
        return it->second;
      }
  }
  const std::shared_ptr<const NarrowBand> band = s->preview();
  check_iso_in_band(*band, q.iso, "iso");
  SurfaceResult surface;
  if (q.method == "nets") {
    SurfaceNetsOptions o;
    o.iso = q.iso;
    surface = surface_nets(*band, o);
  } else {
    MarchingCubesOptions o;
    o.iso = q.iso;
    surface = marching_cubes(*band, o);
  }
  Blob b;
  b.bytes = std::make_shared<const std::string>(write_mesh_to_memory(surface.mesh, "surface." + q.format));
  b.etag = etag;
  b.content_type = content_type_of(q.format);
  b.file_name = session_id + "." + q.format;
  std::lock_guard lock(cache_mutex_);
  mesh_cache_.emplace_front(key, b);
  while (mesh_cache_.size() > 8) mesh_cache_.pop_back();
  return b;
}

Blob Service::band(const std::string& session_id) {
  auto s = sessions_->get(session_id);
  Blob b;
  b.bytes = std::make_shared<const std::string>(encode_lsg(*s->band()));
  b.etag = "\"" + session_id + "-v" + std::to_string(s->version()) + "\"";
  b.content_type = "application/octet-stream";
  b.file_name = session_id + ".lsg";
  return b;
}

Blob Service::points(const std::string& session_id) {
  auto s = sessions_->get(session_id);
  const json info = s->describe().value("points", json());
  if (!info.is_object()) throw ApiError(404, "not_found", "session " + session_id + " has no point cloud");
  const std::string file = info.value("file", "");
  std::ifstream in(s->dir() / file, std::ios::binary);
  if (file.empty() || file.find('/') != std::string::npos || !in)
    throw ApiError(404, "not_found", "session " + session_id + " has no readable point cloud");
  Blob b;
  b.bytes = std::make_shared<const std::string>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  b.etag = "\"" + session_id + "-" + file + "\"";
  b.content_type = "application/octet-stream";
  b.file_name = session_id + "." + info.value("format", "xyz");
  return b;
}

Blob Service::roi(const std::string& session_id) {
  auto s = sessions_->get(session_id);
  const json info = s->describe().value("roi", json());
  auto band = s->roi();
  if (!info.is_object() || !band) throw ApiError(404, "not_found", "session " + session_id + " has no region of influence");
  Blob b;
  b.bytes = std::make_shared<const std::string>(encode_lsg(*band));
  b.etag = "\"" + session_id + "-" + info.value("file", "roi") + "\"";
  b.content_type = "application/octet-stream";
  b.file_name = session_id + "-roi.lsg";
  return b;
}

Blob Service::voxels(const std::string& session_id, const VoxelQuery& q, std::uint64_t& total, std::string& fields) {
  auto s = sessions_->get(session_id);
  bool want_value = false, want_closest = false, want_curvature = false;
  for (const std::string& f : q.fields) {
    if (f == "value") want_value = true;
    else if (f == "closest") want_closest = true;
    else if (f == "curvature") want_curvature = true;
    else throw unprocessable("fields", "unknown field '" + f.substr(0, 20) + "' (value, closest, curvature)");
  }
  if (!(q.min <= q.max)) throw unprocessable("min", "min must be <= max");
  if (q.limit == 0 || q.limit > (std::uint64_t{1} << 24)) throw unprocessable("limit", "expected 1 to 16777216");
  fields = "x,y,z";
  if (want_value) fields += ",value";
  if (want_closest) fields += ",cx,cy,cz";
  if (want_curvature) fields += ",curvature";
  const std::shared_ptr<const NarrowBand> band = s->preview();
  const double h = band->voxel_size();
  BandAccessor acc(*band);
  std::string out;
  total = 0;
  band->for_each_active_world([&](const Coord& c, const Vec3d& p, float v) {
    if (v < q.min || v > q.max) return;
    const std::uint64_t index = total++;
    if (index < q.offset || index - q.offset >= q.limit) return;
    append_f32(out, p.x);
    append_f32(out, p.y);
    append_f32(out, p.z);
    if (want_value) append_f32(out, v);
    if (want_closest) {
      Vec3d g{acc.value(Coord{c.x + 1, c.y, c.z}) - acc.value(Coord{c.x - 1, c.y, c.z}),
              acc.value(Coord{c.x, c.y + 1, c.z}) - acc.value(Coord{c.x, c.y - 1, c.z}),
              acc.value(Coord{c.x, c.y, c.z + 1}) - acc.value(Coord{c.x, c.y, c.z - 1})};
      g = g / (2 * h);
      const double n = length(g);
      const Vec3d cp = n > 0 ? p - g * (double(v) / n) : p;
      append_f32(out, cp.x);
      append_f32(out, cp.y);
      append_f32(out, cp.z);
    }
    if (want_curvature) append_f32(out, apps::band_mean_curvature(acc, *band, p));
  });
  Blob b;
  b.bytes = std::make_shared<const std::string>(std::move(out));
  b.content_type = "application/octet-stream";
  return b;
}

}  // namespace levelset::service
