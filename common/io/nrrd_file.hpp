// NRRD volumes (teem's "nearly raw raster data", readable by ParaView, 3D Slicer, ITK,
// pynrrd): the dense grids of the applications (Voronoi labels, arrival times, cost grids).
//
// Written form: "NRRD0004" header lines (type, dimension 3, sizes nx ny nz, space
//   dimension 3, space directions (h,0,0) (0,h,0) (0,0,h), space origin, endian little,
//   encoding raw), a blank line, then the raw little-endian samples, x fastest.
// Read form (strict subset): magic NRRD0001..NRRD0005; '#' comment lines; fields type
//   (int8/uint8/int16/uint16/int32/uint32/float/double and their NRRD synonyms), dimension
//   (must be 3), sizes, encoding (raw only), endian (little; needed for multi-byte types),
//   spacings or axis-aligned space directions with one positive equal spacing (cubic
//   voxels), space origin; other fields are ignored; a detached "data file" is refused.
//   Samples are converted to double.
// Errors (thrown): Error{UnsupportedFormat} for a wrong magic, an unsupported encoding,
//   type, endianness or detached data; Error{ParseError} naming the header line for
//   malformed fields; Error{LimitExceeded} for a header over 64 KiB or more samples than
//   max_voxels; Error{Truncated} / Error{Corrupt} when the data size differs from the
//   header's sizes; Error{NonFinite} for NaN samples. Allocation follows the bytes present.
// Cost: O(samples). Threading: pure functions.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/vec3.hpp"

namespace levelset {

struct NrrdFrame {
  int sizes[3] = {0, 0, 0};
  double spacing = 1.0;
  Vec3d origin{};
};

std::string encode_nrrd(const NrrdFrame& frame, std::span<const std::int32_t> samples);
std::string encode_nrrd(const NrrdFrame& frame, std::span<const float> samples);
void save_nrrd(const std::filesystem::path& path, const NrrdFrame& frame, std::span<const std::int32_t> samples);
void save_nrrd(const std::filesystem::path& path, const NrrdFrame& frame, std::span<const float> samples);

struct NrrdVolume {
  NrrdFrame frame;
  std::string type;             // the sample type as named in the header
  std::vector<double> samples;  // x fastest
};

NrrdVolume decode_nrrd(std::string_view bytes, std::string_view name,
                       std::uint64_t max_voxels = std::uint64_t{1} << 27);
NrrdVolume load_nrrd(const std::filesystem::path& path, std::uint64_t max_voxels = std::uint64_t{1} << 27);

}  // namespace levelset
