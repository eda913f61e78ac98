// read_point_cloud / read_point_cloud_from_memory: xyz (3 or 6 columns), xyzn, pwn, PLY (ascii
// and binary, optional normals), OFF; every malformed case with its ErrorCode and `where`.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "core/error.hpp"
#include "io/point_cloud_reader.hpp"
#include "reader_test_support.hpp"

namespace levelset {
namespace {

PointCloudReadResult read(std::string_view bytes, std::string_view name,
                          const PointCloudReadOptions& options = {}) {
  return read_point_cloud_from_memory(bytes, name, options);
}

using test::Bytes;

::testing::AssertionResult fails_with(std::string_view bytes, std::string_view name, ErrorCode code,
                                      std::string_view where,
                                      const PointCloudReadOptions& options = {}) {
  return test::fails_with([&] { return read_point_cloud_from_memory(bytes, name, options); },
                          [](const PointCloudReadResult& r) {
                            return std::to_string(r.cloud.points.size()) + " points";
                          },
                          code, where);
}

TEST(PointCloudXyz, ReadsPointsOnly) {
  const PointCloudReadResult r =
      read("# header comment\n0 0 0\n1.5 -2 3e2   # trailing\n\n  4 5 6\r\n", "p.xyz");
  EXPECT_EQ(r.format, PointCloudFormat::Xyz);
  ASSERT_EQ(r.cloud.points.size(), 3u);
  EXPECT_FALSE(r.cloud.has_normals());
  EXPECT_EQ(r.cloud.points[1], (Vec3d{1.5, -2, 300}));
  EXPECT_EQ(r.cloud.points[2], (Vec3d{4, 5, 6}));
}

TEST(PointCloudXyz, SixColumnsArePointAndNormal) {
  const PointCloudReadResult r = read("0 0 0 0 0 1\n1 1 1 0 0 0\n2 2 2 1 0 0", "n.xyz");
  ASSERT_EQ(r.cloud.points.size(), 3u);
  ASSERT_EQ(r.cloud.normals.size(), 3u);
  EXPECT_EQ(r.cloud.normals[0], (Vec3d{0, 0, 1}));
  EXPECT_EQ(r.cloud.normals[1], (Vec3d{0, 0, 0}));  // zero-length normals are kept
  EXPECT_EQ(r.cloud.points[2], (Vec3d{2, 2, 2}));
}

TEST(PointCloudXyz, XyznAndPwnNeedSixColumns) {
  for (const char* name : {"a.xyzn", "a.pwn", "A.PWN"}) {
    SCOPED_TRACE(name);
    const PointCloudReadResult r = read("0 0 0 0 0 1\n1 2 3 0.6 0.8 0\n", name);
    ASSERT_EQ(r.cloud.points.size(), 2u);
    EXPECT_EQ(r.cloud.normals[1], (Vec3d{0.6, 0.8, 0}));
    EXPECT_TRUE(
        fails_with("0 0 0 0 0 1\n1 2 3\n", name, ErrorCode::ParseError, std::string(name) + ":2"));
    EXPECT_TRUE(fails_with("1 2 3\n", name, ErrorCode::ParseError, std::string(name) + ":1"));
  }
  EXPECT_EQ(read("1 2 3 4 5 6\n", "a.pwn").format, PointCloudFormat::Pwn);
  EXPECT_EQ(read("1 2 3 4 5 6\n", "a.xyzn").format, PointCloudFormat::Xyzn);
}

TEST(PointCloudXyz, MalformedInput) {
  EXPECT_TRUE(fails_with("", "e.xyz", ErrorCode::Truncated, "e.xyz:1"));
  EXPECT_TRUE(fails_with("# nothing\n\n", "e.xyz", ErrorCode::Truncated, "e.xyz:3"));
  EXPECT_TRUE(fails_with("0 0 0\n1 1 1\n2 2 2 0 0 1\n", "c.xyz", ErrorCode::ParseError, "c.xyz:3"));
  EXPECT_TRUE(fails_with("0 0 0 0 0 1\n\n1 1 1\n", "c.xyz", ErrorCode::ParseError, "c.xyz:3"));
  EXPECT_TRUE(fails_with("0 0 0 1\n", "c.xyz", ErrorCode::ParseError, "c.xyz:1"));
  EXPECT_TRUE(fails_with("0 0\n", "c.xyz", ErrorCode::ParseError, "c.xyz:1"));
  EXPECT_TRUE(fails_with("1 2 3 4 5 6 7 8 9\n", "c.xyz", ErrorCode::ParseError, "c.xyz:1"));
  EXPECT_TRUE(fails_with("0 0 0\n1 x 1\n", "g.xyz", ErrorCode::ParseError, "g.xyz:2"));
  EXPECT_TRUE(fails_with("0 0 0\n1 nan 1\n", "n.xyz", ErrorCode::NonFinite, "n.xyz:2"));
  EXPECT_TRUE(fails_with("0 0 0 0 0 1\n1 1 1 0 nan 0\n", "n.xyz", ErrorCode::NonFinite, "n.xyz:2"));
  EXPECT_TRUE(fails_with("0 0 0 0 0 1\n1 1 1 0 inf 0\n", "n.pwn", ErrorCode::NonFinite, "n.pwn:2"));
  PointCloudReadOptions small;
  small.max_points = 2;
  EXPECT_TRUE(
      fails_with("0 0 0\n1 1 1\n2 2 2\n", "l.xyz", ErrorCode::LimitExceeded, "l.xyz:3", small));
  small = {};
  small.max_file_bytes = 4;
  EXPECT_TRUE(fails_with("0 0 0\n", "l.xyz", ErrorCode::LimitExceeded, "l.xyz", small));
  EXPECT_TRUE(fails_with("0 0 0\n", "p.las", ErrorCode::UnsupportedFormat, "p.las"));
}

const std::string kAsciiPly =
    "ply\n"                                     // 1
    "format ascii 1.0\n"                        // 2
    "element vertex 3\n"                        // 3
    "property double x\n"                       // 4
    "property double y\n"                       // 5
    "property double z\n"                       // 6
    "property float nx\n"                       // 7
    "property float ny\n"                       // 8
    "property float nz\n"                       // 9
    "property uchar red\n"                      // 10
    "property list uchar int extra\n"           // 11
    "element face 1\n"                          // 12
    "property list uchar int vertex_indices\n"  // 13
    "end_header\n"                              // 14
    "0 0 0 0 0 1 255 0\n"                       // 15
    "1 2 3 0 0 0 7 2 5 6\n"                     // 16
    "4 5 6 1 0 0 0 1 9\n"                       // 17
    "3 0 1 2\n";                                // 18

TEST(PointCloudPly, ReadsAsciiWithNormalsSkippingTheRest) {
  const PointCloudReadResult r = read(kAsciiPly, "a.ply");
  EXPECT_EQ(r.format, PointCloudFormat::Ply);
  ASSERT_EQ(r.cloud.points.size(), 3u);
  ASSERT_EQ(r.cloud.normals.size(), 3u);
  EXPECT_EQ(r.cloud.points[1], (Vec3d{1, 2, 3}));
  EXPECT_EQ(r.cloud.normals[2], (Vec3d{1, 0, 0}));
}

TEST(PointCloudPly, ReadsBinaryWithAndWithoutNormals) {
  for (const bool big : {false, true}) {
    SCOPED_TRACE(big ? "big endian" : "little endian");
    Bytes b;
    b.big = big;
    b.text(std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
           " 1.0\ncomment x\nelement vertex 2\nproperty float nx\nproperty float x\n"
           "property short label\nproperty float y\nproperty float z\nproperty float ny\n"
           "property float nz\nend_header\n");
    b.put(0.f).put(1.f).put(std::int16_t{-4}).put(2.f).put(3.f).put(0.f).put(1.f);
    b.put(1.f).put(4.f).put(std::int16_t{9}).put(5.f).put(6.f).put(0.f).put(0.f);
    const PointCloudReadResult r = read(b.s, "b.ply");
    ASSERT_EQ(r.cloud.points.size(), 2u);
    EXPECT_EQ(r.cloud.points[0], (Vec3d{1, 2, 3}));
    EXPECT_EQ(r.cloud.normals[0], (Vec3d{0, 0, 1}));
    EXPECT_EQ(r.cloud.points[1], (Vec3d{4, 5, 6}));
    EXPECT_EQ(r.cloud.normals[1], (Vec3d{1, 0, 0}));
  }
  Bytes b;
  b.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty double x\n"
      "property double y\nproperty double z\nend_header\n");
  b.put(0.1).put(0.2).put(0.3);
  const PointCloudReadResult r = read(b.s, "b.ply");
  EXPECT_EQ(r.cloud.points[0], (Vec3d{0.1, 0.2, 0.3}));
  EXPECT_FALSE(r.cloud.has_normals());
}

TEST(PointCloudPly, MalformedInput) {
  std::string s = kAsciiPly;
  s.replace(s.find("4 5 6 1 0 0"), 11, "4 5 6 nan 0 0");  // nx of point 2
  EXPECT_TRUE(fails_with(s, "a.ply", ErrorCode::NonFinite, "a.ply:17"));
  s = kAsciiPly;
  s.replace(s.find("1 2 3 0 0 0"), 11, "1 2 3 0 0 zz");
  EXPECT_TRUE(fails_with(s, "a.ply", ErrorCode::ParseError, "a.ply:16"));
  EXPECT_TRUE(fails_with(kAsciiPly.substr(0, kAsciiPly.find("4 5 6")) + "4 5 6      \n", "a.ply",
                         ErrorCode::Truncated, "a.ply:18"));
  s = kAsciiPly;
  s.replace(s.find("property float ny\n"), 18, "");
  EXPECT_TRUE(fails_with(s, "a.ply", ErrorCode::ParseError, "a.ply:3"));
  s = kAsciiPly;
  s.replace(s.find("property double y\n"), 18, "property double w\n");
  EXPECT_TRUE(fails_with(s, "a.ply", ErrorCode::ParseError, "a.ply:3"));
  EXPECT_TRUE(
      fails_with("ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int "
                 "vertex_indices\nend_header\n",
                 "a.ply", ErrorCode::ParseError, "a.ply:5"));
  EXPECT_TRUE(fails_with("ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\n", "a.ply",
                         ErrorCode::UnsupportedFormat, "a.ply:4"));
  EXPECT_TRUE(fails_with("PLY\n", "a.ply", ErrorCode::UnsupportedFormat, "a.ply:1"));
  // A binary body with a NaN normal: named by its byte.
  Bytes b;
  b.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nproperty float nx\nproperty float ny\n"
      "property float nz\nend_header\n");
  const std::size_t body = b.s.size();
  b.put(0.f).put(0.f).put(0.f).put(0.f).put(std::numeric_limits<float>::quiet_NaN()).put(0.f);
  EXPECT_TRUE(
      fails_with(b.s, "n.ply", ErrorCode::NonFinite, "n.ply @ byte " + std::to_string(body + 16)));
  // Too short for the header's count: refused at the element line before reading.
  EXPECT_TRUE(fails_with(b.s.substr(0, b.s.size() - 3), "n.ply", ErrorCode::Truncated, "n.ply:3"));
}

TEST(PointCloudPly, AbsurdCountsRefusedBeforeAllocating) {
  for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(format);
    std::string file = std::string("ply\nformat ") + format +
                       " 1.0\nelement vertex 1000000000000\nproperty float x\nproperty float y\n"
                       "property float z\nend_header\n";
    file.resize(std::max<std::size_t>(file.size(), 100), ' ');
    EXPECT_TRUE(fails_with(file, "h.ply", ErrorCode::LimitExceeded, "h.ply:3"));
    PointCloudReadOptions unlimited;
    unlimited.max_points = UINT64_MAX;
    EXPECT_TRUE(fails_with(file, "h.ply", ErrorCode::Truncated, "h.ply:3", unlimited));
  }
}

TEST(PointCloudOff, ReadsVertices) {
  const PointCloudReadResult r = read("OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "k.off");
  EXPECT_EQ(r.format, PointCloudFormat::Off);
  ASSERT_EQ(r.cloud.points.size(), 3u);
  EXPECT_EQ(r.cloud.points[1], (Vec3d{1, 0, 0}));
  EXPECT_FALSE(r.cloud.has_normals());
  EXPECT_TRUE(
      fails_with("OFF\n3 0 0\n0 0 0\n1 0 0\n0 nan 0\n", "k.off", ErrorCode::NonFinite, "k.off:5"));
}

TEST(PointCloudXyz, ReadsFromDisk) {
  const char* env = std::getenv("LEVELSET_TMP");
  const std::filesystem::path dir = env != nullptr && *env != '\0'
                                        ? std::filesystem::path(env)
                                        : std::filesystem::temp_directory_path() / "levelset-test";
  std::filesystem::create_directories(dir);
  const auto path = dir / "point_cloud.xyz";
  {
    std::ofstream out(path, std::ios::binary);
    out << "1 2 3\n4 5 6\n";
  }
  EXPECT_EQ(read_point_cloud(path).cloud.points.size(), 2u);
  std::filesystem::remove(path);
  try {
    read_point_cloud(path);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::IoError);
  }
}

TEST(PointCloudXyz, FuzzSeedCorpusIsValid) {
  static constexpr const char* kExt[] = {".xyz", ".xyzn", ".pwn", ".ply", ".off"};
  const int seen = test::for_each_fuzz_seed("fuzz_point_cloud_reader", kExt, [](std::string_view bytes, const std::string& name) {
    if (name.rfind("bomb_", 0) == 0) {  // hostile: refused by a limit, at once
      try {
        read(bytes, name);
        ADD_FAILURE() << name << " was read";
      } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << name << ": " << e.what();
      }
      return;
    }
    EXPECT_FALSE(read(bytes, name).cloud.points.empty()) << name;
  });
  EXPECT_GE(seen, 7);
}

}  // namespace
}  // namespace levelset
