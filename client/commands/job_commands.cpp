// jobs submit SESSION --op NAME [--param key=value ...] [--json BODY] [--wait]
//      | list | show JID | cancel JID | stop JID | wait JID
#include <cstdio>
#include <memory>

#include "commands/commands.hpp"
#include "lib/client_error.hpp"
#include "lib/job_follow.hpp"

namespace levelset::client {

using nlohmann::json;

namespace {

struct JobArgs {
  std::string id, op, body;
  std::vector<std::string> params;
  bool wait = false, json = false, quiet = false;
};

std::string job_path(const std::string& id) { return "/api/v1/jobs/" + Api::encode(id); }

}  // namespace

// "a.b=value": value as JSON when it parses (numbers, true, [1,2]), else as a string.
void apply_param(json& body, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ClientError(ClientError::Kind::Usage, "usage", "--param expects key=value, found '" + assignment + "'");
  const std::string key = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  json value = json::parse(text, nullptr, false);
  if (value.is_discarded()) value = text;
  json* at = &body;
  std::size_t start = 0;
  for (;;) {
    const std::size_t dot = key.find('.', start);
    const std::string part = key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (part.empty()) throw ClientError(ClientError::Kind::Usage, "usage", "--param: empty key part in '" + key + "'");
    if (dot == std::string::npos) {
      (*at)[part] = value;
      return;
    }
    if (!(*at)[part].is_object()) (*at)[part] = json::object();
    at = &(*at)[part];
    start = dot + 1;
  }
}


json wait_for_job(const Api& api, const std::string& job_id, bool logs, ProgressView::Mode mode) {
  ProgressView view(mode);
  FollowCallbacks cb;
  cb.on_progress = [&view](const json& p) { view.update(p); };
  if (logs) cb.on_log = [&view](const std::string& line) { view.message(line, stderr); };
  cb.on_notice = [&view](const std::string& m) { view.message("levelsetctl: " + m, stderr); };
  const json job = follow_job(api, job_id, cb);
  view.finish();
  throw_unless_succeeded(job);
  return job;
}

void add_job_commands(CLI::App& app, Globals& g) {
  CLI::App* j = app.add_subcommand("jobs", "Submit, list, show, cancel, stop and wait for jobs");
  j->require_subcommand(1);
  auto a = std::make_shared<JobArgs>();

  CLI::App* submit = j->add_subcommand("submit", "Run an operation on a session; prints the job id");
  submit->add_option("session", a->id, "Session id")->required();
  submit->add_option("--op", a->op, "Operation (GET /api/v1 lists them: evolve offset fair ...)")->required();
  submit->add_option("--param", a->params, "An operation parameter key=value (repeatable; JSON values)")
      ->allow_extra_args(false);
  submit->add_option("--json", a->body, "The request body as a JSON object (--op and --param are merged in)");
  submit->add_flag("--wait", a->wait, "Wait for the job (progress on stderr); exit 0 only when it succeeded");
  submit->callback([a, &g] {
    json body = json::object();
    if (!a->body.empty()) {
      body = json::parse(a->body, nullptr, false);
      if (!body.is_object()) throw ClientError(ClientError::Kind::Usage, "usage", "--json expects a JSON object");
    }
    body["op"] = a->op;
    for (const std::string& p : a->params) apply_param(body, p);
    const Api api = g.api();
    const json r = api.post("/api/v1/sessions/" + Api::encode(a->id) + "/jobs", body);
    const std::string job = r.value("id", "");
    if (!a->wait) {
      std::printf("%s\n", job.c_str());
      return;
    }
    std::fprintf(stderr, "job %s\n", job.c_str());
    const json done = wait_for_job(api, job, true);
    print_json(done.value("result", json()));
  });

  CLI::App* list = j->add_subcommand("list", "One line per job: id, state, op, session, progress");
  list->add_flag("--json", a->json, "Print the server's JSON");
  list->callback([a, &g] {
    const json r = g.api().get("/api/v1/jobs");
    if (a->json) return print_json(r);
    for (const json& x : r.value("jobs", json::array())) {
      const json p = x.value("progress", json::object());
      const double f = p.contains("fraction") && p["fraction"].is_number() ? p["fraction"].get<double>() : 0.0;
      const std::string session = x.contains("session") && x["session"].is_string() ? x["session"].get<std::string>() : "-";
      std::printf("%s\t%s\t%s\t%s\t%d%%\n", x.value("id", "").c_str(), x.value("state", "").c_str(),
                  x.value("op", "").c_str(), session.c_str(), int(f * 100));
    }
  });

  CLI::App* show = j->add_subcommand("show", "A job as JSON");
  show->add_option("jid", a->id, "Job id")->required();
  show->callback([a, &g] { print_json(g.api().get(job_path(a->id))); });

  CLI::App* cancel = j->add_subcommand("cancel", "Cancel a job (the session keeps its state from before)");
  cancel->add_option("jid", a->id, "Job id")->required();
  cancel->callback([a, &g] { g.api().del(job_path(a->id)); });

  CLI::App* stop = j->add_subcommand("stop", "Stop an evolution-like job at its next step, keeping the state reached");
  stop->add_option("jid", a->id, "Job id")->required();
  stop->callback([a, &g] { g.api().post(job_path(a->id) + "/stop", json::object()); });

  CLI::App* wait = j->add_subcommand("wait", "Follow a job to its end (progress on stderr); prints its result");
  wait->add_option("jid", a->id, "Job id")->required();
  wait->add_flag("-q,--quiet", a->quiet, "No progress and no log lines");
  wait->callback([a, &g] {
    const json done = wait_for_job(g.api(), a->id, !a->quiet, a->quiet ? ProgressView::Mode::Off : ProgressView::Mode::Auto);
    print_json(done.value("result", json()));
  });
}

}  // namespace levelset::client
