// File extensions and the formats they name, shared by the readers, the writers and the CLI's
// output checks (a command refuses `-o out.ply` for a band before it computes anything).
//
// lower_extension: the last extension, lower-case, with its dot ("" when none).
// require_extension: Error{UnsupportedFormat} at `path` unless its extension is one of
//   `allowed` (lower-case, with dots), naming `what` ("a narrow band") and the allowed list.
//   An existing device, FIFO or socket (or a link to one, like /dev/stdout) passes: it has no
//   extension, and whether it may be written is core/file_io.hpp's allow_special_outputs.
// Cost: O(path length). Threading: reentrant.
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <string_view>

namespace levelset {

inline constexpr std::string_view kLsgExtensions[] = {".lsg"};
inline constexpr std::string_view kMeshOutputExtensions[] = {".off", ".obj", ".ply", ".stl", ".tria"};
inline constexpr std::string_view kNrrdOutputExtensions[] = {".nrrd"};

std::string lower_extension(const std::filesystem::path& path);

void require_extension(const std::filesystem::path& path,
                       std::span<const std::string_view> allowed, std::string_view what);

}  // namespace levelset
