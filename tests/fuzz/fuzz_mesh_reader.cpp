// Fuzz target: read_mesh_from_memory on arbitrary bytes. The first byte picks the format
// (extension .off .tria .ply .obj .stl, modulo 5); the rest is the file. Small limits keep every
// input cheap. levelset::Error is the expected outcome for malformed input; anything else
// escaping (std::bad_alloc, other exceptions) or a crash is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.hpp"
#include "io/mesh_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static constexpr std::string_view kNames[] = {"fuzz.off", "fuzz.tria", "fuzz.ply", "fuzz.obj",
                                                "fuzz.stl"};
  const std::string_view name = kNames[data[0] % 5];
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  levelset::MeshReadOptions options;
  options.max_file_bytes = 1 << 20;
  options.max_vertices = 1'000'000;
  options.max_triangles = 2'000'000;
  try {
    const levelset::MeshReadResult result = levelset::read_mesh_from_memory(bytes, name, options);
    // Every index must be in range: a reader bug here would crash later code.
    for (const auto& tri : result.mesh.triangles)
      for (const std::uint32_t index : tri)
        if (index >= result.mesh.vertices.size()) __builtin_trap();
    for (const auto& v : result.mesh.vertices)
      if (!levelset::isfinite(v)) __builtin_trap();
  } catch (const levelset::Error&) {
  }
  return 0;
}
