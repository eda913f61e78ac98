#include "service/job_scheduler.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "service/api_error.hpp"
#include "service/ids.hpp"

namespace levelset::service {

using nlohmann::json;

std::string to_string(JobState s) {
  switch (s) {
    case JobState::Queued: return "queued";
    case JobState::Running: return "running";
    case JobState::Succeeded: return "succeeded";
    case JobState::Failed: return "failed";
    case JobState::Cancelled: return "cancelled";
    case JobState::Interrupted: return "interrupted";
  }
  return "?";
}

bool is_final(JobState s) { return s == JobState::Succeeded || s == JobState::Failed || s == JobState::Cancelled; }

namespace {
JobState state_from(const std::string& s) {
  for (JobState st : {JobState::Queued, JobState::Running, JobState::Succeeded, JobState::Failed, JobState::Cancelled,
                      JobState::Interrupted})
    if (to_string(st) == s) return st;
  return JobState::Interrupted;
}
}  // namespace

Job::Job(std::string id, json request, std::string session_id, std::filesystem::path journal)
    : id_(std::move(id)), session_id_(std::move(session_id)), request_(std::move(request)), journal_(std::move(journal)) {
  record_ = {{"id", id_},
             {"state", "queued"},
             {"op", request_.value("op", request_.contains("config") ? "job" : "?")},
             {"session", session_id_.empty() ? json(nullptr) : json(session_id_)},
             {"request", request_},
             {"created", now_iso()},
             {"progress", {{"fraction", 0.0}, {"stage", "queued"}}},
             {"result", nullptr},
             {"error", nullptr}};
}

std::shared_ptr<Job> Job::from_journal(const std::filesystem::path& journal) {
  json j = json::parse(read_file_bytes(journal, 64 << 20), nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("id"))
    throw Error(ErrorCode::Corrupt, journal.string(), "not a job record");
  auto job = std::make_shared<Job>(j["id"].get<std::string>(), j.value("request", json::object()),
                                   j["session"].is_string() ? j["session"].get<std::string>() : "", journal);
  job->record_ = std::move(j);
  return job;
}

JobState Job::state() const {
  std::lock_guard lock(mutex_);
  return state_from(record_.value("state", "interrupted"));
}

json Job::describe() const {
  std::lock_guard lock(mutex_);
  json j = record_;
  j.erase("request");
  j["params"] = request_;
  return j;
}

void Job::persist() {
  try {
    write_file_atomically(journal_, record_.dump(1, ' ', false, json::error_handler_t::replace));
  } catch (const Error&) {
    // A journal that cannot be written (disk full) must not take the job down with it.
  }
}

void Job::set_state(JobState state, json extra) {
  json event;
  {
    std::lock_guard lock(mutex_);
    record_["state"] = to_string(state);
    const std::string now = now_iso();
    if (state == JobState::Running) record_["started"] = now;
    if (is_final(state) || state == JobState::Interrupted) record_["finished"] = now;
    for (auto& [k, v] : extra.items()) record_[k] = v;
    persist();
    event = record_;
    event.erase("request");
  }
  events_.publish("state", event);
  if (is_final(state) || state == JobState::Interrupted) events_.publish("done", {{"state", to_string(state)}});
}

void Job::set_progress(json progress) {
  json p;
  {
    std::lock_guard lock(mutex_);
    for (auto& [k, v] : progress.items()) record_["progress"][k] = v;
    p = record_["progress"];
  }
  events_.publish("progress", p);
}

void Job::log(const std::string& line) { events_.publish("log", {{"line", line}}); }

// ---- JobScheduler ---------------------------------------------------------------------------

namespace {

// Threads computing a job run at a lower priority (nice 5) while they are in its arena, so the
// HTTP threads (nice 0) answer at once even when a job keeps every core busy.
class BackgroundPriority : public tbb::task_scheduler_observer {
 public:
  explicit BackgroundPriority(tbb::task_arena& arena) : tbb::task_scheduler_observer(arena) { observe(true); }
  ~BackgroundPriority() override { observe(false); }
  void on_scheduler_entry(bool) override { set_nice(5); }
  void on_scheduler_exit(bool) override { set_nice(0); }

 private:
  static void set_nice(int value) {
    // Per thread on Linux: setpriority on the thread id.
    ::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), value);
  }
};

}  // namespace

JobScheduler::JobScheduler(int workers, int max_queued, int threads_per_job, Runner runner)
    : max_queued_(max_queued), threads_per_job_(std::max(1, threads_per_job)), runner_(std::move(runner)) {
  for (int i = 0; i < std::max(1, workers); ++i) workers_.emplace_back([this] { work(); });
}

JobScheduler::~JobScheduler() { shutdown(std::chrono::steady_clock::now()); }

void JobScheduler::submit(const std::shared_ptr<Job>& job) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) throw ApiError(503, "shutting_down", "the server is shutting down");
    if (int(queue_.size()) >= max_queued_)
      throw ApiError(429, "too_many_jobs", "the job queue is full (" + std::to_string(queue_.size()) + " waiting, max_queued_jobs)");
    queue_.push_back(job);
    jobs_[job->id()] = job;
  }
  job->set_state(JobState::Queued);
  wake_.notify_one();
}

void JobScheduler::adopt(const std::shared_ptr<Job>& job) {
  std::lock_guard lock(mutex_);
  jobs_[job->id()] = job;
}

std::shared_ptr<Job> JobScheduler::get(const std::string& id) const {
  std::lock_guard lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) throw not_found("job", id);
  return it->second;
}

std::vector<std::shared_ptr<Job>> JobScheduler::list() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<Job>> out;
  for (const auto& [id, j] : jobs_) out.push_back(j);
  return out;
}

int JobScheduler::running() const {
  std::lock_guard lock(mutex_);
  return running_;
}

int JobScheduler::queued() const {
  std::lock_guard lock(mutex_);
  return int(queue_.size());
}

bool JobScheduler::stopping() const {
  std::lock_guard lock(mutex_);
  return stopping_;
}

void JobScheduler::work() {
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job = queue_.front();
      queue_.pop_front();
      ++running_;
    }
    tbb::task_arena arena(threads_per_job_);
    arena.initialize();
    BackgroundPriority priority(arena);
    arena.execute([&] { runner_(*job); });
    {
      std::lock_guard lock(mutex_);
      --running_;
    }
    idle_.notify_all();
  }
}

void JobScheduler::shutdown(std::chrono::steady_clock::time_point deadline) {
  std::vector<std::shared_ptr<Job>> all;
  {
    std::lock_guard lock(mutex_);
    if (workers_.empty()) return;
    stopping_ = true;
    for (const auto& [id, j] : jobs_) all.push_back(j);
    // Queued jobs never started: interrupted, to be resumed after the restart.
    for (const auto& j : queue_) j->set_state(JobState::Interrupted, {{"reason", "the server stopped before it ran"}});
    queue_.clear();
  }
  wake_.notify_all();
  for (const auto& j : all) {
    if (j->state() != JobState::Running) continue;
    j->shutting_down = true;
    j->stop->cancel();
  }
  // Wait for running jobs to reach a step boundary; past the deadline, cancel them.
  {
    std::unique_lock lock(mutex_);
    idle_.wait_until(lock, deadline, [&] { return running_ == 0; });
  }
  for (const auto& j : all)
    if (j->state() == JobState::Running) j->cancel->cancel();
  for (std::thread& t : workers_) t.join();
  workers_.clear();
}

}  // namespace levelset::service
