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

// ---- the runner -----------------------------------------------------------------------------

namespace {

// Links the upload ids named in a job file into its directory (inputs resolve there only).
void stage_job_file_uploads(const config::Set& set, const fs::path& uploads, const fs::path& work) {
  for (const config::Entry& e : set.entries) {
    if (e.is_set) {
      stage_job_file_uploads(e.set, uploads, work);
      continue;
    }
    if (!is_valid_id(e.value.text, 'u')) continue;
    std::error_code ec;
    if (!fs::exists(uploads / e.value.text, ec)) throw not_found("upload", e.value.text);
    fs::create_hard_link(uploads / e.value.text, work / e.value.text, ec);
    if (ec) fs::copy_file(uploads / e.value.text, work / e.value.text, fs::copy_options::overwrite_existing, ec);
  }
}

// A request resumed from a checkpoint asks only for what is left of its steps or time.
json remaining(json request, const json& state) {
  if (request.contains("steps") && request["steps"].is_number())
    request["steps"] = std::max(1, request["steps"].get<int>() - state.value("steps", 0));
  if (request.contains("time") && request["time"].is_number())
    request["time"] = std::max(1e-12, request["time"].get<double>() - state.value("time", 0.0));
  return request;
}

}  // namespace

void Service::run_job(Job& job) {
  std::shared_ptr<Session> session;
  if (!job.session_id().empty()) {
    try {
      session = sessions_->get(job.session_id());
    } catch (const ApiError& e) {
      job.set_state(JobState::Failed, {{"error", e.body()["error"]}});
      job.events().close();
      return;
    }
    if (job.cancel->cancelled()) {  // cancelled while it waited in the queue
      session->release(job.id());
      job.set_state(JobState::Cancelled, {{"reason", "cancelled before it ran"}});
      job.events().close();
      return;
    }
    if (!job.holds_session) {
      // Queued behind another job of the session ("queue": true): wait for it, cancellable.
      while (!session->claim(job.id())) {
        if (job.cancel->cancelled() || scheduler_->stopping()) {
          job.set_state(job.cancel->cancelled() ? JobState::Cancelled : JobState::Interrupted);
          return;
        }
        session->events().wait_after(session->events().last_id(), std::chrono::milliseconds(200));
      }
    }
  }
  const fs::path work = job_dir(job.id());
  std::error_code ec;
  fs::create_directories(work / "out", ec);
  job.set_state(JobState::Running);
  if (session) session->events().publish("job", {{"job", job.id()}, {"state", "running"}});

  const auto started = Clock::now();
  auto last_progress = Clock::now() - std::chrono::seconds(1), last_preview = last_progress;
  auto last_checkpoint = Clock::now();
  json checkpoint_base = {{"steps", 0}, {"time", 0.0}};
  std::shared_ptr<const NarrowBand> input = session ? session->band() : nullptr;
  json request = job.request();
  if (session) {
    if (auto cp = sessions_->load_checkpoint(*session, job.id())) {
      input = std::make_shared<const NarrowBand>(std::move(cp->first));
      checkpoint_base = cp->second;
      request = remaining(request, checkpoint_base);
      job.log("resumed from the checkpoint at step " + std::to_string(checkpoint_base.value("steps", 0)));
    }
  }

  OperationContext ctx;
  ctx.request = request;
  ctx.input = input;
  ctx.uploads_dir = uploads_->dir();
  ctx.work_dir = work;
  ctx.max_formula_length = config_.max_formula_length;
  ctx.max_domain_voxels = domain_budget();
  ctx.session_band_path = [this](const std::string& id) {
    auto other = sessions_->get(id);
    const fs::path p = other->dir() / ("operand-" + std::to_string(other->version()) + ".lsg");
    save_lsg(*other->band(), p);
    return p.string();
  };
  ctx.log = [&job](const std::string& line) { job.log(line); };
  ctx.progress.cancel = job.cancel;
  ctx.progress.stop = job.stop;
  ctx.progress.on_progress = [&](double fraction, std::string_view stage) {
    const auto now = Clock::now();
    if (now - last_progress < std::chrono::milliseconds(50)) return;
    last_progress = now;
    job.set_progress({{"fraction", fraction}, {"stage", std::string(stage)}});
  };
  // For progress only; the operation validates these (a string here is its 422, not ours).
  const int total_steps = request.contains("steps") && request["steps"].is_number() ? request["steps"].get<int>() : 0;
  const double total_time = request.contains("time") && request["time"].is_number() ? request["time"].get<double>() : 0.0;
  // Every evolution the operation runs reports its steps here (evolve::StepObserverScope):
  // previews for all of them; steps, time, ETA and checkpoints for the evolve op, whose steps
  // and time are the request's own (other applications evolve in chunks and levels).
  const bool stepwise = request.value("op", "") == "evolve";
  auto on_step = [&](const evolve::StepInfo& info) {
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - started).count();
    double fraction = total_steps > 0 ? double(info.step) / total_steps : total_time > 0 ? info.time / total_time : 0.0;
    fraction = std::min(1.0, fraction);
    if (!stepwise && now - last_progress >= std::chrono::milliseconds(50)) {
      last_progress = now;
      job.set_progress({{"dt", info.dt}, {"active_voxels", info.active_voxels}});
    }
    if (stepwise && now - last_progress >= std::chrono::milliseconds(50)) {
      last_progress = now;
      job.set_progress({{"fraction", fraction},
                        {"stage", "evolve"},
                        {"step", info.step + checkpoint_base.value("steps", 0)},
                        {"time", info.time + checkpoint_base.value("time", 0.0)},
                        {"dt", info.dt},
                        {"active_voxels", info.active_voxels},
                        {"eta_seconds", fraction > 0 ? json(elapsed * (1 - fraction) / fraction) : json(nullptr)}});
    }
    if (session && info.band != nullptr) {
      if (now - last_preview >= std::chrono::milliseconds(100)) {
        last_preview = now;
        sessions_->set_preview(*session, std::make_shared<const NarrowBand>(*info.band));
      }
      if (stepwise && config_.checkpoint_seconds > 0 &&
          now - last_checkpoint >= std::chrono::duration<double>(config_.checkpoint_seconds)) {
        last_checkpoint = now;
        sessions_->save_checkpoint(*session, job.id(), *info.band,
                                   {{"steps", info.step + checkpoint_base.value("steps", 0)},
                                    {"time", info.time + checkpoint_base.value("time", 0.0)}});
      }
    }
  };

  auto finish = [&] {
    if (session) {
      sessions_->clear_preview(*session);
      session->release(job.id());
      session->events().publish("job", {{"job", job.id()}, {"state", to_string(job.state())}});
    }
    job.events().close();
  };
  try {
    evolve::StepObserverScope observe(on_step);
    OperationResult r;
    if (request.value("op", "") == "job") {
      config::ParseOptions po;
      po.name = request.value("name", "job.conf");
      config::Set root = config::parse_config(request["config"].get<std::string>(), po);
      if (request.contains("set"))
        for (const json& s : request["set"]) config::set_override(root, s.get<std::string>());
      stage_job_file_uploads(root, uploads_->dir(), work);
      jobs::JobOptions o;
      o.output_dir = (work / "out").string();
      o.base_dir = work.string();
      o.name = po.name;
      o.confine_inputs = true;
      o.progress = ctx.progress;
      o.log = [&job](std::string_view line) { job.log(std::string(line)); };
      std::optional<NarrowBand> final_band;
      o.band_sink = [&final_band](const NarrowBand& b, std::string_view suffix) {
        if (suffix.empty()) final_band = b;
      };
      const jobs::JobResult jr = jobs::run_job(root, o);
      r.band = std::move(final_band);
      r.result = jr.stats;
      r.result.erase("outputs");
      for (const std::string& f : jr.outputs) r.files.push_back(fs::path(f).filename().string());
    } else {
      r = run_operation(ctx);
      for (const std::string& f : r.files) fs::rename(work / f, work / "out" / f, ec);
      r.stopped = job.stop->cancelled();
    }
    if (job.shutting_down && r.stopped) {
      // The shutdown stopped it: keep the state reached as a checkpoint, resumable.
      if (session && r.band && stepwise) {  // others resume from their start
        const int done = r.result.value("evolution", json::object()).value("steps", 0);
        const double t = r.result.value("evolution", json::object()).value("time", 0.0);
        sessions_->save_checkpoint(*session, job.id(), *r.band,
                                   {{"steps", done + checkpoint_base.value("steps", 0)},
                                    {"time", t + checkpoint_base.value("time", 0.0)}});
      }
      job.set_state(JobState::Interrupted, {{"reason", "the server shut down; POST .../resume continues"}});
      finish();
      return;
    }
    json result = r.result;
    result["files"] = r.files;
    result["stopped"] = r.stopped;
    if (r.band) {
      if (session) {
        result["version"] = sessions_->commit(*session, std::move(*r.band),
                                              {{"op", request.value("op", "")}, {"job", job.id()}, {"params", job.request()}});
        result["session"] = session->id();
      } else {
        const json& name = job.request().contains("name") ? job.request()["name"] : json();
        auto created = sessions_->create(config_.replica, name.is_string() ? name.get<std::string>() : "", std::move(*r.band),
                                         {{"job", job.id()}, {"params", job.request()}});
        result["session"] = created->id();
        result["version"] = 1;
      }
    }
    if (session) sessions_->drop_checkpoint(*session, job.id());
    json done = {{"fraction", 1.0}, {"stage", "done"}};
    if (result.contains("evolution")) {  // the exact end (step progress is published throttled)
      done["step"] = result["evolution"].value("steps", 0) + checkpoint_base.value("steps", 0);
      done["time"] = result["evolution"].value("time", 0.0) + checkpoint_base.value("time", 0.0);
    }
    job.set_progress(done);
    job.set_state(JobState::Succeeded,
                  {{"result", result}, {"seconds", std::chrono::duration<double>(Clock::now() - started).count()}});
    ++jobs_succeeded_;
  } catch (const Error& e) {
    if (e.code() == ErrorCode::Cancelled) {
      job.set_state(job.shutting_down ? JobState::Interrupted : JobState::Cancelled,
                    {{"reason", job.shutting_down ? "the server shut down" : "cancelled on request"}});
    } else {
      const ApiError api = ApiError::from_error(e);
      json error = api.body()["error"];
      error["status"] = api.status();
      job.set_state(JobState::Failed, {{"error", error}});
      ++jobs_failed_;
    }
  } catch (const ApiError& e) {
    json error = e.body()["error"];
    error["status"] = e.status();
    job.set_state(JobState::Failed, {{"error", error}});
    ++jobs_failed_;
  } catch (const std::exception& e) {
    job.set_state(JobState::Failed, {{"error", {{"code", "internal"}, {"message", e.what()}, {"details", json::object()}}}});
    ++jobs_failed_;
  }
  finish();
}

}  // namespace levelset::service
