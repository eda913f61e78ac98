// EventLog: the ordered events of one job or session (progress, log lines, measures, version
// changes, the final state), kept in a bounded ring for Server-Sent Event readers.
//
// publish() is called by the job's thread; readers (one per open SSE stream) call wait_after()
// with the last id they sent and a timeout, so a stream never blocks a pool thread for longer
// than the timeout (the server's stop() must finish). Ids increase from 1; an id that fell out
// of the ring is reported through `missed` so the reader can send the current state first.
// Threading: all members thread-safe.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace levelset::service {

struct Event {
  std::uint64_t id = 0;
  std::string type;  // "progress", "log", "state", "version", "measures", "done"
  nlohmann::json data;
};

struct EventBatch {
  std::vector<Event> events;
  bool missed = false;  // events after `after` were dropped from the ring
  bool closed = false;  // the log ends here (its job finished)
};

class EventLog {
 public:
  explicit EventLog(std::size_t capacity = 1024) : capacity_(capacity) {}

  std::uint64_t publish(std::string type, nlohmann::json data);
  EventBatch wait_after(std::uint64_t after, std::chrono::milliseconds timeout) const;
  void close();
  std::uint64_t last_id() const;
  bool closed() const;

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::deque<Event> events_;
  std::size_t capacity_;
  std::uint64_t next_id_ = 1;
  bool closed_ = false;
};

}  // namespace levelset::service
