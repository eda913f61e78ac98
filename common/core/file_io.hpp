// Whole-file reading with a size limit, and crash-safe writing (temp file + fsync + rename).
//
// read_file_bytes refuses files larger than max_bytes before allocating anything.
// write_file_atomically writes to "<path>.tmp-<pid>-<n>" in the same directory, flushes it
// to disk and renames it over path, so a crash never leaves a half file under the final name.
// Both throw levelset::Error{IoError | LimitExceeded} naming the path and the reason.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace levelset {

std::string read_file_bytes(const std::filesystem::path& path,
                            std::uint64_t max_bytes = std::uint64_t{1} << 34);

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace levelset
