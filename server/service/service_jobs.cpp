// Service: submitting, running, cancelling, stopping and resuming jobs.
#include <chrono>
#include <map>
#include <system_error>

#include "config/config_file.hpp"
#include "core/error.hpp"
#include "core/file_io.hpp"
#include "grid/lsg_file.hpp"
#include "evolve/speed.hpp"
#include "jobs/job.hpp"
#include "service/api_error.hpp"
#include "service/ids.hpp"
#include "service/operations.hpp"
#include "service/service.hpp"

namespace levelset::service {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

std::shared_ptr<Job> Service::make_job(const json& request, const std::string& session_id) {
  const std::string id = new_id(config_.replica, 'j');
  return std::make_shared<Job>(id, request, session_id, data_ / "jobs" / (id + ".json"));
}

namespace {

// A speed formula is compiled when the job is submitted, so a typo is a 400 with its column
// now, not a failed job later.
void check_formula(const json& body) {
  if (body.value("op", "") != "evolve" || !body.contains("speed") || !body["speed"].is_string()) return;
  std::map<std::string, double, std::less<>> constants;
  if (body.contains("constants") && body["constants"].is_object())
    for (const auto& [k, v] : body["constants"].items())
      if (v.is_number()) constants[k] = v.get<double>();
  try {
    (void)evolve::speed_from_text(body["speed"].get<std::string>(), body.value("c", 1.0), body.value("eps", 0.1), constants);
  } catch (const Error& e) {
    ApiError api = ApiError::from_error(Error(e.code(), "body.speed (" + e.where() + ")", e.reason()));
    // The column inside the formula, for clients that point at it (the viewer's caret).
    json details = api.details();
    details["field"] = "speed";
    const std::size_t at = e.where().find("column ");
    if (at != std::string::npos) details["column"] = std::atoi(e.where().c_str() + at + 7);
    const std::size_t newline = e.reason().find('\n');
    details["message"] = e.reason().substr(0, newline);
    throw ApiError(api.status(), api.code(), api.message(), details);
  }
}

// Queues the job (429 when full): 202 with its Location; a refused job gives its session back.
Reply enqueue(JobScheduler& scheduler, const std::shared_ptr<Job>& job, Session* session) {
  try {
    scheduler.submit(job);
  } catch (...) {
    if (session != nullptr) session->release(job->id());
    throw;
  }
  return {202, job->describe(), "/api/v1/jobs/" + job->id()};
}

}  // namespace

Reply Service::submit(const std::string& session_id, const json& body) {
  if (!body.is_object()) throw bad_request("expected a JSON object");
  if (!body.contains("op") || !body["op"].is_string()) throw bad_request("the body needs \"op\" (GET /api/v1 lists the operations)");
  const OperationInfo* op = find_operation(body["op"].get<std::string>());
  if (op == nullptr) throw unprocessable("body.op", "unknown operation '" + body["op"].get<std::string>().substr(0, 40) + "'");
  std::shared_ptr<Session> session;
  if (!session_id.empty()) {
    session = sessions_->get(session_id);
    if (op->kind == OperationInfo::Creates)
      throw unprocessable("body.op", "'" + op->name + "' creates a session: POST /api/v1/sessions with an upload");
  } else if (op->kind != OperationInfo::Creates) {
    throw unprocessable("body.op", "'" + op->name + "' works on a session: POST /api/v1/sessions/{id}/jobs");
  }
  check_formula(body);
  auto job = make_job(body, session_id);
  // The session is claimed at submission (a second job gets 409 at once), or, with
  // "queue": true, by the worker when the running job has ended.
  if (session) {
    if (session->claim(job->id())) {
      job->holds_session = true;
    } else if (!body.value("queue", false)) {
      throw ApiError(409, "session_busy", "job " + session->running_job() + " runs on session " + session_id +
                                              " (send \"queue\": true to wait for it)");
    }
  }
  return enqueue(*scheduler_, job, session.get());
}

Reply Service::submit_job_file(const json& body) {
  if (!body.is_object() || !body.contains("config") || !body["config"].is_string())
    throw bad_request("expected {\"config\": \"<job file text>\", \"set\": [\"a.b=v\", ...], \"name\": \"job.conf\"}");
  // Parse now, so a malformed job file is a 400 with its line and column, not a failed job.
  config::ParseOptions po;
  po.name = body.value("name", "job.conf");
  config::Set root = config::parse_config(body["config"].get<std::string>(), po);
  if (body.contains("set")) {
    if (!body["set"].is_array()) throw unprocessable("body.set", "expected an array of \"a.b=value\" strings");
    for (const json& s : body["set"]) {
      if (!s.is_string()) throw unprocessable("body.set", "expected strings");
      config::set_override(root, s.get<std::string>());
    }
  }
  json request = body;
  request["op"] = "job";
  auto job = make_job(request, "");
  scheduler_->submit(job);
  return {202, job->describe(), "/api/v1/jobs/" + job->id()};
}

json Service::list_jobs() const {
  json out = json::array();
  for (const auto& j : scheduler_->list()) {
    json d = j->describe();
    d.erase("params");
    out.push_back(d);
  }
  return {{"jobs", out}};
}

json Service::cancel(const std::string& job_id) {
  auto job = scheduler_->get(job_id);
  if (is_final(job->state())) throw conflict("job " + job_id + " already ended (" + to_string(job->state()) + ")");
  job->cancel->cancel();
  return job->describe();
}

json Service::stop(const std::string& job_id) {
  auto job = scheduler_->get(job_id);
  const OperationInfo* op = find_operation(job->request().value("op", ""));
  if (op == nullptr || !op->evolution_like)
    throw conflict("job " + job_id + " has no steps to stop at (only evolution-like operations stop; DELETE cancels)");
  if (is_final(job->state())) throw conflict("job " + job_id + " already ended (" + to_string(job->state()) + ")");
  job->stop->cancel();
  return job->describe();
}

Reply Service::resume(const std::string& job_id) {
  auto old = scheduler_->get(job_id);
  if (old->state() != JobState::Interrupted) throw conflict("job " + job_id + " is " + to_string(old->state()) + ", not interrupted");
  // The same job id runs again: from its checkpoint when one was saved, else from the start.
  auto job = std::make_shared<Job>(old->id(), old->request(), old->session_id(), data_ / "jobs" / (old->id() + ".json"));
  std::shared_ptr<Session> session;
  if (!old->session_id().empty()) {
    session = sessions_->get(old->session_id());
    if (!session->claim(job->id())) throw ApiError(409, "session_busy", "another job runs on the session");
    job->holds_session = true;
  }
  return enqueue(*scheduler_, job, session.get());
}

Blob Service::job_file(const std::string& job_id, const std::string& name) {
  scheduler_->get(job_id);
  if (name.empty() || name.size() > 200 || name.find('/') != std::string::npos || name[0] == '.')
    throw not_found("file", name);
  const fs::path path = job_dir(job_id) / "out" / name;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw not_found("file", name);
  Blob b;
  b.bytes = std::make_shared<const std::string>(read_file_bytes(path));
  b.content_type = "application/octet-stream";
  b.file_name = name;
  return b;
}


}  // namespace levelset::service
