// NRRD volumes: round trips of the written types and the strict reader's errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/nrrd_file.hpp"

namespace levelset {

namespace {

ErrorCode code_of(const std::string& bytes, std::uint64_t max_voxels = 1000) {
  try {
    decode_nrrd(bytes, "t.nrrd", max_voxels);
  } catch (const Error& e) {
    return e.code();
  }
  ADD_FAILURE() << "no error for:\n" << bytes.substr(0, 200);
  return ErrorCode::Cancelled;
}

std::string header(const std::string& fields) { return "NRRD0004\n" + fields + "\n\n"; }

}  // namespace

TEST(NrrdFile, RoundTripsInt32AndFloat) {
  const NrrdFrame frame{{3, 2, 2}, 0.25, {1.5, -2.0, 0.125}};
  std::vector<std::int32_t> labels(12);
  std::vector<float> values(12);
  for (int i = 0; i < 12; ++i) labels[i] = i * 7 - 20, values[i] = 0.5f * float(i) - 1.0f;
  values[5] = std::numeric_limits<float>::infinity();
  const NrrdVolume a = decode_nrrd(encode_nrrd(frame, std::span<const std::int32_t>(labels)), "a");
  const NrrdVolume b = decode_nrrd(encode_nrrd(frame, std::span<const float>(values)), "b");
  for (const NrrdVolume* v : {&a, &b}) {
    EXPECT_EQ(v->frame.sizes[0], 3);
    EXPECT_EQ(v->frame.sizes[1], 2);
    EXPECT_EQ(v->frame.sizes[2], 2);
    EXPECT_EQ(v->frame.spacing, 0.25);
    EXPECT_EQ(v->frame.origin, frame.origin);
  }
  EXPECT_EQ(a.type, "int32");
  EXPECT_EQ(b.type, "float");
  for (int i = 0; i < 12; ++i) {
    EXPECT_EQ(a.samples[i], labels[i]);
    EXPECT_EQ(b.samples[i], double(values[i]));
  }
}

TEST(NrrdFile, ReadsOtherTypesWithCommentsAndSpacings) {
  std::string bytes = header("# a comment\ntype: unsigned char\ndimension: 3\nsizes: 2 1 1\nspacings: 2 2 2\n"
                             "encoding: raw\nkey:=value");
  bytes += std::string("\x07\xff", 2);
  const NrrdVolume v = decode_nrrd(bytes, "u8");
  EXPECT_EQ(v.frame.spacing, 2.0);
  ASSERT_EQ(v.samples.size(), 2u);
  EXPECT_EQ(v.samples[0], 7.0);
  EXPECT_EQ(v.samples[1], 255.0);
}

TEST(NrrdFile, MalformedInputIsRejected) {
  const std::string ok = "type: float\ndimension: 3\nsizes: 2 1 1\nendian: little\nencoding: raw";
  const std::string data(8, '\0');
  EXPECT_NO_THROW(decode_nrrd(header(ok) + data, "ok"));
  EXPECT_EQ(code_of("PNG\n" + data), ErrorCode::UnsupportedFormat);
  EXPECT_EQ(code_of(header(ok) + data.substr(0, 7)), ErrorCode::Truncated);
  EXPECT_EQ(code_of(header(ok) + data + "x"), ErrorCode::Corrupt);
  EXPECT_EQ(code_of("NRRD0004\ntype: float\n"), ErrorCode::Truncated);
  EXPECT_EQ(code_of(header("type: float\ndimension: 2\nsizes: 2 1\nendian: little\nencoding: raw")),
            ErrorCode::UnsupportedFormat);
  EXPECT_EQ(code_of(header("type: float\ndimension: 3\nsizes: 2 1 1\nendian: little\nencoding: gzip") + data),
            ErrorCode::UnsupportedFormat);
  EXPECT_EQ(code_of(header("type: float\ndimension: 3\nsizes: 2 1 1\nendian: big\nencoding: raw") + data),
            ErrorCode::UnsupportedFormat);
  EXPECT_EQ(code_of(header("type: float\ndimension: 3\nsizes: 2 x 1\nendian: little\nencoding: raw") + data),
            ErrorCode::ParseError);
  EXPECT_EQ(code_of(header("type: float\ndimension: 3\nsizes: 2 1 1\nencoding: raw\ndata file: x.raw")),
            ErrorCode::UnsupportedFormat);
  EXPECT_EQ(code_of(header("type: quaternion\ndimension: 3\nsizes: 2 1 1\nencoding: raw") + data),
            ErrorCode::UnsupportedFormat);
  EXPECT_EQ(code_of(header("type: float\ndimension: 3\nsizes: 1000 1000 1000\nendian: little\nencoding: raw") + data),
            ErrorCode::LimitExceeded);
  EXPECT_EQ(code_of(header("type: float\ndimension: 3\nsizes: 2 1 1\nencoding: raw\nspace directions: (1,0,0) (0,2,0) (0,0,1)\nendian: little") + data),
            ErrorCode::UnsupportedFormat);
  EXPECT_EQ(code_of("NRRD0004\n" + std::string(70000, 'a') + "\n\n"), ErrorCode::LimitExceeded);
  std::string nan(8, '\0');
  const float q = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan.data() + 4, &q, 4);
  EXPECT_EQ(code_of(header(ok) + nan), ErrorCode::NonFinite);
}

}  // namespace levelset
