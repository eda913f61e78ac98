#include "lib/cancel_on_signal.hpp"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>

#include "lib/client_error.hpp"

namespace levelset::client {

namespace {

sigset_t handled() {
  sigset_t s;
  sigemptyset(&s);
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGUSR1}) sigaddset(&s, sig);
  return s;
}

}  // namespace

CancelOnSignal::CancelOnSignal(Api api) : api_(std::move(api)) {
  const sigset_t set = handled();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  waiter_ = std::thread([this, set] {
    int sig = 0;
    if (sigwait(&set, &sig) != 0 || sig == SIGUSR1) return;  // SIGUSR1: the destructor
    std::string job;
    {
      std::lock_guard lock(mutex_);
      job = job_;
    }
    if (!job.empty()) {
      try {
        api_.del("/api/v1/jobs/" + Api::encode(job));
        std::fprintf(stderr, "\nlevelsetctl: cancelled: job %s cancelled on signal %d\n", job.c_str(), sig);
      } catch (const ClientError& e) {
        std::fprintf(stderr, "\nlevelsetctl: %s: job %s not cancelled: %s\n", e.code().c_str(), job.c_str(),
                     e.message().c_str());
      }
    }
    std::fflush(stdout);
    std::fflush(stderr);
    ::_exit(128 + sig);
  });
}

CancelOnSignal::~CancelOnSignal() {
  pthread_kill(waiter_.native_handle(), SIGUSR1);
  waiter_.join();
  const sigset_t set = handled();
  pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
}

void CancelOnSignal::arm(const std::string& job_id) {
  std::lock_guard lock(mutex_);
  job_ = job_id;
}

}  // namespace levelset::client
