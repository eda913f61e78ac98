// Jobs: submit on a session or as a job file, list, show, cancel, stop, resume, events, files.
#include "api/route.hpp"
#include "service/api_error.hpp"

namespace levelset::api {

using nlohmann::json;

namespace {
const json kJson = {{"application/json", {{"schema", {{"type", "object"}}}}}};
}

void add_job_routes(std::vector<Route>& r) {
  r.push_back({"POST", "/api/v1/sessions/{id}/jobs",
               "Run an operation on the session: {\"op\": NAME, ...parameters as in the CLI and job files}", true,
               false, {}, kJson,
               {{"202", "queued; Location names the job"}, {"409", "another job runs on the session"},
                {"422", "a parameter out of range"}, {"429", "the queue is full"}},
               [](RouteContext& c) { c.reply(c.service.submit(c.param(1), c.body())); }});
  r.push_back({"POST", "/api/v1/jobs",
               "Run a job file: {\"config\": TEXT, \"set\": [\"a.b=v\"], \"name\": \"job.conf\"}; inputs are upload ids; "
               "its final band becomes a session",
               true, false, {}, kJson, {{"202", "queued"}, {"400", "malformed job file"}},
               [](RouteContext& c) { c.reply(c.service.submit_job_file(c.body())); }});
  r.push_back({"GET", "/api/v1/jobs", "List jobs", false, false, {}, nullptr, {{"200", "jobs"}},
               [](RouteContext& c) { c.reply(200, c.service.list_jobs()); }});
  r.push_back({"GET", "/api/v1/jobs/{jid}", "One job: state, progress, stage, timings, result, error", false, false, {},
               nullptr, {{"200", "the job"}, {"404", "unknown"}},
               [](RouteContext& c) { c.reply(200, c.service.jobs().get(c.param(1))->describe()); }});
  r.push_back({"DELETE", "/api/v1/jobs/{jid}", "Cancel: the session keeps the state it had before the job", true,
               false, {}, nullptr, {{"200", "cancelling"}, {"409", "already ended"}},
               [](RouteContext& c) { c.reply(200, c.service.cancel(c.param(1))); }});
  r.push_back({"POST", "/api/v1/jobs/{jid}/stop", "Stop an evolution-like job at the next step, keeping the state reached",
               true, false, {}, nullptr, {{"200", "stopping"}, {"409", "not stoppable or ended"}},
               [](RouteContext& c) { c.reply(200, c.service.stop(c.param(1))); }});
  r.push_back({"POST", "/api/v1/jobs/{jid}/resume", "Continue an interrupted job from its last checkpoint", true, false,
               {}, nullptr, {{"202", "queued again"}, {"409", "not interrupted"}},
               [](RouteContext& c) { c.reply(c.service.resume(c.param(1))); }});
  r.push_back({"GET", "/api/v1/jobs/{jid}/events", "Server-Sent Events: state, progress, log lines, the final state",
               false, false, {}, nullptr, {{"200", "text/event-stream"}}, [](RouteContext& c) {
                 auto job = c.service.jobs().get(c.param(1));
                 stream_events(c, job, job->events(), [job] { return job->describe(); });
               }});
  r.push_back({"GET", "/api/v1/jobs/{jid}/files/{name}", "A file the job wrote (job files: the batch run's outputs)",
               false, false, {}, nullptr, {{"200", "the file"}, {"404", "unknown"}},
               [](RouteContext& c) { send_blob(c, c.service.job_file(c.param(1), c.param(2))); }});
}

}  // namespace levelset::api
