// Fuzz target: read_point_cloud_from_memory on arbitrary bytes. The first byte picks the
// format (extension .xyz .xyzn .pwn .ply .off, modulo 5); the rest is the file. levelset::Error
// is the expected outcome for malformed input; anything else escaping or a crash is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.hpp"
#include "io/point_cloud_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static constexpr std::string_view kNames[] = {"fuzz.xyz", "fuzz.xyzn", "fuzz.pwn", "fuzz.ply",
                                                "fuzz.off"};
  const std::string_view name = kNames[data[0] % 5];
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  levelset::PointCloudReadOptions options;
  options.max_file_bytes = 1 << 20;
  options.max_points = 1'000'000;
  try {
    const levelset::PointCloudReadResult result =
        levelset::read_point_cloud_from_memory(bytes, name, options);
    if (result.cloud.has_normals() && result.cloud.normals.size() != result.cloud.points.size())
      __builtin_trap();
    for (const auto& p : result.cloud.points)
      if (!levelset::isfinite(p)) __builtin_trap();
    for (const auto& n : result.cloud.normals)
      if (!levelset::isfinite(n)) __builtin_trap();
  } catch (const levelset::Error&) {
  }
  return 0;
}
