// ConnectionMonitor: one thread that asks the server for GET /api/v1 every `period` seconds
// (and, when it answers, the session and job lists). A failure shows the banner ("connection
// lost ... reconnecting", or "refuses" for an HTTP error such as 401); the next answer clears
// it. It keeps trying for as long as it runs, so a restarted daemon is found again without the
// user doing anything.
#pragma once

#include <atomic>
#include <thread>

#include "net_worker.hpp"

namespace levelset::gui {

class ConnectionMonitor {
 public:
  ConnectionMonitor(const ApiHolder& api, Inbox& inbox, double period = 0.5);
  ~ConnectionMonitor();
  void poke() { poke_ = true; }  // ask again now (after a connect)

 private:
  void loop();
  bool poll_once(const client::Api& api);
  const ApiHolder& api_;
  Inbox& inbox_;
  double period_;
  std::atomic<bool> stop_{false}, poke_{false};
  std::thread thread_;
};

}  // namespace levelset::gui
