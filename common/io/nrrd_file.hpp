// NRRD volumes (teem's "nearly raw raster data", readable by ParaView, 3D Slicer, ITK,
// pynrrd): the dense grids of the applications (Voronoi labels, arrival times, cost grids).
//
// Written form: "NRRD0004" header lines (type, dimension 3, sizes nx ny nz, space
//   dimension 3, space directions (h,0,0) (0,h,0) (0,0,h), space origin, endian little,
//   encoding raw), a blank line, then the raw little-endian samples, x fastest.
// Reading: io/image_reader.hpp (read_image reads these and the other NRRD forms; cost grids
//   pass allow_infinite for their +Inf = blocked nodes).
// Errors (thrown): Error{IoError} when the file cannot be written (save_nrrd writes a
//   temporary file and renames it). Cost: O(samples). Threading: pure functions.
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

}  // namespace levelset
