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
#include "core/text.hpp"

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

// The decompressed payload, pulled in pieces of ZSTD_DStreamOutSize() (128 KiB): read()
// inflates only as far as asked, so nothing is ever sized by the header's claim, and
// decompression stops at the first structure error.
class PayloadReader {
 public:
  PayloadReader(std::string_view stored, std::uint64_t expected, std::string_view name, std::uint64_t payload_at)
      : dctx_(ZSTD_createDCtx()), in_{stored.data(), stored.size(), 0}, piece_(ZSTD_DStreamOutSize()),
        expected_(expected), name_(name), payload_at_(payload_at) {
    if (!dctx_) throw Error(ErrorCode::IoError, "zstd", "cannot create a decompression context");
  }
  ~PayloadReader() { ZSTD_freeDCtx(dctx_); }
  PayloadReader(const PayloadReader&) = delete;
  PayloadReader& operator=(const PayloadReader&) = delete;

  // Copies exactly n bytes to dst; Corrupt when the frame ends first.
  void read(void* dst, std::size_t n) {
    char* out = static_cast<char*>(dst);
    while (n > 0) {
      if (pos_ == len_ && !fill())
        corrupt(name_, payload_at_ + in_.pos,
                "payload ends after " + std::to_string(delivered_) + " bytes, header says " + std::to_string(expected_));
      const std::size_t k = std::min(n, len_ - pos_);
      std::memcpy(out, piece_.data() + pos_, k);
      pos_ += k;
      out += k;
      n -= k;
      delivered_ += k;
    }
  }
  std::uint64_t offset() const { return delivered_; }
  // All expected bytes were read: the frame must end here, and the stored bytes with it.
  void finish() {
    if (pos_ != len_ || fill())
      corrupt(name_, payload_at_, "payload decompresses to more than the " + std::to_string(expected_) +
                                      " bytes the header says");
    if (!frame_done_ || in_.pos != in_.size)
      corrupt(name_, payload_at_ + in_.pos, "compressed payload does not end where the header says");
  }

 private:
  // Inflates the next piece; false when the frame (or its input) has ended.
  bool fill() {
    pos_ = len_ = 0;
    while (!frame_done_) {
      ZSTD_outBuffer ob{piece_.data(), piece_.size(), 0};
      const std::size_t ret = ZSTD_decompressStream(dctx_, &ob, &in_);
      if (ZSTD_isError(ret)) corrupt(name_, payload_at_ + in_.pos, std::string("zstd: ") + ZSTD_getErrorName(ret));
      if (ret == 0) frame_done_ = true;  // one frame only: a second one is trailing data
      produced_ += ob.pos;
      if (produced_ > expected_)
        corrupt(name_, payload_at_ + in_.pos, "payload decompresses to more than the " + std::to_string(expected_) +
                                                  " bytes the header says");
      if (ob.pos > 0) {
        len_ = ob.pos;
        return true;
      }
      if (in_.pos == in_.size) return false;  // input ends inside the frame
    }
    return false;
  }

  ZSTD_DCtx* dctx_;
  ZSTD_inBuffer in_;
  std::vector<char> piece_;
  std::size_t pos_ = 0, len_ = 0;
  bool frame_done_ = false;
  std::uint64_t expected_, produced_ = 0, delivered_ = 0;
  std::string_view name_;
  std::uint64_t payload_at_;
};

// What the decode holds at its peak: the file, the brick records (grown by doubling), and
// with values the band's bricks, hash table, sign masks, values and closest points; without
// them 2 bits per voxel. In double: lifted limits must not overflow.
double decode_memory(const LsgHeader& h, std::uint64_t file_bytes, bool keep_values) {
  const double nb = double(h.bricks), nv = double(h.active_voxels);
  double bytes = double(file_bytes) + double(ZSTD_DStreamOutSize()) + 2.0 * nb * double(sizeof(BrickRecord));
  if (!keep_values) return bytes + nv / 4.0;
  bytes += nb * double(sizeof(Brick) + sizeof(BrickMask) + 16) + nv * 4.0;
  if (h.closest_points) bytes += nv * 2.0 * double(sizeof(Vec3f));  // the vector, then the result
  return bytes;
}

// The header, checked (everything before the payload is decompressed).
LsgHeader read_header(std::string_view bytes, std::string_view name, const LsgReadOptions& options,
                      bool keep_values) {
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
  // A decompression bomb: real bands never compress anywhere near this well.
  if (double(h.raw_bytes) > options.max_compression_ratio * double(h.stored_bytes) + double(kLsgRatioSlackBytes))
    throw Error(ErrorCode::LimitExceeded, at_byte(name, 80),
                "payload of " + std::to_string(h.raw_bytes) + " bytes from " + std::to_string(h.stored_bytes) +
                    " compressed bytes: a ratio above the limit of " + format_number(options.max_compression_ratio) +
                    ":1 (real bands compress at most about 900:1)");
  const double memory = decode_memory(h, bytes.size(), keep_values);
  require_within_budget(memory >= 1.8e19 ? ~std::uint64_t{0} : std::uint64_t(memory), options.memory_budget,
                        at_byte(name, 64),
                        "a band of " + std::to_string(h.bricks) + " bricks and " + std::to_string(h.active_voxels) +
                            " active voxels");
  return h;
}

// The payload as it streams: bricks (coordinates, active and inside masks) always; values and
// closest points when keep_values, else only checked. Sections in file order, each checked as
// it arrives.
struct Payload {
  std::vector<BrickRecord> bricks;
  std::vector<float> values;
  std::vector<Vec3f> closest_points;
};

Payload decode_payload(std::string_view bytes, std::string_view name, const LsgHeader& h,
                       const LsgReadOptions& options, bool keep_values) {
  PayloadReader in(bytes.substr(kHeaderBytes), h.raw_bytes, name, kHeaderBytes);
  Payload out;
  const std::uint64_t nb = h.bricks, nv = h.active_voxels;
  constexpr std::size_t kBatch = 4096;  // bricks (or voxels) per read
  std::vector<char> buf;

  // Coordinates: in range, strictly increasing keys; the records grow with what arrived.
  buf.resize(12 * kBatch);
  for (std::uint64_t i = 0; i < nb;) {
    const std::size_t k = std::size_t(std::min<std::uint64_t>(kBatch, nb - i));
    in.read(buf.data(), 12 * k);
    for (std::size_t j = 0; j < k; ++j, ++i) {
      BrickRecord b;
      std::memcpy(&b.coord.x, buf.data() + 12 * j, 4);
      std::memcpy(&b.coord.y, buf.data() + 12 * j + 4, 4);
      std::memcpy(&b.coord.z, buf.data() + 12 * j + 8, 4);
      if (!brick_in_range(b.coord))
        corrupt_payload(name, 12 * i, "brick " + std::to_string(i) + " out of range");
      if (i > 0 && brick_key(out.bricks.back().coord) >= brick_key(b.coord))
        corrupt_payload(name, 12 * i, "bricks not sorted or duplicated at brick " + std::to_string(i));
      out.bricks.push_back(b);
    }
    options.progress.check("bricks");
  }
  options.progress.step(0.3, "masks");
  // Active masks: their popcounts may never pass the header's voxel count.
  buf.resize(64 * kBatch);
  std::uint64_t total = 0;
  for (std::uint64_t i = 0; i < nb;) {
    const std::size_t k = std::size_t(std::min<std::uint64_t>(kBatch, nb - i));
    in.read(buf.data(), 64 * k);
    for (std::size_t j = 0; j < k; ++j, ++i) {
      BrickRecord& b = out.bricks[std::size_t(i)];
      std::memcpy(b.active.words.data(), buf.data() + 64 * j, 64);
      total += std::uint64_t(b.active.count());
      if (total > nv)
        corrupt(name, 72, "active masks hold more than the header's " + std::to_string(nv) + " voxels (brick " +
                              std::to_string(i) + ")");
    }
    options.progress.check("masks");
  }
  if (total != nv)
    corrupt(name, 72, "active masks hold " + std::to_string(total) + " voxels, header says " + std::to_string(nv));
  for (std::uint64_t i = 0; i < nb;) {
    const std::size_t k = std::size_t(std::min<std::uint64_t>(kBatch, nb - i));
    in.read(buf.data(), 64 * k);
    for (std::size_t j = 0; j < k; ++j, ++i)
      std::memcpy(out.bricks[std::size_t(i)].inside.words.data(), buf.data() + 64 * j, 64);
  }
  options.progress.step(0.5, "values");

  // Values: four byte planes. The decoded masks have confirmed nv (at most 512 per decoded
  // brick), so the values are allocated now. Without keep_values two bits per voxel suffice:
  // the top bit of byte 2 (the exponent's low bit) and "bytes 0..2 not all zero" (-0 is not < 0).
  const std::uint64_t values_at = kBytesPerBrick * nb;
  std::vector<std::uint64_t> exp_low, nonzero;
  if (keep_values) {
    out.values.resize(std::size_t(nv));
  } else {
    exp_low.assign(std::size_t((nv + 63) / 64), 0);
    nonzero.assign(std::size_t((nv + 63) / 64), 0);
  }
  // Signs without the values: checked as plane 3 arrives, walking the active voxels in order.
  std::size_t sign_brick = 0, next_brick = 0, slot = 0;
  std::vector<int> slots;  // active voxel numbers of sign_brick
  auto check_sign = [&](bool negative) {
    while (slot == slots.size()) {  // the next brick with active voxels (the masks hold nv)
      sign_brick = next_brick++;
      slots.clear();
      out.bricks[sign_brick].active.for_each_set([&](int n) { slots.push_back(n); });
      slot = 0;
    }
    if (negative != out.bricks[sign_brick].inside.test(slots[slot++]))
      corrupt_payload(name, 76 * nb + 64 * sign_brick,
                      "sign bits disagree with values in brick " + std::to_string(sign_brick));
  };
  buf.resize(kBatch * 16);
  for (int plane = 0; plane < 4; ++plane) {
    for (std::uint64_t i = 0; i < nv;) {
      const std::size_t k = std::size_t(std::min<std::uint64_t>(buf.size(), nv - i));
      in.read(buf.data(), k);
      const unsigned char* p = reinterpret_cast<const unsigned char*>(buf.data());
      if (keep_values) {
        for (std::size_t j = 0; j < k; ++j) {
          std::uint32_t u;
          std::memcpy(&u, &out.values[i + j], 4);
          u |= std::uint32_t(p[j]) << (8 * plane);
          std::memcpy(&out.values[i + j], &u, 4);
        }
        if (plane == 3)
          for (std::size_t j = 0; j < k; ++j)
            if (!std::isfinite(out.values[i + j]))
              corrupt_payload(name, values_at + i + j, "non-finite value at voxel " + std::to_string(i + j));
      } else {
        for (std::size_t j = 0; j < k; ++j) {
          const std::uint64_t v = i + j;
          const std::uint64_t bit = std::uint64_t{1} << (v & 63);
          if (plane < 3 && p[j] != 0) nonzero[v >> 6] |= bit;
          if (plane == 2 && (p[j] & 0x80)) exp_low[v >> 6] |= bit;
          if (plane == 3) {
            const unsigned exponent = ((p[j] & 0x7fu) << 1) | ((exp_low[v >> 6] & bit) ? 1u : 0u);
            if (exponent == 0xff)
              corrupt_payload(name, values_at + v, "non-finite value at voxel " + std::to_string(v));
            check_sign((p[j] & 0x80) && ((p[j] & 0x7f) != 0 || (nonzero[v >> 6] & bit)));
          }
        }
      }
      i += k;
      options.progress.check("values");
    }
  }
  if (keep_values) {
    // Signs, brick by brick (values are complete now).
    std::uint64_t offset = 0;
    for (std::size_t i = 0; i < out.bricks.size(); ++i) {
      const BrickRecord& b = out.bricks[i];
      const float* v = out.values.data() + offset;
      bool ok = true;
      b.active.for_each_set([&](int n) { ok &= (*v++ < 0.0f) == b.inside.test(n); });
      if (!ok) corrupt_payload(name, 76 * nb + 64 * i, "sign bits disagree with values in brick " + std::to_string(i));
      offset += std::uint64_t(b.active.count());
    }
  }
  options.progress.step(0.8, "closest points");

  if (h.closest_points) {
    // 3 nv floats (all x, all y, all z) in four byte planes.
    const std::uint64_t n3 = 3 * nv;
    std::vector<std::uint32_t> planar;
    if (keep_values) planar.resize(std::size_t(n3));
    std::vector<std::uint64_t> low(keep_values ? 0 : std::size_t((n3 + 63) / 64), 0);
    for (int plane = 0; plane < 4; ++plane) {
      for (std::uint64_t i = 0; i < n3;) {
        const std::size_t k = std::size_t(std::min<std::uint64_t>(buf.size(), n3 - i));
        in.read(buf.data(), k);
        const unsigned char* p = reinterpret_cast<const unsigned char*>(buf.data());
        for (std::size_t j = 0; j < k; ++j) {
          const std::uint64_t v = i + j;
          if (keep_values) {
            planar[std::size_t(v)] |= std::uint32_t(p[j]) << (8 * plane);
            if (plane == 3 && !std::isfinite(std::bit_cast<float>(planar[std::size_t(v)])))
              corrupt_payload(name, values_at + 4 * nv + v % nv,
                              "non-finite closest point at voxel " + std::to_string(v % nv));
          } else if (plane == 2 && (p[j] & 0x80)) {
            low[v >> 6] |= std::uint64_t{1} << (v & 63);
          } else if (plane == 3 && (((p[j] & 0x7fu) << 1) | ((low[v >> 6] >> (v & 63)) & 1u)) == 0xff) {
            corrupt_payload(name, values_at + 4 * nv + v % nv,
                            "non-finite closest point at voxel " + std::to_string(v % nv));
          }
        }
        i += k;
        options.progress.check("closest points");
      }
    }
    if (keep_values) {
      out.closest_points.resize(std::size_t(nv));
      for (std::size_t i = 0; i < nv; ++i)
        out.closest_points[i] = {std::bit_cast<float>(planar[i]), std::bit_cast<float>(planar[nv + i]),
                                 std::bit_cast<float>(planar[2 * nv + i])};
    }
  }
  in.finish();
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
  const LsgHeader h = read_header(bytes, name, options, true);
  options.progress.step(0.1, "decompress");
  Payload p = decode_payload(bytes, name, h, options, true);
  options.progress.step(0.9, "index");
  LsgReadResult result{NarrowBand::assemble(h.frame, std::move(p.bricks), std::move(p.values), h.far_inside),
                       h, bytes.size(), std::move(p.closest_points)};
  return result;
}

LsgReadResult load_lsg(const std::filesystem::path& path, const LsgReadOptions& options) {
  const std::string bytes = read_file_bytes(path, options.max_file_bytes);
  return decode_lsg(bytes, path.string(), options);
}

LsgSummary summarize_lsg(std::string_view bytes, std::string_view name, const LsgReadOptions& options) {
  LsgSummary s;
  s.header = read_header(bytes, name, options, false);
  s.file_bytes = bytes.size();
  options.progress.step(0.1, "decompress");
  const Payload p = decode_payload(bytes, name, s.header, options, false);
  // NarrowBand::memory_bytes() of the band decode_lsg would assemble: bricks, values, sign
  // masks of bricks whose inactive voxels lie on both sides, the hash table.
  std::uint64_t mixed = 0;
  for (const BrickRecord& b : p.bricks) {
    bool any_in = false, any_out = false;
    for (int w = 0; w < 8; ++w) {
      const std::uint64_t inactive = ~b.active.words[w];
      any_in |= (inactive & b.inside.words[w]) != 0;
      any_out |= (inactive & ~b.inside.words[w]) != 0;
    }
    mixed += (any_in && any_out) ? 1 : 0;
    if (b.active.none()) continue;
    int lo[3] = {8, 8, 8}, hi[3] = {-1, -1, -1};
    b.active.for_each_set([&](int n) {
      const Coord l = local_coord(n);
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], l[a]);
        hi[a] = std::max(hi[a], l[a]);
      }
    });
    const Coord o = brick_origin(b.coord);
    s.active_index_bounds.extend(o + Coord{lo[0], lo[1], lo[2]});
    s.active_index_bounds.extend(o + Coord{hi[0], hi[1], hi[2]});
  }
  std::uint64_t table = 16;
  while (table < 2 * s.header.bricks) table <<= 1;
  s.memory_bytes = sizeof(NarrowBand) + s.header.bricks * sizeof(Brick) + s.header.active_voxels * sizeof(float) +
                   mixed * sizeof(BrickMask) + table * sizeof(std::uint32_t);
  options.progress.step(1.0, "done");
  return s;
}

LsgSummary summarize_lsg_file(const std::filesystem::path& path, const LsgReadOptions& options) {
  const std::string bytes = read_file_bytes(path, options.max_file_bytes);
  return summarize_lsg(bytes, path.string(), options);
}

}  // namespace levelset
