// Shared output helpers for batch subcommands: the --stats JSON schema and human formatting.
//
// Every subcommand's --stats writes one JSON object:
//   {"op": NAME, "seconds": {"total": T, PHASE: T...}, "threads": N, "active_voxels": N,
//    "bytes": N, ...op-specific fields}
// to a file, or to stdout for "-".
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "grid/narrow_band.hpp"

namespace levelset::cli {

// Seconds from a to b.
inline double secs(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

struct Stats {
  // A record for `op` about `band`: threads in use, its active voxels and bytes.
  Stats(std::string op_name, const NarrowBand& band);

  std::string op;
  nlohmann::json seconds = nlohmann::json::object();
  nlohmann::json extra = nlohmann::json::object();
  int threads = 0;
  std::uint64_t active_voxels = 0;
  std::uint64_t bytes = 0;

  // The usual phases: "read" t0..t1, `work` t1..t2, "write" t2..t3 and "total" t0..t3.
  void set_phases(const std::string& work, std::chrono::steady_clock::time_point t0, std::chrono::steady_clock::time_point t1,
                  std::chrono::steady_clock::time_point t2, std::chrono::steady_clock::time_point t3);

  nlohmann::json to_json() const;
};

// Writes stats to path ("-" = stdout); no-op for an empty path.
void write_stats(const Stats& stats, const std::string& path);

// JSON text (indent 2) that is valid UTF-8 whatever the strings hold: bytes of file names or
// formulas that are not UTF-8 become U+FFFD instead of a json type_error.
std::string json_text(const nlohmann::json& j);

std::string human_bytes(std::uint64_t bytes);

// Where the one-line human summary goes: stderr when --stats writes JSON to stdout ("-") or
// an output is stdout itself (-o /dev/stdout with --allow-special-outputs), so that stdout
// stays parseable; stdout otherwise.
std::FILE* summary_stream(const std::string& stats_path);
void set_output_on_stdout(bool on);  // check_command_files says so, before the command runs

}  // namespace levelset::cli
