// ByteStream (plain or zlib-inflated), the sample decoder and the header number helpers of the
// image readers.
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/error.hpp"
#include "core/memory_budget.hpp"
#include "io/image_format_readers.hpp"

namespace levelset::detail {

bool is_gzip(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

struct ByteStream::Inflater {
  z_stream z{};
  bool ended = false;  // the last member ended (or the input ran out)
  Inflater() {
    if (inflateInit2(&z, 15 + 32) != Z_OK) throw Error(ErrorCode::IoError, "zlib", "inflateInit2 failed");
  }
  ~Inflater() { inflateEnd(&z); }
};

ByteStream::ByteStream(std::string_view bytes, bool inflate, std::string name)
    : bytes_(bytes), name_(std::move(name)) {
  if (inflate) inflater_ = std::make_unique<Inflater>();
}

ByteStream::~ByteStream() = default;

void ByteStream::unread(std::string_view bytes) {
  pending_.insert(0, bytes);
  position_ -= bytes.size();
}

std::uint64_t ByteStream::skip(std::uint64_t n) {
  std::uint64_t done = std::min<std::uint64_t>(n, pending_.size());
  pending_.erase(0, std::size_t(done));
  if (!inflater_) {
    const std::uint64_t k = std::min<std::uint64_t>(n - done, bytes_.size() - offset_);
    offset_ += std::size_t(k);
    done += k;
  }
  position_ += done;
  return done;
}

std::size_t ByteStream::read(char* dst, std::size_t n) {
  std::size_t done = 0;
  if (!pending_.empty()) {
    done = std::min(n, pending_.size());
    std::memcpy(dst, pending_.data(), done);
    pending_.erase(0, done);
  }
  while (done < n) {
    const std::size_t got = read_source(dst + done, n - done);
    if (got == 0) break;
    done += got;
  }
  position_ += done;
  return done;
}

std::size_t ByteStream::read_source(char* dst, std::size_t n) {
  if (!inflater_) {
    const std::size_t got = std::min(n, bytes_.size() - offset_);
    std::memcpy(dst, bytes_.data() + offset_, got);
    offset_ += got;
    return got;
  }
  Inflater& inf = *inflater_;
  if (inf.ended) return 0;
  constexpr std::size_t kPiece = std::size_t{1} << 30;  // z_stream counts are 32-bit
  std::size_t produced = 0;
  while (produced < n && !inf.ended) {
    if (inf.z.avail_in == 0) {
      const std::size_t in = std::min(kPiece, bytes_.size() - offset_);
      inf.z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes_.data() + offset_));
      inf.z.avail_in = static_cast<uInt>(in);
      offset_ += in;
    }
    const std::size_t out = std::min(kPiece, n - produced);
    inf.z.next_out = reinterpret_cast<Bytef*>(dst + produced);
    inf.z.avail_out = static_cast<uInt>(out);
    const int rc = inflate(&inf.z, Z_NO_FLUSH);
    produced += out - inf.z.avail_out;
    const std::uint64_t consumed = offset_ - inf.z.avail_in;
    if (rc == Z_STREAM_END) {
      // Another gzip member may follow; anything else after the stream is ignored.
      const std::string_view rest = bytes_.substr(consumed);
      if (is_gzip(rest)) {
        offset_ = consumed;
        inf.z.avail_in = 0;
        inflateReset(&inf.z);
      } else {
        inf.ended = true;
      }
    } else if (rc == Z_BUF_ERROR || (rc == Z_OK && inf.z.avail_in == 0 && offset_ == bytes_.size() &&
                                     inf.z.avail_out != 0)) {
      inf.ended = true;  // the compressed data ran out: the caller sees a short read
    } else if (rc != Z_OK) {
      throw Error(ErrorCode::Corrupt, at_byte(name_, consumed) + " (compressed)",
                  std::string("broken compressed data: ") + (inf.z.msg ? inf.z.msg : "zlib error"));
    }
  }
  return produced;
}

int sample_size(SampleType type) {
  switch (type) {
    case SampleType::Int8: case SampleType::UInt8: return 1;
    case SampleType::Int16: case SampleType::UInt16: return 2;
    case SampleType::Int32: case SampleType::UInt32: case SampleType::Float32: return 4;
    case SampleType::Int64: case SampleType::UInt64: case SampleType::Float64: return 8;
  }
  return 1;
}

std::string_view sample_type_name(SampleType type) {
  switch (type) {
    case SampleType::Int8: return "int8";
    case SampleType::UInt8: return "uint8";
    case SampleType::Int16: return "int16";
    case SampleType::UInt16: return "uint16";
    case SampleType::Int32: return "int32";
    case SampleType::UInt32: return "uint32";
    case SampleType::Int64: return "int64";
    case SampleType::UInt64: return "uint64";
    case SampleType::Float32: return "float";
    case SampleType::Float64: return "double";
  }
  return "?";
}

void check_image_limits(const SampleLayout& l, const ImageReadOptions& options, const std::string& where) {
  if (l.nx <= 0 || l.ny <= 0 || l.nz <= 0)
    throw Error(ErrorCode::ParseError, where, "image sizes must be positive");
  const std::uint64_t cap = options.max_voxels;
  const std::uint64_t nx = std::uint64_t(l.nx), ny = std::uint64_t(l.ny), nz = std::uint64_t(l.nz);
  if (nx > cap || ny > cap || nz > cap || nx * ny > cap || nx * ny > cap / nz)
    throw Error(ErrorCode::LimitExceeded, where,
                std::to_string(l.nx) + " x " + std::to_string(l.ny) + " x " + std::to_string(l.nz) +
                    " voxels exceed the limit of " + std::to_string(cap));
  const std::uint64_t voxels = nx * ny * nz;
  if (voxels > options.max_sample_bytes / sizeof(float))
    throw Error(ErrorCode::LimitExceeded, where,
                std::to_string(voxels) + " voxels need " + std::to_string(voxels * sizeof(float)) +
                    " bytes, above the budget of " + std::to_string(options.max_sample_bytes));
  if (options.samples == ImageSamples::Load)
    require_within_budget(voxels * sizeof(float), options.memory_budget, where,
                          "the samples of a " + std::to_string(l.nx) + " x " + std::to_string(l.ny) + " x " +
                              std::to_string(l.nz) + " image");
}

namespace {

template <typename T>
T load(const unsigned char* p, bool swap) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  if (swap) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    std::reverse(b, b + sizeof(T));
    std::memcpy(&v, b, sizeof(T));
  }
  return v;
}

float decode(const unsigned char* p, SampleType type, bool swap) {
  switch (type) {
    case SampleType::Int8: return float(static_cast<std::int8_t>(p[0]));
    case SampleType::UInt8: return float(p[0]);
    case SampleType::Int16: return float(load<std::int16_t>(p, swap));
    case SampleType::UInt16: return float(load<std::uint16_t>(p, swap));
    case SampleType::Int32: return float(load<std::int32_t>(p, swap));
    case SampleType::UInt32: return float(load<std::uint32_t>(p, swap));
    case SampleType::Int64: return float(load<std::int64_t>(p, swap));
    case SampleType::UInt64: return float(load<std::uint64_t>(p, swap));
    case SampleType::Float32: return load<float>(p, swap);
    case SampleType::Float64: {
      const double d = load<double>(p, swap);
      // NaN stays NaN; beyond float's range becomes +-Inf (refused below unless allowed).
      if (std::isnan(d)) return std::numeric_limits<float>::quiet_NaN();
      return std::fabs(d) <= double(std::numeric_limits<float>::max())
                 ? float(d)
                 : std::copysign(std::numeric_limits<float>::infinity(), float(d));
    }
  }
  return 0.0f;
}

}  // namespace

void read_samples(ByteStream& stream, const SampleLayout& layout, std::uint64_t byte_base,
                  std::string_view name, const ImageReadOptions& options, ImageReadResult& out) {
  const std::uint64_t voxels = std::uint64_t(layout.nx) * std::uint64_t(layout.ny) * std::uint64_t(layout.nz);
  const int size = sample_size(layout.type);
  const bool swap = layout.big_endian != (std::endian::native == std::endian::big);
  const bool floating = layout.type == SampleType::Float32 || layout.type == SampleType::Float64;
  out.image.nx = layout.nx;
  out.image.ny = layout.ny;
  out.image.nz = layout.nz;
  out.sample_type = std::string(sample_type_name(layout.type));
  out.big_endian = layout.big_endian;
  std::vector<float>& samples = out.image.samples;
  samples.clear();
  if (options.samples == ImageSamples::Skip) {
    // The header describes the image; plain data are checked for length (free), gzip data are
    // left compressed (inflating them would cost what the header claims).
    if (!stream.inflating()) {
      const std::uint64_t need = voxels * std::uint64_t(size);
      const std::uint64_t got = stream.skip(need);
      if (got < need)
        throw Error(ErrorCode::Truncated, at_byte(name, byte_base + got),
                    "image data end after " + std::to_string(got / size) + " of " + std::to_string(voxels) +
                        " samples (" + std::to_string(need) + " bytes expected)");
    }
    return;
  }
  const bool keep = options.samples == ImageSamples::Load;
  // Grow with the data (a short stream must not allocate the header's full claim).
  if (keep) samples.reserve(std::size_t(std::min<std::uint64_t>(voxels, std::uint64_t{1} << 22)));
  constexpr std::size_t kChunkSamples = std::size_t{1} << 18;
  std::vector<unsigned char> buffer(std::size_t(std::min<std::uint64_t>(voxels, kChunkSamples)) * size);
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  std::uint64_t done = 0, next_report = 0;
  while (done < voxels) {
    // Every chunk (~1-10 ms): a cancelled read ends within one, not one report (2^24 samples,
    // ~0.4 s of inflating: a segment job on liver.inr ran ~1 s after its cancel at 250 ms).
    options.progress.check("image");
    const std::size_t want = std::size_t(std::min<std::uint64_t>(voxels - done, kChunkSamples));
    const std::size_t got = stream.read(reinterpret_cast<char*>(buffer.data()), want * size);
    const std::size_t whole = got / size;
    for (std::size_t s = 0; s < whole; ++s) {
      const float v = decode(buffer.data() + s * size, layout.type, swap);
      if (floating && !std::isfinite(v) && (std::isnan(v) || !options.allow_infinite))
        throw Error(ErrorCode::NonFinite, at_byte(name, byte_base + (done + s) * size),
                    "sample " + std::to_string(done + s) + " is not a finite number");
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      if (keep) samples.push_back(v);
    }
    done += whole;
    if (got < want * size)
      throw Error(ErrorCode::Truncated, at_byte(name, byte_base + done * size),
                  "image data end after " + std::to_string(done) + " of " + std::to_string(voxels) +
                      " samples (" + std::to_string(voxels * size) + " bytes expected)");
    if (done >= next_report) {
      options.progress.step(double(done) / double(voxels), "image");
      next_report = done + (std::uint64_t{1} << 24);
    }
  }
  out.min_sample = voxels ? lo : 0.0f;
  out.max_sample = voxels ? hi : 0.0f;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::int64_t parse_dimension(std::string_view text, const std::string& where, std::string_view what) {
  text = trim(text);
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec == std::errc::result_out_of_range)
    throw Error(ErrorCode::LimitExceeded, where, std::string(what) + " '" + std::string(text) + "' is too large");
  if (ec != std::errc() || end != text.data() + text.size() || text.empty())
    throw Error(ErrorCode::ParseError, where, std::string(what) + ": expected an integer, got '" + std::string(text) + "'");
  return v;
}

double parse_real(std::string_view text, const std::string& where, std::string_view what) {
  text = trim(text);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if ((ec != std::errc() && ec != std::errc::result_out_of_range) || end != text.data() + text.size() ||
      text.empty())
    throw Error(ErrorCode::ParseError, where, std::string(what) + ": expected a number, got '" + std::string(text) + "'");
  if (!std::isfinite(v) || ec == std::errc::result_out_of_range)
    throw Error(ErrorCode::NonFinite, where, std::string(what) + " is not finite: '" + std::string(text) + "'");
  return v;
}

}  // namespace levelset::detail
