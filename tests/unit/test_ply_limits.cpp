// PLY headers and ASCII values against hostile input: element and property caps, header parsing
// linear in its size (duplicate names found by hashing), integer values within their type.
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "core/error.hpp"
#include "io/mesh_reader.hpp"
#include "io/ply_parser.hpp"
#include "io/point_cloud_reader.hpp"
#include "reader_test_support.hpp"

namespace levelset {
namespace {

::testing::AssertionResult mesh_fails_with(std::string_view bytes, ErrorCode code,
                                           std::string_view where) {
  return test::fails_with([&] { return read_mesh_from_memory(bytes, "h.ply"); },
                          [](const MeshReadResult& r) {
                            return std::to_string(r.mesh.triangles.size()) + " triangles";
                          },
                          code, where);
}

std::string header_with_elements(std::size_t n) {
  std::string s = "ply\nformat ascii 1.0\n";
  for (std::size_t i = 0; i < n; ++i) s += "element e" + std::to_string(i) + " 0\n";
  return s + "end_header\n";
}

std::string header_with_properties(std::size_t n) {
  std::string s = "ply\nformat ascii 1.0\nelement vertex 0\n";
  for (std::size_t i = 0; i < n; ++i) s += "property float p" + std::to_string(i) + "\n";
  return s + "end_header\n";
}

double seconds_to_parse(const std::string& bytes) {
  const auto t0 = std::chrono::steady_clock::now();
  try {
    (void)ply::parse_header(bytes, "h.ply");
  } catch (const Error&) {
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

TEST(PlyHeaderLimits, ElementAndPropertyCountsCapped) {
  // 100k empty elements took 20.8 s (each name compared with every earlier one).
  EXPECT_TRUE(mesh_fails_with(header_with_elements(100000), ErrorCode::LimitExceeded,
                              "h.ply:" + std::to_string(ply::kMaxElements + 3)));
  EXPECT_TRUE(mesh_fails_with(header_with_properties(100000), ErrorCode::LimitExceeded,
                              "h.ply:" + std::to_string(ply::kMaxPropertiesPerElement + 4)));
  // At the caps the header parses.
  EXPECT_EQ(ply::parse_header(header_with_elements(ply::kMaxElements), "h.ply").elements.size(),
            ply::kMaxElements);
  EXPECT_EQ(ply::parse_header(header_with_properties(ply::kMaxPropertiesPerElement), "h.ply")
                .elements[0]
                .properties.size(),
            ply::kMaxPropertiesPerElement);
}

TEST(PlyHeaderLimits, ParsingIsLinearInTheHeader) {
  // Headers at the caps, and a 3.4 MB header of comments: all well under a second (a quadratic
  // duplicate check took 0.1 s for the 4096 properties alone and grows with the square).
  EXPECT_LT(seconds_to_parse(header_with_elements(ply::kMaxElements)), 0.5);
  EXPECT_LT(seconds_to_parse(header_with_properties(ply::kMaxPropertiesPerElement)), 0.5);
  std::string comments = "ply\nformat ascii 1.0\n";
  for (int i = 0; i < 100000; ++i) comments += "comment padding padding padding\n";
  comments += "element vertex 0\nproperty float x\nend_header\n";
  EXPECT_LT(seconds_to_parse(comments), 0.5);
  // Duplicates are still found, in both places.
  EXPECT_TRUE(mesh_fails_with("ply\nformat ascii 1.0\nelement a 0\nelement b 0\nelement a 0\n"
                              "end_header\n",
                              ErrorCode::ParseError, "h.ply:5"));
  EXPECT_TRUE(mesh_fails_with("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
                              "element face 0\nproperty float x\nproperty float x\nend_header\n",
                              ErrorCode::ParseError, "h.ply:7"));
}

TEST(PlyAsciiValues, IntegersMustFitTheirDeclaredType) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";  // body on line 11
  const std::string faces = "3 0 1 2\n";
  ASSERT_NO_THROW(read_mesh_from_memory(header + "0 0 0 0\n1 0 0 255\n0 1 0 7\n" + faces, "h.ply"));
  EXPECT_TRUE(mesh_fails_with(header + "0 0 0 300\n1 0 0 0\n0 1 0 0\n" + faces,
                              ErrorCode::ParseError, "h.ply:11"));
  EXPECT_TRUE(mesh_fails_with(header + "0 0 0 0\n1 0 0 -1\n0 1 0 0\n" + faces,
                              ErrorCode::ParseError, "h.ply:12"));
  // A list count beyond its uchar type.
  EXPECT_TRUE(mesh_fails_with(header + "0 0 0 0\n1 0 0 0\n0 1 0 0\n256 0 1 2\n",
                              ErrorCode::ParseError, "h.ply:14"));
  // A short index beyond its range.
  const std::string short_faces =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar short vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 70000\n";
  EXPECT_TRUE(mesh_fails_with(short_faces, ErrorCode::ParseError, "h.ply:13"));
  // The point cloud reader refuses the same values.
  const std::string cloud =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nend_header\n0 0 0 999\n";
  EXPECT_THROW(read_point_cloud_from_memory(cloud, "c.ply"), Error);
}

}  // namespace
}  // namespace levelset
