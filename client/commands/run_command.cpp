// run JOB.conf [--set key=value ...] [-o OUTDIR] [-q]: `levelsetd run` through a server. The job
// file is parsed here (a malformed one never leaves the machine), the input files it names are
// uploaded and replaced by their ids (lib/job_inputs.hpp), the job text goes to POST /api/v1/jobs
// with its file name, its log lines are printed as they come (as `levelsetd run` prints them),
// and every file of result.files is downloaded into OUTDIR under the same name `levelsetd run`
// gives it. STEM.stats.json's "outputs" are rewritten to the local paths. SIGINT / SIGTERM /
// SIGHUP while the job runs cancel it on the server (exit 128 + the signal).
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>

#include "commands/commands.hpp"
#include "config/config_file.hpp"
#include "core/error.hpp"
#include "core/file_io.hpp"
#include "lib/cancel_on_signal.hpp"
#include "lib/client_error.hpp"
#include "lib/job_follow.hpp"
#include "lib/job_inputs.hpp"

namespace levelset::client {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct RunArgs {
  std::string job;
  std::vector<std::string> overrides;
  std::string output_dir = "out";
  bool quiet = false, delete_session = false;
};

// The job file, parsed with the overrides applied (as the server will), and its text.
config::Set parse_job(const RunArgs& a, std::string& text) {
  try {
    text = read_file_bytes(a.job, config::Limits{}.max_bytes);
    config::ParseOptions po;
    po.name = a.job;
    config::Set root = config::parse_config(text, po);
    for (const std::string& o : a.overrides) config::set_override(root, o);
    return root;
  } catch (const Error& e) {
    const ClientError::Kind kind = e.code() == ErrorCode::IoError ? ClientError::Kind::Local : ClientError::Kind::Usage;
    throw ClientError(kind, e.code() == ErrorCode::IoError ? "io_error" : "invalid_job", e.where() + ": " + e.reason());
  }
}

void rewrite_stats_outputs(const fs::path& stats, const std::vector<std::string>& local) {
  std::string text;
  try {
    text = read_file_bytes(stats, 64 << 20);
  } catch (const Error&) {
    return;
  }
  json j = json::parse(text, nullptr, false);
  if (!j.is_object()) return;
  j["outputs"] = local;
  try {
    write_file_atomically(stats, j.dump(2, ' ', false, json::error_handler_t::replace) + "\n");
  } catch (const Error& e) {
    throw ClientError(ClientError::Kind::Local, "io_error", e.what());
  }
}

void run(const RunArgs& a, const Globals& g) {
  std::string text;
  const config::Set root = parse_job(a, text);
  const Api api = g.api();

  // Inputs: each local file uploaded once, its keys pointed at the upload id.
  json sets = json::array();
  for (const std::string& o : a.overrides) sets.push_back(o);
  std::map<std::string, std::string> uploaded;  // path -> id
  for (const InputFile& f : job_input_files(root, fs::path(a.job).parent_path().string())) {
    if (f.path.empty()) continue;
    auto it = uploaded.find(f.path);
    if (it == uploaded.end()) {
      const json u = api.upload(f.path, upload_format_of(f.path));
      it = uploaded.emplace(f.path, u.value("id", "")).first;
      if (!a.quiet) std::fprintf(stderr, "uploaded %s as %s\n", f.path.c_str(), it->second.c_str());
    }
    sets.push_back(f.key + "=" + it->second);
  }

  const std::string name = fs::path(a.job).filename().string();
  CancelOnSignal cancel_on_signal(api);  // from the submission on, a signal cancels the job
  const json submitted = api.post("/api/v1/jobs", {{"config", text}, {"set", sets}, {"name", name}});
  const std::string job_id = submitted.value("id", "");
  cancel_on_signal.arm(job_id);

  ProgressView view(::isatty(::fileno(stderr)) && !a.quiet ? ProgressView::Mode::Bar : ProgressView::Mode::Off);
  FollowCallbacks cb;
  cb.on_progress = [&view](const json& p) { view.update(p); };
  if (!a.quiet) cb.on_log = [&view](const std::string& line) { view.message(line, stdout); };
  cb.on_notice = [&view](const std::string& m) { view.message("levelsetctl: " + m, stderr); };
  const json job = follow_job(api, job_id, cb);
  cancel_on_signal.arm("");  // ended: a signal from here on only ends the client
  view.finish();
  throw_unless_succeeded(job);

  const json result = job.value("result", json::object());
  std::error_code ec;
  fs::create_directories(a.output_dir, ec);
  if (ec) throw ClientError(ClientError::Kind::Local, "io_error", "cannot create " + a.output_dir + ": " + ec.message());
  std::vector<std::string> local;
  for (const json& f : result.value("files", json::array())) {
    const std::string file = f.get<std::string>();
    if (file.empty() || file.find('/') != std::string::npos || file[0] == '.')
      throw ClientError(ClientError::Kind::Server, "bad_response", "the job names an odd output file '" + file + "'");
    const std::string path = (fs::path(a.output_dir) / file).string();
    api.download("/api/v1/jobs/" + Api::encode(job_id) + "/files/" + Api::encode(file), path);
    local.push_back(path);
  }
  const std::string stem = fs::path(name).extension() == ".conf" ? fs::path(name).stem().string() : name;
  for (const std::string& p : local)
    if (fs::path(p).filename() == stem + ".stats.json") rewrite_stats_outputs(p, local);

  const double seconds = result.contains("seconds") && result["seconds"].is_object()
                             ? result["seconds"].value("total", 0.0)
                             : job.value("seconds", 0.0);
  std::printf("%s: job %s done in %.2f s; outputs:\n", a.job.c_str(), result.value("job", std::string("?")).c_str(),
              seconds);
  for (const std::string& p : local) std::printf("  %s\n", p.c_str());
  const std::string session = result.value("session", "");
  if (!session.empty()) {
    if (a.delete_session) {
      api.del("/api/v1/sessions/" + Api::encode(session));
    } else if (!a.quiet) {
      std::printf("session %s holds the final level set\n", session.c_str());
    }
  }
  std::fflush(stdout);
}

}  // namespace

void add_run_command(CLI::App& app, Globals& g) {
  auto a = std::make_shared<RunArgs>();
  CLI::App* sub = app.add_subcommand("run", "Run a job file on the server (as levelsetd run does locally) and download its outputs");
  sub->add_option("job", a->job, "Job file (configs/jobs/*.conf); the input files it names are uploaded")->required();
  sub->add_option("--set", a->overrides, "Override a job key, e.g. --set raster.resolution=64 (repeatable)")
      ->allow_extra_args(false);
  sub->add_option("-o,--output-dir", a->output_dir, "Directory for the outputs (created; default: out)");
  sub->add_flag("-q,--quiet", a->quiet, "Do not echo the job's log");
  sub->add_flag("--delete-session", a->delete_session, "Delete the session the job's final level set became");
  sub->callback([a, &g] { run(*a, g); });
}

}  // namespace levelset::client
