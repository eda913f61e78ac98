// OFF (and its ST/C/N variants) and the thesis tria format: counted text records.
#include "io/mesh_format_readers.hpp"

#include <array>
#include <cctype>
#include <cstdint>
#include <string>
#include <string_view>

#include "io/ply_parser.hpp"

namespace levelset::detail {

namespace {

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

// Moves to record i (zero-based) of n, or Truncated when the file ends first.
void skip_to_record(TextScanner& sc, std::string_view what, std::uint64_t i, std::uint64_t n) {
  if (!sc.skip_to_token())
    sc.fail(ErrorCode::Truncated, "expected " + std::string(what) + " " + std::to_string(i + 1) +
                                      " of " + std::to_string(n) + ", found the end of the file");
}

// Reads nv vertex records, one a line; end_of_record consumes what follows the coordinates.
template <typename EndOfRecord>
void read_vertex_records(Reader& r, TextScanner& sc, std::uint64_t nv,
                         const EndOfRecord& end_of_record) {
  auto& vertices = r.result.mesh.vertices;
  vertices.reserve(nv);
  for (std::uint64_t i = 0; i < nv; ++i) {
    skip_to_record(sc, "vertex", i, nv);
    vertices.push_back(read_vertex_on_line(sc));
    end_of_record();
    r.tick(sc.offset());
  }
}

void expect_only_whitespace(TextScanner& sc, std::string_view after) {
  if (sc.skip_to_token())
    sc.fail(ErrorCode::ParseError, "expected the end of the file after " + std::string(after) +
                                       ", found '" + TextScanner::quote(sc.line_token()) + "'");
}

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

std::uint64_t read_header_number(TextScanner& sc, std::string_view what, std::uint64_t& line) {
  if (!sc.skip_to_token()) sc.fail_missing(what);
  const std::uint64_t n = sc.parse_count(sc.line_token(), what);
  line = sc.line();
  sc.expect_end_of_line(what);
  return n;
}

}  // namespace

// ---- OFF ---------------------------------------------------------------------------------

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
  mesh.triangles.reserve(nf);
  read_vertex_records(r, sc, nv, [&] { skip_numeric_extras(sc, "vertex coordinates"); });
  Fan fan;
  const auto where_fn = [&] { return sc.where(); };
  const auto fail_fn = [&](std::string reason) {
    sc.fail(ErrorCode::ParseError, std::move(reason));
  };
  for (std::uint64_t f = 0; f < nf; ++f) {
    skip_to_record(sc, "face", f, nf);
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
  mesh.triangles.reserve(nt);
  read_vertex_records(r, sc, nv, [&] { sc.expect_end_of_line("the vertex coordinates"); });
  for (std::uint64_t t = 0; t < nt; ++t) {
    skip_to_record(sc, "triangle", t, nt);
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

}  // namespace levelset::detail
