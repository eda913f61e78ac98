#include "lib/job_follow.hpp"

#include <chrono>
#include <thread>

#include "lib/client_error.hpp"
#include "lib/sse.hpp"

namespace levelset::client {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

bool job_ended(const std::string& state) {
  return state == "succeeded" || state == "failed" || state == "cancelled" || state == "interrupted";
}

json follow_job(const Api& api, const std::string& job_id, const FollowCallbacks& cb) {
  const std::string path = "/api/v1/jobs/" + Api::encode(job_id);
  std::string last_id = "0";  // from the job's first event: its whole log (the server's ring holds 1024)
  bool done = false;
  double failing_since = -1;  // seconds of consecutive connection failures
  auto started_failing = Clock::now();
  for (int attempt = 0;; ++attempt) {
    bool received = false;
    try {
      api.events(path + "/events", last_id, [&](const SseEvent& e) {
        received = true;
        if (!e.id.empty()) last_id = e.id;
        json data = json::parse(e.data, nullptr, false);
        if (e.type == "log" && data.is_object() && cb.on_log) {
          cb.on_log(data.value("line", ""));
        } else if (e.type == "progress" && data.is_object() && cb.on_progress) {
          cb.on_progress(data);
        } else if (e.type == "state" && data.is_object()) {
          if (cb.on_progress && data.contains("progress")) cb.on_progress(data["progress"]);
          if (job_ended(data.value("state", ""))) done = true;
        } else if (e.type == "done") {
          done = true;
        }
        return true;
      }, cb.stop);
      failing_since = -1;
      if (cb.stop != nullptr && cb.stop->load()) return nullptr;
    } catch (const ClientError& e) {
      if (e.kind() != ClientError::Kind::Connect) throw;
      if (received) failing_since = -1;
      if (failing_since < 0) {
        failing_since = 0;
        started_failing = Clock::now();
      }
      const double waited = std::chrono::duration<double>(Clock::now() - started_failing).count();
      if (waited >= cb.reconnect_seconds) throw;
      if (cb.on_notice) cb.on_notice("connection lost (" + e.message() + "); resuming after event " +
                                     last_id);
      std::this_thread::sleep_for(std::chrono::milliseconds(std::min(2000, 100 << std::min(attempt, 4))));
      if (cb.stop != nullptr && cb.stop->load()) return nullptr;
      continue;
    }
    // The stream ended: normally after the job's end; otherwise (a server restart reset the
    // event ids, a shutdown) the job's record says whether it ended.
    json job = api.get(path);
    if (done || job_ended(job.value("state", ""))) return job;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

void throw_unless_succeeded(const json& job) {
  const std::string state = job.value("state", "");
  if (state == "succeeded") return;
  if (state == "failed") throw ClientError::from_job_error(job.value("error", json()), state);
  std::string why = job.value("reason", "");
  throw ClientError(ClientError::Kind::Server, "job_" + state,
                    "job " + job.value("id", "") + " " + state + (why.empty() ? "" : ": " + why));
}

}  // namespace levelset::client
