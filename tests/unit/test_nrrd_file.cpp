// NRRD volumes written by the applications (labels, travel times) read back through the
// image reader (io/image_reader.hpp) with their frame and samples, Inf included when allowed.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "core/error.hpp"
#include "io/image_reader.hpp"
#include "io/nrrd_file.hpp"

namespace levelset {

TEST(NrrdFile, WrittenInt32AndFloatReadBackExactly) {
  const NrrdFrame frame{{3, 2, 2}, 0.25, {1.5, -2.0, 0.125}};
  std::vector<std::int32_t> labels(12);
  std::vector<float> values(12);
  for (int i = 0; i < 12; ++i) labels[i] = i * 7 - 20, values[i] = 0.5f * float(i) - 1.0f;
  values[5] = std::numeric_limits<float>::infinity();
  ImageReadOptions allow_inf;
  allow_inf.allow_infinite = true;
  const ImageReadResult a = read_image_from_memory(encode_nrrd(frame, std::span<const std::int32_t>(labels)), "a.nrrd");
  const ImageReadResult b =
      read_image_from_memory(encode_nrrd(frame, std::span<const float>(values)), "b.nrrd", allow_inf);
  for (const ImageReadResult* r : {&a, &b}) {
    const ImageVolume& v = r->image;
    EXPECT_EQ(r->format, ImageFormat::Nrrd);
    EXPECT_EQ(v.nx, 3);
    EXPECT_EQ(v.ny, 2);
    EXPECT_EQ(v.nz, 2);
    EXPECT_EQ(v.spacing, (Vec3d{0.25, 0.25, 0.25}));
    EXPECT_EQ(v.origin, frame.origin);
  }
  EXPECT_EQ(a.sample_type, "int32");
  EXPECT_EQ(b.sample_type, "float");
  for (int i = 0; i < 12; ++i) {
    EXPECT_EQ(a.image.samples[i], float(labels[i]));
    EXPECT_EQ(b.image.samples[i], values[i]);
  }
  // Without allow_infinite the Inf sample is an error naming its byte.
  try {
    read_image_from_memory(encode_nrrd(frame, std::span<const float>(values)), "b.nrrd");
    ADD_FAILURE() << "Inf accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NonFinite);
    EXPECT_NE(e.where().find("@ byte"), std::string::npos) << e.where();
  }
}

TEST(NrrdFile, WriterRefusesMismatchedSizes) {
  const NrrdFrame frame{{3, 2, 2}, 1.0, {}};
  const std::vector<float> too_few(11);
  EXPECT_THROW(encode_nrrd(frame, std::span<const float>(too_few)), Error);
}

}  // namespace levelset
