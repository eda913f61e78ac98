// The UI thread never waits on the network: requests run on Worker threads (one queue each, in
// order) and their results come back as closures through the Inbox, applied by the UI thread
// at the start of a frame. ApiHolder hands every thread the current server (it can change).
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "app_state.hpp"
#include "lib/api.hpp"

namespace levelset::gui {

class Inbox {
 public:
  void post(std::function<void(AppState&)> update);
  void apply(AppState& state);  // UI thread
 private:
  std::mutex mutex_;
  std::vector<std::function<void(AppState&)>> pending_;
};

class ApiHolder {
 public:
  void set(std::shared_ptr<const client::Api> api);
  std::shared_ptr<const client::Api> get() const;  // null before the first connect
 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const client::Api> api_;
};

class Worker {
 public:
  explicit Worker(std::string name);
  ~Worker();  // finishes the task in progress, drops the rest
  void post(std::function<void()> task);
  bool idle() const { return busy_.load() == 0; }

 private:
  void loop();
  std::string name_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> tasks_;
  std::atomic<int> busy_{0};
  bool stop_ = false;
  std::thread thread_;
};

// Sleeps up to `seconds` unless `stop` is set (checked every 50 ms): background threads wait
// between retries without delaying shutdown much.
void sleep_unless(const std::atomic<bool>& stop, double seconds);

// A readable line for an exception from a request: "CODE: MESSAGE" of the server, or the text.
std::string describe_error(const std::exception& e);

}  // namespace levelset::gui
