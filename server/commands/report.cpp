#include "commands/report.hpp"

#include <cstdio>
#include <iostream>
#include <utility>

#include <tbb/global_control.h>

#include "core/file_io.hpp"

namespace levelset::cli {

Stats::Stats(std::string op_name, const NarrowBand& band)
    : op(std::move(op_name)),
      threads(int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism))),
      active_voxels(band.active_voxel_count()),
      bytes(band.memory_bytes()) {}

void Stats::set_phases(const std::string& work, std::chrono::steady_clock::time_point t0,
                       std::chrono::steady_clock::time_point t1, std::chrono::steady_clock::time_point t2,
                       std::chrono::steady_clock::time_point t3) {
  seconds["read"] = secs(t0, t1);
  seconds[work] = secs(t1, t2);
  seconds["write"] = secs(t2, t3);
  seconds["total"] = secs(t0, t3);
}

nlohmann::json Stats::to_json() const {
  nlohmann::json j = extra;
  j["op"] = op;
  j["seconds"] = seconds;
  j["threads"] = threads;
  j["active_voxels"] = active_voxels;
  j["bytes"] = bytes;
  return j;
}

std::string json_text(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

void write_stats(const Stats& stats, const std::string& path) {
  if (path.empty()) return;
  const std::string text = json_text(stats.to_json()) + "\n";
  if (path == "-") {
    std::cout << text;
  } else {
    write_file_atomically(path, text);
  }
}

namespace {
bool g_output_on_stdout = false;
}  // namespace

void set_output_on_stdout(bool on) { g_output_on_stdout = on; }

std::FILE* summary_stream(const std::string& stats_path) {
  return stats_path == "-" || g_output_on_stdout ? stderr : stdout;
}

std::string human_bytes(std::uint64_t bytes) {
  char buf[64];
  if (bytes < 1024) {
    std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  } else if (bytes < (1u << 20)) {
    std::snprintf(buf, sizeof buf, "%.1f KiB", bytes / 1024.0);
  } else if (bytes < (1u << 30)) {
    std::snprintf(buf, sizeof buf, "%.2f MiB", bytes / 1048576.0);
  } else {
    std::snprintf(buf, sizeof buf, "%.2f GiB", bytes / 1073741824.0);
  }
  return buf;
}

}  // namespace levelset::cli
