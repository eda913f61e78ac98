#include "event_streams.hpp"

#include "lib/client_error.hpp"
#include "lib/job_follow.hpp"
#include "lib/sse.hpp"

namespace levelset::gui {

using nlohmann::json;

EventStreams::EventStreams(const ApiHolder& api, Inbox& inbox) : api_(api), inbox_(inbox) {}

EventStreams::~EventStreams() {
  for (auto& s : streams_) s->stop = true;
  for (auto& s : streams_) s->thread.join();
}

void EventStreams::watch_session(const std::string& id) {
  if (session_ != nullptr) session_->stop = true;
  session_ = nullptr;
  if (id.empty()) return;
  auto stream = std::make_unique<Stream>();
  Stream* raw = stream.get();
  stream->thread = std::thread([this, raw, id] {
    session_loop(*raw, id);
    raw->done = true;
  });
  session_ = raw;
  streams_.push_back(std::move(stream));
}

void EventStreams::follow_job(const std::string& id, JobThen then) {
  if (id.empty() || !followed_.insert(id).second) return;
  auto stream = std::make_unique<Stream>();
  Stream* raw = stream.get();
  stream->thread = std::thread([this, raw, id, then = std::move(then)] {
    job_loop(*raw, id, then);
    raw->done = true;
  });
  streams_.push_back(std::move(stream));
}

void EventStreams::reap() {
  for (auto it = streams_.begin(); it != streams_.end();) {
    if ((*it)->done) {
      (*it)->thread.join();
      it = streams_.erase(it);
    } else {
      ++it;
    }
  }
}

void EventStreams::session_loop(Stream& self, std::string id) {
  std::string last_id;
  const std::string path = "/api/v1/sessions/" + client::Api::encode(id) + "/events";
  while (!self.stop) {
    auto api = api_.get();
    try {
      if (api) api->events(path, last_id, [&](const client::SseEvent& e) {
        if (!e.id.empty()) last_id = e.id;
        json data = json::parse(e.data, nullptr, false);
        if (e.type == "roi" && (data.is_object() || data.is_null())) {  // stored or removed
          inbox_.post([id, data](AppState& s) {
            if (s.current == id && s.session.is_object()) s.session["roi"] = data;
          });
          return !self.stop;
        }
        if (!data.is_object()) return !self.stop;
        inbox_.post([id, type = e.type, data](AppState& s) {
          if (s.current != id) return;
          if (type == "state") s.session = data;
          if (type == "version" && s.session.is_object()) s.session["version"] = data.value("version", 0);
          if (type == "job") {
            for (JobRow& j : s.jobs)
              if (j.id == data.value("job", "")) j.state = data.value("state", j.state);
          }
        });
        return !self.stop;
      }, &self.stop);
    } catch (const client::ClientError& e) {
      if (e.kind() == client::ClientError::Kind::Server && e.status() == 404) {
        inbox_.post([id](AppState& s) {
          if (s.current == id) s.add_log("session " + id + " is gone");
        });
        return;
      }
      last_id.clear();  // a restarted daemon numbers its events anew: start from its state
    }
    sleep_unless(self.stop, 0.5);
  }
}

namespace {

void apply_job_end(AppState& s, const std::string& id, const json& job, const json& session) {
  const std::string state = job.value("state", "");
  if (s.select_after_job == id) {
    if (state == "succeeded" && session.is_object()) s.current = session.value("id", "");
    s.select_after_job.clear();
  }
  if (session.is_object() && session.value("id", "") == s.current) s.session = session;
  for (JobRow& j : s.jobs)
    if (j.id == id) {
      j.state = state;
      if (state == "succeeded") j.fraction = 1;
    }
  if (state == "failed" || (state != "succeeded" && job.value("error", json()).is_object())) {
    const json err = job.value("error", json::object());
    s.add_error("job " + id + " (" + job.value("op", "") + ") " + state + ": " + err.value("code", "") + ": " +
                err.value("message", ""));
  } else {
    s.add_log("job " + id + " (" + job.value("op", "") + ") " + state);
  }
}

}  // namespace

void EventStreams::job_loop(Stream& self, std::string id, const JobThen& then) {
  client::FollowCallbacks cb;
  cb.stop = &self.stop;
  cb.reconnect_seconds = 1e9;  // the connection monitor shows the banner; keep trying
  cb.on_log = [this, id](const std::string& line) { inbox_.post([line](AppState& s) { s.add_log(line); }); };
  cb.on_progress = [this, id](const json& p) {
    inbox_.post([id, p](AppState& s) {
      for (JobRow& j : s.jobs)
        if (j.id == id) {
          j.fraction = p.value("fraction", j.fraction);
          if (p.contains("stage") && p["stage"].is_string()) j.stage = p["stage"].get<std::string>();
        }
    });
  };
  try {
    auto api = api_.get();
    if (!api) return;
    const json job = client::follow_job(*api, id, cb);
    if (job.is_null()) return;
    if (then && job.value("state", "") == "succeeded") {
      try {
        then(*api, job);
      } catch (const std::exception& e) {
        inbox_.post([id, why = describe_error(e)](AppState& s) { s.add_error("after job " + id + ": " + why); });
      }
    }
    // The session the job changed or made, read now: the job's end and the version it made reach
    // the window together (the session's own stream may deliver the version a moment later).
    json session;
    const json result = job.value("result", json::object());
    std::string sid = job.value("session", json()).is_string() ? job["session"].get<std::string>() : "";
    if (result.is_object() && result.contains("session") && result["session"].is_string()) sid = result["session"];
    if (!sid.empty() && job.value("state", "") == "succeeded") {
      try {
        session = api->get("/api/v1/sessions/" + client::Api::encode(sid));
      } catch (const std::exception&) {  // the session stream brings it later
      }
    }
    inbox_.post([id, job, session](AppState& s) { apply_job_end(s, id, job, session); });
  } catch (const std::exception& e) {
    inbox_.post([id, why = describe_error(e)](AppState& s) { s.add_error("job " + id + ": " + why); });
  }
}

}  // namespace levelset::gui
