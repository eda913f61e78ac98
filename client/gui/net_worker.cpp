#include "net_worker.hpp"

#include <chrono>
#include <cstdio>

#include "core/error.hpp"
#include "lib/client_error.hpp"

namespace levelset::gui {

void Inbox::post(std::function<void(AppState&)> update) {
  std::lock_guard lock(mutex_);
  pending_.push_back(std::move(update));
}

void Inbox::apply(AppState& state) {
  std::vector<std::function<void(AppState&)>> now;
  {
    std::lock_guard lock(mutex_);
    now.swap(pending_);
  }
  for (auto& update : now) update(state);
}

void ApiHolder::set(std::shared_ptr<const client::Api> api) {
  std::lock_guard lock(mutex_);
  api_ = std::move(api);
}

std::shared_ptr<const client::Api> ApiHolder::get() const {
  std::lock_guard lock(mutex_);
  return api_;
}

Worker::Worker(std::string name) : name_(std::move(name)), thread_([this] { loop(); }) {}

Worker::~Worker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    tasks_.clear();
  }
  cv_.notify_all();
  thread_.join();
}

void Worker::post(std::function<void()> task) {
  {
    std::lock_guard lock(mutex_);
    tasks_.push_back(std::move(task));
    ++busy_;
  }
  cv_.notify_one();
}

void Worker::loop() {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock lock(mutex_);
      cv_.wait(lock, [this] { return stop_ || !tasks_.empty(); });
      if (stop_) return;
      task = std::move(tasks_.front());
      tasks_.pop_front();
    }
    try {
      task();
    } catch (const std::exception& e) {  // tasks report their own errors; this is a last resort
      std::fprintf(stderr, "levelset-gui: %s: %s\n", name_.c_str(), e.what());
    }
    --busy_;
  }
}

void sleep_unless(const std::atomic<bool>& stop, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!stop.load() && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

std::string describe_error(const std::exception& e) {
  if (const auto* c = dynamic_cast<const client::ClientError*>(&e)) {
    std::string text = c->code() + ": " + c->message();
    // A formula error's message repeats the formula with a caret line; the panel draws its own.
    const nlohmann::json& d = c->details();
    if (d.is_object() && d.contains("where") && d.contains("message") && d["where"].is_string() && d["message"].is_string())
      text = c->code() + ": " + d["where"].get<std::string>() + ": " + d["message"].get<std::string>();
    if (c->status() > 0) text += " (HTTP " + std::to_string(c->status()) + ")";
    return text;
  }
  if (const auto* l = dynamic_cast<const Error*>(&e)) return l->where() + ": " + l->reason();
  return e.what();
}

}  // namespace levelset::gui
