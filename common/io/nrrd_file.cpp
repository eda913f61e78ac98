#include "io/nrrd_file.hpp"

#include <bit>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/error.hpp"
#include "core/file_extension.hpp"
#include "core/file_io.hpp"

namespace levelset {

namespace {

static_assert(std::endian::native == std::endian::little, "the NRRD writer assumes a little-endian host");

template <typename T>
std::string encode(const NrrdFrame& f, std::span<const T> samples, const char* type) {
  const std::uint64_t n = std::uint64_t(f.sizes[0]) * std::uint64_t(f.sizes[1]) * std::uint64_t(f.sizes[2]);
  if (samples.size() != n)
    throw Error(ErrorCode::InvalidArgument, "encode_nrrd", "sample count does not match the sizes");
  char head[1024];
  const double h = f.spacing;
  std::snprintf(head, sizeof head,
                "NRRD0004\n# levelset dense grid\ntype: %s\ndimension: 3\nsizes: %d %d %d\nspace dimension: 3\n"
                "space directions: (%.17g,0,0) (0,%.17g,0) (0,0,%.17g)\nspace origin: (%.17g,%.17g,%.17g)\n"
                "endian: little\nencoding: raw\n\n",
                type, f.sizes[0], f.sizes[1], f.sizes[2], h, h, h, f.origin.x, f.origin.y, f.origin.z);
  std::string out(head);
  const std::size_t at = out.size();
  out.resize(at + samples.size_bytes());
  if (!samples.empty()) std::memcpy(out.data() + at, samples.data(), samples.size_bytes());
  return out;
}

}  // namespace

std::string encode_nrrd(const NrrdFrame& frame, std::span<const std::int32_t> samples) {
  return encode(frame, samples, "int32");
}
std::string encode_nrrd(const NrrdFrame& frame, std::span<const float> samples) {
  return encode(frame, samples, "float");
}
void save_nrrd(const std::filesystem::path& path, const NrrdFrame& frame, std::span<const std::int32_t> samples) {
  require_extension(path, kNrrdOutputExtensions, "an NRRD image");
  write_file_atomically(path, encode_nrrd(frame, samples));
}
void save_nrrd(const std::filesystem::path& path, const NrrdFrame& frame, std::span<const float> samples) {
  require_extension(path, kNrrdOutputExtensions, "an NRRD image");
  write_file_atomically(path, encode_nrrd(frame, samples));
}

}  // namespace levelset
