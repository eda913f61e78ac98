#include "grid/lsg_file.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include <xxhash.h>
#include <zstd.h>

#include "core/error.hpp"
#include "core/file_extension.hpp"
#include "core/file_io.hpp"

namespace levelset {

static_assert(std::endian::native == std::endian::little, ".lsg I/O assumes a little-endian host");

namespace {

constexpr char kMagic[8] = {'\x89', 'L', 'S', 'G', '\r', '\n', '\x1a', '\n'};
constexpr std::size_t kHeaderBytes = 128;
constexpr std::size_t kChecksumOffset = 120;
constexpr std::uint64_t kBytesPerBrick = 12 + 64 + 64;

template <typename T>
void put(std::string& s, std::size_t at, T v) {
  std::memcpy(s.data() + at, &v, sizeof(T));
}
template <typename T>
T get(std::string_view s, std::size_t at) {
  T v;
  std::memcpy(&v, s.data() + at, sizeof(T));
  return v;
}

std::uint64_t checksum(std::string_view header120, std::string_view stored) {
  XXH3_state_t* st = XXH3_createState();
  XXH3_64bits_reset(st);
  XXH3_64bits_update(st, header120.data(), header120.size());
  XXH3_64bits_update(st, stored.data(), stored.size());
  const std::uint64_t h = XXH3_64bits_digest(st);
  XXH3_freeState(st);
  return h;
}

// Byte planes: all byte 0s of the n floats, then all byte 1s, ... (zstd then sees the slowly
// varying exponent bytes together).
void shuffle_floats(const float* src, std::size_t n, char* dst) {
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t u;
    std::memcpy(&u, &src[i], 4);
    for (int k = 0; k < 4; ++k) dst[k * n + i] = static_cast<char>((u >> (8 * k)) & 0xff);
  }
}
float unshuffle_float(const unsigned char* planes, std::size_t n, std::size_t i) {
  const std::uint32_t u = std::uint32_t(planes[i]) | (std::uint32_t(planes[n + i]) << 8) |
                          (std::uint32_t(planes[2 * n + i]) << 16) | (std::uint32_t(planes[3 * n + i]) << 24);
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

std::uint64_t raw_size(std::uint64_t bricks, std::uint64_t voxels, bool closest_points) {
  return bricks * kBytesPerBrick + voxels * (closest_points ? 16 : 4);
}

std::string raw_payload(const NarrowBand& band, std::span<const Vec3f> closest_points) {
  const auto bricks = band.bricks();
  const auto values = band.values();
  const std::size_t nb = bricks.size(), nv = values.size();
  std::string raw(raw_size(nb, nv, !closest_points.empty()), '\0');
  char* p = raw.data();
  for (const Brick& b : bricks) {
    std::memcpy(p, &b.coord.x, 4);
    std::memcpy(p + 4, &b.coord.y, 4);
    std::memcpy(p + 8, &b.coord.z, 4);
    p += 12;
  }
  for (const Brick& b : bricks) { std::memcpy(p, b.active.words.data(), 64); p += 64; }
  for (std::uint32_t b = 0; b < nb; ++b) {
    const BrickMask inside = band.inside_mask(b);
    std::memcpy(p, inside.words.data(), 64);
    p += 64;
  }
  shuffle_floats(values.data(), nv, p);
  p += 4 * nv;
  if (!closest_points.empty()) {
    std::vector<float> planar(3 * nv);
    for (std::size_t i = 0; i < nv; ++i) {
      planar[i] = closest_points[i].x;
      planar[nv + i] = closest_points[i].y;
      planar[2 * nv + i] = closest_points[i].z;
    }
    shuffle_floats(planar.data(), 3 * nv, p);
  }
  return raw;
}

[[noreturn]] void corrupt(std::string_view name, std::uint64_t at, const std::string& why) {
  throw Error(ErrorCode::Corrupt, at_byte(name, at), why);
}

// Structure errors inside the decompressed payload name the payload offset.
[[noreturn]] void corrupt_payload(std::string_view name, std::uint64_t at, const std::string& why) {
  throw Error(ErrorCode::Corrupt, std::string(name) + " @ payload byte " + std::to_string(at), why);
}

// Streaming decompression: the output grows with what zstd actually produces and may never
// exceed `expected`, so a tiny file claiming a huge payload cannot force a huge allocation.
std::string decompress_bounded(std::string_view stored, std::uint64_t expected, std::string_view name,
                               std::uint64_t payload_at) {
  std::string out;
  out.resize(static_cast<std::size_t>(std::min<std::uint64_t>(expected, std::uint64_t{1} << 24)));
  ZSTD_DCtx* dctx = ZSTD_createDCtx();
  ZSTD_inBuffer in{stored.data(), stored.size(), 0};
  std::size_t produced = 0;
  std::size_t ret = 1;
  while (true) {
    if (produced == out.size() && out.size() < expected)
      out.resize(static_cast<std::size_t>(std::min<std::uint64_t>(expected, out.size() * 2 + 1)));
    ZSTD_outBuffer ob{out.data(), out.size(), produced};
    ret = ZSTD_decompressStream(dctx, &ob, &in);
    if (ZSTD_isError(ret)) {
      ZSTD_freeDCtx(dctx);
      corrupt(name, payload_at + in.pos, std::string("zstd: ") + ZSTD_getErrorName(ret));
    }
    produced = ob.pos;
    if (ret == 0) break;                                   // frame complete
    if (in.pos == in.size && ob.pos < ob.size) break;      // input ends mid-frame
    if (produced == out.size() && out.size() >= expected) break;  // more output than declared
  }
  ZSTD_freeDCtx(dctx);
  if (ret != 0 || in.pos != in.size)
    corrupt(name, payload_at + in.pos, "compressed payload does not end where the header says");
  if (produced != expected)
    corrupt(name, payload_at, "payload decompresses to " + std::to_string(produced) +
                                  " bytes, header says " + std::to_string(expected));
  // A complete frame with more output than expected leaves ret != 0 above.
  out.resize(produced);
  return out;
}

}  // namespace

std::string encode_lsg(const NarrowBand& band, const LsgWriteOptions& options) {
  if (options.compression_level < 1 || options.compression_level > 19)
    throw Error(ErrorCode::InvalidArgument, "compression_level", "must be in [1, 19]");
  if (!options.closest_points.empty() && options.closest_points.size() != band.active_voxel_count())
    throw Error(ErrorCode::InvalidArgument, "closest_points", "need one closest point per active voxel");
  for (const Vec3f& q : options.closest_points)
    if (!isfinite(q)) throw Error(ErrorCode::NonFinite, "closest_points", "non-finite closest point");
  const std::string raw = raw_payload(band, options.closest_points);
  std::string out(kHeaderBytes + ZSTD_compressBound(raw.size()), '\0');
  const std::size_t stored = ZSTD_compress(out.data() + kHeaderBytes, out.size() - kHeaderBytes,
                                           raw.data(), raw.size(), options.compression_level);
  if (ZSTD_isError(stored))
    throw Error(ErrorCode::IoError, "zstd", ZSTD_getErrorName(stored));
  out.resize(kHeaderBytes + stored);
  std::memcpy(out.data(), kMagic, 8);
  put<std::uint32_t>(out, 8, kLsgVersion);
  put<std::uint32_t>(out, 12, kHeaderBytes);
  put<std::uint32_t>(out, 16, 1);
  put<std::uint32_t>(out, 20, (band.far_inside() ? 1u : 0u) | (options.closest_points.empty() ? 0u : 2u));
  put<double>(out, 24, band.voxel_size());
  put<double>(out, 32, band.origin().x);
  put<double>(out, 40, band.origin().y);
  put<double>(out, 48, band.origin().z);
  put<double>(out, 56, band.half_width());
  put<std::uint64_t>(out, 64, band.brick_count());
  put<std::uint64_t>(out, 72, band.active_voxel_count());
  put<std::uint64_t>(out, 80, raw.size());
  put<std::uint64_t>(out, 88, stored);
  const std::string_view view(out);
  put<std::uint64_t>(out, kChecksumOffset,
                     checksum(view.substr(0, kChecksumOffset), view.substr(kHeaderBytes)));
  return out;
}

LsgWriteResult save_lsg(const NarrowBand& band, const std::filesystem::path& path,
                        const LsgWriteOptions& options) {
  require_extension(path, kLsgExtensions, "a narrow band");
  const std::string bytes = encode_lsg(band, options);
  write_file_atomically(path, bytes);
  return {bytes.size(), raw_size(band.brick_count(), band.active_voxel_count(), !options.closest_points.empty())};
}

LsgReadResult decode_lsg(std::string_view bytes, std::string_view name, const LsgReadOptions& options) {
  const std::string_view magic(kMagic, 8);
  if (bytes.substr(0, 8) != magic) {
    if (bytes.size() < 8 && magic.substr(0, bytes.size()) == bytes)
      throw Error(ErrorCode::Truncated, at_byte(name, bytes.size()), "file ends inside the magic");
    throw Error(ErrorCode::UnsupportedFormat, at_byte(name, 0), "not an .lsg file (wrong magic)");
  }
  if (bytes.size() < kHeaderBytes)
    throw Error(ErrorCode::Truncated, at_byte(name, bytes.size()),
                "file ends inside the 128-byte header");
  LsgHeader h;
  h.version = get<std::uint32_t>(bytes, 8);
  if (h.version > kLsgVersion)
    throw Error(ErrorCode::UnsupportedVersion, at_byte(name, 8),
                "file version " + std::to_string(h.version) + " is newer than this build reads (" +
                    std::to_string(kLsgVersion) + ")");
  if (h.version == 0) corrupt(name, 8, "version 0 does not exist");
  if (get<std::uint32_t>(bytes, 12) != kHeaderBytes) corrupt(name, 12, "header size is not 128");
  h.value_type = get<std::uint32_t>(bytes, 16);
  if (h.value_type != 1)
    throw Error(ErrorCode::UnsupportedFormat, at_byte(name, 16),
                "value type " + std::to_string(h.value_type) + " (only 1 = float32 is known)");
  const std::uint32_t flags = get<std::uint32_t>(bytes, 20);
  if (flags > 3) corrupt(name, 20, "unknown flag bits");
  h.far_inside = flags & 1u;
  h.closest_points = (flags & 2u) != 0;
  h.frame.voxel_size = get<double>(bytes, 24);
  h.frame.origin = {get<double>(bytes, 32), get<double>(bytes, 40), get<double>(bytes, 48)};
  h.frame.half_width = get<double>(bytes, 56);
  h.bricks = get<std::uint64_t>(bytes, 64);
  h.active_voxels = get<std::uint64_t>(bytes, 72);
  h.raw_bytes = get<std::uint64_t>(bytes, 80);
  h.stored_bytes = get<std::uint64_t>(bytes, 88);
  for (std::size_t at = 96; at < kChecksumOffset; ++at)
    if (bytes[at] != 0) corrupt(name, at, "reserved header bytes are not zero");

  // Truncation first: it is the common failure and explains a bad checksum best.
  const std::uint64_t available = bytes.size() - kHeaderBytes;
  if (h.stored_bytes > available)
    throw Error(ErrorCode::Truncated, at_byte(name, bytes.size()),
                "payload needs " + std::to_string(h.stored_bytes) + " bytes, file has " +
                    std::to_string(available) + " after the header");
  if (h.stored_bytes < available)
    corrupt(name, kHeaderBytes + h.stored_bytes, "trailing bytes after the payload");
  const std::uint64_t stored_sum = get<std::uint64_t>(bytes, kChecksumOffset);
  if (checksum(bytes.substr(0, kChecksumOffset), bytes.substr(kHeaderBytes)) != stored_sum)
    corrupt(name, kChecksumOffset, "checksum mismatch: the file is damaged");

  if (!(std::isfinite(h.frame.voxel_size) && h.frame.voxel_size > 0))
    corrupt(name, 24, "voxel size must be finite and > 0");
  if (!isfinite(h.frame.origin)) corrupt(name, 32, "origin must be finite");
  if (!(h.frame.half_width >= 1.0 && h.frame.half_width <= 1024.0))
    corrupt(name, 56, "band half-width must be in [1, 1024] voxels");
  try {
    NarrowBand validate(h.frame);
    (void)validate;
  } catch (const Error& e) {
    corrupt(name, 24, "bad grid frame: " + e.reason());
  }
  if (h.active_voxels > options.max_active_voxels || h.bricks > (std::uint64_t{1} << 32))
    throw Error(ErrorCode::LimitExceeded, at_byte(name, 64),
                std::to_string(h.bricks) + " bricks / " + std::to_string(h.active_voxels) +
                    " active voxels exceed the limits");
  if (h.raw_bytes != raw_size(h.bricks, h.active_voxels, h.closest_points))
    corrupt(name, 80, "raw payload size does not match brick and voxel counts");
  if (h.raw_bytes > options.max_raw_bytes)
    throw Error(ErrorCode::LimitExceeded, at_byte(name, 80),
                "payload of " + std::to_string(h.raw_bytes) + " bytes exceeds the limit of " +
                    std::to_string(options.max_raw_bytes));
  options.progress.step(0.1, "decompress");

  const std::string raw = decompress_bounded(bytes.substr(kHeaderBytes), h.raw_bytes, name, kHeaderBytes);
  options.progress.step(0.6, "bricks");

  const std::size_t nb = static_cast<std::size_t>(h.bricks), nv = static_cast<std::size_t>(h.active_voxels);
  std::vector<BrickRecord> bricks(nb);
  const char* p = raw.data();
  std::vector<std::uint64_t> offsets(nb);
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < nb; ++i) {
    BrickRecord& b = bricks[i];
    std::memcpy(&b.coord.x, p + 12 * i, 4);
    std::memcpy(&b.coord.y, p + 12 * i + 4, 4);
    std::memcpy(&b.coord.z, p + 12 * i + 8, 4);
    std::memcpy(b.active.words.data(), p + 12 * nb + 64 * i, 64);
    std::memcpy(b.inside.words.data(), p + 76 * nb + 64 * i, 64);
    if (!brick_in_range(b.coord))
      corrupt_payload(name, 12 * i, "brick " + std::to_string(i) + " out of range");
    if (i > 0 && brick_key(bricks[i - 1].coord) >= brick_key(b.coord))
      corrupt_payload(name, 12 * i, "bricks not sorted or duplicated at brick " + std::to_string(i));
    offsets[i] = total;
    total += static_cast<std::uint64_t>(b.active.count());
  }
  if (total != h.active_voxels)
    corrupt(name, 72, "active masks hold " + std::to_string(total) + " voxels, header says " +
                          std::to_string(h.active_voxels));
  std::vector<float> values(nv);
  const unsigned char* planes = reinterpret_cast<const unsigned char*>(p + kBytesPerBrick * nb);
  for (std::size_t i = 0; i < nv; ++i) {
    values[i] = unshuffle_float(planes, nv, i);
    if (!std::isfinite(values[i]))
      corrupt_payload(name, kBytesPerBrick * nb + i, "non-finite value at voxel " + std::to_string(i));
  }
  std::vector<Vec3f> closest_points;
  if (h.closest_points) {
    const unsigned char* cp = planes + 4 * nv;
    closest_points.resize(nv);
    for (std::size_t i = 0; i < nv; ++i) {
      closest_points[i] = {unshuffle_float(cp, 3 * nv, i), unshuffle_float(cp, 3 * nv, nv + i),
                           unshuffle_float(cp, 3 * nv, 2 * nv + i)};
      if (!isfinite(closest_points[i]))
        corrupt_payload(name, kBytesPerBrick * nb + 4 * nv + i,
                        "non-finite closest point at voxel " + std::to_string(i));
    }
  }
  for (std::size_t i = 0; i < nb; ++i) {
    const BrickRecord& b = bricks[i];
    const float* v = values.data() + offsets[i];
    bool ok = true;
    b.active.for_each_set([&](int n) { ok &= (*v++ < 0.0f) == b.inside.test(n); });
    if (!ok)
      corrupt_payload(name, 76 * nb + 64 * i, "sign bits disagree with values in brick " + std::to_string(i));
  }
  options.progress.step(0.9, "index");
  LsgReadResult result{NarrowBand::assemble(h.frame, std::move(bricks), std::move(values), h.far_inside),
                       h, bytes.size(), std::move(closest_points)};
  return result;
}

LsgReadResult load_lsg(const std::filesystem::path& path, const LsgReadOptions& options) {
  const std::string bytes = read_file_bytes(path, options.max_file_bytes);
  return decode_lsg(bytes, path.string(), options);
}

}  // namespace levelset
