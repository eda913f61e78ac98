// levelsetd run JOB.conf [--set key=value ...] [-o OUTDIR]: run a job file end to end
// (common/jobs/job.hpp) and say where its outputs went.
#include <cstdio>
#include <memory>

#include "commands/command.hpp"
#include "commands/report.hpp"
#include "core/error.hpp"
#include "jobs/job.hpp"

namespace levelset::cli {

namespace {

struct RunArgs {
  std::string job;
  std::vector<std::string> overrides;
  std::string output_dir = "out";
  bool quiet = false;
  std::string stats;
};

}  // namespace

Command add_run_command(CLI::App& app, int& threads) {
  auto args = std::make_shared<RunArgs>();
  std::string apps;
  for (const std::string& n : jobs::job_application_names()) apps += " " + n;
  CLI::App* sub = app.add_subcommand("run", "Run a job file (configs/jobs/*.conf) end to end; applications:" + apps);
  sub->add_option("job", args->job, "Job file in the thesis's configuration format")->required();
  sub->add_option("--set", args->overrides, "Override a job key, e.g. --set raster.resolution=64 (repeatable)");
  sub->add_option("-o,--output-dir", args->output_dir, "Directory for the outputs (created; default: out)");
  sub->add_flag("-q,--quiet", args->quiet, "Do not echo the progress log");
  add_common_options(sub, threads, args->stats);
  return {sub, [args]() {
            jobs::JobOptions options;
            options.output_dir = args->output_dir;
            // With --stats - the JSON owns stdout, so the log goes to stderr.
            std::FILE* log_stream = args->stats == "-" ? stderr : stdout;
            if (!args->quiet)
              options.log = [log_stream](std::string_view line) {
                std::fprintf(log_stream, "%.*s\n", static_cast<int>(line.size()), line.data());
                std::fflush(log_stream);
              };
            const jobs::JobResult result = jobs::run_job_file(args->job, args->overrides, options);
            std::FILE* out = log_stream;
            std::fprintf(out, "%s: job %s done in %.2f s; outputs:\n", args->job.c_str(), result.application.c_str(),
                         result.seconds);
            for (const std::string& path : result.outputs) std::fprintf(out, "  %s\n", path.c_str());
            if (args->stats == "-") {
              std::printf("%s\n", json_text(result.stats).c_str());
            } else if (!args->stats.empty()) {
              std::FILE* f = std::fopen(args->stats.c_str(), "w");
              if (f == nullptr) throw Error(ErrorCode::IoError, args->stats, "cannot write the stats");
              std::fprintf(f, "%s\n", json_text(result.stats).c_str());
              std::fclose(f);
            }
            return 0;
          }};
}

}  // namespace levelset::cli
