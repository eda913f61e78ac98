#include "jobs/job_context.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "distance/closest_point_transform.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/lsg_file.hpp"
#include "io/mesh_reader.hpp"
#include "io/mesh_writer.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/surface_nets.hpp"

namespace levelset::jobs {

namespace fs = std::filesystem;

namespace {

const config::Set& empty_set() {
  static const config::Set empty;
  return empty;
}

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string cgal_data_dir() {
  // $LEVELSET_CGAL_DATA names the data directory (meshes/, points_3/, images/) or, as in
  // deploy/install-deps.sh, the directory the tarball was unpacked into (holding data/).
  const char* env = std::getenv("LEVELSET_CGAL_DATA");
  if (env != nullptr && *env != '\0') {
    std::error_code ec;
    if (fs::is_directory(fs::path(env) / "meshes", ec)) return env;
    return std::string(env) + "/data";
  }
  return "/usr/local/share/levelset/cgal-data/data";
}

}  // namespace

JobContext::JobContext(const config::Set& root, const JobOptions& options) : root_(root), options_(options) {}

std::string JobContext::place(const config::Set& set, std::string_view key) const {
  const config::Entry* e = set.find(key);
  if (e == nullptr) return options_.name;
  return config::place_of(*e, options_.name);
}

const config::Entry& JobContext::entry(const config::Set& set, std::string_view key) const {
  const config::Entry* e = set.find(key);
  if (e == nullptr) throw Error(ErrorCode::InvalidArgument, options_.name, "missing key '" + std::string(key) + "'");
  if (e->is_set)
    throw Error(ErrorCode::InvalidArgument, place(set, key), "'" + std::string(key) + "' must be a value, not a set");
  return *e;
}

const config::Set& JobContext::section(std::string_view key, const std::vector<std::string>& allowed) const {
  const config::Entry* e = root_.find(key);
  if (e == nullptr) return empty_set();
  if (!e->is_set)
    throw Error(ErrorCode::InvalidArgument, place(root_, key), "'" + std::string(key) + "' must be a set: " +
                std::string(key) + " { ... }");
  config::check_keys(e->set, allowed, options_.name);
  return e->set;
}

namespace {
// A bound as a reader writes it: 1000, 0.5, 1e-09 (not std::to_string's 1000.000000).
std::string shortest(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", v);
  return text;
}
}  // namespace

double JobContext::number(const config::Set& set, std::string_view key, double fallback, double lo, double hi) const {
  if (!has(set, key)) return fallback;
  const config::Entry& e = entry(set, key);
  if (e.value.kind != config::Value::Kind::Number)
    throw Error(ErrorCode::InvalidArgument, place(set, key), "'" + std::string(key) + "' must be a number, got '" +
                e.value.text + "'");
  const double v = e.value.number;
  if (!std::isfinite(v) || v < lo || v > hi)
    throw Error(ErrorCode::InvalidArgument, place(set, key),
                "'" + std::string(key) + "' = " + e.value.text + " is outside [" + shortest(lo) + ", " + shortest(hi) + "]");
  return v;
}

int JobContext::integer(const config::Set& set, std::string_view key, int fallback, int lo, int hi) const {
  const double v = number(set, key, fallback, lo, hi);
  if (v != std::floor(v))
    throw Error(ErrorCode::InvalidArgument, place(set, key), "'" + std::string(key) + "' must be a whole number");
  return static_cast<int>(v);
}

bool JobContext::flag(const config::Set& set, std::string_view key, bool fallback) const {
  if (!has(set, key)) return fallback;
  const std::string w = word(set, key, "", {"yes", "no", "true", "false", "on", "off", "1", "0"});
  return w == "yes" || w == "true" || w == "on" || w == "1";
}

std::string JobContext::word(const config::Set& set, std::string_view key, std::string fallback,
                             const std::vector<std::string>& choices) const {
  if (!has(set, key)) return fallback;
  const config::Entry& e = entry(set, key);
  if (e.value.kind == config::Value::Kind::Tuple)
    throw Error(ErrorCode::InvalidArgument, place(set, key), "'" + std::string(key) + "' must be a word, not a tuple");
  const std::string& w = e.value.text;
  if (!choices.empty()) {
    for (const std::string& c : choices)
      if (c == w) return w;
    throw Error(ErrorCode::InvalidArgument, place(set, key),
                "'" + std::string(key) + "' = '" + w + "' is not one of: " + join(choices));
  }
  return w;
}

std::string JobContext::text(const config::Set& set, std::string_view key, std::string fallback) const {
  if (!has(set, key)) return fallback;
  return entry(set, key).value.text;
}

Vec3d JobContext::vec3(const config::Set& set, std::string_view key, Vec3d fallback) const {
  if (!has(set, key)) return fallback;
  const config::Entry& e = entry(set, key);
  if (e.value.kind != config::Value::Kind::Tuple || e.value.tuple.size() != 3)
    throw Error(ErrorCode::InvalidArgument, place(set, key), "'" + std::string(key) + "' must be a tuple (x, y, z)");
  for (double v : e.value.tuple)
    if (!std::isfinite(v)) throw Error(ErrorCode::NonFinite, place(set, key), "'" + std::string(key) + "' is not finite");
  return {e.value.tuple[0], e.value.tuple[1], e.value.tuple[2]};
}

std::vector<Vec3d> JobContext::points(const config::Set& set, std::string_view key) const {
  const config::Entry& e = entry(set, key);
  if (e.value.kind != config::Value::Kind::Tuple || e.value.tuple.empty() || e.value.tuple.size() % 3 != 0)
    throw Error(ErrorCode::InvalidArgument, place(set, key),
                "'" + std::string(key) + "' must be a tuple of 3n numbers (x1, y1, z1, x2, y2, z2, ...)");
  std::vector<Vec3d> out;
  for (std::size_t i = 0; i < e.value.tuple.size(); i += 3) {
    const Vec3d p{e.value.tuple[i], e.value.tuple[i + 1], e.value.tuple[i + 2]};
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error(ErrorCode::NonFinite, place(set, key), "'" + std::string(key) + "' has a non-finite coordinate");
    out.push_back(p);
  }
  return out;
}

std::string JobContext::input_path(const config::Set& set, std::string_view key) const {
  const config::Entry& e = entry(set, key);
  const std::string& name = e.value.text;
  if (name.empty()) throw Error(ErrorCode::InvalidArgument, place(set, key), "empty file name");
  fs::path path;
  bool confined = options_.confine_inputs;
  fs::path root = options_.base_dir;  // where a confined input must stay
  if (name.rfind("cgal:", 0) == 0) {
    // The installed sample data is read-only and public: confined to its own directory.
    const fs::path rest(name.substr(5));
    if (rest.has_root_path() || name.find("..") != std::string::npos)
      throw Error(ErrorCode::InvalidArgument, place(set, key), "cgal: names are relative, without '..'");
    root = cgal_data_dir();
    path = root / rest;
    confined = true;
  } else {
    path = fs::path(name);
    if (path.is_relative()) path = fs::path(options_.base_dir) / path;
  }
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(path, ec);
  if (confined) {
    const fs::path base = fs::weakly_canonical(root, ec);
    const auto rel = resolved.lexically_relative(base);
    if (ec || rel.empty() || *rel.begin() == "..")
      throw Error(ErrorCode::InvalidArgument, place(set, key), "'" + name + "' leaves the job's directory");
  }
  if (!fs::is_regular_file(resolved, ec))
    throw Error(ErrorCode::IoError, place(set, key), "no such file: " + resolved.string());
  return resolved.string();
}

JobContext::Raster JobContext::raster(int fallback_resolution, double fallback_band) const {
  const config::Set& r = section("raster", {"resolution", "depth", "voxel_size", "band"});
  Raster out;
  out.resolution = fallback_resolution;
  if (has(r, "depth")) {
    if (has(r, "resolution"))
      throw Error(ErrorCode::InvalidArgument, place(r, "depth"), "give 'depth' or 'resolution', not both");
    out.resolution = 1 << integer(r, "depth", 7, 3, 12);
  }
  out.resolution = integer(r, "resolution", out.resolution, 8, 4096);
  out.voxel_size = number(r, "voxel_size", 0.0, 0.0, 1e30);
  out.band = number(r, "band", fallback_band, 1.0, 16.0);
  return out;
}

NarrowBand JobContext::input_band(const config::Set& input) const {
  const int given = (has(input, "shape") ? 1 : 0) + (has(input, "mesh") ? 1 : 0) + (has(input, "lsg") ? 1 : 0);
  if (given == 0 && options_.input_band) return *options_.input_band;
  if (given != 1)
    throw Error(ErrorCode::InvalidArgument, options_.name,
                "the input set needs exactly one of shape = NAME, mesh = FILE, lsg = FILE");
  const Raster r = raster();
  auto frame_for = [&](const BBox& bounds) {
    if (r.voxel_size <= 0) return frame_for_resolution(bounds, r.resolution, r.band);
    GridFrame f;
    f.voxel_size = r.voxel_size;
    f.half_width = r.band;
    const double pad = (r.band + 1) * r.voxel_size;
    f.origin = bounds.min - Vec3d{pad, pad, pad};
    return f;
  };
  // Placement (shapes and meshes): x -> scale * x + translate.
  const Vec3d translate = vec3(input, "translate", {0, 0, 0});
  const double scale = number(input, "scale", 1.0, 1e-6, 1e6);
  if (has(input, "shape")) {
    const auto shape = make_builtin_shape(word(input, "shape", "", builtin_shape_names()));
    const BBox b = shape->bounds();
    const BBox placed{b.min * scale + translate, b.max * scale + translate};
    SdfBuildOptions o;
    o.frame = frame_for(placed);
    o.progress = options_.progress;
    if (options_.max_domain_voxels > 0) o.max_domain_voxels = options_.max_domain_voxels;
    log("input: built-in " + shape->name());
    return build_from_sdf([&](const Vec3d& p) { return scale * shape->distance((p - translate) / scale); }, placed, o)
        .band;
  }
  if (has(input, "mesh")) {
    const std::string path = input_path(input, "mesh");
    MeshReadResult read = read_mesh(path);
    for (Vec3d& v : read.mesh.vertices) v = v * scale + translate;
    CptOptions o;
    o.frame = frame_for(read.mesh.bounds());
    o.progress = options_.progress;
    if (options_.max_domain_voxels > 0) o.max_domain_voxels = options_.max_domain_voxels;
    log("input: " + path + " (" + std::to_string(read.mesh.triangles.size()) + " triangles), closest point transform");
    return closest_point_transform(read.mesh, o).band;
  }
  if (has(input, "translate") || has(input, "scale"))
    throw Error(ErrorCode::InvalidArgument, place(input, has(input, "scale") ? "scale" : "translate"),
                "a saved level set (lsg) cannot be moved or scaled here");
  const std::string path = input_path(input, "lsg");
  log("input: " + path);
  return load_lsg(path).band;
}

const config::Set& JobContext::output_section() const { return section("output", {"mesh", "lsg", "method"}); }

std::string JobContext::output_path(std::string_view file_name) const {
  return (fs::path(options_.output_dir) / std::string(file_name)).string();
}

void JobContext::write_band(const NarrowBand& band, std::string_view suffix) {
  if (options_.band_sink) options_.band_sink(band, suffix);
  const config::Set& out = output_section();
  if (!flag(out, "lsg", true)) return;
  const std::string path = output_path(std::string(stem(options_.name)) + std::string(suffix) + ".lsg");
  save_lsg(band, path);
  add_output(path);
}

SurfaceResult JobContext::surface_of(const NarrowBand& band) const {
  const config::Set& out = output_section();
  const std::string method = word(out, "method", "mc", {"mc", "nets"});
  return method == "nets" ? surface_nets(band, {}) : marching_cubes(band, {});
}

MeshMeasures JobContext::measure_band(const NarrowBand& band) const { return measure_mesh(surface_of(band).mesh); }

MeshMeasures JobContext::write_surface(const NarrowBand& band, std::string_view suffix) {
  const SurfaceResult surface = surface_of(band);
  const MeshMeasures m = measure_mesh(surface.mesh);
  stats_[std::string("mesh") + std::string(suffix)] = measures_json(m);
  write_mesh(surface.mesh, suffix);
  return m;
}

void JobContext::write_mesh(const TriangleMesh& mesh, std::string_view suffix) {
  const config::Set& out = output_section();
  const std::string format = word(out, "mesh", "ply", {"ply", "obj", "off", "stl", "none"});
  if (format == "none") return;
  const std::string path = output_path(std::string(stem(options_.name)) + std::string(suffix) + "." + format);
  levelset::write_mesh(mesh, path);
  add_output(path);
}

void JobContext::log(const std::string& line) const {
  if (options_.log) options_.log(line);
}

std::string stem(std::string_view job_name) {
  std::string s = fs::path(std::string(job_name)).filename().string();
  if (s.size() > 5 && s.compare(s.size() - 5, 5, ".conf") == 0) s.resize(s.size() - 5);
  return s.empty() ? "job" : s;
}


}  // namespace levelset::jobs
