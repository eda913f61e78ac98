#include "api/route.hpp"

#include <chrono>
#include <thread>

#include "service/api_error.hpp"

namespace levelset::api {

using nlohmann::json;
using service::ApiError;

json RouteContext::body() const {
  if (body_text.empty()) return json::object();
  try {
    return json::parse(body_text);
  } catch (const json::out_of_range& e) {  // a number beyond double's range (1e999)
    throw ApiError(400, "malformed_json", std::string("the body has a number out of range: ") + e.what());
  } catch (const json::parse_error& e) {
    // Line and column of the byte where parsing stopped.
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < body_text.size(); ++i) {
      if (body_text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    throw ApiError(400, "malformed_json",
                   "the body is not valid JSON at line " + std::to_string(line) + ", column " + std::to_string(column),
                   {{"line", line}, {"column", column}, {"byte", e.byte}});
  }
}

void RouteContext::reply(int status, const json& j, const std::string& location) const {
  res.status = status;
  if (!location.empty()) res.set_header("Location", location);
  res.set_content(j.dump(-1, ' ', false, json::error_handler_t::replace), "application/json");
}

void run_handler(const Route& route, RouteContext& ctx) {
  try {
    route.handler(ctx);
  } catch (const json::type_error& e) {
    throw ApiError(422, "invalid_argument", std::string("a field of the body has the wrong type: ") + e.what());
  } catch (const json::out_of_range& e) {
    throw ApiError(422, "invalid_argument", std::string("a field of the body is out of range: ") + e.what());
  }
}

const std::vector<Route>& api_routes() {
  static const std::vector<Route> routes = [] {
    std::vector<Route> r;
    add_system_routes(r);
    add_session_routes(r);
    add_job_routes(r);
    return r;
  }();
  return routes;
}

void stream_events(RouteContext& ctx, std::shared_ptr<const void> owner, service::EventLog& log,
                   std::function<json()> state) {
  service::Service& svc = ctx.service;
  if (int(svc.streams_open.load()) >= svc.config().max_streams)
    throw ApiError(503, "too_many_streams", "the server holds " + std::to_string(svc.config().max_streams) +
                                                " open streams (max_streams); retry later");
  struct Cursor {
    std::uint64_t last = 0;
    bool send_state = true;
    std::chrono::steady_clock::time_point last_write{};
  };
  auto cursor = std::make_shared<Cursor>();
  const std::string resume = ctx.req.get_header_value("Last-Event-ID");
  if (!resume.empty()) {
    char* end = nullptr;
    const unsigned long long id = std::strtoull(resume.c_str(), &end, 10);
    if (end != resume.c_str() && *end == 0) {
      cursor->last = id;
      cursor->send_state = false;
    }
  }
  if (cursor->send_state) cursor->last = log.last_id();
  ++svc.streams_open;
  ctx.res.set_header("Cache-Control", "no-cache");
  ctx.res.set_header("X-Accel-Buffering", "no");
  ctx.res.set_chunked_content_provider(
      "text/event-stream",
      [&svc, &log, owner, cursor, state](std::size_t, httplib::DataSink& sink) {
        auto write_event = [&](std::uint64_t id, const std::string& type, const json& data) {
          std::string text = "id: " + std::to_string(id) + "\nevent: " + type + "\ndata: " +
                             data.dump(-1, ' ', false, json::error_handler_t::replace) + "\n\n";
          return sink.write(text.data(), text.size());
        };
        if (cursor->send_state) {
          cursor->send_state = false;
          if (!write_event(cursor->last, "state", state())) return false;
        }
        // At most ~10 writes a second: a fast job cannot flood a slow client.
        const auto since = std::chrono::steady_clock::now() - cursor->last_write;
        if (since < std::chrono::milliseconds(100)) std::this_thread::sleep_for(std::chrono::milliseconds(100) - since);
        const service::EventBatch batch = log.wait_after(cursor->last, std::chrono::milliseconds(1000));
        if (!svc.ready()) {
          sink.done();
          return true;
        }
        if (batch.missed && !write_event(cursor->last, "state", state())) return false;
        // Progress events are coalesced: only the newest of a batch is sent.
        std::size_t last_progress = batch.events.size();
        for (std::size_t i = 0; i < batch.events.size(); ++i)
          if (batch.events[i].type == "progress") last_progress = i;
        for (std::size_t i = 0; i < batch.events.size(); ++i) {
          const service::Event& e = batch.events[i];
          if (e.type == "progress" && i != last_progress) continue;
          if (!write_event(e.id, e.type, e.data)) return false;
        }
        if (!batch.events.empty()) {
          cursor->last = batch.events.back().id;
          cursor->last_write = std::chrono::steady_clock::now();
        } else if (!sink.write(": keep-alive\n\n", 14)) {
          return false;
        }
        if (batch.closed && (batch.events.empty() || batch.events.back().id == log.last_id())) sink.done();
        return true;
      },
      [&svc](bool) { --svc.streams_open; });
}

void send_blob(RouteContext& ctx, const service::Blob& blob) {
  if (!blob.etag.empty()) {
    ctx.res.set_header("ETag", blob.etag);
    if (ctx.req.get_header_value("If-None-Match") == blob.etag) {
      ctx.res.status = 304;
      return;
    }
  }
  if (!blob.file_name.empty())
    ctx.res.set_header("Content-Disposition", "attachment; filename=\"" + blob.file_name + "\"");
  auto bytes = blob.bytes;
  ctx.res.set_chunked_content_provider(blob.content_type, [bytes](std::size_t offset, httplib::DataSink& sink) {
    constexpr std::size_t kChunk = 1 << 20;
    if (offset < bytes->size()) {
      const std::size_t n = std::min(kChunk, bytes->size() - offset);
      if (!sink.write(bytes->data() + offset, n)) return false;
    }
    if (offset + kChunk >= bytes->size()) sink.done();
    return true;
  });
}

}  // namespace levelset::api
