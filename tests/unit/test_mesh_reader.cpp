// read_mesh / read_mesh_from_memory: every format's good input, every malformed case with its
// ErrorCode and the line or byte named in `where`, limits checked before allocating.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/mesh_reader.hpp"
#include "reader_test_support.hpp"

namespace levelset {
namespace {

using Tri = std::array<std::uint32_t, 3>;

MeshReadResult read(std::string_view bytes, std::string_view name,
                    const MeshReadOptions& options = {}) {
  return read_mesh_from_memory(bytes, name, options);
}

using test::Bytes;

// Succeeds when reading fails with exactly this code and where.
::testing::AssertionResult fails_with(std::string_view bytes, std::string_view name, ErrorCode code,
                                      std::string_view where, const MeshReadOptions& options = {}) {
  return test::fails_with([&] { return read_mesh_from_memory(bytes, name, options); },
                          [](const MeshReadResult& r) {
                            return std::to_string(r.mesh.vertices.size()) + " vertices, " +
                                   std::to_string(r.mesh.triangles.size()) + " triangles";
                          },
                          code, where);
}

const std::string kCubeOff =
    "OFF\n"                                                     // 1
    "8 12 0\n"                                                  // 2
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"  // 3-10
    "3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n"    // 11-16
    "3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";   // 17-22

// ---- OFF ----------------------------------------------------------------------------------

TEST(MeshReaderOff, ReadsTriangleMesh) {
  const MeshReadResult r = read(kCubeOff, "cube.off");
  EXPECT_EQ(r.format, MeshFormat::Off);
  ASSERT_EQ(r.mesh.vertices.size(), 8u);
  ASSERT_EQ(r.mesh.triangles.size(), 12u);
  EXPECT_EQ(r.mesh.vertices[6], (Vec3d{1, 1, 1}));
  EXPECT_EQ(r.mesh.triangles[0], (Tri{0, 2, 1}));
  EXPECT_EQ(r.mesh.triangles[11], (Tri{3, 4, 7}));
  EXPECT_EQ(r.source_faces, 12u);
  EXPECT_EQ(r.polygons_triangulated, 0u);
}

TEST(MeshReaderOff, ExtensionIsCaseInsensitiveAndValuesExact) {
  const MeshReadResult r =
      read("OFF\n3 1 0\n0.1 -2.5e-3 1e+2\n+3 .5 -0\n1.7976931348623157e308 4.9e-324 -7\n3 0 1 2\n",
           "UPPER.OFF");
  ASSERT_EQ(r.mesh.vertices.size(), 3u);
  EXPECT_EQ(r.mesh.vertices[0], (Vec3d{0.1, -2.5e-3, 100.0}));
  EXPECT_EQ(r.mesh.vertices[1], (Vec3d{3.0, 0.5, 0.0}));
  EXPECT_TRUE(std::signbit(r.mesh.vertices[1].z));
  EXPECT_EQ(r.mesh.vertices[2].x, std::numeric_limits<double>::max());
  EXPECT_EQ(r.mesh.vertices[2].y, std::numeric_limits<double>::denorm_min());
}

TEST(MeshReaderOff, NumberEdgeCases) {
  const auto one_vertex = [](const std::string& x) {
    return "OFF\n3 1 0\n" + x + " 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  };
  EXPECT_EQ(read(one_vertex("1e-400"), "u.off").mesh.vertices[0].x, 0.0);  // underflow: 0
  EXPECT_EQ(read(one_vertex("+1.5E+1"), "p.off").mesh.vertices[0].x, 15.0);
  EXPECT_EQ(read(one_vertex("0.000000000000000000000001"), "s.off").mesh.vertices[0].x, 1e-24);
  EXPECT_TRUE(fails_with(one_vertex("1" + std::string(400, '0')), "o.off", ErrorCode::NonFinite,
                         "o.off:3"));
  EXPECT_TRUE(fails_with(one_vertex("-1e309"), "o.off", ErrorCode::NonFinite, "o.off:3"));
  for (const char* bad : {"--1", "1.2.3", "+", "-", ".", "1e", "1,5", "0x10", "1_000", "\x01"}) {
    SCOPED_TRACE(bad);
    EXPECT_TRUE(fails_with(one_vertex(bad), "b.off", ErrorCode::ParseError, "b.off:3"));
  }
  for (const char* non_finite : {"nan", "-nan", "inf", "-inf", "infinity", "NaN", "INF"}) {
    SCOPED_TRACE(non_finite);
    EXPECT_TRUE(fails_with(one_vertex(non_finite), "n.off", ErrorCode::NonFinite, "n.off:3"));
  }
}

TEST(MeshReaderOff, SkipsCommentsEverywhere) {
  const std::string text =
      "# leading comment\n"
      "#CBP\n"
      "\n"
      "OFF # keyword comment\n"
      "# between\n"
      "3 1 0 # counts\n"
      "0 0 0 # v0\n"
      "   # indented comment\n"
      "1 0 0#v1 glued\n"
      "\n"
      "0 1 0\n"
      "# facets\n"
      "3 0 1 2 # face\n"
      "# trailing comment without newline";
  const MeshReadResult r = read(text, "comments.off");
  ASSERT_EQ(r.mesh.vertices.size(), 3u);
  EXPECT_EQ(r.mesh.vertices[1], (Vec3d{1, 0, 0}));
  ASSERT_EQ(r.mesh.triangles.size(), 1u);
  EXPECT_EQ(r.mesh.triangles[0], (Tri{0, 1, 2}));
}

TEST(MeshReaderOff, SkipsColorsNormalsAndTextureValues) {
  const std::string coff =
      "COFF\n4 2 0\n"
      "0 0 0 255 0 0 255\n"  // rgba ints
      "1 0 0 0.0 0.9 0.0\n"  // rgb floats
      "1 1 0 0 0 1 1\n"
      "0 1 0 1 1 1\n"
      "3 0 1 2 0.7 0 0\n"  // face color
      "3 0 2 3 255 0 0 255\n";
  MeshReadResult r = read(coff, "c.off");
  EXPECT_EQ(r.mesh.vertices.size(), 4u);
  EXPECT_EQ(r.mesh.triangles.size(), 2u);
  EXPECT_EQ(r.mesh.vertices[2], (Vec3d{1, 1, 0}));

  for (const char* kw : {"NOFF", "CNOFF", "STOFF", "STCNOFF"}) {
    SCOPED_TRACE(kw);
    const std::string text = std::string(kw) +
                             "\n3 1\n0 0 0 0 0 1 0.5 0.5\n1 0 0 0 0 1 0.5 0.5\n"
                             "0 1 0 0 0 1 0.5 0.5 1\n3 0 1 2\n";
    r = read(text, "n.off");
    ASSERT_EQ(r.mesh.vertices.size(), 3u);
    EXPECT_EQ(r.mesh.vertices[2], (Vec3d{0, 1, 0}));
    EXPECT_EQ(r.mesh.triangles.size(), 1u);
  }
}

TEST(MeshReaderOff, KeywordOptionalAndCountsOnKeywordLine) {
  const MeshReadResult a = read("3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "nokw.off");
  EXPECT_EQ(a.mesh.vertices.size(), 3u);
  EXPECT_EQ(a.mesh.triangles.size(), 1u);
  const MeshReadResult b = read("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2", "same.off");
  EXPECT_EQ(b.mesh.vertices.size(), 3u);
  EXPECT_EQ(b.mesh.triangles.size(), 1u);
  const MeshReadResult c = read("OFF\r\n3 1\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n", "crlf.off");
  EXPECT_EQ(c.mesh.triangles.size(), 1u);
  const MeshReadResult empty = read("OFF\n0 0 0\n", "empty_mesh.off");
  EXPECT_TRUE(empty.mesh.vertices.empty());
}

TEST(MeshReaderOff, FanTriangulatesPolygons) {
  const std::string text =
      "OFF\n6 2 0\n0 0 0\n1 0 0\n2 1 0\n1 2 0\n0 2 0\n-1 1 0\n"
      "4 0 1 2 3\n"
      "5 0 1 2 3 4\n";
  const MeshReadResult r = read(text, "poly.off");
  ASSERT_EQ(r.mesh.triangles.size(), 5u);  // quad -> 2, pentagon -> 3
  EXPECT_EQ(r.mesh.triangles[0], (Tri{0, 1, 2}));
  EXPECT_EQ(r.mesh.triangles[1], (Tri{0, 2, 3}));
  EXPECT_EQ(r.mesh.triangles[2], (Tri{0, 1, 2}));
  EXPECT_EQ(r.mesh.triangles[3], (Tri{0, 2, 3}));
  EXPECT_EQ(r.mesh.triangles[4], (Tri{0, 3, 4}));
  EXPECT_EQ(r.source_faces, 2u);
  EXPECT_EQ(r.polygons_triangulated, 2u);
}

TEST(MeshReaderOff, KeepsDegenerateAndNonManifoldFacesAsTheyAre) {
  // Repeated index, zero area, and three faces sharing one edge: all survive.
  const std::string text =
      "OFF\n5 4 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n"
      "3 0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n";
  const MeshReadResult r = read(text, "nm.off");
  ASSERT_EQ(r.mesh.triangles.size(), 4u);
  EXPECT_EQ(r.mesh.triangles[0], (Tri{0, 0, 1}));
}

TEST(MeshReaderOff, MalformedInput) {
  const std::string three = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";  // lines 1-5
  const std::string pad = "# padding so that the counts fit the bytes\n";
  EXPECT_TRUE(fails_with("", "e.off", ErrorCode::Truncated, "e.off:1"));
  EXPECT_TRUE(fails_with("# only\n# comments\n", "c.off", ErrorCode::Truncated, "c.off:3"));
  EXPECT_TRUE(fails_with("OFF\n", "k.off", ErrorCode::Truncated, "k.off:2"));
  EXPECT_TRUE(fails_with("OFF\n3\n", "k.off", ErrorCode::ParseError, "k.off:2"));
  EXPECT_TRUE(fails_with(three + "2 0 1\n" + pad, "a.off", ErrorCode::ParseError, "a.off:6"));
  EXPECT_TRUE(fails_with(three + "3 0 1 3\n", "a.off", ErrorCode::ParseError, "a.off:6"));
  EXPECT_TRUE(fails_with(three + "3 0 -1 2\n", "a.off", ErrorCode::ParseError, "a.off:6"));
  EXPECT_TRUE(fails_with(three + "3 0 1\n" + pad, "a.off", ErrorCode::ParseError, "a.off:6"));
  EXPECT_TRUE(fails_with(three + "3 0 1 2 red\n", "a.off", ErrorCode::ParseError, "a.off:6"));
  EXPECT_TRUE(fails_with(three + "3 0 1 2.5\n", "a.off", ErrorCode::ParseError, "a.off:6"));
  EXPECT_TRUE(fails_with(three + "3 0 1 2\n3 0 1 2\n", "a.off", ErrorCode::ParseError, "a.off:7"));
  EXPECT_TRUE(fails_with(three + "3 0 1 2\nxyz\n", "a.off", ErrorCode::ParseError, "a.off:7"));
  EXPECT_TRUE(fails_with("OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "n.off",
                         ErrorCode::NonFinite, "n.off:4"));
  EXPECT_TRUE(fails_with("OFF\n3 1 0\n0 0 0\n1 0 -inf\n0 1 0\n3 0 1 2\n", "n.off",
                         ErrorCode::NonFinite, "n.off:4"));
  EXPECT_TRUE(fails_with("OFF\n3 1 0\n0 0 0\n1 0 1e999\n0 1 0\n3 0 1 2\n", "n.off",
                         ErrorCode::NonFinite, "n.off:4"));
  EXPECT_TRUE(fails_with("OFF\n3 1 0\n0 0 0\n1 0 0x1\n0 1 0\n3 0 1 2\n", "g.off",
                         ErrorCode::ParseError, "g.off:4"));
  EXPECT_TRUE(fails_with("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n" + pad, "s.off",
                         ErrorCode::ParseError, "s.off:4"));
  EXPECT_TRUE(fails_with("OFF\n3 1 0\n0 0 0\n1 0 0 junk\n0 1 0\n3 0 1 2\n", "j.off",
                         ErrorCode::ParseError, "j.off:4"));
  EXPECT_TRUE(fails_with("OFX\n3 1 0\n", "x.off", ErrorCode::ParseError, "x.off:1"));
  EXPECT_TRUE(fails_with("4OFF\n3 1 0\n", "x.off", ErrorCode::UnsupportedFormat, "x.off:1"));
  EXPECT_TRUE(fails_with("nOFF\n3\n3 1 0\n", "x.off", ErrorCode::UnsupportedFormat, "x.off:1"));
  EXPECT_TRUE(fails_with("OFF BINARY\n", "x.off", ErrorCode::UnsupportedFormat, "x.off:1"));
  EXPECT_TRUE(fails_with("OFF\n-3 1 0\n", "x.off", ErrorCode::ParseError, "x.off:2"));
  EXPECT_TRUE(fails_with("OFF\n3 1 0 0\n", "x.off", ErrorCode::ParseError, "x.off:2"));
  EXPECT_TRUE(fails_with("OFF\n99999999999999999999999 1 0\n", "x.off", ErrorCode::LimitExceeded,
                         "x.off:2"));
}

TEST(MeshReaderOff, TruncatedInput) {
  // Enough bytes for the header's claims overall, but the file ends inside a record / early.
  const std::string wide =
      "OFF\n3 1 0\n0.000000 0.000000 0.000000\n1.000000 0.000000 0.000000\n"
      "0.000000 1.000000 0.000000\n3 0 1 2\n";  // lines 1-6
  EXPECT_TRUE(fails_with(wide.substr(0, wide.find("1.000000 0.000000\n3")), "t.off",
                         ErrorCode::Truncated, "t.off:5"));  // ends inside vertex 3
  EXPECT_TRUE(fails_with(wide.substr(0, wide.find("3 0 1 2")), "t.off", ErrorCode::Truncated,
                         "t.off:6"));  // ends before the face
  EXPECT_TRUE(fails_with(wide.substr(0, wide.size() - 3), "t.off", ErrorCode::Truncated,
                         "t.off:6"));  // ends inside the face
}

TEST(MeshReaderOff, AbsurdCountsRefusedBeforeAllocating) {
  std::string hundred = "OFF\n1000000000000 1000000000000 0\n";
  hundred.resize(100, ' ');
  EXPECT_TRUE(fails_with(hundred, "huge.off", ErrorCode::LimitExceeded, "huge.off:2"));
  MeshReadOptions unlimited;
  unlimited.max_vertices = UINT64_MAX;
  unlimited.max_triangles = UINT64_MAX;
  std::string hundred_in_limits = "OFF\n4000000000 1 0\n";
  hundred_in_limits.resize(100, ' ');
  EXPECT_TRUE(
      fails_with(hundred_in_limits, "huge.off", ErrorCode::Truncated, "huge.off:2", unlimited));
  std::string faces = "OFF\n3 1000000000000 0\n";
  faces.resize(100, ' ');
  EXPECT_TRUE(fails_with(faces, "huge.off", ErrorCode::Truncated, "huge.off:2", unlimited));
  // One face claiming a billion vertices.
  EXPECT_TRUE(fails_with("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1000000000 0 1 2\n", "f.off",
                         ErrorCode::Truncated, "f.off:6"));
}

TEST(MeshReaderOff, LimitsFromOptions) {
  MeshReadOptions small;
  small.max_vertices = 7;
  EXPECT_TRUE(fails_with(kCubeOff, "l.off", ErrorCode::LimitExceeded, "l.off:2", small));
  small = {};
  small.max_triangles = 11;
  EXPECT_TRUE(fails_with(kCubeOff, "l.off", ErrorCode::LimitExceeded, "l.off:2", small));
  // Triangulation may exceed the budget even when the face count does not.
  small.max_triangles = 2;
  EXPECT_TRUE(fails_with("OFF\n5 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n-1 0 0\n5 0 1 2 3 4\n", "p.off",
                         ErrorCode::LimitExceeded, "p.off:8", small));
  small = {};
  small.max_file_bytes = 10;
  EXPECT_TRUE(fails_with(kCubeOff, "b.off", ErrorCode::LimitExceeded, "b.off", small));
}

// ---- tria ---------------------------------------------------------------------------------

const std::string kTetTria =
    "4\n4\n4\n"                      // 1-3
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"   // 4-7
    "0 2 1\n0 1 3\n1 2 3\n0 3 2\n";  // 8-11

TEST(MeshReaderTria, ReadsThesisFormat) {
  const MeshReadResult r = read(kTetTria, "tet.tria");
  EXPECT_EQ(r.format, MeshFormat::Tria);
  ASSERT_EQ(r.mesh.vertices.size(), 4u);
  ASSERT_EQ(r.mesh.triangles.size(), 4u);
  EXPECT_EQ(r.mesh.vertices[3], (Vec3d{0, 0, 1}));
  EXPECT_EQ(r.mesh.triangles[3], (Tri{0, 3, 2}));
  EXPECT_EQ(r.source_faces, 4u);
}

TEST(MeshReaderTria, MalformedInput) {
  EXPECT_TRUE(fails_with("", "t.tria", ErrorCode::Truncated, "t.tria:1"));
  EXPECT_TRUE(fails_with("3\n4\n4\n", "t.tria", ErrorCode::ParseError, "t.tria:1"));
  EXPECT_TRUE(fails_with("4\n4 4\n", "t.tria", ErrorCode::ParseError, "t.tria:2"));
  EXPECT_TRUE(fails_with("4\n4\n", "t.tria", ErrorCode::Truncated, "t.tria:3"));
  std::string bad = kTetTria;
  bad.replace(bad.find("1 2 3"), 5, "1 2 4");
  EXPECT_TRUE(fails_with(bad, "t.tria", ErrorCode::ParseError, "t.tria:10"));
  bad = kTetTria;
  bad.replace(bad.find("0 1 3"), 5, "0 1 3 5");
  EXPECT_TRUE(fails_with(bad, "t.tria", ErrorCode::ParseError, "t.tria:9"));
  bad = kTetTria;
  bad.replace(bad.find("0 0 1\n"), 5, "0 0 nan");
  EXPECT_TRUE(fails_with(bad, "t.tria", ErrorCode::NonFinite, "t.tria:7"));
  bad = kTetTria;
  bad.replace(bad.find("1 0 0\n"), 5, "1 0");
  bad += "\n\n\n";
  EXPECT_TRUE(fails_with(bad, "t.tria", ErrorCode::ParseError, "t.tria:5"));
  EXPECT_TRUE(fails_with(kTetTria.substr(0, kTetTria.size() - 6) + "     \n", "t.tria",
                         ErrorCode::Truncated, "t.tria:12"));
  EXPECT_TRUE(fails_with(kTetTria + "0 1 2\n", "t.tria", ErrorCode::ParseError, "t.tria:12"));
  EXPECT_TRUE(
      fails_with(kTetTria.substr(0, 3) + "4\n-4\n", "t.tria", ErrorCode::ParseError, "t.tria:3"));
}

TEST(MeshReaderTria, AbsurdCountsRefusedBeforeAllocating) {
  std::string v = "4\n1000000000000\n4\n";
  v.resize(100, ' ');
  EXPECT_TRUE(fails_with(v, "h.tria", ErrorCode::LimitExceeded, "h.tria:2"));
  std::string t = "4\n4\n1000000000000\n";
  t.resize(100, ' ');
  EXPECT_TRUE(fails_with(t, "h.tria", ErrorCode::LimitExceeded, "h.tria:3"));
  MeshReadOptions unlimited;
  unlimited.max_vertices = UINT64_MAX;
  unlimited.max_triangles = UINT64_MAX;
  std::string u = "4\n4000000000\n4\n";
  u.resize(100, ' ');
  EXPECT_TRUE(fails_with(u, "h.tria", ErrorCode::Truncated, "h.tria:3", unlimited));
}

// ---- PLY ----------------------------------------------------------------------------------

const std::string kAsciiPly =
    "ply\n"                                     // 1
    "format ascii 1.0\n"                        // 2
    "comment made by hand\n"                    // 3
    "obj_info nothing\n"                        // 4
    "element vertex 4\n"                        // 5
    "property float x\n"                        // 6
    "property uchar red\n"                      // 7
    "property float32 y\n"                      // 8
    "property list uchar float uv\n"            // 9
    "property float64 z\n"                      // 10
    "element face 2\n"                          // 11
    "property uchar flags\n"                    // 12
    "property list uchar int vertex_indices\n"  // 13
    "property list ushort float texcoord\n"     // 14
    "element edge 1\n"                          // 15
    "property int vertex1\n"                    // 16
    "property int vertex2\n"                    // 17
    "end_header\n"                              // 18
    "0 255 0 2 0.5 0.5 0\n"                     // 19
    "1 0 0 0 0\n"                               // 20
    "1 7 1 1 0.25 0\n"                          // 21
    "0 9 1 0 -2.5\n"                            // 22
    "1 3 0 1 2 2 0.5 0.5\n"                     // 23
    "0 4 0 1 2 3 0\n"                           // 24
    "0 1\n";                                    // 25

TEST(MeshReaderPly, ReadsAsciiWithExtraPropertiesAndElements) {
  const MeshReadResult r = read(kAsciiPly, "a.ply");
  EXPECT_EQ(r.format, MeshFormat::PlyAscii);
  ASSERT_EQ(r.mesh.vertices.size(), 4u);
  EXPECT_EQ(r.mesh.vertices[0], (Vec3d{0, 0, 0}));
  EXPECT_EQ(r.mesh.vertices[2], (Vec3d{1, 1, 0}));
  EXPECT_EQ(r.mesh.vertices[3], (Vec3d{0, 1, -2.5}));
  ASSERT_EQ(r.mesh.triangles.size(), 3u);
  EXPECT_EQ(r.mesh.triangles[0], (Tri{0, 1, 2}));
  EXPECT_EQ(r.mesh.triangles[2], (Tri{0, 2, 3}));
  EXPECT_EQ(r.source_faces, 2u);
  EXPECT_EQ(r.polygons_triangulated, 1u);
}

TEST(MeshReaderPly, AcceptsVertexIndexNameAndIntegerCoordinates) {
  const std::string text =
      "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty int x\r\nproperty short y\r\n"
      "property uint8 z\r\nelement face 1\r\nproperty list int uint16 vertex_index\r\n"
      "end_header\r\n-5 7 255\r\n1 2 3\r\n4 5 6\r\n3 2 1 0\r\n";
  const MeshReadResult r = read(text, "i.PLY");
  ASSERT_EQ(r.mesh.vertices.size(), 3u);
  EXPECT_EQ(r.mesh.vertices[0], (Vec3d{-5, 7, 255}));
  EXPECT_EQ(r.mesh.triangles[0], (Tri{2, 1, 0}));
}

// A binary PLY: 4 vertices (x y z of type `coord`, uchar red, a float list) and 2 faces (short
// flags, a list <count> <index> of indices, an int list), plus an edge element.
Bytes binary_ply(bool big, std::string_view coord, std::string_view count, std::string_view index) {
  Bytes b;
  b.big = big;
  b.text("ply\nformat ")
      .text(big ? "binary_big_endian" : "binary_little_endian")
      .text(" 1.0\nelement vertex 4\nproperty ")
      .text(coord)
      .text(" x\nproperty uchar red\nproperty ")
      .text(coord)
      .text(" y\nproperty ")
      .text(coord)
      .text(
          " z\nproperty list uchar float uv\nelement face 2\nproperty short flags\n"
          "property list ")
      .text(count)
      .text(" ")
      .text(index)
      .text(
          " vertex_indices\nproperty list uint int extra\nelement edge 1\n"
          "property int a\nproperty int b\nend_header\n");
  const double coords[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, -2}};
  for (const auto& c : coords) {
    for (int a = 0; a < 3; ++a) {
      if (a == 1) b.put(std::uint8_t{200});
      if (coord == "double")
        b.put(c[a]);
      else if (coord == "float")
        b.put(static_cast<float>(c[a]));
      else
        b.put(static_cast<std::int32_t>(c[a]));
    }
    b.put(std::uint8_t{2}).put(0.5f).put(0.25f);
  }
  const std::vector<std::vector<int>> faces = {{0, 1, 2}, {0, 1, 2, 3}};
  for (const auto& f : faces) {
    b.put(std::int16_t{-1});
    if (count == "uchar")
      b.put(static_cast<std::uint8_t>(f.size()));
    else if (count == "ushort")
      b.put(static_cast<std::uint16_t>(f.size()));
    else
      b.put(static_cast<std::uint32_t>(f.size()));
    for (const int i : f) {
      if (index == "int")
        b.put(static_cast<std::int32_t>(i));
      else if (index == "uint")
        b.put(static_cast<std::uint32_t>(i));
      else if (index == "short")
        b.put(static_cast<std::int16_t>(i));
      else
        b.put(static_cast<std::uint8_t>(i));
    }
    b.put(std::uint32_t{1}).put(std::int32_t{42});
  }
  b.put(std::int32_t{0}).put(std::int32_t{1});
  return b;
}

TEST(MeshReaderPly, ReadsBinaryBothEndiannessesAllTypes) {
  for (const bool big : {false, true}) {
    for (const char* coord : {"float", "double", "int"}) {
      for (const auto& [count, index] : std::vector<std::pair<const char*, const char*>>{
               {"uchar", "int"}, {"ushort", "uint"}, {"uint", "short"}, {"uchar", "uchar"}}) {
        SCOPED_TRACE(std::string(big ? "big " : "little ") + coord + " " + count + " " + index);
        const MeshReadResult r = read(binary_ply(big, coord, count, index).s, "b.ply");
        EXPECT_EQ(r.format,
                  big ? MeshFormat::PlyBinaryBigEndian : MeshFormat::PlyBinaryLittleEndian);
        ASSERT_EQ(r.mesh.vertices.size(), 4u);
        EXPECT_EQ(r.mesh.vertices[3], (Vec3d{0, 1, -2}));
        EXPECT_EQ(r.mesh.vertices[1], (Vec3d{1, 0, 0}));
        ASSERT_EQ(r.mesh.triangles.size(), 3u);
        EXPECT_EQ(r.mesh.triangles[1], (Tri{0, 1, 2}));
        EXPECT_EQ(r.mesh.triangles[2], (Tri{0, 2, 3}));
        EXPECT_EQ(r.polygons_triangulated, 1u);
      }
    }
  }
}

TEST(MeshReaderPly, BinaryBodyAfterCrlfHeader) {
  Bytes b;
  b.text(
      "ply\r\nformat binary_little_endian 1.0\r\nelement vertex 3\r\nproperty float x\r\n"
      "property float y\r\nproperty float z\r\nelement face 1\r\n"
      "property list uchar int vertex_indices\r\nend_header\r\n");
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) b.put(v);
  b.put(std::uint8_t{3}).put(0).put(1).put(2);
  const MeshReadResult r = read(b.s, "crlf.ply");
  EXPECT_EQ(r.mesh.vertices[2], (Vec3d{0, 1, 0}));
  EXPECT_EQ(r.mesh.triangles.size(), 1u);
}

TEST(MeshReaderPly, MalformedHeader) {
  const std::string head = "ply\nformat ascii 1.0\n";
  const std::string tail =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  ASSERT_NO_THROW(read(head + tail, "ok.ply"));
  EXPECT_TRUE(fails_with("", "h.ply", ErrorCode::Truncated, "h.ply:1"));
  EXPECT_TRUE(fails_with("plx\n", "h.ply", ErrorCode::UnsupportedFormat, "h.ply:1"));
  EXPECT_TRUE(
      fails_with("ply\nformat ascii 2.0\n", "h.ply", ErrorCode::UnsupportedVersion, "h.ply:2"));
  EXPECT_TRUE(fails_with("ply\nformat binary_middle_endian 1.0\n", "h.ply",
                         ErrorCode::UnsupportedFormat, "h.ply:2"));
  EXPECT_TRUE(fails_with("ply\nelement vertex 3\n", "h.ply", ErrorCode::ParseError, "h.ply:2"));
  EXPECT_TRUE(fails_with(head + "property float x\n", "h.ply", ErrorCode::ParseError, "h.ply:3"));
  EXPECT_TRUE(fails_with(head + "element vertex 3\nproperty float128 x\n", "h.ply",
                         ErrorCode::UnsupportedFormat, "h.ply:4"));
  EXPECT_TRUE(fails_with(head + "element vertex 3\nproperty list float int x\n", "h.ply",
                         ErrorCode::UnsupportedFormat, "h.ply:4"));
  EXPECT_TRUE(fails_with(head + "element vertex 3\nproperty float x\nproperty float x\n", "h.ply",
                         ErrorCode::ParseError, "h.ply:5"));
  EXPECT_TRUE(fails_with(head + "element vertex x\n", "h.ply", ErrorCode::ParseError, "h.ply:3"));
  EXPECT_TRUE(fails_with(head + "element vertex -3\n", "h.ply", ErrorCode::ParseError, "h.ply:3"));
  EXPECT_TRUE(fails_with(head + "bogus line\n", "h.ply", ErrorCode::ParseError, "h.ply:3"));
  EXPECT_TRUE(fails_with(head + "element vertex 3\nproperty float x\n", "h.ply",
                         ErrorCode::Truncated, "h.ply:5"));
  EXPECT_TRUE(fails_with(head + "element vertex 3\nend_header\n0\n0\n0\n", "h.ply",
                         ErrorCode::ParseError, "h.ply:3"));
  // Required elements and properties.
  EXPECT_TRUE(fails_with(head + "element face 0\nproperty list uchar int vertex_indices\n"
                                "end_header\n",
                         "h.ply", ErrorCode::ParseError, "h.ply:5"));
  EXPECT_TRUE(fails_with(head + "element vertex 1\nproperty float x\nproperty float y\n"
                                "property float z\nend_header\n0 0 0\n",
                         "h.ply", ErrorCode::ParseError, "h.ply:7"));
  EXPECT_TRUE(fails_with(head + "element vertex 1\nproperty float x\nproperty float z\n"
                                "element face 0\nproperty list uchar int vertex_indices\n"
                                "end_header\n0 0\n",
                         "h.ply", ErrorCode::ParseError, "h.ply:3"));
  EXPECT_TRUE(fails_with(head + "element vertex 0\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 0\nproperty uchar flags\n"
                                "end_header\n",
                         "h.ply", ErrorCode::ParseError, "h.ply:7"));
  EXPECT_TRUE(fails_with(head + "element vertex 0\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 0\n"
                                "property list uchar float vertex_indices\nend_header\n",
                         "h.ply", ErrorCode::UnsupportedFormat, "h.ply:7"));
}

TEST(MeshReaderPly, MalformedAsciiBody) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "property uchar flags\nend_header\n";  // 10 lines; body starts on line 11
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2 0\n", "a.ply",
                         ErrorCode::NonFinite, "a.ply:12"));
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 0 0\n0 1 oops\n3 0 1 2 0\n", "a.ply",
                         ErrorCode::ParseError, "a.ply:13"));
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3 0\n", "a.ply",
                         ErrorCode::ParseError, "a.ply:14"));
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2 0\n", "a.ply",
                         ErrorCode::ParseError, "a.ply:14"));
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 0 0\n0 1 0\n2 0 1 0\n", "a.ply", ErrorCode::ParseError,
                         "a.ply:14"));
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2 0\n", "a.ply",
                         ErrorCode::ParseError, "a.ply:14"));
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2 zz\n", "a.ply",
                         ErrorCode::ParseError, "a.ply:14"));
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2 0\n7\n", "a.ply",
                         ErrorCode::ParseError, "a.ply:15"));
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2       \n", "a.ply",
                         ErrorCode::Truncated, "a.ply:15"));
  EXPECT_TRUE(fails_with(header + "0 0 0\n1 0 0\n0 1 0\n250 0 1 2 0\n", "a.ply",
                         ErrorCode::Truncated, "a.ply:14"));
}

TEST(MeshReaderPly, MalformedBinaryBody) {
  const Bytes good = binary_ply(false, "float", "uchar", "int");
  ASSERT_NO_THROW(read(good.s, "b.ply"));
  const std::size_t body = good.s.find("end_header\n") + 11;
  // Vertex layout: x(4) red(1) y(4) z(4) uv-count(1) uv(8) = 22 bytes.
  const std::size_t vertex_bytes = 22;
  const std::size_t faces = body + 4 * vertex_bytes;

  std::string s = good.s;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&s[body + vertex_bytes + 5], &nan, 4);  // y of vertex 1
  EXPECT_TRUE(fails_with(s, "b.ply", ErrorCode::NonFinite,
                         "b.ply @ byte " + std::to_string(body + vertex_bytes + 5)));

  s = good.s;
  const std::int32_t out_of_range = 4;
  std::memcpy(&s[faces + 2 + 1 + 4], &out_of_range, 4);  // second index of face 0
  EXPECT_TRUE(fails_with(s, "b.ply", ErrorCode::ParseError,
                         "b.ply @ byte " + std::to_string(faces + 2 + 1 + 4)));

  s = good.s;
  s[faces + 2] = 2;  // face 0 with two vertices
  EXPECT_TRUE(
      fails_with(s, "b.ply", ErrorCode::ParseError, "b.ply @ byte " + std::to_string(faces + 2)));

  s = good.s;
  s[faces + 2] = static_cast<char>(250);  // face 0 claims 250 indices
  EXPECT_TRUE(
      fails_with(s, "b.ply", ErrorCode::Truncated, "b.ply @ byte " + std::to_string(faces + 2)));

  s = good.s;
  s += '\n';
  EXPECT_TRUE(fails_with(s, "b.ply", ErrorCode::ParseError,
                         "b.ply @ byte " + std::to_string(good.s.size())));

  // Truncation anywhere in the body: Truncated at a byte offset inside the body.
  for (std::size_t cut = body + 1; cut < good.s.size(); cut += 7) {
    try {
      read(good.s.substr(0, cut), "b.ply");
      ADD_FAILURE() << "cut at " << cut << " was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Truncated) << e.what();
    }
  }
  // A truncated value right at the end: named by its start.
  EXPECT_TRUE(fails_with(good.s.substr(0, good.s.size() - 2), "b.ply", ErrorCode::Truncated,
                         "b.ply @ byte " + std::to_string(good.s.size() - 4)));
}

TEST(MeshReaderPly, AbsurdCountsRefusedBeforeAllocating) {
  for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(format);
    std::string v = std::string("ply\nformat ") + format +
                    " 1.0\nelement vertex 1000000000000\nproperty float x\n";
    const std::string v_tail =
        "property float y\nproperty float z\nelement face 0\n"
        "property list uchar int vertex_indices\nend_header\n";
    std::string file = v + v_tail;
    EXPECT_TRUE(fails_with(file, "h.ply", ErrorCode::LimitExceeded, "h.ply:3"));
    MeshReadOptions unlimited;
    unlimited.max_vertices = UINT64_MAX;
    unlimited.max_triangles = UINT64_MAX;
    // Within the limits (indices are 32-bit), but the bytes cannot hold the claim.
    file = std::string("ply\nformat ") + format +
           " 1.0\nelement vertex 4000000000\nproperty float x\n" + v_tail + std::string(100, ' ');
    EXPECT_TRUE(fails_with(file, "h.ply", ErrorCode::Truncated, "h.ply:3", unlimited));
    const std::string f = std::string("ply\nformat ") + format +
                          " 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 4000000000\n"
                          "property list uchar int vertex_indices\nend_header\n0 0 0\n";
    EXPECT_TRUE(fails_with(f, "h.ply", ErrorCode::LimitExceeded, "h.ply:7"));
    EXPECT_TRUE(fails_with(f, "h.ply", ErrorCode::Truncated, "h.ply:7", unlimited));
  }
  // Enough bytes for the list counts alone, not for faces of three indices: refused before the
  // triangles are reserved.
  std::string faces =
      "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1000\n"
      "property list uchar int vertex_indices\nend_header\n";
  faces += std::string(1000, '\3');
  EXPECT_TRUE(fails_with(faces, "f.ply", ErrorCode::Truncated, "f.ply:7"));
}

// ---- OBJ ----------------------------------------------------------------------------------

TEST(MeshReaderObj, ReadsAllCornerFormsAndIgnoresOtherStatements) {
  const std::string text =
      "# comment\n"
      "mtllib cube.mtl\n"
      "o thing\n"
      "v 0 0 0\n"
      "v 1 0 0 1.0\n"          // w
      "v 1 1 0 0.5 0.5 0.5\n"  // vertex color
      "v 0 1 0 # trailing comment\n"
      "vt 0 0\nvt 1 0\nvt 1 1\n"
      "vn 0 0 1\n"
      "g group\nusemtl red\ns off\n"
      "f 1 2 3\n"
      "f 1/1 3/3 4/2\n"
      "f 1/1/1 2/2/1 3/3/1\n"
      "f 1//1 3//1 4//1\n"
      "l 1 2\n"
      "f 1 2 3 4\n";
  const MeshReadResult r = read(text, "m.obj");
  EXPECT_EQ(r.format, MeshFormat::Obj);
  ASSERT_EQ(r.mesh.vertices.size(), 4u);
  EXPECT_EQ(r.mesh.vertices[2], (Vec3d{1, 1, 0}));
  ASSERT_EQ(r.mesh.triangles.size(), 6u);
  EXPECT_EQ(r.mesh.triangles[1], (Tri{0, 2, 3}));
  EXPECT_EQ(r.mesh.triangles[5], (Tri{0, 2, 3}));
  EXPECT_EQ(r.source_faces, 5u);
  EXPECT_EQ(r.polygons_triangulated, 1u);
}

TEST(MeshReaderObj, ResolvesNegativeRelativeIndices) {
  const std::string text =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
      "f -3 -2 -1\n"
      "v 5 5 5\nv 6 5 5\n"
      "f -1 -2 -5/-1/-1\n"  // 4, 3, 0 (zero-based)
      "f 1 -1 -4\n";        // 0, 4, 1
  const MeshReadResult r = read(text, "rel.obj");
  ASSERT_EQ(r.mesh.triangles.size(), 3u);
  EXPECT_EQ(r.mesh.triangles[0], (Tri{0, 1, 2}));
  EXPECT_EQ(r.mesh.triangles[1], (Tri{4, 3, 0}));
  EXPECT_EQ(r.mesh.triangles[2], (Tri{0, 4, 1}));
}

TEST(MeshReaderObj, ForwardReferencesCheckedAtTheEnd) {
  const MeshReadResult r = read("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "fwd.obj");
  EXPECT_EQ(r.mesh.triangles[0], (Tri{0, 1, 2}));
  EXPECT_TRUE(
      fails_with("v 0 0 0\nf 1 2 3\nv 1 0 0\n", "fwd.obj", ErrorCode::ParseError, "fwd.obj:2"));
}

TEST(MeshReaderObj, MalformedInput) {
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";  // lines 1-3
  EXPECT_TRUE(fails_with("", "o.obj", ErrorCode::Truncated, "o.obj:1"));
  EXPECT_TRUE(fails_with(v3 + "f 1 2\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f 0 1 2\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f 1 2 -4\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f 1 2 4\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f 1/1/1/1 2 3\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f 1/ 2 3\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f 1// 2 3\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f 1/x 2 3\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f a b c\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f 1 2 99999999999999999999999\n", "o.obj", ErrorCode::LimitExceeded,
                         "o.obj:4"));
  EXPECT_TRUE(fails_with(v3 + "f 1 2 99999999999999\n", "o.obj", ErrorCode::ParseError, "o.obj:4"));
  EXPECT_TRUE(fails_with("v 0 0\n", "o.obj", ErrorCode::ParseError, "o.obj:1"));
  EXPECT_TRUE(fails_with("v 0 0 0\nv 1 nan 0\n", "o.obj", ErrorCode::NonFinite, "o.obj:2"));
  EXPECT_TRUE(fails_with("v 0 0 0 junk\n", "o.obj", ErrorCode::ParseError, "o.obj:1"));
  EXPECT_TRUE(fails_with(v3 + "\nbogus 1 2\n", "o.obj", ErrorCode::ParseError, "o.obj:5"));
  MeshReadOptions small;
  small.max_vertices = 2;
  EXPECT_TRUE(fails_with(v3, "o.obj", ErrorCode::LimitExceeded, "o.obj:3", small));
  small = {};
  small.max_triangles = 1;
  EXPECT_TRUE(
      fails_with(v3 + "f 1 2 3\nf 3 2 1\n", "o.obj", ErrorCode::LimitExceeded, "o.obj:5", small));
}

// ---- STL ----------------------------------------------------------------------------------

const std::string kAsciiStl =
    "solid two\n"           // 1
    "facet normal 0 0 1\n"  // 2
    "  outer loop\n"        // 3
    "    vertex 0 0 0\n"    // 4
    "    vertex 1 0 0\n"    // 5
    "    vertex 0 1 0\n"    // 6
    "  endloop\n"           // 7
    "endfacet\n"            // 8
    "facet normal 0 0 1\n"  // 9
    "  outer loop\n"        // 10
    "    vertex 1 0 0\n"    // 11
    "    vertex 1 1 0\n"    // 12
    "    vertex 0 1 -0\n"   // 13
    "  endloop\n"           // 14
    "endfacet\n"            // 15
    "endsolid two\n";       // 16

TEST(MeshReaderStl, ReadsAsciiAndWeldsEqualVertices) {
  const MeshReadResult r = read(kAsciiStl, "two.stl");
  EXPECT_EQ(r.format, MeshFormat::StlAscii);
  ASSERT_EQ(r.mesh.vertices.size(), 4u);  // -0 welds with 0
  ASSERT_EQ(r.mesh.triangles.size(), 2u);
  EXPECT_EQ(r.mesh.triangles[0], (Tri{0, 1, 2}));
  EXPECT_EQ(r.mesh.triangles[1], (Tri{1, 3, 2}));
  EXPECT_EQ(r.source_faces, 2u);
}

TEST(MeshReaderStl, AsciiUppercaseAndSeveralSolids) {
  const std::string text =
      "SOLID a\nFACET NORMAL 0 0 0\nOUTER LOOP\nVERTEX 0 0 0\nVERTEX 1 0 0\nVERTEX 0 1 0\n"
      "ENDLOOP\nENDFACET\nENDSOLID a\n"
      "solid b\nfacet normal nan nan nan\nouter loop\nvertex 0 0 0\nvertex 0 1 0\n"
      "vertex 0 0 1\nvertex 0 2 2\nendloop\nendfacet\nendsolid";
  const MeshReadResult r = read(text, "multi.stl");
  EXPECT_EQ(r.mesh.vertices.size(), 5u);
  ASSERT_EQ(r.mesh.triangles.size(), 3u);
  EXPECT_EQ(r.mesh.triangles[2], (Tri{0, 3, 4}));
  EXPECT_EQ(r.polygons_triangulated, 1u);
}

Bytes binary_stl(std::string_view header, const std::vector<std::array<float, 9>>& tris) {
  Bytes b;
  std::string h(header);
  h.resize(80, ' ');
  b.text(h).put(static_cast<std::uint32_t>(tris.size()));
  for (const auto& t : tris) {
    b.put(0.f).put(0.f).put(1.f);
    for (const float v : t) b.put(v);
    b.put(std::uint16_t{0});
  }
  return b;
}

const std::vector<std::array<float, 9>> kTwoTris = {{0, 0, 0, 1, 0, 0, 0, 1, 0},
                                                    {1, 0, 0, 1, 1, 0, 0, 1, 0}};

TEST(MeshReaderStl, ReadsBinaryAndWelds) {
  for (const char* header : {"binary", "solid looks like ascii but is binary"}) {
    SCOPED_TRACE(header);
    const MeshReadResult r = read(binary_stl(header, kTwoTris).s, "b.stl");
    EXPECT_EQ(r.format, MeshFormat::StlBinary);
    ASSERT_EQ(r.mesh.vertices.size(), 4u);
    ASSERT_EQ(r.mesh.triangles.size(), 2u);
    EXPECT_EQ(r.mesh.triangles[1], (Tri{1, 3, 2}));
    EXPECT_EQ(r.mesh.vertices[3], (Vec3d{1, 1, 0}));
    EXPECT_EQ(r.source_faces, 2u);
  }
  const MeshReadResult empty = read(binary_stl("none", {}).s, "e.stl");
  EXPECT_TRUE(empty.mesh.triangles.empty());
}

TEST(MeshReaderStl, MalformedAscii) {
  EXPECT_TRUE(fails_with("solid x\n", "a.stl", ErrorCode::Truncated, "a.stl:2"));
  std::string bad = kAsciiStl;
  bad.replace(bad.find("endloop"), 7, "endlop");
  EXPECT_TRUE(fails_with(bad, "a.stl", ErrorCode::ParseError, "a.stl:7"));
  bad = kAsciiStl;
  bad.replace(bad.find("vertex 0 1 0"), 12, "vertex 0 1 inf");
  EXPECT_TRUE(fails_with(bad, "a.stl", ErrorCode::NonFinite, "a.stl:6"));
  bad = kAsciiStl;
  bad.replace(bad.find("vertex 0 1 0"), 12, "vertex 0 1 q");
  EXPECT_TRUE(fails_with(bad, "a.stl", ErrorCode::ParseError, "a.stl:6"));
  bad = kAsciiStl;
  bad.erase(bad.find("    vertex 0 1 0\n"), 17);  // facet with two vertices
  EXPECT_TRUE(fails_with(bad, "a.stl", ErrorCode::ParseError, "a.stl:6"));
  bad = kAsciiStl;
  bad.replace(bad.find("outer"), 5, "inner");
  EXPECT_TRUE(fails_with(bad, "a.stl", ErrorCode::ParseError, "a.stl:3"));
  EXPECT_TRUE(fails_with(kAsciiStl.substr(0, kAsciiStl.find("endfacet\nfacet")), "a.stl",
                         ErrorCode::Truncated, "a.stl:8"));
  EXPECT_TRUE(fails_with(kAsciiStl + "garbage\n", "a.stl", ErrorCode::ParseError, "a.stl:17"));
  EXPECT_TRUE(fails_with(kAsciiStl.substr(0, kAsciiStl.find("endsolid")) + "facet x", "a.stl",
                         ErrorCode::ParseError, "a.stl:16"));
}

TEST(MeshReaderStl, MalformedBinary) {
  const Bytes good = binary_stl("bin", kTwoTris);
  std::string s = good.s;
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t at = 84 + 50 + 12 + 12 + 4;  // triangle 1, vertex 1, y
  std::memcpy(&s[at], &inf, 4);
  EXPECT_TRUE(fails_with(s, "b.stl", ErrorCode::NonFinite, "b.stl @ byte " + std::to_string(at)));
  EXPECT_TRUE(fails_with(good.s.substr(0, good.s.size() - 1), "b.stl", ErrorCode::Truncated,
                         "b.stl @ byte 80"));
  EXPECT_TRUE(fails_with(good.s + "xx", "b.stl", ErrorCode::ParseError, "b.stl @ byte 184"));
  EXPECT_TRUE(fails_with(std::string(40, '\1'), "b.stl", ErrorCode::Truncated, "b.stl @ byte 40"));
  EXPECT_TRUE(fails_with("", "b.stl", ErrorCode::Truncated, "b.stl @ byte 0"));
  MeshReadOptions small;
  small.max_triangles = 1;
  EXPECT_TRUE(fails_with(good.s, "b.stl", ErrorCode::LimitExceeded, "b.stl @ byte 80", small));
  small = {};
  small.max_vertices = 3;
  EXPECT_TRUE(fails_with(good.s, "b.stl", ErrorCode::LimitExceeded, "b.stl @ byte 134", small));
}

TEST(MeshReaderStl, AbsurdCountsRefusedBeforeAllocating) {
  Bytes b;
  b.text(std::string(80, 'x')).put(std::uint32_t{0xFFFFFFFF});
  b.s.resize(100, '\0');
  EXPECT_TRUE(fails_with(b.s, "h.stl", ErrorCode::LimitExceeded, "h.stl @ byte 80"));
  MeshReadOptions unlimited;
  unlimited.max_vertices = UINT64_MAX;
  unlimited.max_triangles = UINT64_MAX;
  EXPECT_TRUE(fails_with(b.s, "h.stl", ErrorCode::Truncated, "h.stl @ byte 80", unlimited));
}

// ---- dispatch, files, progress ------------------------------------------------------------

TEST(MeshReaderDispatch, FormatNames) {
  EXPECT_EQ(to_string(MeshFormat::Off), "off");
  EXPECT_EQ(to_string(MeshFormat::Tria), "tria");
  EXPECT_EQ(to_string(MeshFormat::PlyAscii), "ply_ascii");
  EXPECT_EQ(to_string(MeshFormat::PlyBinaryLittleEndian), "ply_binary_little_endian");
  EXPECT_EQ(to_string(MeshFormat::PlyBinaryBigEndian), "ply_binary_big_endian");
  EXPECT_EQ(to_string(MeshFormat::Obj), "obj");
  EXPECT_EQ(to_string(MeshFormat::StlAscii), "stl_ascii");
  EXPECT_EQ(to_string(MeshFormat::StlBinary), "stl_binary");
}

TEST(MeshReaderDispatch, UnknownExtensionsAndMissingFiles) {
  EXPECT_TRUE(fails_with(kCubeOff, "cube.gltf", ErrorCode::UnsupportedFormat, "cube.gltf"));
  EXPECT_TRUE(fails_with(kCubeOff, "noextension", ErrorCode::UnsupportedFormat, "noextension"));
  try {
    read_mesh("/nonexistent/dir/cube.off");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::IoError);
  }
}

std::filesystem::path scratch_dir() {
  const char* env = std::getenv("LEVELSET_TMP");
  std::filesystem::path dir = env != nullptr && *env != '\0'
                                  ? std::filesystem::path(env)
                                  : std::filesystem::temp_directory_path() / "levelset-test";
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(MeshReaderDispatch, ReadsFromDisk) {
  const auto path = scratch_dir() / "mesh_reader_cube.off";
  {
    std::ofstream out(path, std::ios::binary);
    out << kCubeOff;
  }
  const MeshReadResult r = read_mesh(path);
  EXPECT_EQ(r.mesh.triangles.size(), 12u);
  MeshReadOptions small;
  small.max_file_bytes = 16;
  try {
    read_mesh(path, small);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
  }
  std::filesystem::remove(path);
}

TEST(MeshReaderDispatch, ProgressAndCancellation) {
  // 2^20 + 1 vertices: at least one progress step.
  const std::uint64_t n = (std::uint64_t{1} << 20) + 1;
  std::string text = "4\n" + std::to_string(n) + "\n1\n";
  text.reserve(text.size() + n * 6 + 8);
  for (std::uint64_t i = 0; i < n; ++i) text += "0 0 0\n";
  text += "0 1 2\n";
  MeshReadOptions options;
  int steps = 0;
  options.progress.on_progress = [&](double fraction, std::string_view stage) {
    EXPECT_GT(fraction, 0.0);
    EXPECT_LE(fraction, 1.0);
    EXPECT_EQ(stage, "read mesh");
    ++steps;
  };
  const MeshReadResult r = read(text, "big.tria", options);
  EXPECT_EQ(r.mesh.vertices.size(), n);
  EXPECT_GE(steps, 1);

  auto token = std::make_shared<CancelToken>();
  token->cancel();
  options.progress.cancel = token;
  try {
    read(text, "big.tria", options);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Cancelled);
  }
}

TEST(MeshReaderDispatch, FuzzSeedCorpusIsValid) {
  // Every seed of the fuzz corpus is a valid file (so mutations start from good input).
  static constexpr const char* kExt[] = {".off", ".tria", ".ply", ".obj", ".stl"};
  const int seen = test::for_each_fuzz_seed("fuzz_mesh_reader", kExt, [](std::string_view bytes, const std::string& name) {
    if (name.rfind("bomb_", 0) == 0 || name.rfind("bad_", 0) == 0) {
      // Hostile seeds: refused with a typed error (bombs: by a limit, at once).
      try {
        read(bytes, name);
        ADD_FAILURE() << name << " was read";
      } catch (const Error& e) {
        if (name.rfind("bomb_", 0) == 0) {
          EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << name << ": " << e.what();
        }
      }
      return;
    }
    EXPECT_FALSE(read(bytes, name).mesh.triangles.empty()) << name;
  });
  EXPECT_GE(seen, 10);
}

}  // namespace
}  // namespace levelset
