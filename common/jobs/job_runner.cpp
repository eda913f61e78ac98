// run_job / run_job_file (jobs/job.hpp): the checks every job shares, the dispatch to its
// application, and the stats / log files.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>

#include "core/error.hpp"
#include "core/text.hpp"
#include "core/file_io.hpp"
#include "core/suggest.hpp"
#include "jobs/applications.hpp"
#include "jobs/job.hpp"

namespace levelset::jobs {

namespace fs = std::filesystem;

const std::vector<ApplicationEntry>& applications() {
  static const std::vector<ApplicationEntry> list = {
      {"reconstruct", run_reconstruct_job, "watertight surface from unorganised points (thesis 5.1.3)"},
      {"evolve", run_evolve_job, "move the input surface with a speed formula (thesis 4.7)"},
      {"offset", run_offset_job, "offset surfaces, and +D then -D (thesis 5.1.1)"},
      {"fair", run_fair_job, "fairing by curvature flows (thesis 3.1, 5.1.2)"},
      {"minmax", run_minmax_job, "feature-preserving min/max flow to a steady state (thesis 3.3)"},
      {"csg", run_csg_job, "union, intersection, difference of two level sets (thesis 3.5, 5.1.4)"},
      {"segment", run_segment_job, "shape detection in a 3D image by an edge-stopped front (thesis 3.4)"},
      {"path", run_path_job, "shortest path by fast marching around obstacles (thesis 3.6)"},
      {"voronoi", run_voronoi_job, "geodesic Voronoi regions of seeds by fast marching (thesis 3.5)"},
  };
  return list;
}

std::vector<std::string> job_application_names() {
  std::vector<std::string> names;
  for (const ApplicationEntry& a : applications()) names.emplace_back(a.name);
  return names;
}

JobResult run_job(const config::Set& job, const JobOptions& options_in) {
  const auto t0 = std::chrono::steady_clock::now();
  const config::Entry* app_entry = job.find("job");
  if (app_entry == nullptr || app_entry->is_set)
    throw Error(ErrorCode::InvalidArgument, options_in.name,
                "a job file starts with 'job = NAME' (one of the applications)");
  const ApplicationEntry* app = nullptr;
  for (const ApplicationEntry& a : applications())
    if (a.name == app_entry->value.text) app = &a;
  if (app == nullptr) {
    std::string known;
    for (const ApplicationEntry& a : applications()) known += (known.empty() ? "" : ", ") + std::string(a.name);
    const std::string best = closest_name(app_entry->value.text, job_application_names());
    throw Error(ErrorCode::InvalidArgument, config::place_of(*app_entry, options_in.name),
                "unknown application '" + app_entry->value.text + "'" +
                    (best.empty() ? "" : " (did you mean '" + best + "'?)") + "; known: " + known);
  }
  config::check_keys(job, {"job", "input", "raster", "output", std::string(app->name)}, options_in.name);
  JobContext(job, options_in).check_outputs();

  std::error_code ec;
  fs::create_directories(options_in.output_dir, ec);
  if (ec) throw Error(ErrorCode::IoError, options_in.output_dir, "cannot create the output directory: " + ec.message());

  // The log goes to OUTDIR/STEM.log and to the caller's sink, each line once. Its path and the
  // stats' pass the same destination checks as every other output before anything is written.
  const std::string log_path = (fs::path(options_in.output_dir) / (stem(options_in.name) + ".log")).string();
  const std::string stats_path = (fs::path(options_in.output_dir) / (stem(options_in.name) + ".stats.json")).string();
  check_output_paths({}, {log_path, stats_path});
  auto log_file = std::make_shared<std::ofstream>(log_path, std::ios::trunc);
  if (!*log_file) throw Error(ErrorCode::IoError, log_path, "cannot write the log");
  auto log_mutex = std::make_shared<std::mutex>();
  JobOptions options = options_in;
  options.log = [log_file, log_mutex, sink = options_in.log, t0](std::string_view line) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    char stamp[32];
    std::snprintf(stamp, sizeof stamp, "[%8.2f s] ", s);
    std::lock_guard<std::mutex> lock(*log_mutex);
    *log_file << stamp << line << '\n';
    log_file->flush();
    if (sink) sink(std::string(stamp) + std::string(line));
  };

  JobContext context(job, options);
  context.log("job " + std::string(app->name) + ": " + std::string(app->summary));
  try {
    app->run(context);
  } catch (const Error& e) {
    // An application's own place ("segment_image", "obstacle clearance") gets the job's name.
    if (e.where().find(options_in.name) != std::string::npos || e.where().rfind("--set", 0) == 0) throw;
    throw Error(e.code(), options_in.name + " (" + std::string(app->name) + ": " + e.where() + ")", e.reason());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  context.log("done in " + format_number(seconds) + " s");

  JobResult result;
  result.application = std::string(app->name);
  result.seconds = seconds;
  result.outputs = context.outputs();
  result.outputs.push_back(log_path);
  result.outputs.push_back(stats_path);
  result.stats = context.stats();
  result.stats["job"] = result.application;
  result.stats["name"] = options.name;
  result.stats["seconds"]["total"] = seconds;
  result.stats["outputs"] = result.outputs;
  write_file_atomically(stats_path, result.stats.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  return result;
}

JobResult run_job_file(const std::string& path, const std::vector<std::string>& overrides, JobOptions options) {
  config::Set job = config::read_config_file(path);
  for (const std::string& o : overrides) config::set_override(job, o);
  options.name = path;
  options.base_dir = fs::path(path).parent_path().string();
  if (options.base_dir.empty()) options.base_dir = ".";
  return run_job(job, options);
}

}  // namespace levelset::jobs
