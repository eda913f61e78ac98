// read_image: INRIMAGE-4 and NRRD (raw, gzip, detached), every error kind, CGAL's sample images.
#include <gtest/gtest.h>
#include <zlib.h>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/progress.hpp"
#include "io/image_reader.hpp"
#include "reader_test_support.hpp"

namespace levelset {
namespace {

namespace fs = std::filesystem;
using test::fails_with;

std::string describe(const ImageReadResult& r) {
  return std::to_string(r.image.nx) + "x" + std::to_string(r.image.ny) + "x" + std::to_string(r.image.nz);
}

::testing::AssertionResult fails(std::string_view bytes, std::string_view name, ErrorCode code,
                                 std::string_view where, const ImageReadOptions& options = {}) {
  return fails_with([&] { return read_image_from_memory(bytes, name, options); }, describe, code, where);
}

// An INR header with the given fields, padded with newlines to 256 bytes (or not).
std::string inr_header(const std::string& fields, bool pad = true) {
  std::string h = "#INRIMAGE-4#{\n" + fields;
  if (pad)
    while ((h.size() + 4) % 256 != 0) h += '\n';
  return h + "##}\n";
}

template <typename T>
std::string raw(const std::vector<T>& values, bool big_endian = false) {
  std::string out(values.size() * sizeof(T), '\0');
  std::memcpy(out.data(), values.data(), out.size());
  if (big_endian != (std::endian::native == std::endian::big))
    for (std::size_t i = 0; i < out.size(); i += sizeof(T)) std::reverse(out.begin() + std::ptrdiff_t(i), out.begin() + std::ptrdiff_t(i + sizeof(T)));
  return out;
}

std::string gzip(std::string_view data) {
  z_stream z{};
  EXPECT_EQ(deflateInit2(&z, 9, Z_DEFLATED, 16 + 15, 9, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&z, uLong(data.size())) + 64, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = uInt(data.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

const std::string kInrU8 = "XDIM=3\nYDIM=2\nZDIM=2\nVDIM=1\nTYPE=unsigned fixed\nPIXSIZE=8 bits\nSCALE=2**0\nCPU=decm\n";

TEST(ImageReader, InrUnsigned8WithSpacingAndOrigin) {
  const std::string bytes = inr_header(kInrU8 + "VX=0.5\nVY=2\nVZ=3.25\nTX=1\nTY=-2\nTZ=4\n#GEOMETRY=CARTESIAN\n") +
                            raw<std::uint8_t>({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 255});
  const ImageReadResult r = read_image_from_memory(bytes, "a.inr");
  EXPECT_EQ(r.format, ImageFormat::Inr);
  EXPECT_EQ(r.sample_type, "uint8");
  ASSERT_EQ(r.image.nx, 3);
  ASSERT_EQ(r.image.ny, 2);
  ASSERT_EQ(r.image.nz, 2);
  EXPECT_EQ(r.image.at(2, 0, 0), 2.0f);
  EXPECT_EQ(r.image.at(0, 1, 0), 3.0f);
  EXPECT_EQ(r.image.at(2, 1, 1), 255.0f);
  EXPECT_EQ(r.image.spacing, (Vec3d{0.5, 2, 3.25}));
  EXPECT_EQ(r.image.origin, (Vec3d{1, -2, 4}));
  EXPECT_EQ(r.image.world(1, 1, 1), (Vec3d{1.5, 0, 7.25}));
  EXPECT_EQ(r.min_sample, 0.0f);
  EXPECT_EQ(r.max_sample, 255.0f);
}

TEST(ImageReader, InrTypesAndEndianness) {
  const std::string dims = "XDIM=2\nYDIM=1\nZDIM=1\n";
  const ImageReadResult s16 = read_image_from_memory(
      inr_header(dims + "TYPE=signed fixed\nPIXSIZE=16 bits\nCPU=sun\n") + raw<std::int16_t>({-300, 1234}, true), "b.inr");
  EXPECT_EQ(s16.sample_type, "int16");
  EXPECT_TRUE(s16.big_endian);
  EXPECT_EQ(s16.image.samples, (std::vector<float>{-300, 1234}));
  const ImageReadResult f32 = read_image_from_memory(
      inr_header(dims + "TYPE=float\nPIXSIZE=32 bits\nCPU=pc\n") + raw<float>({-1.5f, 2.25f}), "c.inr");
  EXPECT_EQ(f32.image.samples, (std::vector<float>{-1.5f, 2.25f}));
  const ImageReadResult f64 = read_image_from_memory(
      inr_header(dims + "TYPE=float\nPIXSIZE=64 bits\nCPU=sgi\n") + raw<double>({0.125, -8.0}, true), "d.inr");
  EXPECT_EQ(f64.image.samples, (std::vector<float>{0.125f, -8.0f}));
  const ImageReadResult u32 = read_image_from_memory(
      inr_header(dims + "TYPE=unsigned fixed\nPIXSIZE=32 bits\n") + raw<std::uint32_t>({7, 1u << 20}), "e.inr");
  EXPECT_EQ(u32.image.samples, (std::vector<float>{7.0f, float(1u << 20)}));
}

TEST(ImageReader, InrHeaderNotPaddedAndGzip) {
  const std::string data = raw<std::uint8_t>({9, 8, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2});
  const std::string plain = inr_header(kInrU8, false) + data;
  EXPECT_EQ(read_image_from_memory(plain, "p.inr").image.at(0, 0, 0), 9.0f);
  const ImageReadResult z = read_image_from_memory(gzip(inr_header(kInrU8) + data), "p.inr.gz");
  EXPECT_TRUE(z.gzip);
  EXPECT_EQ(z.image.samples[3], 6.0f);
  // Two gzip members (as `cat a.gz b.gz` makes) read as one stream.
  const std::string whole = inr_header(kInrU8) + data;
  const ImageReadResult two = read_image_from_memory(gzip(whole.substr(0, 100)) + gzip(whole.substr(100)), "q.inr.gz");
  EXPECT_EQ(two.image.samples, z.image.samples);
}

TEST(ImageReader, ACancelDuringTheSamplesEndsTheReadWithinAChunk) {
  // 128^3 gzip samples (2M, under one progress report of 2^24): the token fires at the first
  // report, after the first chunk. The read must end there with Error{Cancelled} (a daemon's
  // cancelled job stops inflating), not run to the end as when only the reports checked.
  const std::string fields = "XDIM=128\nYDIM=128\nZDIM=128\nVDIM=1\nTYPE=unsigned fixed\nPIXSIZE=8 bits\nSCALE=2**0\nCPU=decm\n";
  const std::string bytes = gzip(inr_header(fields) + std::string(std::size_t{128} * 128 * 128, '\x07'));
  auto token = std::make_shared<CancelToken>();
  int reports = 0;
  ImageReadOptions o;
  o.progress.cancel = token;
  o.progress.on_progress = [&](double, std::string_view) {
    ++reports;
    token->cancel();
  };
  EXPECT_TRUE(fails(bytes, "c.inr.gz", ErrorCode::Cancelled, "image", o));
  EXPECT_EQ(reports, 1);
  // Without the cancel the same bytes read whole.
  EXPECT_EQ(read_image_from_memory(bytes, "c.inr.gz").image.samples.size(), std::size_t{128} * 128 * 128);
}

TEST(ImageReader, InrErrors) {
  const std::string data = raw<std::uint8_t>(std::vector<std::uint8_t>(12, 1));
  EXPECT_TRUE(fails("", "e.inr", ErrorCode::Truncated, "e.inr @ byte 0"));
  EXPECT_TRUE(fails("#INRIMAGE-5#{\nXDIM=1\n", "e.inr", ErrorCode::UnsupportedFormat, "e.inr:1"));
  EXPECT_TRUE(fails("#INRIMAGE-4#{\nXDIM=3\n", "e.inr", ErrorCode::Truncated, "e.inr @ byte 21"));
  EXPECT_TRUE(fails(inr_header("XDIM=3\nYDIM=2\nTYPE=float\nPIXSIZE=32 bits\n"), "e.inr", ErrorCode::ParseError, "e.inr:203"));
  EXPECT_TRUE(fails(inr_header("XDIM=3x\nYDIM=2\nZDIM=2\n") + data, "e.inr", ErrorCode::ParseError, "e.inr:2"));
  EXPECT_TRUE(fails(inr_header("XDIM=3\nXDIM=3\n") + data, "e.inr", ErrorCode::ParseError, "e.inr:3"));
  EXPECT_TRUE(fails(inr_header("XDIM=3\nYDIM=2\nZDIM=2\nbad line\n") + data, "e.inr", ErrorCode::ParseError, "e.inr:5"));
  EXPECT_TRUE(fails(inr_header(kInrU8 + "VX=nan\n") + data, "e.inr", ErrorCode::NonFinite, "e.inr:10"));
  EXPECT_TRUE(fails(inr_header(kInrU8 + "VY=-1\n") + data, "e.inr", ErrorCode::ParseError, "e.inr:10"));
  EXPECT_TRUE(fails(inr_header("XDIM=3\nYDIM=2\nZDIM=2\nTYPE=complex\nPIXSIZE=8 bits\n") + data, "e.inr",
                    ErrorCode::UnsupportedFormat, "e.inr:5"));
  EXPECT_TRUE(fails(inr_header("XDIM=3\nYDIM=2\nZDIM=2\nTYPE=float\nPIXSIZE=16 bits\n") + data, "e.inr",
                    ErrorCode::UnsupportedFormat, "e.inr:5"));
  EXPECT_TRUE(fails(inr_header("XDIM=3\nYDIM=2\nZDIM=2\nVDIM=3\nTYPE=float\nPIXSIZE=32 bits\n") + data, "e.inr",
                    ErrorCode::UnsupportedFormat, "e.inr:5"));
  EXPECT_TRUE(fails(inr_header(kInrU8 + "CPU=vax\n"), "e.inr", ErrorCode::ParseError, "e.inr:10"));  // repeated CPU
  EXPECT_TRUE(fails(inr_header("XDIM=3\nYDIM=2\nZDIM=2\nTYPE=float\nPIXSIZE=32 bits\nCPU=vax\n") + data, "e.inr",
                    ErrorCode::UnsupportedFormat, "e.inr:7"));
  // Absurd sizes: beyond the voxel cap, and 64-bit overflow of the product.
  EXPECT_TRUE(fails(inr_header("XDIM=100000\nYDIM=100000\nZDIM=100000\nTYPE=float\nPIXSIZE=32 bits\n"), "e.inr",
                    ErrorCode::LimitExceeded, "e.inr:2"));
  EXPECT_TRUE(fails(inr_header("XDIM=4294967296\nYDIM=4294967296\nZDIM=4294967296\nTYPE=float\nPIXSIZE=32 bits\n"),
                    "e.inr", ErrorCode::LimitExceeded, "e.inr:2"));
  EXPECT_TRUE(fails(inr_header("XDIM=99999999999999999999\nYDIM=1\nZDIM=1\n"), "e.inr", ErrorCode::LimitExceeded, "e.inr:2"));
  ImageReadOptions small;
  small.max_sample_bytes = 1000;
  EXPECT_TRUE(fails(inr_header("XDIM=100\nYDIM=100\nZDIM=1\nTYPE=float\nPIXSIZE=32 bits\n"), "e.inr",
                    ErrorCode::LimitExceeded, "e.inr:2", small));
  // Truncated data: the place is the first missing sample's byte.
  const std::string header = inr_header(kInrU8);
  EXPECT_TRUE(fails(header + data.substr(0, 7), "e.inr", ErrorCode::Truncated, "e.inr @ byte " + std::to_string(header.size() + 7)));
  const std::string fheader = inr_header("XDIM=3\nYDIM=1\nZDIM=1\nTYPE=float\nPIXSIZE=32 bits\n");
  EXPECT_TRUE(fails(fheader + raw<float>({1.0f, std::numeric_limits<float>::quiet_NaN(), 2.0f}), "e.inr",
                    ErrorCode::NonFinite, "e.inr @ byte " + std::to_string(fheader.size() + 4)));
  EXPECT_TRUE(fails("plain text", "e.inr", ErrorCode::UnsupportedFormat, "e.inr @ byte 0"));
}

TEST(ImageReader, GzipErrorsAndBombs) {
  // Incompressible data, so that a cut stream ends inside the samples.
  std::vector<std::uint8_t> noise(4096);
  std::uint32_t state = 1;
  for (std::uint8_t& b : noise) b = std::uint8_t((state = state * 1664525u + 1013904223u) >> 24);
  const std::string z = gzip(inr_header("XDIM=16\nYDIM=16\nZDIM=16\nTYPE=unsigned fixed\nPIXSIZE=8 bits\n") + raw(noise));
  // A cut stream reads as truncated data (at a byte inside the samples); a damaged one is Corrupt.
  try {
    read_image_from_memory(z.substr(0, z.size() / 2), "t.inr.gz");
    ADD_FAILURE() << "read a cut gzip stream";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Truncated) << e.what();
    EXPECT_EQ(e.where().rfind("t.inr.gz @ byte ", 0), 0u) << e.what();
    const long byte = std::atol(e.where().c_str() + 16);
    EXPECT_GT(byte, 256);
    EXPECT_LT(byte, 256 + 4096);
  }
  std::string bad = z;
  for (std::size_t i = 10; i < 30; ++i) bad[i] = char(0xff);
  try {
    read_image_from_memory(bad, "c.inr.gz");
    ADD_FAILURE() << "read a damaged gzip stream";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Corrupt) << e.what();
  }
  // A bomb: 8 MiB of zeros after a header claiming a 2^40-voxel image stops at the header;
  // after a header claiming 16^3 voxels only those are inflated.
  const std::string zeros(std::size_t{1} << 23, '\0');
  const std::string big = gzip(inr_header("XDIM=1048576\nYDIM=1048576\nZDIM=1\nTYPE=unsigned fixed\nPIXSIZE=8 bits\n") + zeros);
  EXPECT_LT(big.size(), 40000u);
  EXPECT_TRUE(fails(big, "bomb.inr.gz", ErrorCode::LimitExceeded, "bomb.inr.gz:2"));
  const std::string small = gzip(inr_header("XDIM=16\nYDIM=16\nZDIM=16\nTYPE=unsigned fixed\nPIXSIZE=8 bits\n") + zeros);
  const ImageReadResult r = read_image_from_memory(small, "bomb.inr.gz");
  EXPECT_EQ(r.image.samples.size(), 4096u);
  EXPECT_LE(r.image.samples.capacity(), 8192u);
  // A small file claiming an image within the caps fails without allocating it.
  ImageReadOptions options;
  const std::string claim = gzip(inr_header("XDIM=512\nYDIM=512\nZDIM=512\nTYPE=unsigned fixed\nPIXSIZE=8 bits\n") + "abc");
  EXPECT_TRUE(fails(claim, "claim.inr.gz", ErrorCode::Truncated, "claim.inr.gz @ byte 259", options));
}

std::string nrrd(const std::string& fields) { return "NRRD0004\n# a comment\n" + fields + "\n"; }

TEST(ImageReader, NrrdRawTypesSpacingOrigin) {
  const ImageReadResult a = read_image_from_memory(
      nrrd("type: unsigned short\ndimension: 3\nsizes: 2 1 2\nendian: big\nencoding: raw\nspacings: 0.5 1 2\nkinds: domain domain domain\nkey:=value\n") +
          raw<std::uint16_t>({1, 2, 60000, 4}, true),
      "a.nrrd");
  EXPECT_EQ(a.format, ImageFormat::Nrrd);
  EXPECT_EQ(a.sample_type, "uint16");
  EXPECT_EQ(a.image.samples, (std::vector<float>{1, 2, 60000, 4}));
  EXPECT_EQ(a.image.spacing, (Vec3d{0.5, 1, 2}));
  const ImageReadResult b = read_image_from_memory(
      nrrd("type: double\ndimension: 3\nsizes: 1 1 2\nendian: little\nencoding: raw\nspace: left-posterior-superior\n"
           "space directions: (0.25,0,0) (0,0.5,0) (0,0,4)\nspace origin: (1,2,-3)\n") +
          raw<double>({-1.0, 3.5}),
      "b.nrrd");
  EXPECT_EQ(b.image.samples, (std::vector<float>{-1.0f, 3.5f}));
  EXPECT_EQ(b.image.spacing, (Vec3d{0.25, 0.5, 4}));
  EXPECT_EQ(b.image.origin, (Vec3d{1, 2, -3}));
  // 2D image: nz = 1; int8; byte skip -1 (data at the end); line skip.
  const ImageReadResult c = read_image_from_memory(
      nrrd("type: int8\ndimension: 2\nsizes: 2 2\nencoding: raw\nbyte skip: -1\n") + "junk" + raw<std::int8_t>({-5, 5, -128, 127}),
      "c.nrrd");
  EXPECT_EQ(c.image.nz, 1);
  EXPECT_EQ(c.image.samples, (std::vector<float>{-5, 5, -128, 127}));
  const ImageReadResult d = read_image_from_memory(
      nrrd("type: uint8\ndimension: 1\nsizes: 3\nencoding: raw\nline skip: 2\nbyte skip: 1\n") + "a\nb\nX" + raw<std::uint8_t>({1, 2, 3}),
      "d.nrrd");
  EXPECT_EQ(d.image.samples, (std::vector<float>{1, 2, 3}));
}

TEST(ImageReader, NrrdGzipAndDetached) {
  const std::string data = raw<float>({1, 2, 3, 4, 5, 6});
  const ImageReadResult z = read_image_from_memory(
      nrrd("type: float\ndimension: 3\nsizes: 3 2 1\nendian: little\nencoding: gzip\n") + gzip(data), "z.nrrd");
  EXPECT_TRUE(z.gzip);
  EXPECT_EQ(z.image.samples, (std::vector<float>{1, 2, 3, 4, 5, 6}));
  // Detached: .nhdr next to its data file (relative path), raw and gzip.
  const char* tmp_env = std::getenv("LEVELSET_TMP");
  const fs::path dir = fs::path(tmp_env && *tmp_env ? tmp_env : fs::temp_directory_path().string()) / "image_reader_test";
  fs::create_directories(dir);
  std::ofstream(dir / "vol.raw", std::ios::binary) << data;
  std::ofstream(dir / "vol.raw.gz", std::ios::binary) << gzip(data);
  std::ofstream(dir / "vol.nhdr", std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nsizes: 3 2 1\nendian: little\nencoding: raw\ndata file: vol.raw\n";
  std::ofstream(dir / "volz.nhdr", std::ios::binary)
      << "NRRD0004\ntype: float\ndimension: 3\nsizes: 3 2 1\nendian: little\nencoding: gzip\ndatafile: vol.raw.gz\n";
  const ImageReadResult det = read_image(dir / "vol.nhdr");
  EXPECT_TRUE(det.detached);
  EXPECT_EQ(det.image.samples, z.image.samples);
  EXPECT_EQ(read_image(dir / "volz.nhdr").image.samples, z.image.samples);
  // From memory there is no folder to look in.
  const std::string header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 3 2 1\nendian: little\nencoding: raw\ndata file: vol.raw\n";
  EXPECT_TRUE(fails(header, "m.nhdr", ErrorCode::UnsupportedFormat, "m.nhdr:7"));
  try {
    read_image(dir / "missing.nhdr");
    ADD_FAILURE() << "read a missing file";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::IoError);
  }
  fs::remove_all(dir);
}

TEST(ImageReader, NrrdErrors) {
  const std::string u8 = "type: uint8\ndimension: 3\nsizes: 2 2 1\n";
  const std::string data = raw<std::uint8_t>({1, 2, 3, 4});
  EXPECT_TRUE(fails("NRRD0009\n", "e.nrrd", ErrorCode::UnsupportedFormat, "e.nrrd:1"));
  EXPECT_TRUE(fails(nrrd(u8) + data, "e.nrrd", ErrorCode::ParseError, "e.nrrd:6"));  // no encoding
  EXPECT_TRUE(fails(nrrd(u8 + "encoding: bzip2\n") + data, "e.nrrd", ErrorCode::UnsupportedFormat, "e.nrrd:6"));
  EXPECT_TRUE(fails(nrrd("type: quaternion\ndimension: 3\nsizes: 2 2 1\nencoding: raw\n"), "e.nrrd", ErrorCode::UnsupportedFormat, "e.nrrd:3"));
  EXPECT_TRUE(fails(nrrd("type: short\ndimension: 3\nsizes: 2 2 1\nencoding: raw\n"), "e.nrrd", ErrorCode::ParseError, "e.nrrd:7"));
  EXPECT_TRUE(fails(nrrd("type: uint8\ndimension: 3\nsizes: 2 2\nencoding: raw\n"), "e.nrrd", ErrorCode::ParseError, "e.nrrd:5"));
  EXPECT_TRUE(fails(nrrd("type: uint8\ndimension: 4\nsizes: 1 2 2 1\nencoding: raw\n"), "e.nrrd", ErrorCode::UnsupportedFormat, "e.nrrd:4"));
  EXPECT_TRUE(fails(nrrd(u8 + "encoding: raw\nspacings: 1 nan 1\n") + data, "e.nrrd", ErrorCode::NonFinite, "e.nrrd:7"));
  EXPECT_TRUE(fails(nrrd(u8 + "encoding: raw\nspace directions: (0,1,0) (1,0,0) (0,0,1)\n") + data, "e.nrrd",
                    ErrorCode::UnsupportedFormat, "e.nrrd:7"));
  EXPECT_TRUE(fails(nrrd(u8 + "encoding: raw\nspace origin: (1,2)\n") + data, "e.nrrd", ErrorCode::ParseError, "e.nrrd:7"));
  EXPECT_TRUE(fails(nrrd(u8 + "encoding: raw\nthis is not a field\n") + data, "e.nrrd", ErrorCode::ParseError, "e.nrrd:7"));
  EXPECT_TRUE(fails(nrrd(u8 + "encoding: raw\nencoding: raw\n") + data, "e.nrrd", ErrorCode::ParseError, "e.nrrd:7"));
  EXPECT_TRUE(fails(nrrd("type: uint8\ndimension: 3\nsizes: 4096 4096 4096\nencoding: raw\n"), "e.nrrd", ErrorCode::LimitExceeded, "e.nrrd:5"));
  EXPECT_TRUE(fails(nrrd(u8 + "encoding: raw\n") + data.substr(0, 3), "e.nrrd", ErrorCode::Truncated, "e.nrrd @ byte 77"));
  EXPECT_TRUE(fails("NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 1\nencoding: raw\n", "e.nrrd", ErrorCode::Truncated, "e.nrrd:5"));
  EXPECT_TRUE(fails(nrrd(u8 + "encoding: gzip\n") + gzip(data.substr(0, 2)), "e.nrrd", ErrorCode::Truncated,
                    "e.nrrd (decompressed) @ byte 2"));
}

fs::path cgal_images() {
  const char* env = std::getenv("LEVELSET_CGAL_DATA");
  return (env != nullptr && *env != '\0' ? fs::path(env) : fs::path(LEVELSET_CGAL_DATA)) / "images";
}

TEST(ImageReader, CgalSampleImages) {
  const fs::path dir = cgal_images();
  ASSERT_TRUE(fs::is_directory(dir))
      << "CGAL sample data not found at " << dir << " (install-deps.sh installs it)";
  const ImageReadResult skull = read_image(dir / "skull_2.9.inr");
  EXPECT_EQ(skull.image.nx, 64);
  EXPECT_EQ(skull.image.nz, 64);
  EXPECT_EQ(skull.sample_type, "float");
  EXPECT_NEAR(skull.image.spacing.x, 3.943050, 1e-9);
  EXPECT_NEAR(skull.image.spacing.z, 3.650790, 1e-9);
  EXPECT_GE(skull.min_sample, 0.0f);
  EXPECT_GT(skull.max_sample, 2.9f);  // the file's name is its iso-value
  const ImageReadResult small = read_image(dir / "small-scalar.inr");  // a 240-byte header
  EXPECT_EQ(small.image.samples, (std::vector<float>{6, -2, -1, 3, -3, 1, -1, -1.4f}));
  const ImageReadResult tiny = read_image(dir / "420.inr");
  EXPECT_EQ(tiny.image.voxel_count(), 8u);
  EXPECT_EQ(tiny.image.spacing, (Vec3d{100, 100, 100}));
  const ImageReadResult liver = read_image(dir / "liver.inr.gz");
  EXPECT_TRUE(liver.gzip);
  EXPECT_EQ(liver.image.nx, 438);
  EXPECT_EQ(liver.image.ny, 353);
  EXPECT_EQ(liver.image.nz, 165);
  EXPECT_EQ(liver.max_sample, 255.0f);
}

}  // namespace
}  // namespace levelset
