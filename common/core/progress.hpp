// Progress reporting and cancellation for long operations.
//
// Every long operation takes a ProgressHook in its Options. The operation calls
// hook.step(fraction, stage) at coarse points (per brick batch, per phase); that reports
// progress and throws Error{Cancelled} if the token fired. Callbacks may come from any
// worker thread but never concurrently (the hook serialises them).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string_view>

namespace levelset {

class CancelToken {
 public:
  void cancel() noexcept { flag_.store(true, std::memory_order_relaxed); }
  bool cancelled() const noexcept { return flag_.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> flag_{false};
};

struct ProgressHook {
  // fraction in [0,1] of the current operation; stage names the phase ("bricks", "write").
  std::function<void(double fraction, std::string_view stage)> on_progress;
  std::shared_ptr<const CancelToken> cancel;
  // A gentler request than cancel: an evolution-like operation ends at its next step boundary
  // and returns the state it reached (the thesis's start / stop button; the daemon's
  // POST /jobs/{id}/stop). Operations without steps ignore it.
  std::shared_ptr<const CancelToken> stop;

  bool cancelled() const noexcept { return cancel && cancel->cancelled(); }
  bool stop_requested() const noexcept { return stop && stop->cancelled(); }
  // Reports progress (serialised) and throws Error{Cancelled} when the token fired.
  void step(double fraction, std::string_view stage) const;
  // Throws Error{Cancelled} when the token fired; cheap enough for inner batch loops.
  void check(std::string_view stage) const;

 private:
  mutable std::shared_ptr<std::mutex> mutex_ = std::make_shared<std::mutex>();
};

}  // namespace levelset
