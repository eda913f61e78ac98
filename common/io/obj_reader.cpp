// Wavefront OBJ: v and f statements (absolute, relative and forward indices); others ignored.
#include "io/mesh_format_readers.hpp"

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <string>
#include <string_view>

namespace levelset::detail {

namespace {

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

}  // namespace

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

}  // namespace levelset::detail
