// Jobs and their scheduler. A Job is one operation request with its state machine
//   queued -> running -> succeeded | failed | cancelled | interrupted (cut off by a crash or a
//   shutdown; resume queues it again), its progress, result or error, its cancel and stop
// tokens and its event log. The JobScheduler runs at most `workers` jobs at once, each in its
// own TBB arena, from a FIFO of at most `max_queued` (ApiError 429 beyond; 503 once stopping).
// The journal (DATA/jobs/<id>.json, rewritten atomically at every state change) lets a restart
// mark cut-off jobs interrupted. Threading: all members thread-safe.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.hpp"
#include "service/event_log.hpp"

namespace levelset::service {

enum class JobState { Queued, Running, Succeeded, Failed, Cancelled, Interrupted };
std::string to_string(JobState state);
bool is_final(JobState state);

class Job {
 public:
  Job(std::string id, nlohmann::json request, std::string session_id, std::filesystem::path journal);

  const std::string& id() const { return id_; }
  const std::string& session_id() const { return session_id_; }
  const nlohmann::json& request() const { return request_; }
  JobState state() const;
  nlohmann::json describe() const;
  EventLog& events() { return events_; }

  // Transitions (each rewrites the journal and publishes a "state" event).
  void set_state(JobState state, nlohmann::json extra = nlohmann::json::object());
  void set_progress(nlohmann::json progress);  // merged into "progress"; published (coalesced by readers)
  void log(const std::string& line);

  std::shared_ptr<CancelToken> cancel = std::make_shared<CancelToken>();
  std::shared_ptr<CancelToken> stop = std::make_shared<CancelToken>();
  std::atomic<bool> shutting_down{false};  // a stop from the shutdown: end as interrupted
  std::atomic<bool> holds_session{false};  // claimed its session at submission

  static std::shared_ptr<Job> from_journal(const std::filesystem::path& journal);  // Error if unreadable

 private:
  void persist();  // under mutex_
  mutable std::mutex mutex_;
  std::string id_, session_id_;
  nlohmann::json request_;
  std::filesystem::path journal_;
  nlohmann::json record_;
  EventLog events_;
};

class JobScheduler {
 public:
  using Runner = std::function<void(Job& job)>;
  JobScheduler(int workers, int max_queued, int threads_per_job, Runner runner);
  ~JobScheduler();

  void submit(const std::shared_ptr<Job>& job);
  void adopt(const std::shared_ptr<Job>& job);  // known (journal) but not queued
  std::shared_ptr<Job> get(const std::string& id) const;  // ApiError 404
  std::vector<std::shared_ptr<Job>> list() const;
  int running() const;
  int queued() const;
  bool stopping() const;

  // Stops taking jobs, asks running ones to stop (shutting_down) and waits for the workers
  // until `deadline`; then cancels what remains.
  void shutdown(std::chrono::steady_clock::time_point deadline);

 private:
  void work();

  int max_queued_, threads_per_job_;
  Runner runner_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<std::shared_ptr<Job>> queue_;
  std::map<std::string, std::shared_ptr<Job>> jobs_;
  int running_ = 0;
  bool stopping_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace levelset::service
