#include "io/point_cloud_reader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <string>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "io/mesh_reader.hpp"
#include "io/ply_parser.hpp"
#include "io/text_scanner.hpp"

namespace levelset {

std::string_view to_string(PointCloudFormat format) {
  switch (format) {
    case PointCloudFormat::Xyz:
      return "xyz";
    case PointCloudFormat::Xyzn:
      return "xyzn";
    case PointCloudFormat::Pwn:
      return "pwn";
    case PointCloudFormat::Ply:
      return "ply";
    case PointCloudFormat::Off:
      return "off";
  }
  return "unknown";
}

namespace {

constexpr std::uint64_t kProgressEvery = std::uint64_t{1} << 20;
constexpr std::string_view kStage = "read point cloud";

void read_columns(std::string_view bytes, std::string_view name, PointCloudFormat format,
                  const PointCloudReadOptions& options, PointCloud& cloud) {
  TextScanner sc(bytes, name, '#');
  const std::uint64_t lines =
      static_cast<std::uint64_t>(std::count(bytes.begin(), bytes.end(), '\n')) + 1;
  cloud.points.reserve(std::min(lines, options.max_points));
  std::size_t columns = format == PointCloudFormat::Xyz ? 0 : 6;  // 0: decided by line 1
  std::uint64_t first_line = 0;
  static constexpr const char* kWhat[6] = {"a point x coordinate", "a point y coordinate",
                                           "a point z coordinate", "a normal x component",
                                           "a normal y component", "a normal z component"};
  while (sc.skip_to_token()) {
    std::array<std::string_view, 6> tok;
    std::size_t n = 0;
    for (std::string_view t = sc.line_token(); !t.empty(); t = sc.line_token()) {
      if (n == 6) {
        std::size_t more = 1;
        while (!sc.line_token().empty()) ++more;
        sc.fail(ErrorCode::ParseError,
                "expected " + std::string(columns == 0 ? "3 or 6" : std::to_string(columns)) +
                    " numbers on the line, found " + std::to_string(6 + more));
      }
      tok[n++] = t;
    }
    if (first_line == 0) {
      first_line = sc.line();
      if (columns == 0) {
        if (n != 3 && n != 6)
          sc.fail(ErrorCode::ParseError,
                  "expected 3 numbers (x y z) or 6 (x y z nx ny nz) on the line, found " +
                      std::to_string(n));
        columns = n;
      }
      if (columns == 6) cloud.normals.reserve(cloud.points.capacity());
    }
    if (n != columns)
      sc.fail(ErrorCode::ParseError,
              "expected " + std::to_string(columns) + " numbers on the line" +
                  (first_line != sc.line() ? " (as on line " + std::to_string(first_line) + ")"
                                           : std::string()) +
                  ", found " + std::to_string(n));
    if (cloud.points.size() >= options.max_points)
      sc.fail(ErrorCode::LimitExceeded,
              "more than " + std::to_string(options.max_points) + " points");
    double v[6];
    for (std::size_t i = 0; i < n; ++i) v[i] = sc.parse_double(tok[i], kWhat[i]);
    cloud.points.push_back({v[0], v[1], v[2]});
    if (n == 6) cloud.normals.push_back({v[3], v[4], v[5]});
    sc.consume_newline();
    if (cloud.points.size() % kProgressEvery == 0)
      options.progress.step(static_cast<double>(sc.offset()) / static_cast<double>(bytes.size()),
                            kStage);
  }
  if (cloud.points.empty())
    sc.fail(ErrorCode::Truncated,
            "expected at least one point, found only comments and blank lines");
}

void read_ply_points(std::string_view bytes, std::string_view name,
                     const PointCloudReadOptions& options, PointCloud& cloud) {
  const ply::Header h = ply::parse_header(bytes, name);
  const ply::Element* vertex = h.find("vertex");
  if (vertex == nullptr)
    throw Error(ErrorCode::ParseError, at_line(name, h.body_line - 1),
                "the PLY header declares no 'vertex' element");
  static constexpr const char* kNames[6] = {"x", "y", "z", "nx", "ny", "nz"};
  int slot_of[6];
  for (int a = 0; a < 6; ++a) {
    slot_of[a] = vertex->find(kNames[a]);
    if (slot_of[a] >= 0 && vertex->properties[static_cast<std::size_t>(slot_of[a])].is_list)
      throw Error(ErrorCode::ParseError, at_line(name, vertex->line),
                  std::string("the vertex property '") + kNames[a] + "' is a list");
    if (a < 3 && slot_of[a] < 0)
      throw Error(ErrorCode::ParseError, at_line(name, vertex->line),
                  std::string("the 'vertex' element has no property '") + kNames[a] + "'");
  }
  const int normal_parts = (slot_of[3] >= 0) + (slot_of[4] >= 0) + (slot_of[5] >= 0);
  if (normal_parts != 0 && normal_parts != 3)
    throw Error(ErrorCode::ParseError, at_line(name, vertex->line),
                "the 'vertex' element has only some of nx, ny, nz");
  const bool normals = normal_parts == 3;
  if (vertex->count > options.max_points)
    throw Error(ErrorCode::LimitExceeded, at_line(name, vertex->line),
                "the file claims " + std::to_string(vertex->count) + " points, the limit is " +
                    std::to_string(options.max_points));
  ply::check_body_size(h, bytes, name);

  // role[p]: which of x y z nx ny nz property p is, or -1.
  std::vector<int> role(vertex->properties.size(), -1);
  for (int a = 0; a < (normals ? 6 : 3); ++a) role[static_cast<std::size_t>(slot_of[a])] = a;
  cloud.points.reserve(vertex->count);
  if (normals) cloud.normals.reserve(vertex->count);
  ply::BodyReader body(h, bytes, name);
  std::uint64_t records = 0;
  for (const ply::Element& e : h.elements) {
    for (std::uint64_t i = 0; i < e.count; ++i) {
      if (&e != vertex) {
        for (const ply::Property& prop : e.properties) body.skip(prop);
      } else {
        double v[6] = {0, 0, 0, 0, 0, 0};
        for (std::size_t p = 0; p < e.properties.size(); ++p) {
          const int a = role[p];
          if (a < 0) {
            body.skip(e.properties[p]);
            continue;
          }
          v[a] = body.read_number(e.properties[p].type, kNames[a]);
          if (!std::isfinite(v[a]))
            body.fail(ErrorCode::NonFinite,
                      "point " + std::to_string(i) + " has a non-finite " + kNames[a] + " value");
        }
        cloud.points.push_back({v[0], v[1], v[2]});
        if (normals) cloud.normals.push_back({v[3], v[4], v[5]});
      }
      if (++records % kProgressEvery == 0) options.progress.step(body.fraction(), kStage);
    }
  }
  body.finish();
}

PointCloudFormat format_from_name(std::string_view name) {
  std::string ext = std::filesystem::path(std::string(name)).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".xyz") return PointCloudFormat::Xyz;
  if (ext == ".xyzn") return PointCloudFormat::Xyzn;
  if (ext == ".pwn") return PointCloudFormat::Pwn;
  if (ext == ".ply") return PointCloudFormat::Ply;
  if (ext == ".off") return PointCloudFormat::Off;
  throw Error(
      ErrorCode::UnsupportedFormat, std::string(name),
      "unknown point cloud extension '" + ext + "' (expected .xyz, .xyzn, .pwn, .ply or .off)");
}

}  // namespace

PointCloudReadResult read_point_cloud_from_memory(std::string_view bytes, std::string_view name,
                                                  const PointCloudReadOptions& options) {
  PointCloudReadResult result;
  result.format = format_from_name(name);
  if (bytes.size() > options.max_file_bytes)
    throw Error(ErrorCode::LimitExceeded, std::string(name),
                "the input is " + std::to_string(bytes.size()) + " bytes, the limit is " +
                    std::to_string(options.max_file_bytes));
  if (bytes.empty()) throw Error(ErrorCode::Truncated, at_line(name, 1), "the file is empty");
  options.progress.check(kStage);
  switch (result.format) {
    case PointCloudFormat::Xyz:
    case PointCloudFormat::Xyzn:
    case PointCloudFormat::Pwn:
      read_columns(bytes, name, result.format, options, result.cloud);
      break;
    case PointCloudFormat::Ply:
      read_ply_points(bytes, name, options, result.cloud);
      break;
    case PointCloudFormat::Off: {
      MeshReadOptions mesh_options;
      mesh_options.max_file_bytes = options.max_file_bytes;
      mesh_options.max_vertices = options.max_points;
      mesh_options.progress = options.progress;
      result.cloud.points = read_mesh_from_memory(bytes, name, mesh_options).mesh.vertices;
      break;
    }
  }
  return result;
}

PointCloudReadResult read_point_cloud(const std::filesystem::path& path,
                                      const PointCloudReadOptions& options) {
  format_from_name(path.string());  // refuse unknown extensions before reading
  const std::string bytes = read_file_bytes(path, options.max_file_bytes);
  return read_point_cloud_from_memory(bytes, path.string(), options);
}

}  // namespace levelset
