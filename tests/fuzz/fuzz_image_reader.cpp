// Fuzz target: read_image_from_memory on arbitrary bytes (INR, INR inside gzip, NRRD with raw or
// gzip data), header only (ImageSamples::Skip) and loaded. Small limits and a 4 MiB memory
// budget keep every input cheap (gzip bombs among the seeds). levelset::Error is the expected outcome for
// malformed input; anything else escaping, a crash, or an image that breaks its own invariants
// (sample count, finite positive spacing, finite samples) is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.hpp"
#include "io/image_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  levelset::ImageReadOptions options;
  options.max_file_bytes = 1 << 20;
  options.max_voxels = 1 << 22;
  options.max_sample_bytes = 1 << 24;
  options.memory_budget = 1 << 22;  // loads of more than 1M voxels are refused before inflating
  // Header only (what info does): never inflates, whatever the header claims.
  try {
    levelset::ImageReadOptions skip = options;
    skip.samples = levelset::ImageSamples::Skip;
    const levelset::ImageReadResult r = levelset::read_image_from_memory(bytes, "fuzz.img", skip);
    if (!r.image.samples.empty() || r.image.voxel_count() == 0) __builtin_trap();
  } catch (const levelset::Error&) {
  }
  try {
    const levelset::ImageReadResult r = levelset::read_image_from_memory(bytes, "fuzz.img", options);
    const levelset::ImageVolume& im = r.image;
    if (im.samples.size() != im.voxel_count() || im.voxel_count() == 0) __builtin_trap();
    if (!levelset::isfinite(im.spacing) || !levelset::isfinite(im.origin)) __builtin_trap();
    if (!(im.spacing.x > 0 && im.spacing.y > 0 && im.spacing.z > 0)) __builtin_trap();
    for (const float v : im.samples)
      if (!std::isfinite(v)) __builtin_trap();
  } catch (const levelset::Error&) {
  }
  return 0;
}
