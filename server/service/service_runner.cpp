// Service::run_job: one job from its worker's start to its final state, in steps: claim the
// session, load a checkpoint, run the operation (or the job file) with progress, previews and
// checkpoints, then commit the result or record why not.
#include <chrono>
#include <optional>
#include <system_error>

#include "config/config_file.hpp"
#include "core/error.hpp"
#include "grid/lsg_file.hpp"
#include "jobs/job.hpp"
#include "service/api_error.hpp"
#include "service/ids.hpp"
#include "service/operations.hpp"
#include "service/service.hpp"

namespace levelset::service {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

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

class Service::JobRun {
 public:
  JobRun(Service& service, Job& job) : svc_(service), job_(job), work_(service.job_dir(job.id())) {}

  void run() {
    if (!acquire_session()) return;
    std::error_code ec;
    fs::create_directories(work_ / "out", ec);
    job_.set_state(JobState::Running);
    if (session_) session_->events().publish("job", {{"job", job_.id()}, {"state", "running"}});
    load_checkpoint();
    try {
      evolve::StepObserverScope observe([this](const evolve::StepInfo& info) { on_step(info); });
      OperationResult r = request_.value("op", "") == "job" ? run_job_file() : run_op();
      if (job_.shutting_down && r.stopped) {
        interrupted_by_shutdown(r);
      } else {
        succeed(std::move(r));
      }
    } catch (const Error& e) {
      if (e.code() == ErrorCode::Cancelled) {
        job_.set_state(job_.shutting_down ? JobState::Interrupted : JobState::Cancelled,
                       {{"reason", job_.shutting_down ? "the server shut down" : "cancelled on request"}});
      } else {
        const ApiError api = ApiError::from_error(e);
        fail(api.body()["error"], api.status());
      }
    } catch (const ApiError& e) {
      fail(e.body()["error"], e.status());
    } catch (const std::exception& e) {
      fail({{"code", "internal"}, {"message", e.what()}, {"details", json::object()}}, 500);
    }
    finish();
  }

 private:
  // The job's session: claimed at submission, or (queued with "queue": true) now. False when
  // the job ended here (its session is gone, or it was cancelled while it waited).
  bool acquire_session() {
    if (job_.session_id().empty()) return true;
    try {
      session_ = svc_.sessions_->get(job_.session_id());
    } catch (const ApiError& e) {
      job_.set_state(JobState::Failed, {{"error", e.body()["error"]}});
      job_.events().close();
      return false;
    }
    if (job_.cancel->cancelled()) {
      session_->release(job_.id());
      job_.set_state(JobState::Cancelled, {{"reason", "cancelled before it ran"}});
      job_.events().close();
      return false;
    }
    while (!job_.holds_session && !session_->claim(job_.id())) {
      if (job_.cancel->cancelled() || svc_.scheduler_->stopping()) {
        job_.set_state(job_.cancel->cancelled() ? JobState::Cancelled : JobState::Interrupted);
        job_.events().close();
        return false;
      }
      session_->events().wait_after(session_->events().last_id(), std::chrono::milliseconds(200));
    }
    return true;
  }

  // A resumed job starts from its checkpoint and asks only for what is left.
  void load_checkpoint() {
    input_ = session_ ? session_->band() : nullptr;
    request_ = job_.request();
    if (!session_) return;
    if (auto cp = svc_.sessions_->load_checkpoint(*session_, job_.id())) {
      input_ = std::make_shared<const NarrowBand>(std::move(cp->first));
      base_ = cp->second;
      request_ = remaining(request_, base_);
      job_.log("resumed from the checkpoint at step " + std::to_string(base_.value("steps", 0)));
    }
    stepwise_ = request_.value("op", "") == "evolve";
    // For progress only; the operation validates these (a string here is its 422, not ours).
    total_steps_ = request_.contains("steps") && request_["steps"].is_number() ? request_["steps"].get<int>() : 0;
    total_time_ = request_.contains("time") && request_["time"].is_number() ? request_["time"].get<double>() : 0.0;
  }

  ProgressHook progress() {
    ProgressHook p;
    p.cancel = job_.cancel;
    p.stop = job_.stop;
    p.on_progress = [this](double fraction, std::string_view stage) {
      if (!throttle(last_progress_, 50)) return;
      job_.set_progress({{"fraction", fraction}, {"stage", std::string(stage)}});
    };
    return p;
  }

  // Every evolution the operation runs reports its steps here: previews for all of them;
  // steps, time, ETA and checkpoints for the evolve op, whose steps and time are the
  // request's own (other applications evolve in chunks and levels).
  void on_step(const evolve::StepInfo& info) {
    const int step = info.step + base_.value("steps", 0);
    const double time = info.time + base_.value("time", 0.0);
    if (throttle(last_progress_, 50)) {
      if (stepwise_) {
        double f = total_steps_ > 0 ? double(info.step) / total_steps_ : total_time_ > 0 ? info.time / total_time_ : 0.0;
        f = std::min(1.0, f);
        const double elapsed = std::chrono::duration<double>(Clock::now() - started_).count();
        job_.set_progress({{"fraction", f}, {"stage", "evolve"}, {"step", step}, {"time", time}, {"dt", info.dt},
                           {"active_voxels", info.active_voxels},
                           {"eta_seconds", f > 0 ? json(elapsed * (1 - f) / f) : json(nullptr)}});
      } else {
        job_.set_progress({{"dt", info.dt}, {"active_voxels", info.active_voxels}});
      }
    }
    if (!session_ || info.band == nullptr) return;
    if (throttle(last_preview_, 100)) svc_.sessions_->set_preview(*session_, std::make_shared<const NarrowBand>(*info.band));
    const auto every = std::chrono::duration<double>(svc_.config_.checkpoint_seconds);
    if (stepwise_ && svc_.config_.checkpoint_seconds > 0 && Clock::now() - last_checkpoint_ >= every) {
      last_checkpoint_ = Clock::now();
      svc_.sessions_->save_checkpoint(*session_, job_.id(), *info.band, {{"steps", step}, {"time", time}});
    }
  }

  static bool throttle(Clock::time_point& last, int ms) {
    const auto now = Clock::now();
    if (now - last < std::chrono::milliseconds(ms)) return false;
    last = now;
    return true;
  }

  OperationResult run_op() {
    OperationContext ctx;
    ctx.request = request_;
    ctx.input = input_;
    if (session_) {  // fields for speed formulas: the session's cloud (dist, dgx..) and ROI (roi)
      ctx.points = session_->points();
      ctx.roi = session_->roi();
    }
    ctx.uploads_dir = svc_.uploads_->dir();
    ctx.work_dir = work_;
    ctx.max_formula_length = svc_.config_.max_formula_length;
    ctx.max_domain_voxels = svc_.domain_budget();
    ctx.session_band_path = [this](const std::string& id) {
      auto other = svc_.sessions_->get(id);
      const fs::path p = other->dir() / ("operand-" + std::to_string(other->version()) + ".lsg");
      save_lsg(*other->band(), p);
      return p.string();
    };
    ctx.log = [this](const std::string& line) { job_.log(line); };
    ctx.progress = progress();
    OperationResult r = run_operation(ctx);
    std::error_code ec;
    for (const std::string& f : r.files) fs::rename(work_ / f, work_ / "out" / f, ec);
    r.stopped = job_.stop->cancelled();
    return r;
  }

  // A whole job file, run confined to the job's directory; its outputs are the batch run's.
  OperationResult run_job_file() {
    config::ParseOptions po;
    po.name = request_.value("name", "job.conf");
    config::Set root = config::parse_config(request_["config"].get<std::string>(), po);
    if (request_.contains("set"))
      for (const json& s : request_["set"]) config::set_override(root, s.get<std::string>());
    stage_job_file_uploads(root, svc_.uploads_->dir(), work_);
    jobs::JobOptions o;
    o.output_dir = (work_ / "out").string();
    o.base_dir = work_.string();
    o.name = po.name;
    o.confine_inputs = true;
    o.progress = progress();
    o.log = [this](std::string_view line) { job_.log(std::string(line)); };
    std::optional<NarrowBand> final_band;
    o.band_sink = [&final_band](const NarrowBand& b, std::string_view suffix) {
      if (suffix.empty()) final_band = b;
    };
    const jobs::JobResult jr = jobs::run_job(root, o);
    OperationResult r;
    r.band = std::move(final_band);
    r.result = jr.stats;
    r.result.erase("outputs");
    for (const std::string& f : jr.outputs) r.files.push_back(fs::path(f).filename().string());
    return r;
  }

  // Stopped by the shutdown: the state reached becomes a checkpoint (evolve jobs; others
  // resume from their start), the job is interrupted.
  void interrupted_by_shutdown(const OperationResult& r) {
    if (session_ && r.band && stepwise_) {
      const json evolution = r.result.value("evolution", json::object());
      svc_.sessions_->save_checkpoint(*session_, job_.id(), *r.band,
                                      {{"steps", evolution.value("steps", 0) + base_.value("steps", 0)},
                                       {"time", evolution.value("time", 0.0) + base_.value("time", 0.0)}});
    }
    job_.set_state(JobState::Interrupted, {{"reason", "the server shut down; POST .../resume continues"}});
  }

  void succeed(OperationResult r) {
    json result = r.result;
    result["files"] = r.files;
    result["stopped"] = r.stopped;
    if (r.band && session_) {
      result["version"] = svc_.sessions_->commit(*session_, std::move(*r.band),
                                                 {{"op", request_.value("op", "")}, {"job", job_.id()}, {"params", job_.request()}});
      result["session"] = session_->id();
    } else if (r.band) {
      const json name = job_.request().contains("name") ? job_.request()["name"] : json();
      auto created = svc_.sessions_->create(svc_.config_.replica, name.is_string() ? name.get<std::string>() : "",
                                            std::move(*r.band), {{"job", job_.id()}, {"params", job_.request()}});
      result["session"] = created->id();
      result["version"] = 1;
      show_input_points(*created);
    }
    if (session_) svc_.sessions_->drop_checkpoint(*session_, job_.id());
    json done = {{"fraction", 1.0}, {"stage", "done"}};
    if (result.contains("evolution")) {  // the exact end (step progress is published throttled)
      done["step"] = result["evolution"].value("steps", 0) + base_.value("steps", 0);
      done["time"] = result["evolution"].value("time", 0.0) + base_.value("time", 0.0);
    }
    job_.set_progress(done);
    job_.set_state(JobState::Succeeded,
                   {{"result", result}, {"seconds", std::chrono::duration<double>(Clock::now() - started_).count()}});
    ++svc_.jobs_succeeded_;
  }

  // A session made from a point upload (reconstruct) shows those points in its frames.
  void show_input_points(Session& created) {
    const json input = job_.request().value("input", json::object());
    if (!input.is_object() || !input.contains("points") || !input["points"].is_string()) return;
    try {
      svc_.attach_points(created, input["points"].get<std::string>(), "input.points");
    } catch (const std::exception& e) {  // the session stands without its cloud
      job_.log(std::string("warning: the point cloud is not kept with the session: ") + e.what());
    }
  }

  void fail(json error, int status) {
    error["status"] = status;
    job_.set_state(JobState::Failed, {{"error", error}});
    ++svc_.jobs_failed_;
  }

  void finish() {
    if (session_) {
      svc_.sessions_->clear_preview(*session_);
      session_->release(job_.id());
      session_->events().publish("job", {{"job", job_.id()}, {"state", to_string(job_.state())}});
    }
    job_.events().close();
  }

  Service& svc_;
  Job& job_;
  const fs::path work_;
  std::shared_ptr<Session> session_;
  std::shared_ptr<const NarrowBand> input_;
  json request_, base_ = {{"steps", 0}, {"time", 0.0}};
  bool stepwise_ = false;
  int total_steps_ = 0;
  double total_time_ = 0;
  const Clock::time_point started_ = Clock::now();
  Clock::time_point last_progress_ = started_ - std::chrono::seconds(1), last_preview_ = last_progress_;
  Clock::time_point last_checkpoint_ = started_;
};

void Service::run_job(Job& job) { JobRun(*this, job).run(); }

}  // namespace levelset::service
