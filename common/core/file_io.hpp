// Whole-file reading with a size limit, and crash-safe writing (temp file + fsync + rename).
//
// read_file_bytes refuses files larger than max_bytes before allocating anything.
// write_file_atomically writes to "<path>.tmp-<pid>-<n>" in the same directory, flushes it
// to disk and renames it over path, so a crash never leaves a half file under the final name.
// Both throw levelset::Error{IoError | LimitExceeded} naming the path and the reason.
//
// Outputs never clobber (issue 14): a destination that exists and is a symbolic link, or is
// not a regular file (a device such as /dev/null, a FIFO, a directory), is refused before
// anything is written, unless allow_special_outputs(true) lets a character device or FIFO be
// written in place (no temp file, no rename), also through a link that leads to one or to this process's stdout (/dev/stdout), appending. With the output guard on (the batch CLI turns it
// on; off by default, so a long-running daemon keeps no list), every file read through
// read_file_bytes and every file written is remembered, and a write over one of them (an input
// of this run, or an output it already wrote) is refused. A temp file is removed on every
// error path, and on SIGINT / SIGTERM / SIGHUP once remove_temp_files_on_signals() ran.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace levelset {

std::string read_file_bytes(const std::filesystem::path& path,
                            std::uint64_t max_bytes = std::uint64_t{1} << 34);

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

// True when path (following links) is the same file as this process's stdout (fd 1).
bool is_stdout(const std::filesystem::path& path);

// Process-wide switches (see above); thread-safe.
void allow_special_outputs(bool on);
void enable_output_guard(bool on);

// Checks, before any work, that each output may be written: not a symbolic link, not an
// existing non-regular file (unless allowed), not the same file as any input (compared by
// device and inode), and no two outputs the same file (by inode when they exist, by their
// normalised absolute path when not). Paths that do not exist as inputs are skipped.
// Error{IoError} at the offending output path.
void check_output_paths(const std::vector<std::filesystem::path>& inputs,
                        const std::vector<std::filesystem::path>& outputs);

// Installs handlers for SIGINT, SIGTERM and SIGHUP that unlink the temp files of writes in
// progress and then end the process with the signal's default action.
void remove_temp_files_on_signals();

}  // namespace levelset
