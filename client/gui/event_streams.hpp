// EventStreams: the Server-Sent Event streams the window follows, each on its own thread: the
// shown session's events (its state, version changes, job states) and every running job's
// events (progress bars, the live log, the final state and error). A dropped stream resumes
// (Last-Event-ID) once the server answers again. Replacing or ending a stream never waits
// on the network: its thread is told to stop and is joined once it has ended (reap()).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "net_worker.hpp"

namespace levelset::gui {

class EventStreams {
 public:
  EventStreams(const ApiHolder& api, Inbox& inbox);
  ~EventStreams();  // stops every stream and joins (each notices within about a second)

  void watch_session(const std::string& id);  // "" for none
  // Runs on the job's stream thread once the job has succeeded, before its end reaches the
  // window (a follow-up request, e.g. storing the field it made as a region of influence).
  using JobThen = std::function<void(const client::Api& api, const nlohmann::json& job)>;
  void follow_job(const std::string& id, JobThen then = {});  // once per job id
  void reap();                                // joins the streams that have ended

 private:
  struct Stream {
    std::atomic<bool> stop{false}, done{false};
    std::thread thread;
  };
  void session_loop(Stream& self, std::string id);
  void job_loop(Stream& self, std::string id, const JobThen& then);
  const ApiHolder& api_;
  Inbox& inbox_;
  std::vector<std::unique_ptr<Stream>> streams_;
  Stream* session_ = nullptr;
  std::set<std::string> followed_;
};

}  // namespace levelset::gui
