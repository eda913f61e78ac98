// Tests of the .lsg reader and writer (common/grid/lsg_file.*).
//
// The test carries its own minimal encoder, written from the layout in lsg_file.hpp and using
// zstd and xxhash directly. It pins the format (its bytes must equal encode_lsg's) and crafts
// files whose checksum is valid but whose structure is not, so the reader's structure checks
// are reached.
#include <gtest/gtest.h>

#include <xxhash.h>
#include <zstd.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <unistd.h>
#include <vector>

#include "core/error.hpp"
#include "grid/lsg_file.hpp"
#include "shape_band.hpp"
#include "grid/narrow_band.hpp"
#include "shape_band.hpp"

namespace levelset {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kName = "test.lsg";

// ---------------------------------------------------------------------------------------------
// Independent encoder.

struct RawBrick {
  Coord coord;
  BrickMask active;
  BrickMask inside;
};

// Everything a file holds, in file order, without any of NarrowBand's derived tables.
struct RawBand {
  GridFrame frame;
  bool far_inside = false;
  std::vector<RawBrick> bricks;
  std::vector<float> values;
};

RawBand raw_band_of(const NarrowBand& band) {
  RawBand r;
  r.frame = band.frame();
  r.far_inside = band.far_inside();
  for (std::uint32_t b = 0; b < band.brick_count(); ++b)
    r.bricks.push_back({band.bricks()[b].coord, band.bricks()[b].active, band.inside_mask(b)});
  r.values.assign(band.values().begin(), band.values().end());
  return r;
}

// Header fields as written, one member per field of the spec.
struct Header {
  std::uint32_t version = 1;
  std::uint32_t header_bytes = 128;
  std::uint32_t value_type = 1;
  std::uint32_t flags = 0;
  double voxel_size = 1.0;
  double origin[3] = {0, 0, 0};
  double half_width = 3.0;
  std::uint64_t bricks = 0;
  std::uint64_t active = 0;
  std::uint64_t raw_bytes = 0;
  std::uint64_t stored_bytes = 0;
  unsigned char reserved[24] = {};
};

void append_le(std::string& s, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void append_f64(std::string& s, double d) { append_le(s, std::bit_cast<std::uint64_t>(d), 8); }

std::uint64_t read_le(std::string_view s, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= std::uint64_t(static_cast<unsigned char>(s[at + i])) << (8 * i);
  return v;
}

// The uncompressed payload: coords, active masks, inside masks, values in 4 byte planes.
std::string raw_payload_of(const RawBand& r) {
  std::string s;
  for (const RawBrick& b : r.bricks) {
    append_le(s, static_cast<std::uint32_t>(b.coord.x), 4);
    append_le(s, static_cast<std::uint32_t>(b.coord.y), 4);
    append_le(s, static_cast<std::uint32_t>(b.coord.z), 4);
  }
  for (const RawBrick& b : r.bricks)
    for (std::uint64_t w : b.active.words) append_le(s, w, 8);
  for (const RawBrick& b : r.bricks)
    for (std::uint64_t w : b.inside.words) append_le(s, w, 8);
  for (int plane = 0; plane < 4; ++plane)
    for (float v : r.values)
      s.push_back(static_cast<char>((std::bit_cast<std::uint32_t>(v) >> (8 * plane)) & 0xff));
  return s;
}

std::string zstd_compress(std::string_view raw, int level) {
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  const std::size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), level);
  if (ZSTD_isError(n)) throw std::runtime_error(ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

Header header_of(const RawBand& r, std::uint64_t raw_bytes, std::uint64_t stored_bytes) {
  Header h;
  h.flags = r.far_inside ? 1u : 0u;
  h.voxel_size = r.frame.voxel_size;
  h.origin[0] = r.frame.origin.x;
  h.origin[1] = r.frame.origin.y;
  h.origin[2] = r.frame.origin.z;
  h.half_width = r.frame.half_width;
  h.bricks = r.bricks.size();
  h.active = r.values.size();
  h.raw_bytes = raw_bytes;
  h.stored_bytes = stored_bytes;
  return h;
}

std::uint64_t file_checksum(std::string_view file) {
  // One-shot over a concatenation (the library streams; the result must be the same).
  std::string covered(file.substr(0, 120));
  covered.append(file.substr(128));
  return XXH3_64bits(covered.data(), covered.size());
}

// Recomputes the checksum field after the header or payload was patched.
std::string reseal(std::string file) {
  const std::uint64_t sum = file_checksum(file);
  for (int i = 0; i < 8; ++i) file[120 + i] = static_cast<char>((sum >> (8 * i)) & 0xff);
  return file;
}

std::string file_of(const Header& h, std::string_view stored) {
  std::string s("\x89LSG\r\n\x1a\n", 8);
  append_le(s, h.version, 4);
  append_le(s, h.header_bytes, 4);
  append_le(s, h.value_type, 4);
  append_le(s, h.flags, 4);
  append_f64(s, h.voxel_size);
  for (double o : h.origin) append_f64(s, o);
  append_f64(s, h.half_width);
  append_le(s, h.bricks, 8);
  append_le(s, h.active, 8);
  append_le(s, h.raw_bytes, 8);
  append_le(s, h.stored_bytes, 8);
  s.append(reinterpret_cast<const char*>(h.reserved), sizeof h.reserved);
  append_le(s, 0, 8);  // checksum, below
  EXPECT_EQ(s.size(), 128u);
  s.append(stored);
  return reseal(std::move(s));
}

// A complete file; patch may change header fields after they were derived from r.
std::string craft(const RawBand& r, int level = 3, const std::function<void(Header&)>& patch = {}) {
  const std::string raw = raw_payload_of(r);
  const std::string stored = zstd_compress(raw, level);
  Header h = header_of(r, raw.size(), stored.size());
  if (patch) patch(h);
  return file_of(h, stored);
}

// A complete file around an arbitrary uncompressed payload (sizes from it, counts from h).
std::string craft_raw(Header h, std::string_view raw) {
  const std::string stored = zstd_compress(raw, 3);
  h.raw_bytes = raw.size();
  h.stored_bytes = stored.size();
  return file_of(h, stored);
}

// ---------------------------------------------------------------------------------------------
// Bands used by the tests.

GridFrame odd_frame() {
  GridFrame f;
  f.voxel_size = 0.1;
  f.origin = {-1.5, 2.25, 0.125};
  f.half_width = 2.0;
  return f;
}

// A few voxels around negative coordinates, with mixed signs, six bricks, one voxel
// deactivated (its inside bit stays set in an allocated brick).
NarrowBand negative_coord_band() {
  NarrowBand band(odd_frame());
  band.set_value({-1, -1, -1}, -0.05f);
  band.set_value({0, -1, -1}, 0.05f);
  band.set_value({-1, 0, -1}, 0.06f);
  band.set_value({-17, -3, -100}, -0.15f);
  band.set_value({-16, -3, -100}, 0.0f);
  band.set_value({-18, -3, -100}, -0.125f);
  band.set_value({5, -9, 2}, 0.1f);
  band.set_value({6, -9, 2}, -0.1f);
  band.deactivate({6, -9, 2});
  return band;
}

// Two bricks, a handful of voxels: a small file for exhaustive truncation and bit flips.
NarrowBand small_band() {
  NarrowBand band(odd_frame());
  const float vals[] = {-0.15f, -0.05f, 0.05f, 0.15f};
  for (int i = 0; i < 4; ++i) band.set_value({2 + i, 3, 4}, vals[i]);
  for (int i = 0; i < 4; ++i) band.set_value({2 + i, 3, 12}, -vals[i]);
  return band;
}

// ---------------------------------------------------------------------------------------------
// Assertions.

std::uint64_t where_offset(const std::string& where) {
  const std::string prefix = std::string(kName) + " @ byte ";
  if (where.rfind(prefix, 0) != 0) return std::numeric_limits<std::uint64_t>::max();
  return std::stoull(where.substr(prefix.size()));
}

// decode_lsg must throw Error{code}; where must be "test.lsg @ byte <offset>" (any offset within
// the input when offset is nullopt).
testing::AssertionResult refused(std::string_view bytes, ErrorCode code,
                                 std::optional<std::uint64_t> offset,
                                 const LsgReadOptions& options = {}) {
  try {
    const LsgReadResult r = decode_lsg(bytes, kName, options);
    return testing::AssertionFailure() << "accepted a " << bytes.size() << "-byte input ("
                                       << r.band.active_voxel_count() << " voxels)";
  } catch (const Error& e) {
    if (e.code() != code)
      return testing::AssertionFailure() << "code " << to_string(e.code()) << " instead of "
                                         << to_string(code) << ": " << e.what();
    // Structure errors inside the decompressed payload name a payload offset instead.
    const bool in_payload = e.where().rfind(std::string(kName) + " @ payload byte ", 0) == 0;
    const std::uint64_t at = where_offset(e.where());
    if (offset ? at != *offset : (at > bytes.size() && !in_payload))
      return testing::AssertionFailure() << "where '" << e.where() << "' does not name byte "
                                         << (offset ? std::to_string(*offset) : "in the input");
    if (e.reason().empty()) return testing::AssertionFailure() << "empty reason";
    return testing::AssertionSuccess();
  } catch (const std::exception& e) {
    return testing::AssertionFailure() << "non-levelset exception: " << e.what();
  }
}

std::string set_byte(std::string s, std::size_t at, unsigned char v) {
  s[at] = static_cast<char>(v);
  return s;
}

// Scratch directory: $LEVELSET_TMP/lsg_file/<test>-<pid>, fresh for every test.
fs::path scratch_dir() {
  const char* env = std::getenv("LEVELSET_TMP");
  const fs::path base = env && *env ? fs::path(env) : fs::temp_directory_path() / "levelset-tests";
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir =
      base / "lsg_file" / (std::string(info->name()) + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void expect_round_trip(const NarrowBand& band) {
  const std::string bytes = encode_lsg(band);
  const LsgReadResult r = decode_lsg(bytes, kName);
  EXPECT_TRUE(r.band.identical(band));
  EXPECT_EQ(r.band.far_inside(), band.far_inside());
  EXPECT_EQ(r.band.brick_count(), band.brick_count());
  EXPECT_EQ(r.band.active_voxel_count(), band.active_voxel_count());
  EXPECT_EQ(r.file_bytes, bytes.size());
  EXPECT_EQ(r.header.version, kLsgVersion);
  EXPECT_EQ(r.header.value_type, 1u);
  EXPECT_EQ(r.header.far_inside, band.far_inside());
  EXPECT_EQ(r.header.bricks, band.brick_count());
  EXPECT_EQ(r.header.active_voxels, band.active_voxel_count());
  EXPECT_EQ(r.header.raw_bytes, band.brick_count() * 140 + band.active_voxel_count() * 4);
  EXPECT_EQ(r.header.stored_bytes + 128, bytes.size());
  EXPECT_EQ(encode_lsg(r.band), bytes) << "re-encoding the decoded band changed the bytes";
  EXPECT_EQ(r.band.mixed_sign_bricks(), band.mixed_sign_bricks());
  for (std::uint32_t b = 0; b < band.brick_count(); ++b)
    ASSERT_EQ(r.band.inside_mask(b), band.inside_mask(b)) << "brick " << b;
  // Every voxel reads back the same through the band's own lookups.
  band.for_each_active([&](const Coord& c, float v) {
    const std::optional<float> got = r.band.value(c);
    ASSERT_TRUE(got.has_value());
    EXPECT_EQ(std::bit_cast<std::uint32_t>(*got), std::bit_cast<std::uint32_t>(v));
    EXPECT_EQ(r.band.is_inside(c), band.is_inside(c));
  });
}

// ---------------------------------------------------------------------------------------------
// (a) Round trips.

TEST(LsgFileRoundTrip, EveryBuiltinShapeIsBitIdentical) {
  for (const std::string& name : builtin_shape_names()) {
    SCOPED_TRACE(name);
    const test::ShapeBand sb = test::make_shape_band(name, 48);
    ASSERT_GT(sb.band.active_voxel_count(), 1000u);
    expect_round_trip(sb.band);
  }
}

TEST(LsgFileRoundTrip, EmptyBand) {
  const NarrowBand band(odd_frame());
  expect_round_trip(band);
  const LsgReadResult r = decode_lsg(encode_lsg(band), kName);
  EXPECT_EQ(r.band.brick_count(), 0u);
  EXPECT_DOUBLE_EQ(r.band.voxel_size(), 0.1);
  EXPECT_EQ(r.band.origin().x, -1.5);
  EXPECT_EQ(r.band.half_width(), 2.0);
  EXPECT_FALSE(r.band.is_inside({0, 0, 0}));
}

TEST(LsgFileRoundTrip, FarInsideFlagSurvives) {
  test::ShapeBand sb = test::make_shape_band("torus", 48);
  sb.band.set_far_inside(true);
  const std::string bytes = encode_lsg(sb.band);
  EXPECT_EQ(read_le(bytes, 20, 4), 1u);
  expect_round_trip(sb.band);
  const LsgReadResult r = decode_lsg(bytes, kName);
  EXPECT_TRUE(r.band.far_inside());
  EXPECT_TRUE(r.band.is_inside({-1000, -1000, -1000}));  // far outside any brick: far_inside

  NarrowBand empty(odd_frame());
  empty.set_far_inside(true);
  expect_round_trip(empty);
  EXPECT_TRUE(decode_lsg(encode_lsg(empty), kName).band.is_inside({3, 4, 5}));
}

TEST(LsgFileRoundTrip, SetValueBandWithNegativeCoordinates) {
  const NarrowBand band = negative_coord_band();
  ASSERT_EQ(band.brick_count(), 6u);
  ASSERT_EQ(band.active_voxel_count(), 7u);
  expect_round_trip(band);
  EXPECT_GE(band.mixed_sign_bricks(), 1u) << "expected a brick with inactive voxels on both sides";
  const NarrowBand back = decode_lsg(encode_lsg(band), kName).band;
  EXPECT_EQ(back.value({-17, -3, -100}), -0.15f);
  EXPECT_FALSE(back.is_active({6, -9, 2}));
  EXPECT_TRUE(back.is_inside({6, -9, 2})) << "inside bit of a deactivated voxel was lost";
  EXPECT_EQ(back.value_or_background({6, -9, 2}), -back.background());
}

TEST(LsgFileRoundTrip, EveryCompressionLevelDecodesTheSame) {
  const NarrowBand band = test::make_shape_band("dumbbell", 32).band;
  for (int level : {1, 3, 9, 19}) {
    const LsgReadResult r = decode_lsg(encode_lsg(band, {level, {}}), kName);
    EXPECT_TRUE(r.band.identical(band)) << "level " << level;
  }
  EXPECT_THROW(encode_lsg(band, {0, {}}), Error);
  EXPECT_THROW(encode_lsg(band, {20, {}}), Error);
}

TEST(LsgFileRoundTrip, ReportsProgressAndHonoursCancellation) {
  const std::string bytes = encode_lsg(small_band());
  LsgReadOptions options;
  std::vector<double> fractions;
  options.progress.on_progress = [&](double f, std::string_view) { fractions.push_back(f); };
  (void)decode_lsg(bytes, kName, options);
  ASSERT_FALSE(fractions.empty());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  auto token = std::make_shared<CancelToken>();
  token->cancel();
  options.progress.cancel = token;
  try {
    (void)decode_lsg(bytes, kName, options);
    FAIL() << "a cancelled decode returned a band";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Cancelled);
  }
}

// ---------------------------------------------------------------------------------------------
// (b) The independent encoder pins the format.

TEST(LsgFileFormat, IndependentEncoderMatchesEncodeLsgByteForByte) {
  const NarrowBand bands[] = {negative_coord_band(), small_band(), NarrowBand(odd_frame()),
                              test::make_shape_band("knot", 40).band,
                              test::make_shape_band("box", 24, 1.5).band};
  for (const NarrowBand& band : bands) {
    for (int level : {1, 3, 19}) {
      SCOPED_TRACE(testing::Message() << band.active_voxel_count() << " voxels, level " << level);
      const std::string mine = craft(raw_band_of(band), level);
      const std::string theirs = encode_lsg(band, {level, {}});
      EXPECT_EQ(mine.size(), theirs.size());
      EXPECT_TRUE(mine == theirs) << "independent encoder and encode_lsg disagree";
      const LsgReadResult r = decode_lsg(mine, kName);
      EXPECT_TRUE(r.band.identical(band));
    }
  }
}

TEST(LsgFileFormat, HeaderFieldsSitWhereTheSpecSays) {
  const NarrowBand band = negative_coord_band();
  const std::string f = encode_lsg(band);
  EXPECT_EQ(f.substr(0, 8), std::string("\x89LSG\r\n\x1a\n", 8));
  EXPECT_EQ(read_le(f, 8, 4), 1u);
  EXPECT_EQ(read_le(f, 12, 4), 128u);
  EXPECT_EQ(read_le(f, 16, 4), 1u);
  EXPECT_EQ(read_le(f, 20, 4), 0u);
  EXPECT_EQ(std::bit_cast<double>(read_le(f, 24, 8)), 0.1);
  EXPECT_EQ(std::bit_cast<double>(read_le(f, 32, 8)), -1.5);
  EXPECT_EQ(std::bit_cast<double>(read_le(f, 40, 8)), 2.25);
  EXPECT_EQ(std::bit_cast<double>(read_le(f, 48, 8)), 0.125);
  EXPECT_EQ(std::bit_cast<double>(read_le(f, 56, 8)), 2.0);
  EXPECT_EQ(read_le(f, 64, 8), 6u);
  EXPECT_EQ(read_le(f, 72, 8), 7u);
  EXPECT_EQ(read_le(f, 80, 8), 6u * 140 + 7u * 4);
  EXPECT_EQ(read_le(f, 88, 8), f.size() - 128);
  for (std::size_t i = 96; i < 120; ++i) EXPECT_EQ(f[i], '\0') << "reserved byte " << i;
  EXPECT_EQ(read_le(f, 120, 8), file_checksum(f));
  // The payload is one zstd frame holding exactly the raw layout.
  const std::string raw = raw_payload_of(raw_band_of(band));
  std::string out(raw.size() + 16, '\0');
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), f.data() + 128, f.size() - 128);
  ASSERT_FALSE(ZSTD_isError(n));
  out.resize(n);
  EXPECT_TRUE(out == raw);
}

// ---------------------------------------------------------------------------------------------
// (c) Refusals.

TEST(LsgFileRefuse, EmptyAndTinyInputs) {
  EXPECT_TRUE(refused(std::string_view{}, ErrorCode::Truncated, 0));
  EXPECT_TRUE(refused(std::string_view("", 0), ErrorCode::Truncated, 0));
  const std::string magic("\x89LSG\r\n\x1a\n", 8);
  for (std::size_t n = 1; n < 8; ++n)
    EXPECT_TRUE(refused(magic.substr(0, n), ErrorCode::Truncated, n)) << n;
  EXPECT_TRUE(refused("hello", ErrorCode::UnsupportedFormat, 0));
  EXPECT_TRUE(refused("\x89LSX", ErrorCode::UnsupportedFormat, 0));
  EXPECT_TRUE(refused(magic + "\x01", ErrorCode::Truncated, 9));
}

TEST(LsgFileRefuse, WrongMagic) {
  const std::string good = encode_lsg(small_band());
  for (std::size_t i = 0; i < 8; ++i)
    EXPECT_TRUE(refused(set_byte(good, i, 'X'), ErrorCode::UnsupportedFormat, 0)) << i;
  EXPECT_TRUE(refused(std::string("\x89PNG\r\n\x1a\n") + std::string(200, '\0'),
                      ErrorCode::UnsupportedFormat, 0));
  EXPECT_TRUE(refused("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", ErrorCode::UnsupportedFormat, 0));
}

TEST(LsgFileRefuse, NewerVersionComesBeforeEverythingElse) {
  const std::string good = encode_lsg(small_band());
  Header h;
  // Valid checksum.
  EXPECT_TRUE(refused(reseal(set_byte(good, 8, 2)), ErrorCode::UnsupportedVersion, 8));
  // Bad checksum, bad value type, trailing bytes, truncated payload: still the version.
  EXPECT_TRUE(refused(set_byte(good, 8, 2), ErrorCode::UnsupportedVersion, 8));
  EXPECT_TRUE(refused(set_byte(set_byte(good, 8, 2), 16, 7), ErrorCode::UnsupportedVersion, 8));
  EXPECT_TRUE(refused(set_byte(good, 8, 2) + "xyz", ErrorCode::UnsupportedVersion, 8));
  EXPECT_TRUE(refused(set_byte(good, 8, 2).substr(0, 128), ErrorCode::UnsupportedVersion, 8));
  EXPECT_TRUE(refused(set_byte(good, 11, 0x80), ErrorCode::UnsupportedVersion, 8));
  try {
    (void)decode_lsg(set_byte(good, 8, 2), kName);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.reason()).find('2'), std::string::npos) << e.reason();
  }
  // Version 0 never existed.
  EXPECT_TRUE(refused(reseal(set_byte(good, 8, 0)), ErrorCode::Corrupt, 8));
}

TEST(LsgFileRefuse, TruncationAtEveryLength) {
  const std::string good = encode_lsg(small_band());
  ASSERT_LT(good.size(), 1000u);
  ASSERT_GT(good.size(), 160u);
  for (std::size_t n = 0; n < good.size(); ++n)
    EXPECT_TRUE(refused(std::string_view(good).substr(0, n), ErrorCode::Truncated, n)) << "length " << n;
  EXPECT_NO_THROW((void)decode_lsg(good, kName));
}

TEST(LsgFileRefuse, OneFlippedBitAtEveryByte) {
  const std::string good = encode_lsg(small_band());
  const std::uint64_t stored = good.size() - 128;
  int corrupt = 0, total = 0;
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::string bad = good;
      bad[i] = static_cast<char>(bad[i] ^ (1 << bit));
      ErrorCode expect = ErrorCode::Corrupt;
      if (i < 8) {
        expect = ErrorCode::UnsupportedFormat;
      } else if (i < 12) {
        expect = (i == 8 && bit == 0) ? ErrorCode::Corrupt : ErrorCode::UnsupportedVersion;
      } else if (i >= 16 && i < 20) {
        expect = ErrorCode::UnsupportedFormat;
      } else if (i >= 88 && i < 96) {
        expect = read_le(bad, 88, 8) > stored ? ErrorCode::Truncated : ErrorCode::Corrupt;
      }
      // Where: the field checked before the checksum, else the checksum field.
      std::optional<std::uint64_t> at = 120;
      if (i < 8) at = 0;
      if (i >= 8 && i < 24) at = i & ~std::size_t{3};
      if (i == 20 && bit <= 1) at = 120;  // flags 1 and 2 are valid: checksum fails
      if (i >= 88 && i < 96) at = std::nullopt;  // stored size: truncated or trailing bytes
      if (i >= 96 && i < 120) at = i;  // reserved bytes are checked before the checksum
      EXPECT_TRUE(refused(bad, expect, at)) << "byte " << i << " bit " << bit;
      corrupt += expect == ErrorCode::Corrupt;
      ++total;
    }
  }
  EXPECT_GT(corrupt, total * 3 / 4);
}

TEST(LsgFileRefuse, TrailingBytes) {
  const std::string good = encode_lsg(small_band());
  EXPECT_TRUE(refused(good + '\0', ErrorCode::Corrupt, good.size()));
  EXPECT_TRUE(refused(good + good, ErrorCode::Corrupt, good.size()));
  // Trailing bytes covered by a recomputed checksum are still trailing bytes.
  EXPECT_TRUE(refused(reseal(good + "junk"), ErrorCode::Corrupt, good.size()));
}

TEST(LsgFileRefuse, HeaderFieldsWithValidChecksum) {
  const RawBand r = raw_band_of(small_band());
  EXPECT_NO_THROW((void)decode_lsg(craft(r), kName));
  EXPECT_TRUE(refused(craft(r, 3, [](Header& h) { h.header_bytes = 256; }), ErrorCode::Corrupt, 12));
  EXPECT_TRUE(refused(craft(r, 3, [](Header& h) { h.value_type = 2; }), ErrorCode::UnsupportedFormat, 16));
  EXPECT_TRUE(refused(craft(r, 3, [](Header& h) { h.value_type = 0; }), ErrorCode::UnsupportedFormat, 16));
  for (std::uint32_t flags : {4u, 5u, 0x100u, 0x80000000u})
    EXPECT_TRUE(refused(craft(r, 3, [&](Header& h) { h.flags = flags; }), ErrorCode::Corrupt, 20)) << flags;
  for (std::size_t i = 0; i < 24; ++i)
    EXPECT_TRUE(refused(craft(r, 3, [&](Header& h) { h.reserved[i] = 1; }), ErrorCode::Corrupt, 96 + i));
}

TEST(LsgFileRefuse, BadGridFrame) {
  const RawBand r = raw_band_of(small_band());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  // The frame fields live in [24, 64); the error names a byte there.
  auto frame_refused = [&](const std::function<void(Header&)>& patch) {
    try {
      (void)decode_lsg(craft(r, 3, patch), kName);
      return testing::AssertionFailure() << "accepted";
    } catch (const Error& e) {
      const std::uint64_t at = where_offset(e.where());
      if (e.code() != ErrorCode::Corrupt || at < 24 || at >= 64)
        return testing::AssertionFailure() << e.what();
      return testing::AssertionSuccess();
    }
  };
  for (double h : {0.0, -0.0, -1.0, nan, inf, -inf})
    EXPECT_TRUE(frame_refused([&](Header& hd) { hd.voxel_size = h; })) << "voxel size " << h;
  for (double w : {0.5, 0.0, -3.0, nan, inf, 1e9})
    EXPECT_TRUE(frame_refused([&](Header& hd) { hd.half_width = w; })) << "half width " << w;
  for (int a = 0; a < 3; ++a) {
    EXPECT_TRUE(frame_refused([&](Header& hd) { hd.origin[a] = nan; })) << "origin " << a;
    EXPECT_TRUE(frame_refused([&](Header& hd) { hd.origin[a] = -inf; })) << "origin " << a;
  }
}

TEST(LsgFileRefuse, UnsortedAndDuplicateBricks) {
  const RawBand good = raw_band_of(negative_coord_band());
  ASSERT_EQ(good.bricks.size(), 6u);
  EXPECT_NO_THROW((void)decode_lsg(craft(good), kName));

  // Swap two bricks (values moved along, so only the order is wrong).
  RawBand swapped;
  swapped.frame = good.frame;
  {
    const NarrowBand band = negative_coord_band();
    for (std::uint32_t b : {1u, 0u, 2u, 3u, 4u, 5u}) {
      const Brick& br = band.bricks()[b];
      swapped.bricks.push_back({br.coord, br.active, band.inside_mask(b)});
      const auto v = band.brick_values(b);
      swapped.values.insert(swapped.values.end(), v.begin(), v.end());
    }
  }
  EXPECT_TRUE(refused(craft(swapped), ErrorCode::Corrupt, std::nullopt));

  // Brick 1 twice, each copy with its own values: only the duplication is wrong.
  RawBand dup = good;
  dup.bricks.insert(dup.bricks.begin() + 1, dup.bricks[1]);
  dup.values = [&] {
    std::vector<float> v;
    const NarrowBand band = negative_coord_band();
    for (std::uint32_t b : {0u, 1u, 1u, 2u, 3u, 4u, 5u}) {
      const auto bv = band.brick_values(b);
      v.insert(v.end(), bv.begin(), bv.end());
    }
    return v;
  }();
  EXPECT_TRUE(refused(craft(dup), ErrorCode::Corrupt, std::nullopt));

  // Out of the index range.
  RawBand far = good;
  far.bricks[2].coord.x = kBrickCoordLimit;
  EXPECT_TRUE(refused(craft(far), ErrorCode::Corrupt, std::nullopt));
  far.bricks[2].coord.x = std::numeric_limits<std::int32_t>::min();
  EXPECT_TRUE(refused(craft(far), ErrorCode::Corrupt, std::nullopt));
}

TEST(LsgFileRefuse, ActiveCountDisagreesWithMasks) {
  const RawBand good = raw_band_of(small_band());
  // One mask bit more than there are values (sizes stay consistent with the header).
  RawBand more = good;
  more.bricks[0].active.set(511);
  Header h = header_of(good, 0, 0);
  EXPECT_TRUE(refused(craft_raw(h, raw_payload_of(more)), ErrorCode::Corrupt, 72));
  // One mask bit fewer.
  RawBand fewer = good;
  int first = -1;
  fewer.bricks[0].active.for_each_set([&](int n) { if (first < 0) first = n; });
  fewer.bricks[0].active.reset(first);
  EXPECT_TRUE(refused(craft_raw(h, raw_payload_of(fewer)), ErrorCode::Corrupt, 72));
  // Header count off by one with a matching raw size: masks and header disagree.
  RawBand extra_value = good;
  extra_value.values.push_back(1.0f);
  h.active = extra_value.values.size();
  EXPECT_TRUE(refused(craft_raw(h, raw_payload_of(extra_value)), ErrorCode::Corrupt, 72));
}

TEST(LsgFileRefuse, RawSizeDisagreesWithCounts) {
  const RawBand r = raw_band_of(small_band());
  const std::string raw = raw_payload_of(r);
  const std::string stored = zstd_compress(raw, 3);
  for (std::int64_t delta : {-4, -1, 1, 4, 140}) {
    Header h = header_of(r, raw.size() + delta, stored.size());
    EXPECT_TRUE(refused(file_of(h, stored), ErrorCode::Corrupt, 80)) << delta;
  }
  // Counts and raw size agree, but the frame holds fewer bytes.
  Header h = header_of(r, raw.size() + 4, stored.size());
  h.active += 1;
  EXPECT_TRUE(refused(file_of(h, stored), ErrorCode::Corrupt, std::nullopt));
  // Or more (the frame is longer than the header says).
  const std::string longer = zstd_compress(raw + std::string(300, 'x'), 3);
  h = header_of(r, raw.size(), longer.size());
  EXPECT_TRUE(refused(file_of(h, longer), ErrorCode::Corrupt, std::nullopt));
  // Much more: a frame of 1 MiB of zeros behind a header saying a few hundred bytes.
  const std::string huge = zstd_compress(raw + std::string(1 << 20, '\0'), 19);
  h = header_of(r, raw.size(), huge.size());
  EXPECT_TRUE(refused(file_of(h, huge), ErrorCode::Corrupt, std::nullopt));
}

TEST(LsgFileRefuse, BadCompressedPayload) {
  const RawBand r = raw_band_of(small_band());
  const std::string raw = raw_payload_of(r);
  const std::string stored = zstd_compress(raw, 3);
  // Not zstd at all.
  const std::string garbage(stored.size(), 'g');
  EXPECT_TRUE(refused(file_of(header_of(r, raw.size(), garbage.size()), garbage), ErrorCode::Corrupt,
                      std::nullopt));
  // A frame cut short (sizes consistent with the header, checksum valid).
  const std::string cut = stored.substr(0, stored.size() - 3);
  EXPECT_TRUE(refused(file_of(header_of(r, raw.size(), cut.size()), cut), ErrorCode::Corrupt,
                      std::nullopt));
  // Two frames, the first already complete.
  const std::string two = stored + stored;
  EXPECT_TRUE(refused(file_of(header_of(r, raw.size(), two.size()), two), ErrorCode::Corrupt,
                      std::nullopt));
  // The raw payload split over two frames.
  const std::string split = zstd_compress(raw.substr(0, 100), 3) + zstd_compress(raw.substr(100), 3);
  EXPECT_TRUE(refused(file_of(header_of(r, raw.size(), split.size()), split), ErrorCode::Corrupt,
                      std::nullopt));
  // No payload at all where one is expected.
  EXPECT_TRUE(refused(file_of(header_of(r, raw.size(), 0), ""), ErrorCode::Corrupt, std::nullopt));
}

TEST(LsgFileRefuse, NonFiniteValues) {
  const RawBand good = raw_band_of(small_band());
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::quiet_NaN(),
                    std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()}) {
    RawBand r = good;
    r.values[3] = bad;
    EXPECT_TRUE(refused(craft(r), ErrorCode::Corrupt, std::nullopt)) << bad;
  }
  // A signalling NaN bit pattern, too.
  RawBand r = good;
  r.values[0] = std::bit_cast<float>(0x7f800001u);
  EXPECT_TRUE(refused(craft(r), ErrorCode::Corrupt, std::nullopt));
}

TEST(LsgFileRefuse, SignBitsDisagreeWithValues) {
  const NarrowBand band = small_band();
  const RawBand good = raw_band_of(band);
  ASSERT_NO_THROW((void)decode_lsg(craft(good), kName));
  // Flip the inside bit of each active voxel in turn.
  int n_checked = 0;
  for (std::size_t b = 0; b < good.bricks.size(); ++b) {
    good.bricks[b].active.for_each_set([&](int n) {
      RawBand r = good;
      r.bricks[b].inside.assign(n, !r.bricks[b].inside.test(n));
      EXPECT_TRUE(refused(craft(r), ErrorCode::Corrupt, std::nullopt)) << "brick " << b << " voxel " << n;
      ++n_checked;
    });
  }
  EXPECT_EQ(n_checked, 8);
  // Negate a value instead (0 would stay "not inside", so pick a non-zero one).
  RawBand r = good;
  ASSERT_NE(r.values[1], 0.0f);
  r.values[1] = -r.values[1];
  EXPECT_TRUE(refused(craft(r), ErrorCode::Corrupt, std::nullopt));
  // Inside bits of inactive voxels are free: flipping one is a valid file.
  RawBand inactive = good;
  inactive.bricks[0].inside.assign(511, !inactive.bricks[0].inside.test(511));
  const NarrowBand back = decode_lsg(craft(inactive), kName).band;
  EXPECT_EQ(back.inside_mask(0), inactive.bricks[0].inside);
  EXPECT_EQ(back.is_inside({7, 7, 7}), inactive.bricks[0].inside.test(511));
}

TEST(LsgFileRefuse, HugeCountsInATinyFileFailFastWithoutAllocating) {
  const RawBand r = raw_band_of(small_band());
  const std::string raw = raw_payload_of(r);
  const std::string stored = zstd_compress(raw, 3);
  Header h = header_of(r, 0, stored.size());
  h.active = 1'000'000'000'000ull;
  h.raw_bytes = h.bricks * 140 + h.active * 4;
  const std::string file = file_of(h, stored);
  ASSERT_LT(file.size(), 400u);

  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(refused(file, ErrorCode::LimitExceeded, 64));
  // Even with every limit lifted, the reader may only allocate what it decompresses.
  LsgReadOptions lifted;
  lifted.max_active_voxels = std::numeric_limits<std::uint64_t>::max();
  lifted.max_raw_bytes = std::numeric_limits<std::uint64_t>::max();
  lifted.max_compression_ratio = std::numeric_limits<double>::infinity();
  lifted.memory_budget = std::numeric_limits<std::uint64_t>::max();
  EXPECT_TRUE(refused(file, ErrorCode::Corrupt, std::nullopt, lifted));
  // Bricks beyond 2^32 (with a raw size that does not overflow either way).
  Header hb = header_of(r, 0, stored.size());
  hb.bricks = (std::uint64_t{1} << 32) + 1;
  hb.raw_bytes = hb.bricks * 140 + hb.active * 4;
  EXPECT_TRUE(refused(file_of(hb, stored), ErrorCode::LimitExceeded, 64, lifted));
  // Counts whose product overflows 64 bits.
  Header ho = header_of(r, 0, stored.size());
  ho.active = std::uint64_t{1} << 62;
  ho.raw_bytes = raw.size();
  EXPECT_TRUE(refused(file_of(ho, stored), ErrorCode::LimitExceeded, 64));
  EXPECT_TRUE(refused(file_of(ho, stored), ErrorCode::Corrupt, std::nullopt, lifted));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 2.0) << "refusing absurd counts took too long (allocating?)";
}

TEST(LsgFileRefuse, ReadLimitsAreHonoured) {
  const NarrowBand band = test::make_shape_band("sphere", 32).band;
  const std::string bytes = encode_lsg(band);
  LsgReadOptions options;
  options.max_raw_bytes = band.brick_count() * 140 + band.active_voxel_count() * 4 - 1;
  EXPECT_TRUE(refused(bytes, ErrorCode::LimitExceeded, 80, options));
  options.max_raw_bytes += 1;
  EXPECT_NO_THROW((void)decode_lsg(bytes, kName, options));
  options.max_active_voxels = band.active_voxel_count() - 1;
  EXPECT_TRUE(refused(bytes, ErrorCode::LimitExceeded, 64, options));
}

// ---------------------------------------------------------------------------------------------
// (d) Files.

TEST(LsgFileSave, WritesAtomicallyAndLoadsBack) {
  const fs::path dir = scratch_dir();
  const NarrowBand band = test::make_shape_band("sphere", 32).band;
  const fs::path path = dir / "sphere.lsg";
  const LsgWriteResult w = save_lsg(band, path);
  EXPECT_EQ(listing(dir), std::vector<std::string>{"sphere.lsg"}) << "temporary file left behind";
  EXPECT_EQ(w.file_bytes, fs::file_size(path));
  EXPECT_EQ(w.raw_bytes, band.brick_count() * 140 + band.active_voxel_count() * 4);
  EXPECT_EQ(read_all(path), encode_lsg(band));
  const LsgReadResult r = load_lsg(path);
  EXPECT_TRUE(r.band.identical(band));
  EXPECT_EQ(r.file_bytes, w.file_bytes);
  // A read limit below the file size refuses before reading.
  LsgReadOptions small;
  small.max_file_bytes = w.file_bytes - 1;
  try {
    (void)load_lsg(path, small);
    FAIL() << "max_file_bytes ignored";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
  }
  fs::remove_all(dir);
}

TEST(LsgFileSave, ReplacesAnExistingFileCompletely) {
  const fs::path dir = scratch_dir();
  const fs::path path = dir / "out.lsg";
  {
    std::ofstream junk(path, std::ios::binary);
    junk << std::string(1 << 20, 'x');
  }
  const NarrowBand band = small_band();
  const LsgWriteResult w = save_lsg(band, path);
  EXPECT_EQ(fs::file_size(path), w.file_bytes);
  EXPECT_LT(w.file_bytes, 1000u);
  EXPECT_EQ(read_all(path), encode_lsg(band));
  // And again with a different band: no trace of the first.
  const NarrowBand other = negative_coord_band();
  save_lsg(other, path);
  EXPECT_EQ(read_all(path), encode_lsg(other));
  EXPECT_TRUE(load_lsg(path).band.identical(other));
  EXPECT_EQ(listing(dir), std::vector<std::string>{"out.lsg"});
  fs::remove_all(dir);
}

TEST(LsgFileSave, MissingDirectoryThrowsIoErrorAndCreatesNothing) {
  const fs::path dir = scratch_dir();
  const fs::path path = dir / "no" / "such" / "dir" / "x.lsg";
  try {
    save_lsg(small_band(), path);
    FAIL() << "saved into a missing directory";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::IoError);
    EXPECT_NE(e.where().find("x.lsg"), std::string::npos) << e.where();
  }
  EXPECT_FALSE(fs::exists(dir / "no"));
  EXPECT_TRUE(listing(dir).empty());
  fs::remove_all(dir);
}

TEST(LsgFileLoad, MissingFileDirectoryAndEmptyFile) {
  const fs::path dir = scratch_dir();
  auto load_error = [](const fs::path& p) -> std::optional<Error> {
    try {
      (void)load_lsg(p);
    } catch (const Error& e) {
      return e;
    }
    return std::nullopt;
  };
  const auto missing = load_error(dir / "missing.lsg");
  ASSERT_TRUE(missing.has_value());
  EXPECT_EQ(missing->code(), ErrorCode::IoError);
  EXPECT_NE(missing->where().find("missing.lsg"), std::string::npos);
  EXPECT_NE(missing->reason().find("does not exist"), std::string::npos) << missing->reason();

  fs::create_directory(dir / "sub.lsg");
  const auto directory = load_error(dir / "sub.lsg");
  ASSERT_TRUE(directory.has_value());
  EXPECT_EQ(directory->code(), ErrorCode::IoError);
  EXPECT_NE(directory->where().find("sub.lsg"), std::string::npos);
  EXPECT_NE(directory->reason().find("not a regular file"), std::string::npos) << directory->reason();

  { std::ofstream empty(dir / "empty.lsg"); }
  const auto empty = load_error(dir / "empty.lsg");
  ASSERT_TRUE(empty.has_value());
  EXPECT_EQ(empty->code(), ErrorCode::Truncated);
  EXPECT_EQ(empty->where(), at_byte((dir / "empty.lsg").string(), 0));

  // A damaged file on disk names its path and the byte.
  std::string bytes = encode_lsg(small_band());
  bytes.back() = static_cast<char>(bytes.back() ^ 0x10);
  { std::ofstream out(dir / "bad.lsg", std::ios::binary); out << bytes; }
  const auto bad = load_error(dir / "bad.lsg");
  ASSERT_TRUE(bad.has_value());
  EXPECT_EQ(bad->code(), ErrorCode::Corrupt);
  EXPECT_EQ(bad->where(), at_byte((dir / "bad.lsg").string(), 120));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace levelset

namespace levelset {
namespace {

TEST(LsgFileRoundTrip, ClosestPointsFieldSurvivesBitExactly) {
  const auto sb = test::make_shape_band("torus", 32);
  std::vector<Vec3f> points(sb.band.active_voxel_count());
  std::size_t i = 0;
  sb.band.for_each_active_world([&](const Coord&, const Vec3d& p, float) {
    points[i++] = {float(p.x * 0.5), float(p.y - 1.0), float(p.z) + 1e-7f * float(i)};
  });
  LsgWriteOptions options;
  options.closest_points = points;
  const std::string bytes = encode_lsg(sb.band, options);
  const LsgReadResult r = decode_lsg(bytes, "cp.lsg");
  EXPECT_TRUE(r.header.closest_points);
  EXPECT_TRUE(r.band.identical(sb.band));
  ASSERT_EQ(r.closest_points.size(), points.size());
  EXPECT_EQ(std::memcmp(r.closest_points.data(), points.data(), points.size() * sizeof(Vec3f)), 0);
  // Without the field the flag is clear and nothing extra comes back.
  const LsgReadResult plain = decode_lsg(encode_lsg(sb.band), "plain.lsg");
  EXPECT_FALSE(plain.header.closest_points);
  EXPECT_TRUE(plain.closest_points.empty());
}

TEST(LsgFileRefuse, ClosestPointsOfTheWrongCountOrNonFinite) {
  const auto sb = test::make_shape_band("sphere", 24);
  std::vector<Vec3f> points(sb.band.active_voxel_count() - 1);
  LsgWriteOptions options;
  options.closest_points = points;
  EXPECT_THROW(encode_lsg(sb.band, options), Error);
  points.resize(sb.band.active_voxel_count());
  points[3].y = std::nanf("");
  options.closest_points = points;
  EXPECT_THROW(encode_lsg(sb.band, options), Error);
}

// ---------------------------------------------------------------------------------------------
// (e) summarize_lsg (what levelsetd info reads): the decode's checks without keeping values.

testing::AssertionResult summary_matches(const std::string& bytes) {
  const LsgReadResult r = decode_lsg(bytes, kName);
  const LsgSummary s = summarize_lsg(bytes, kName);
  if (s.header.bricks != r.band.brick_count() || s.header.active_voxels != r.band.active_voxel_count() ||
      s.header.closest_points != r.header.closest_points || s.file_bytes != bytes.size())
    return testing::AssertionFailure() << "counts differ";
  if (s.memory_bytes != r.band.memory_bytes())
    return testing::AssertionFailure() << "memory " << s.memory_bytes << " vs " << r.band.memory_bytes();
  if (!(s.active_index_bounds == r.band.active_index_bounds())) return testing::AssertionFailure() << "bounds differ";
  return testing::AssertionSuccess();
}

// Both refuse with the same code, or both accept.
testing::AssertionResult same_verdict(const std::string& bytes) {
  std::optional<ErrorCode> a, b;
  try { (void)decode_lsg(bytes, kName); } catch (const Error& e) { a = e.code(); }
  try { (void)summarize_lsg(bytes, kName); } catch (const Error& e) { b = e.code(); }
  if (a != b)
    return testing::AssertionFailure() << "decode: " << (a ? to_string(*a) : "accepted")
                                       << ", summary: " << (b ? to_string(*b) : "accepted");
  return testing::AssertionSuccess() << (a ? to_string(*a) : "accepted");
}

TEST(LsgFileSummary, AgreesWithTheDecodedBand) {
  for (const char* name : {"sphere", "torus", "knot", "box", "dumbbell"})
    EXPECT_TRUE(summary_matches(encode_lsg(test::make_shape_band(name, 32).band))) << name;
  EXPECT_TRUE(summary_matches(encode_lsg(negative_coord_band())));
  EXPECT_TRUE(summary_matches(encode_lsg(small_band())));
  EXPECT_TRUE(summary_matches(encode_lsg(NarrowBand(odd_frame()))));
  const auto sb = test::make_shape_band("torus", 24);
  std::vector<Vec3f> points(sb.band.active_voxel_count(), Vec3f{1.0f, -2.0f, 3.0f});
  LsgWriteOptions options;
  options.closest_points = points;
  EXPECT_TRUE(summary_matches(encode_lsg(sb.band, options)));
}

TEST(LsgFileSummary, RefusesWhatTheDecodeRefuses) {
  const RawBand good = raw_band_of(small_band());
  EXPECT_TRUE(same_verdict(craft(good)));
  // Every inside bit of every active voxel flipped in turn, and every value negated.
  for (std::size_t b = 0; b < good.bricks.size(); ++b)
    good.bricks[b].active.for_each_set([&](int n) {
      RawBand r = good;
      r.bricks[b].inside.assign(n, !r.bricks[b].inside.test(n));
      EXPECT_TRUE(same_verdict(craft(r))) << "brick " << b << " voxel " << n;
    });
  for (std::size_t i = 0; i < good.values.size(); ++i) {
    RawBand r = good;
    r.values[i] = -r.values[i];
    EXPECT_TRUE(same_verdict(craft(r))) << "value " << i;
    for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                      -std::numeric_limits<float>::infinity(), std::bit_cast<float>(0x7f800001u),
                      std::bit_cast<float>(0xff800001u), -0.0f, 0.0f, std::bit_cast<float>(0x80000001u),
                      std::numeric_limits<float>::max(), -std::numeric_limits<float>::max()}) {
      r.values[i] = bad;
      EXPECT_TRUE(same_verdict(craft(r))) << "value " << i << " = " << bad;
    }
  }
  // -0 is not < 0: accepted with the inside bit clear, refused with it set.
  RawBand zero = good;
  int first = -1;
  zero.bricks[0].active.for_each_set([&](int n) { if (first < 0) first = n; });
  zero.values[0] = -0.0f;
  zero.bricks[0].inside.assign(first, false);
  EXPECT_NO_THROW((void)summarize_lsg(craft(zero), kName));
  zero.bricks[0].inside.assign(first, true);
  EXPECT_THROW((void)summarize_lsg(craft(zero), kName), Error);
  // Masks and counts that disagree, bricks out of order.
  RawBand more = good;
  more.bricks[0].active.set(511);
  EXPECT_TRUE(same_verdict(craft_raw(header_of(good, 0, 0), raw_payload_of(more))));
  RawBand swapped = good;
  std::swap(swapped.bricks[0], swapped.bricks[1]);
  EXPECT_TRUE(same_verdict(craft(swapped)));
  // A closest point that is not finite (the writer refuses them, so the payload is built here).
  for (std::size_t at : {std::size_t{0}, good.values.size() + 1, 3 * good.values.size() - 1}) {
    std::string raw = raw_payload_of(good);
    std::vector<float> planar(3 * good.values.size(), 0.5f);
    planar[at] = std::numeric_limits<float>::infinity();
    for (int plane = 0; plane < 4; ++plane)
      for (float v : planar) raw.push_back(static_cast<char>((std::bit_cast<std::uint32_t>(v) >> (8 * plane)) & 0xff));
    Header h = header_of(good, 0, 0);
    h.flags |= 2;
    EXPECT_TRUE(same_verdict(craft_raw(h, raw))) << at;
    EXPECT_THROW((void)summarize_lsg(craft_raw(h, raw), kName), Error) << at;
  }
}

}  // namespace
}  // namespace levelset
