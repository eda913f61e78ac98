#include "io/mesh_reader.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "io/ply_parser.hpp"
#include "io/text_scanner.hpp"

namespace levelset {

std::string_view to_string(MeshFormat format) {
  switch (format) {
    case MeshFormat::Off:
      return "off";
    case MeshFormat::Tria:
      return "tria";
    case MeshFormat::PlyAscii:
      return "ply_ascii";
    case MeshFormat::PlyBinaryLittleEndian:
      return "ply_binary_little_endian";
    case MeshFormat::PlyBinaryBigEndian:
      return "ply_binary_big_endian";
    case MeshFormat::Obj:
      return "obj";
    case MeshFormat::StlAscii:
      return "stl_ascii";
    case MeshFormat::StlBinary:
      return "stl_binary";
  }
  return "unknown";
}

namespace {

constexpr std::uint64_t kProgressEvery = std::uint64_t{1} << 20;
constexpr std::string_view kStage = "read mesh";

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
void skip_numeric_extras(TextScanner& sc, std::string_view record) {
  for (std::string_view tok = sc.line_token(); !tok.empty(); tok = sc.line_token()) {
    if (!TextScanner::is_number(tok))
      sc.fail(ErrorCode::ParseError, "expected only numbers after the " + std::string(record) +
                                         ", found '" + TextScanner::quote(tok) + "'");
  }
  sc.consume_newline();
}

Vec3d read_vertex_on_line(TextScanner& sc) {
  Vec3d v;
  v.x = sc.parse_double(sc.line_token(), "a vertex x coordinate");
  v.y = sc.parse_double(sc.line_token(), "a vertex y coordinate");
  v.z = sc.parse_double(sc.line_token(), "a vertex z coordinate");
  return v;
}

std::uint32_t checked_index(const TextScanner& sc, std::uint64_t index, std::uint64_t nv) {
  if (index >= nv)
    sc.fail(ErrorCode::ParseError, "vertex index " + std::to_string(index) +
                                       " is out of range (the file has " + std::to_string(nv) +
                                       " vertices)");
  return static_cast<std::uint32_t>(index);
}

// Bytes that nv vertex records and nf face records need at least.
void check_text_room(const TextScanner& sc, std::uint64_t nv, std::uint64_t vertex_bytes,
                     std::uint64_t nf, std::uint64_t face_bytes, const std::string& where) {
  std::uint64_t needed = ply::saturating_add(ply::saturating_mul(nv, vertex_bytes),
                                             ply::saturating_mul(nf, face_bytes));
  if (needed > 0) --needed;  // the final newline may be missing
  if (needed > sc.remaining())
    throw Error(ErrorCode::Truncated, where,
                "the header claims " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                    " faces, which need at least " + std::to_string(needed) + " bytes, but only " +
                    std::to_string(sc.remaining()) + " bytes follow");
}

void expect_only_whitespace(TextScanner& sc, std::string_view after) {
  if (sc.skip_to_token())
    sc.fail(ErrorCode::ParseError, "expected the end of the file after " + std::string(after) +
                                       ", found '" + TextScanner::quote(sc.line_token()) + "'");
}

// ---- OFF ---------------------------------------------------------------------------------

// Accepts [ST][C][N]OFF; refuses 4OFF / nOFF (4D and n-dimensional vertices).
void check_off_keyword(const TextScanner& sc, std::string_view kw) {
  std::string_view rest = kw;
  if (rest.starts_with("ST")) rest.remove_prefix(2);
  if (rest.starts_with("C")) rest.remove_prefix(1);
  if (rest.starts_with("N")) rest.remove_prefix(1);
  if (rest.starts_with("4") || rest.starts_with("n"))
    sc.fail(ErrorCode::UnsupportedFormat,
            "'" + TextScanner::quote(kw) + "' (4D or n-dimensional vertices) is not supported");
  if (rest != "OFF")
    sc.fail(ErrorCode::ParseError,
            "expected an OFF keyword (OFF, COFF, NOFF, CNOFF, STOFF...) or the vertex count, "
            "found '" +
                TextScanner::quote(kw) + "'");
}

void read_off(Reader& r) {
  TextScanner sc(r.bytes, r.name, '#');
  if (!sc.skip_to_token())
    sc.fail(ErrorCode::Truncated, "expected the OFF header, found only comments");
  std::string_view tok = sc.line_token();
  if (std::isalpha(static_cast<unsigned char>(tok[0])) ||
      tok.find("OFF") != std::string_view::npos) {
    check_off_keyword(sc, tok);
    if (sc.at_end_of_line()) {
      sc.consume_newline();
      if (!sc.skip_to_token())
        sc.fail(ErrorCode::Truncated,
                "expected the vertex and face counts, found the end of the file");
    }
    tok = sc.line_token();
    if (tok == "BINARY") sc.fail(ErrorCode::UnsupportedFormat, "binary OFF is not supported");
  }
  const std::string header_where = sc.where();
  const std::uint64_t nv = sc.parse_count(tok, "the vertex count");
  const std::uint64_t nf = sc.parse_count(sc.line_token(), "the face count");
  const std::string_view ne = sc.line_token();
  if (!ne.empty()) sc.parse_count(ne, "the edge count");
  sc.expect_end_of_line("the vertex, face and edge counts");
  r.check_counts(nv, nf, header_where, "faces");
  check_text_room(sc, nv, 6, nf, 8, header_where);

  auto& mesh = r.result.mesh;
  mesh.vertices.reserve(nv);
  mesh.triangles.reserve(nf);
  for (std::uint64_t i = 0; i < nv; ++i) {
    if (!sc.skip_to_token())
      sc.fail(ErrorCode::Truncated, "expected vertex " + std::to_string(i + 1) + " of " +
                                        std::to_string(nv) + ", found the end of the file");
    mesh.vertices.push_back(read_vertex_on_line(sc));
    skip_numeric_extras(sc, "vertex coordinates");
    r.tick(sc.offset());
  }
  Fan fan;
  const auto where_fn = [&] { return sc.where(); };
  const auto fail_fn = [&](std::string reason) {
    sc.fail(ErrorCode::ParseError, std::move(reason));
  };
  for (std::uint64_t f = 0; f < nf; ++f) {
    if (!sc.skip_to_token())
      sc.fail(ErrorCode::Truncated, "expected face " + std::to_string(f + 1) + " of " +
                                        std::to_string(nf) + ", found the end of the file");
    const std::uint64_t n = sc.parse_count(sc.line_token(), "the vertex count of a face");
    if (n < 3) fail_fn("a face needs at least 3 vertices, found " + std::to_string(n));
    if (n > sc.remaining() / 2 + 1)
      sc.fail(ErrorCode::Truncated, "a face claims " + std::to_string(n) + " vertices but only " +
                                        std::to_string(sc.remaining()) + " bytes remain");
    for (std::uint64_t k = 0; k < n; ++k) {
      const std::uint64_t index = sc.parse_count(sc.line_token(), "a vertex index");
      fan.add(checked_index(sc, index, nv), r, where_fn);
    }
    fan.finish(r, fail_fn);
    skip_numeric_extras(sc, "face's vertex indices");
    r.tick(sc.offset());
  }
  expect_only_whitespace(sc, "the " + std::to_string(nf) + " faces the header declares");
}

// ---- tria (thesis appendix A.4) ------------------------------------------------------------

std::uint64_t read_header_number(TextScanner& sc, std::string_view what, std::uint64_t& line) {
  if (!sc.skip_to_token()) sc.fail_missing(what);
  const std::uint64_t n = sc.parse_count(sc.line_token(), what);
  line = sc.line();
  sc.expect_end_of_line(what);
  return n;
}

void read_tria(Reader& r) {
  TextScanner sc(r.bytes, r.name);
  if (!sc.skip_to_token()) sc.fail(ErrorCode::Truncated, "expected the tria header 4, nv, nt");
  const std::string_view magic = sc.line_token();
  if (magic != "4")
    sc.fail(ErrorCode::ParseError,
            "expected the tria header's first line '4', found '" + TextScanner::quote(magic) + "'");
  sc.expect_end_of_line("the tria magic number");
  std::uint64_t line = 0;
  const std::uint64_t nv = read_header_number(sc, "the vertex count", line);
  r.check_counts(nv, 0, at_line(r.name, line), "triangles");
  const std::uint64_t nt = read_header_number(sc, "the triangle count", line);
  r.check_counts(0, nt, at_line(r.name, line), "triangles");
  check_text_room(sc, nv, 6, nt, 6, at_line(r.name, line));

  auto& mesh = r.result.mesh;
  mesh.vertices.reserve(nv);
  mesh.triangles.reserve(nt);
  for (std::uint64_t i = 0; i < nv; ++i) {
    if (!sc.skip_to_token())
      sc.fail(ErrorCode::Truncated, "expected vertex " + std::to_string(i + 1) + " of " +
                                        std::to_string(nv) + ", found the end of the file");
    mesh.vertices.push_back(read_vertex_on_line(sc));
    sc.expect_end_of_line("the vertex coordinates");
    r.tick(sc.offset());
  }
  for (std::uint64_t t = 0; t < nt; ++t) {
    if (!sc.skip_to_token())
      sc.fail(ErrorCode::Truncated, "expected triangle " + std::to_string(t + 1) + " of " +
                                        std::to_string(nt) + ", found the end of the file");
    std::array<std::uint32_t, 3> tri{};
    for (auto& index : tri)
      index = checked_index(sc, sc.parse_count(sc.line_token(), "a vertex index"), nv);
    sc.expect_end_of_line("the triangle's three vertex indices");
    mesh.triangles.push_back(tri);
    r.tick(sc.offset());
  }
  r.result.source_faces = nt;
  expect_only_whitespace(sc, "the " + std::to_string(nt) + " triangles the header declares");
}

// ---- PLY ----------------------------------------------------------------------------------

void read_ply(Reader& r) {
  const ply::Header h = ply::parse_header(r.bytes, r.name);
  switch (h.encoding) {
    case ply::Encoding::Ascii:
      r.result.format = MeshFormat::PlyAscii;
      break;
    case ply::Encoding::BinaryLittleEndian:
      r.result.format = MeshFormat::PlyBinaryLittleEndian;
      break;
    case ply::Encoding::BinaryBigEndian:
      r.result.format = MeshFormat::PlyBinaryBigEndian;
      break;
  }
  const ply::Element* vertex = h.find("vertex");
  const ply::Element* face = h.find("face");
  if (vertex == nullptr)
    throw Error(ErrorCode::ParseError, at_line(r.name, h.body_line - 1),
                "the PLY header declares no 'vertex' element");
  if (face == nullptr)
    throw Error(ErrorCode::ParseError, at_line(r.name, h.body_line - 1),
                "the PLY header declares no 'face' element (a point cloud? read it with "
                "read_point_cloud)");
  int xyz[3];
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    xyz[a] = vertex->find(axes[a]);
    if (xyz[a] < 0 || vertex->properties[static_cast<std::size_t>(xyz[a])].is_list)
      throw Error(ErrorCode::ParseError, at_line(r.name, vertex->line),
                  std::string("the 'vertex' element has no scalar property '") + axes[a] + "'");
  }
  int indices = face->find("vertex_indices");
  if (indices < 0) indices = face->find("vertex_index");
  if (indices < 0 || !face->properties[static_cast<std::size_t>(indices)].is_list)
    throw Error(ErrorCode::ParseError, at_line(r.name, face->line),
                "the 'face' element has no list property 'vertex_indices' or 'vertex_index'");
  if (!ply::is_integer(face->properties[static_cast<std::size_t>(indices)].type))
    throw Error(ErrorCode::UnsupportedFormat, at_line(r.name, face->line),
                "the face vertex indices must have an integer type");
  r.check_counts(vertex->count, 0, at_line(r.name, vertex->line), "faces");
  r.check_counts(0, face->count, at_line(r.name, face->line), "faces");
  ply::check_body_size(h, r.bytes, r.name);
  {
    // Every face lists at least 3 indices: a tighter bound than the generic one, before the
    // triangles are reserved.
    const ply::Property& list = face->properties[static_cast<std::size_t>(indices)];
    const std::uint64_t min_face =
        h.encoding == ply::Encoding::Ascii
            ? 2 * face->properties.size() + 6
            : ply::min_item_bytes(*face, h.encoding) + 3 * ply::type_size(list.type);
    const std::uint64_t available = r.bytes.size() - h.body_offset + 1;
    if (ply::saturating_mul(face->count, min_face) > available)
      throw Error(ErrorCode::Truncated, at_line(r.name, face->line),
                  "element 'face' claims " + std::to_string(face->count) +
                      " faces of at least 3 vertices, which need at least " +
                      std::to_string(min_face) + " bytes each, but only " +
                      std::to_string(available - 1) + " bytes follow the header");
  }

  auto& mesh = r.result.mesh;
  mesh.vertices.reserve(vertex->count);
  mesh.triangles.reserve(face->count);
  const std::uint64_t nv = vertex->count;
  ply::BodyReader body(h, r.bytes, r.name);
  const auto where_fn = [&] { return body.where(); };
  const auto fail_fn = [&](std::string reason) {
    body.fail(ErrorCode::ParseError, std::move(reason));
  };
  Fan fan;
  for (const ply::Element& e : h.elements) {
    const std::size_t np = e.properties.size();
    if (&e == vertex) {
      for (std::uint64_t i = 0; i < e.count; ++i) {
        Vec3d v;
        for (std::size_t p = 0; p < np; ++p) {
          const ply::Property& prop = e.properties[p];
          const int ip = static_cast<int>(p);
          if (ip == xyz[0] || ip == xyz[1] || ip == xyz[2]) {
            const double value = body.read_number(prop.type, "a vertex coordinate");
            if (!std::isfinite(value))
              body.fail(ErrorCode::NonFinite, "vertex " + std::to_string(i) + " has a non-finite " +
                                                  prop.name + " coordinate");
            v[ip == xyz[0] ? 0 : (ip == xyz[1] ? 1 : 2)] = value;
          } else {
            body.skip(prop);
          }
        }
        mesh.vertices.push_back(v);
        if (++r.records % kProgressEvery == 0) r.options.progress.step(body.fraction(), kStage);
      }
    } else if (&e == face) {
      for (std::uint64_t f = 0; f < e.count; ++f) {
        for (std::size_t p = 0; p < np; ++p) {
          const ply::Property& prop = e.properties[p];
          if (static_cast<int>(p) != indices) {
            body.skip(prop);
            continue;
          }
          const std::uint64_t n = body.read_list_count(prop, "the vertex count of a face");
          if (n < 3) fail_fn("a face needs at least 3 vertices, found " + std::to_string(n));
          for (std::uint64_t k = 0; k < n; ++k) {
            const std::int64_t index = body.read_integer(prop.type, "a vertex index");
            if (index < 0 || static_cast<std::uint64_t>(index) >= nv)
              body.fail(ErrorCode::ParseError, "vertex index " + std::to_string(index) +
                                                   " is out of range (the file has " +
                                                   std::to_string(nv) + " vertices)");
            fan.add(static_cast<std::uint32_t>(index), r, where_fn);
          }
          fan.finish(r, fail_fn);
        }
        if (++r.records % kProgressEvery == 0) r.options.progress.step(body.fraction(), kStage);
      }
    } else {
      for (std::uint64_t i = 0; i < e.count; ++i) {
        for (const ply::Property& prop : e.properties) body.skip(prop);
        if (++r.records % kProgressEvery == 0) r.options.progress.step(body.fraction(), kStage);
      }
    }
  }
  body.finish();
}

// ---- OBJ ----------------------------------------------------------------------------------

bool is_ignored_obj_statement(std::string_view kw) {
  static constexpr std::string_view kIgnored[] = {
      "vt",     "vn",         "vp",        "g",     "o",     "s",        "usemtl",
      "mtllib", "l",          "p",         "deg",   "bmat",  "step",     "cstype",
      "curv",   "curv2",      "surf",      "parm",  "trim",  "hole",     "scrv",
      "sp",     "end",        "con",       "mg",    "bevel", "c_interp", "d_interp",
      "lod",    "shadow_obj", "trace_obj", "ctech", "stech", "maplib",   "usemap"};
  return std::find(std::begin(kIgnored), std::end(kIgnored), kw) != std::end(kIgnored);
}

// One face corner "v", "v/vt", "v/vt/vn" or "v//vn": returns the vertex part (1-based or
// negative); validates the other parts as integers.
std::int64_t parse_obj_corner(const TextScanner& sc, std::string_view tok) {
  const std::size_t s1 = tok.find('/');
  const std::int64_t v =
      sc.parse_int(tok.substr(0, s1 == std::string_view::npos ? tok.size() : s1), "a vertex index");
  if (s1 == std::string_view::npos) return v;
  const std::string_view rest = tok.substr(s1 + 1);
  const std::size_t s2 = rest.find('/');
  const std::string_view vt = rest.substr(0, s2 == std::string_view::npos ? rest.size() : s2);
  const auto bad = [&] {
    sc.fail(ErrorCode::ParseError, "expected a face corner v, v/vt, v/vt/vn or v//vn, found '" +
                                       TextScanner::quote(tok) + "'");
  };
  if (s2 == std::string_view::npos) {
    if (vt.empty()) bad();
    sc.parse_int(vt, "a texture coordinate index");
    return v;
  }
  const std::string_view vn = rest.substr(s2 + 1);
  if (vn.empty() || vn.find('/') != std::string_view::npos) bad();
  if (!vt.empty()) sc.parse_int(vt, "a texture coordinate index");
  sc.parse_int(vn, "a normal index");
  return v;
}

void read_obj(Reader& r) {
  TextScanner sc(r.bytes, r.name, '#');
  auto& mesh = r.result.mesh;
  // Positive indices may refer to vertices defined later; the largest one is checked at the end.
  std::uint64_t max_forward = 0;
  std::uint64_t max_forward_line = 0;
  Fan fan;
  const auto where_fn = [&] { return sc.where(); };
  const auto fail_fn = [&](std::string reason) {
    sc.fail(ErrorCode::ParseError, std::move(reason));
  };
  while (sc.skip_to_token()) {
    const std::string_view kw = sc.line_token();
    if (kw == "v") {
      if (mesh.vertices.size() >= r.vertex_limit)
        sc.fail(ErrorCode::LimitExceeded,
                "more than " + std::to_string(r.vertex_limit) + " vertices");
      mesh.vertices.push_back(read_vertex_on_line(sc));
      skip_numeric_extras(sc, "vertex coordinates");
    } else if (kw == "f") {
      const std::uint64_t nv = mesh.vertices.size();
      for (std::string_view tok = sc.line_token(); !tok.empty(); tok = sc.line_token()) {
        const std::int64_t v = parse_obj_corner(sc, tok);
        std::uint64_t index = 0;
        if (v > 0) {
          index = static_cast<std::uint64_t>(v) - 1;
          if (index >= r.vertex_limit)
            sc.fail(ErrorCode::ParseError, "vertex index " + std::to_string(v) +
                                               " is beyond the vertex limit " +
                                               std::to_string(r.vertex_limit));
          if (index >= nv && index >= max_forward) {
            max_forward = index + 1;
            max_forward_line = sc.line();
          }
        } else if (v < 0) {
          const std::uint64_t back = static_cast<std::uint64_t>(-(v + 1)) + 1;
          if (back > nv)
            sc.fail(ErrorCode::ParseError, "relative vertex index " + std::to_string(v) +
                                               " reaches before the first vertex (" +
                                               std::to_string(nv) + " vertices so far)");
          index = nv - back;
        } else {
          sc.fail(ErrorCode::ParseError, "vertex index 0 (OBJ indices start at 1)");
        }
        fan.add(static_cast<std::uint32_t>(index), r, where_fn);
      }
      fan.finish(r, fail_fn);
      sc.consume_newline();
    } else if (is_ignored_obj_statement(kw)) {
      sc.skip_line();
    } else {
      sc.fail(ErrorCode::ParseError,
              "expected an OBJ statement (v, f, vt, vn, g, o, s, usemtl, ...), found '" +
                  TextScanner::quote(kw) + "'");
    }
    r.tick(sc.offset());
  }
  if (max_forward > mesh.vertices.size())
    throw Error(ErrorCode::ParseError, at_line(r.name, max_forward_line),
                "vertex index " + std::to_string(max_forward) + " is out of range (the file has " +
                    std::to_string(mesh.vertices.size()) + " vertices)");
}

// ---- STL ----------------------------------------------------------------------------------

// Welds exactly equal coordinates (after mapping -0 to +0) into one vertex: open addressing
// on the bit patterns; table entries are vertex indices. The hash is seeded per process so that
// a crafted file cannot make every vertex collide (the output order does not depend on it).
class VertexWelder {
 public:
  // expected: a guess of the distinct vertices, to size the table once (it still grows).
  VertexWelder(std::vector<Vec3d>& out, std::uint64_t expected)
      : out_(out), table_(std::bit_ceil(std::max<std::uint64_t>(2 * expected, 1024)), kEmpty) {}

  // Index of p (appended if new); false when a new vertex would exceed limit.
  bool add(Vec3d p, std::uint64_t limit, std::uint32_t& index) {
    p = Vec3d{p.x + 0.0, p.y + 0.0, p.z + 0.0};
    const std::size_t mask = table_.size() - 1;
    std::size_t slot = hash(p) & mask;
    while (table_[slot] != kEmpty) {
      if (out_[table_[slot]] == p) {
        index = table_[slot];
        return true;
      }
      slot = (slot + 1) & mask;
    }
    if (out_.size() >= limit) return false;
    index = static_cast<std::uint32_t>(out_.size());
    out_.push_back(p);
    table_[slot] = index;
    if (out_.size() * 2 > table_.size()) grow();
    return true;
  }

 private:
  static constexpr std::uint32_t kEmpty = UINT32_MAX;

  static std::uint64_t seed() {
    static const std::uint64_t value = [] {
      std::random_device device;
      return (std::uint64_t{device()} << 32) ^ device();
    }();
    return value;
  }

  static std::size_t hash(const Vec3d& p) {
    std::uint64_t h = seed();
    for (const double c : {p.x, p.y, p.z}) {
      h = (h ^ std::bit_cast<std::uint64_t>(c)) * 0x9E3779B97F4A7C15ull;
      h ^= h >> 32;
    }
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 29;
    return static_cast<std::size_t>(h);
  }

  void grow() {
    std::vector<std::uint32_t> bigger(table_.size() * 2, kEmpty);
    const std::size_t mask = bigger.size() - 1;
    for (std::uint32_t i = 0; i < out_.size(); ++i) {
      std::size_t slot = hash(out_[i]) & mask;
      while (bigger[slot] != kEmpty) slot = (slot + 1) & mask;
      bigger[slot] = i;
    }
    table_.swap(bigger);
  }

  std::vector<Vec3d>& out_;
  std::vector<std::uint32_t> table_;
};

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

void read_stl_ascii(Reader& r) {
  r.result.format = MeshFormat::StlAscii;
  TextScanner sc(r.bytes, r.name);
  VertexWelder welder(r.result.mesh.vertices, 0);
  const auto expect = [&](std::string_view keyword) {
    const std::string_view tok = sc.next_token();
    if (tok.empty()) sc.fail_missing("'" + std::string(keyword) + "'");
    if (!iequals(tok, keyword))
      sc.fail(ErrorCode::ParseError,
              "expected '" + std::string(keyword) + "', found '" + TextScanner::quote(tok) + "'");
  };
  const auto where_fn = [&] { return sc.where(); };
  const auto fail_fn = [&](std::string reason) {
    sc.fail(ErrorCode::ParseError, std::move(reason));
  };
  expect("solid");
  sc.rest_of_line();  // the solid's name
  Fan fan;
  for (;;) {
    const std::string_view tok = sc.next_token();
    if (tok.empty()) sc.fail_missing("'facet' or 'endsolid'");
    if (iequals(tok, "endsolid")) {
      sc.rest_of_line();
      if (!sc.skip_to_token()) break;
      expect("solid");  // another solid follows
      sc.rest_of_line();
      continue;
    }
    if (!iequals(tok, "facet"))
      sc.fail(ErrorCode::ParseError,
              "expected 'facet' or 'endsolid', found '" + TextScanner::quote(tok) + "'");
    expect("normal");
    for (int k = 0; k < 3; ++k) sc.parse_any_number(sc.next_token(), "a facet normal component");
    expect("outer");
    expect("loop");
    for (;;) {
      const std::string_view vt = sc.next_token();
      if (vt.empty()) sc.fail_missing("'vertex' or 'endloop'");
      if (iequals(vt, "endloop")) break;
      if (!iequals(vt, "vertex"))
        sc.fail(ErrorCode::ParseError,
                "expected 'vertex' or 'endloop', found '" + TextScanner::quote(vt) + "'");
      Vec3d p;
      for (int k = 0; k < 3; ++k) p[k] = sc.parse_double(sc.next_token(), "a vertex coordinate");
      std::uint32_t index = 0;
      if (!welder.add(p, r.vertex_limit, index))
        sc.fail(ErrorCode::LimitExceeded,
                "more than " + std::to_string(r.vertex_limit) + " distinct vertices");
      fan.add(index, r, where_fn);
    }
    fan.finish(r, fail_fn);
    expect("endfacet");
    r.tick(sc.offset());
  }
}

std::uint32_t load_le32(const char* p) {
  std::uint32_t u = 0;
  for (int i = 3; i >= 0; --i) u = (u << 8) | static_cast<unsigned char>(p[i]);
  return u;
}

void read_stl_binary(Reader& r) {
  r.result.format = MeshFormat::StlBinary;
  const std::uint64_t size = r.bytes.size();
  if (size < 84)
    throw Error(ErrorCode::Truncated, at_byte(r.name, size),
                "a binary STL needs an 84-byte header, found " + std::to_string(size) + " bytes");
  const std::uint64_t n = load_le32(r.bytes.data() + 80);
  if (n > r.options.max_triangles)
    throw Error(ErrorCode::LimitExceeded, at_byte(r.name, 80),
                "the file claims " + std::to_string(n) + " triangles, the limit is " +
                    std::to_string(r.options.max_triangles));
  const std::uint64_t expected = 84 + 50 * n;
  if (size < expected)
    throw Error(ErrorCode::Truncated, at_byte(r.name, 80),
                "the header claims " + std::to_string(n) + " triangles, which need " +
                    std::to_string(expected) + " bytes, but the file has " + std::to_string(size));
  if (size > expected)
    throw Error(ErrorCode::ParseError, at_byte(r.name, expected),
                std::to_string(size - expected) + " unexpected bytes after the last of the " +
                    std::to_string(n) + " triangles the header claims");
  auto& mesh = r.result.mesh;
  mesh.triangles.reserve(n);
  const std::uint64_t expected_vertices = std::min<std::uint64_t>(n / 2 + 3, r.vertex_limit);
  mesh.vertices.reserve(expected_vertices);
  VertexWelder welder(mesh.vertices, expected_vertices);
  for (std::uint64_t t = 0; t < n; ++t) {
    const std::uint64_t record = 84 + 50 * t;
    std::array<std::uint32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      Vec3d p;
      for (int a = 0; a < 3; ++a) {
        const std::uint64_t at =
            record + 12 + 12 * static_cast<std::uint64_t>(k) + 4 * static_cast<std::uint64_t>(a);
        const float value = std::bit_cast<float>(load_le32(r.bytes.data() + at));
        if (!std::isfinite(value))
          throw Error(ErrorCode::NonFinite, at_byte(r.name, at),
                      "triangle " + std::to_string(t) + " has a non-finite vertex coordinate");
        p[a] = static_cast<double>(value);
      }
      if (!welder.add(p, r.vertex_limit, tri[static_cast<std::size_t>(k)]))
        throw Error(ErrorCode::LimitExceeded, at_byte(r.name, record),
                    "more than " + std::to_string(r.vertex_limit) + " distinct vertices");
    }
    mesh.triangles.push_back(tri);
    r.tick(record);
  }
  r.result.source_faces = n;
}

// Binary when the size matches 84 + 50 n (even if it starts with "solid"), else ascii when it
// starts with "solid", else binary (and the size check explains what is wrong).
bool stl_is_binary(std::string_view bytes) {
  if (bytes.size() >= 84 && 84 + 50 * std::uint64_t{load_le32(bytes.data() + 80)} == bytes.size())
    return true;
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  return !(bytes.size() - i >= 5 && iequals(bytes.substr(i, 5), "solid"));
}

// ---- dispatch -----------------------------------------------------------------------------

enum class Kind { Off, Tria, Ply, Obj, Stl };

Kind kind_from_name(std::string_view name) {
  std::string ext = std::filesystem::path(std::string(name)).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".off") return Kind::Off;
  if (ext == ".tria") return Kind::Tria;
  if (ext == ".ply") return Kind::Ply;
  if (ext == ".obj") return Kind::Obj;
  if (ext == ".stl") return Kind::Stl;
  throw Error(ErrorCode::UnsupportedFormat, std::string(name),
              "unknown mesh extension '" + ext + "' (expected .off, .tria, .ply, .obj or .stl)");
}

}  // namespace

MeshReadResult read_mesh_from_memory(std::string_view bytes, std::string_view name,
                                     const MeshReadOptions& options) {
  const Kind kind = kind_from_name(name);
  if (bytes.size() > options.max_file_bytes)
    throw Error(ErrorCode::LimitExceeded, std::string(name),
                "the input is " + std::to_string(bytes.size()) + " bytes, the limit is " +
                    std::to_string(options.max_file_bytes));
  if (bytes.empty())
    throw Error(ErrorCode::Truncated, kind == Kind::Stl ? at_byte(name, 0) : at_line(name, 1),
                "the file is empty");
  Reader r(bytes, name, options);
  options.progress.check(kStage);
  switch (kind) {
    case Kind::Off:
      r.result.format = MeshFormat::Off;
      read_off(r);
      break;
    case Kind::Tria:
      r.result.format = MeshFormat::Tria;
      read_tria(r);
      break;
    case Kind::Ply:
      read_ply(r);
      break;
    case Kind::Obj:
      r.result.format = MeshFormat::Obj;
      read_obj(r);
      break;
    case Kind::Stl:
      if (stl_is_binary(bytes))
        read_stl_binary(r);
      else
        read_stl_ascii(r);
      break;
  }
  return std::move(r.result);
}

MeshReadResult read_mesh(const std::filesystem::path& path, const MeshReadOptions& options) {
  kind_from_name(path.string());  // refuse unknown extensions before reading
  const std::string bytes = read_file_bytes(path, options.max_file_bytes);
  return read_mesh_from_memory(bytes, path.string(), options);
}

}  // namespace levelset
