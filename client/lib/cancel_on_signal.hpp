// CancelOnSignal: while alive, SIGINT / SIGTERM / SIGHUP cancel the job set with arm() on the
// server (DELETE /api/v1/jobs/{jid}) and end the process with 128 + the signal. For commands that
// own their job (`run`): a workflow system killing the client must not leave the job running.
// Construct it on the main thread before any other thread starts (the signals are blocked there
// and taken by a sigwait thread). Threading: arm() from any thread.
#pragma once

#include <atomic>
#include <mutex>
#include <string>
#include <thread>

#include "lib/api.hpp"

namespace levelset::client {

class CancelOnSignal {
 public:
  explicit CancelOnSignal(Api api);
  ~CancelOnSignal();
  CancelOnSignal(const CancelOnSignal&) = delete;
  CancelOnSignal& operator=(const CancelOnSignal&) = delete;

  void arm(const std::string& job_id);

 private:
  Api api_;
  std::mutex mutex_;
  std::string job_;
  std::thread waiter_;
};

}  // namespace levelset::client
