// Internal to the image readers (image_reader.cpp, inr_reader.cpp, nrrd_reader.cpp): a byte
// stream over memory that may be gzip-inflated, the sample types, and the shared sample decoder.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "io/image_reader.hpp"

namespace levelset::detail {

bool is_gzip(std::string_view bytes);

// Forward-only bytes from memory, plain or inflated (gzip or zlib; concatenated gzip members
// are read one after the other). Inflation happens on demand, so nothing is allocated beyond
// what read() asks for.
class ByteStream {
 public:
  // name: for messages; the Corrupt error names "name @ byte N (compressed)".
  ByteStream(std::string_view bytes, bool inflate, std::string name);
  ~ByteStream();
  ByteStream(const ByteStream&) = delete;
  ByteStream& operator=(const ByteStream&) = delete;

  // Copies up to n bytes to dst; fewer only at the end of the data.
  std::size_t read(char* dst, std::size_t n);
  // Bytes read() has delivered so far.
  std::uint64_t position() const { return position_; }
  // Gives bytes back: the next read() returns them first (position moves back).
  void unread(std::string_view bytes);
  // True when the bytes are inflated (skip() would have to decompress).
  bool inflating() const { return inflater_ != nullptr; }
  // Plain streams only: moves past up to n bytes without copying; returns how many.
  std::uint64_t skip(std::uint64_t n);

 private:
  struct Inflater;
  std::size_t read_source(char* dst, std::size_t n);

  std::string_view bytes_;
  std::size_t offset_ = 0;   // plain: next byte of bytes_
  std::unique_ptr<Inflater> inflater_;
  std::string pending_;      // unread bytes
  std::uint64_t position_ = 0;
  std::string name_;
};

enum class SampleType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };
int sample_size(SampleType type);
std::string_view sample_type_name(SampleType type);

struct SampleLayout {
  std::int64_t nx = 0, ny = 0, nz = 0;
  SampleType type = SampleType::UInt8;
  bool big_endian = false;
};

// Error{LimitExceeded} at `where` when the image exceeds the options' voxel or sample limits
// (also on overflow of nx*ny*nz), or, when its samples are to be loaded, the memory budget.
void check_image_limits(const SampleLayout& layout, const ImageReadOptions& options,
                        const std::string& where);

// Reads the layout's samples from the stream into out.image.samples (and min/max), growing
// the array as data arrive; with options.samples Scan only checks them (and min/max), with
// Skip reads nothing from gzip data and only checks the length of plain data. byte_base: the stream offset of the data's first byte, for
// messages "name @ byte N". Throws Truncated, NonFinite (float samples), Cancelled.
void read_samples(ByteStream& stream, const SampleLayout& layout, std::uint64_t byte_base,
                  std::string_view name, const ImageReadOptions& options, ImageReadResult& out);

// Loads a detached data file named in a header; empty function: reading from memory.
using DataFileLoader = std::function<std::string(const std::string& file)>;

// The formats. read_inr: the stream starts at the file's first byte. read_nrrd: the file's
// bytes (its header is never compressed).
ImageReadResult read_inr(ByteStream& stream, std::string_view name, const ImageReadOptions& options);
ImageReadResult read_nrrd(std::string_view bytes, std::string_view name, const ImageReadOptions& options,
                          const DataFileLoader& load_data_file);

// Header helpers shared by both formats.
std::int64_t parse_dimension(std::string_view text, const std::string& where, std::string_view what);
double parse_real(std::string_view text, const std::string& where, std::string_view what);
std::string_view trim(std::string_view s);

}  // namespace levelset::detail
