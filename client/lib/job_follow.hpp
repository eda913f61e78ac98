// follow_job: follows GET /api/v1/jobs/{jid}/events (Server-Sent Events) to the job's end and
// returns its final description (GET /api/v1/jobs/{jid}). It asks for the events after id 0, so
// the whole log comes, also what the job said before the stream opened. A dropped connection is resumed with
// Last-Event-ID (the server replays what came after it); connection failures are retried for
// `reconnect_seconds` in all before ClientError{Connect}. A job that already ended answers at
// once. The caller decides what a final state means (succeeded or not).
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "lib/api.hpp"

namespace levelset::client {

struct FollowCallbacks {
  std::function<void(const std::string& line)> on_log;             // "log" events
  std::function<void(const nlohmann::json& progress)> on_progress;  // "progress" events and the state's
  std::function<void(const std::string& message)> on_notice;        // reconnects
  double reconnect_seconds = 60;
  // Set by another thread to end the follow early (checked at every chunk, keep-alives included,
  // so within about a second); follow_job then returns null.
  const std::atomic<bool>* stop = nullptr;
};

bool job_ended(const std::string& state);  // succeeded failed cancelled interrupted

nlohmann::json follow_job(const Api& api, const std::string& job_id, const FollowCallbacks& callbacks);

// The exit of a job for a CLI: nothing when it succeeded, else the ClientError of its end.
void throw_unless_succeeded(const nlohmann::json& job);

}  // namespace levelset::client
