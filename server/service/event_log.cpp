#include "service/event_log.hpp"

namespace levelset::service {

std::uint64_t EventLog::publish(std::string type, nlohmann::json data) {
  std::uint64_t id;
  {
    std::lock_guard lock(mutex_);
    id = next_id_++;
    events_.push_back({id, std::move(type), std::move(data)});
    while (events_.size() > capacity_) events_.pop_front();
  }
  changed_.notify_all();
  return id;
}

EventBatch EventLog::wait_after(std::uint64_t after, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return closed_ || next_id_ - 1 > after; });
  EventBatch batch;
  batch.closed = closed_;
  if (!events_.empty() && events_.front().id > after + 1) batch.missed = true;
  for (const Event& e : events_)
    if (e.id > after) batch.events.push_back(e);
  return batch;
}

void EventLog::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

std::uint64_t EventLog::last_id() const {
  std::lock_guard lock(mutex_);
  return next_id_ - 1;
}

bool EventLog::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

}  // namespace levelset::service
