// Internal to common/io: the per-format mesh readers behind read_mesh (mesh_reader.hpp) and
// the state and helpers they share. Not a public interface; include only from common/io/*.cpp.
//
// Contract: mesh_reader.cpp picks the format (by extension, and for .stl by sniffing), refuses
// empty and oversized input, builds one Reader and calls exactly one read_* below. Each read_*
// parses the whole of r.bytes into r.result (mesh, source_faces, polygons_triangulated; PLY and
// STL also set r.result.format, the others get it from the dispatcher), checks counts against
// r.options / r.vertex_limit before allocating, steps the progress hook every kProgressEvery
// records and throws levelset::Error as documented in mesh_reader.hpp.
// Files: off_reader.cpp (OFF, tria), ply_mesh_reader.cpp, obj_reader.cpp, stl_reader.cpp.
#pragma once

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/error.hpp"
#include "io/mesh_reader.hpp"
#include "io/text_scanner.hpp"

namespace levelset::detail {

inline constexpr std::uint64_t kProgressEvery = std::uint64_t{1} << 20;
inline constexpr std::string_view kStage = "read mesh";

// Shared state of one read: limits, output, progress.
struct Reader {
  std::string_view bytes;
  std::string_view name;
  const MeshReadOptions& options;
  std::uint64_t vertex_limit;  // min(options.max_vertices, 2^32 - 1): indices are uint32
  MeshReadResult result;
  std::uint64_t records = 0;

  Reader(std::string_view b, std::string_view n, const MeshReadOptions& o)
      : bytes(b),
        name(n),
        options(o),
        vertex_limit(std::min<std::uint64_t>(o.max_vertices, UINT32_MAX)) {}

  void tick(std::size_t offset) {
    if (++records % kProgressEvery == 0)
      options.progress.step(static_cast<double>(offset) / static_cast<double>(bytes.size()),
                            kStage);
  }

  // Throws LimitExceeded (at `where`) when the counts from a header exceed the options.
  void check_counts(std::uint64_t vertices, std::uint64_t triangles, const std::string& where,
                    std::string_view what_triangles) const {
    if (vertices > vertex_limit)
      throw Error(ErrorCode::LimitExceeded, where,
                  "the file claims " + std::to_string(vertices) + " vertices, the limit is " +
                      std::to_string(vertex_limit));
    if (triangles > options.max_triangles)
      throw Error(ErrorCode::LimitExceeded, where,
                  "the file claims " + std::to_string(triangles) + " " +
                      std::string(what_triangles) + ", the limit is " +
                      std::to_string(options.max_triangles) + " triangles");
  }

  // Room for one more triangle, or LimitExceeded at `where`.
  void reserve_one_triangle(const auto& where_fn) const {
    if (result.mesh.triangles.size() >= options.max_triangles)
      throw Error(
          ErrorCode::LimitExceeded, where_fn(),
          "more than " + std::to_string(options.max_triangles) + " triangles after triangulation");
  }
};

// Fan triangulation of a polygon streamed one index at a time.
struct Fan {
  std::uint32_t first = 0, prev = 0;
  std::uint64_t count = 0;

  template <typename WhereFn>
  void add(std::uint32_t index, Reader& r, const WhereFn& where_fn) {
    if (count >= 2) {
      r.reserve_one_triangle(where_fn);
      r.result.mesh.triangles.push_back({first, prev, index});
    } else if (count == 0) {
      first = index;
    }
    prev = index;
    ++count;
  }

  // Call at the end of a face: counts it, refuses faces with fewer than 3 vertices.
  template <typename FailFn>
  void finish(Reader& r, const FailFn& fail) {
    if (count < 3) fail("a face needs at least 3 vertices, found " + std::to_string(count));
    ++r.result.source_faces;
    if (count > 3) ++r.result.polygons_triangulated;
    count = 0;
  }
};

// Consumes the rest of a record's line: only numbers (colors, normals, texture coordinates)
// may follow the required values.
inline void skip_numeric_extras(TextScanner& sc, std::string_view record) {
  for (std::string_view tok = sc.line_token(); !tok.empty(); tok = sc.line_token()) {
    if (!TextScanner::is_number(tok))
      sc.fail(ErrorCode::ParseError, "expected only numbers after the " + std::string(record) +
                                         ", found '" + TextScanner::quote(tok) + "'");
  }
  sc.consume_newline();
}

inline Vec3d read_vertex_on_line(TextScanner& sc) {
  Vec3d v;
  v.x = sc.parse_double(sc.line_token(), "a vertex x coordinate");
  v.y = sc.parse_double(sc.line_token(), "a vertex y coordinate");
  v.z = sc.parse_double(sc.line_token(), "a vertex z coordinate");
  return v;
}

// ASCII case-insensitive equality (STL keywords).
inline bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

// Little-endian uint32 at p (binary STL).
inline std::uint32_t load_le32(const char* p) {
  std::uint32_t u = 0;
  for (int i = 3; i >= 0; --i) u = (u << 8) | static_cast<unsigned char>(p[i]);
  return u;
}

// ---- the per-format readers ----------------------------------------------------------------

void read_off(Reader& r);         // off_reader.cpp
void read_tria(Reader& r);        // off_reader.cpp
void read_ply(Reader& r);         // ply_mesh_reader.cpp; sets the PLY format from the header
void read_obj(Reader& r);         // obj_reader.cpp
void read_stl_ascii(Reader& r);   // stl_reader.cpp; sets MeshFormat::StlAscii
void read_stl_binary(Reader& r);  // stl_reader.cpp; sets MeshFormat::StlBinary

}  // namespace levelset::detail
