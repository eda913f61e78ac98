#include "connection_monitor.hpp"

#include <algorithm>
#include <chrono>

#include "lib/client_error.hpp"
#include "lib/job_follow.hpp"

namespace levelset::gui {

using nlohmann::json;

ConnectionMonitor::ConnectionMonitor(const ApiHolder& api, Inbox& inbox, double period)
    : api_(api), inbox_(inbox), period_(period), thread_([this] { loop(); }) {}

ConnectionMonitor::~ConnectionMonitor() {
  stop_ = true;
  thread_.join();
}

namespace {

std::vector<JobRow> job_rows(const json& list) {
  std::vector<JobRow> rows;
  for (const json& j : list.value("jobs", json::array())) {
    JobRow r;
    r.id = j.value("id", "");
    r.op = j.value("op", "");
    r.session = j.value("session", json("")).is_string() ? j.value("session", "") : "";
    r.state = j.value("state", "");
    const json p = j.value("progress", json::object());
    r.fraction = p.is_object() ? p.value("fraction", 0.0) : 0.0;
    r.stage = p.is_object() && p.contains("stage") && p["stage"].is_string() ? p["stage"].get<std::string>() : "";
    rows.push_back(std::move(r));
  }
  return rows;
}

}  // namespace

bool ConnectionMonitor::poll_once(const client::Api& api) {
  try {
    api.get("/api/v1");
    json sessions = api.get("/api/v1/sessions").value("sessions", json::array());
    std::vector<JobRow> rows = job_rows(api.get("/api/v1/jobs"));
    inbox_.post([sessions = std::move(sessions), rows = std::move(rows)](AppState& s) mutable {
      if (!s.connected) s.add_log(s.ever_connected ? "reconnected to " + s.server : "connected to " + s.server);
      s.connected = s.ever_connected = true;
      s.banner.clear();
      s.sessions = std::move(sessions);
      // The list is the truth for states; SSE progress (newer) is kept for running jobs.
      for (JobRow& r : rows)
        for (const JobRow& old : s.jobs)
          if (old.id == r.id) {
            r.mine = old.mine;
            if (r.state == "running" && old.state == "running" && old.fraction > r.fraction) r.fraction = old.fraction;
          }
      // A job submitted here after the list was read is not in it yet: keep its row.
      for (const JobRow& old : s.jobs)
        if (old.mine && std::none_of(rows.begin(), rows.end(), [&](const JobRow& r) { return r.id == old.id; }))
          rows.push_back(old);
      s.jobs = std::move(rows);
    });
    return true;
  } catch (const std::exception& e) {
    // An HTTP answer (401, 403, 503 ...) means the server is there but refuses: say so, not
    // "connection lost"; both keep being retried (a token can be given, a server can come back).
    const auto* ce = dynamic_cast<const client::ClientError*>(&e);
    const bool refused = ce != nullptr && ce->kind() == client::ClientError::Kind::Server;
    inbox_.post([why = describe_error(e), refused](AppState& s) {
      const std::string banner = refused ? "The server " + s.server + " refuses this window (" + why +
                                               "): check the token (Sessions tab) and press Connect; retrying..."
                                         : "Connection lost to " + s.server + " (" + why + "); reconnecting...";
      if (s.connected || s.banner != banner) s.add_log(refused ? "refused: " + why : "connection lost: " + why);
      s.connected = false;
      s.banner = banner;
    });
    return false;
  }
}

void ConnectionMonitor::loop() {
  while (!stop_) {
    if (auto api = api_.get()) poll_once(*api);
    for (int i = 0; i < int(period_ / 0.05) && !stop_ && !poke_; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    poke_ = false;
  }
}

}  // namespace levelset::gui
