// Uploads and sessions: create (primitive, band upload, or a first job), list, show, rename,
// delete, snapshots, events, and the results (mesh, band, voxels).
#include <chrono>
#include <cstdlib>
#include <thread>

#include "api/replica_routing.hpp"
#include "api/route.hpp"
#include "service/api_error.hpp"

namespace levelset::api {

using nlohmann::json;
using service::ApiError;

namespace {

const json kJson = {{"application/json", {{"schema", {{"type", "object"}}}}}};
const json kBinary = {{"application/octet-stream", {{"schema", {{"type", "string"}, {"format", "binary"}}}}}};

double query_number(const httplib::Request& req, const char* name, double fallback) {
  if (!req.has_param(name)) return fallback;
  const std::string v = req.get_param_value(name);
  char* end = nullptr;
  const double x = std::strtod(v.c_str(), &end);
  if (end == v.c_str() || *end != 0 || !std::isfinite(x))
    throw service::unprocessable(name, "expected a finite number, found '" + v.substr(0, 40) + "'");
  return x;
}

std::string query_text(const httplib::Request& req, const char* name, const std::string& fallback) {
  return req.has_param(name) ? req.get_param_value(name).substr(0, 200) : fallback;
}

// width, height, format, quality; every other parameter is a view setting for the renderer.
service::FrameRequest frame_settings(const httplib::Request& req) {
  service::FrameRequest f;
  f.width = int(query_number(req, "width", 800));
  f.height = int(query_number(req, "height", 600));
  f.quality = int(query_number(req, "quality", 85));
  f.format = query_text(req, "format", "jpeg");
  if (f.format == "jpg") f.format = "jpeg";
  for (const auto& [key, value] : req.params)
    if (key != "width" && key != "height" && key != "quality" && key != "format" && key != "access_token")
      f.query.emplace_back(key.substr(0, 64), value.substr(0, 256));
  return f;
}

// MJPEG: a new part whenever the session's state (a step, a version), view or point cloud
// changed, at most stream_fps a second; the provider draws the newest state when the client is ready for it, so a slow
// client skips frames instead of queueing them.
void stream_frames(RouteContext& c) {
  service::Service& svc = c.service;
  auto session = svc.sessions().get(c.param(1));
  if (!svc.rendering()) throw ApiError(503, "rendering_off", svc.render_status());
  if (int(svc.streams_open.load()) >= svc.config().max_streams)
    throw ApiError(503, "too_many_streams", "the server holds " + std::to_string(svc.config().max_streams) +
                                                " open streams (max_streams); retry later");
  service::FrameRequest settings = frame_settings(c.req);
  settings.format = "jpeg";
  struct Cursor {
    std::uint64_t state = ~std::uint64_t{0};
    std::chrono::steady_clock::time_point last{};
    std::shared_ptr<const std::string> frame;  // the last part sent
  };
  auto cursor = std::make_shared<Cursor>();
  ++svc.streams_open;
  c.res.set_header("Cache-Control", "no-cache");
  c.res.set_chunked_content_provider(
      "multipart/x-mixed-replace; boundary=levelsetframe",
      [&svc, session, settings, cursor](std::size_t, httplib::DataSink& sink) {
        const auto min_gap = std::chrono::milliseconds(1000 / svc.config().stream_fps);
        for (int waited = 0; waited < 10; ++waited) {  // at most ~1 s in one call
          if (!svc.ready()) {
            sink.done();
            return true;
          }
          const std::uint64_t now_state = session->frame_state();
          if (now_state != cursor->state) {
            const auto since = std::chrono::steady_clock::now() - cursor->last;
            if (since < min_gap) std::this_thread::sleep_for(min_gap - since);
            std::uint64_t drawn = 0;
            service::EncodedFrame f;
            try {
              f = svc.frame(session->id(), settings, &drawn);
            } catch (const std::exception&) {
              return false;  // the session went away or the renderer stopped: end the stream
            }
            // Each part ends with the next boundary, so a browser shows it at once instead of
            // waiting for the following frame (which may not come until something changes).
            const std::string head = std::string(cursor->state == ~std::uint64_t{0} ? "--levelsetframe\r\n" : "") +
                                     "Content-Type: image/jpeg\r\nContent-Length: " + std::to_string(f.bytes->size()) +
                                     "\r\n\r\n";
            static const std::string tail = "\r\n--levelsetframe\r\n";
            if (!sink.write(head.data(), head.size()) || !sink.write(f.bytes->data(), f.bytes->size()) ||
                !sink.write(tail.data(), tail.size()))
              return false;
            cursor->state = drawn;
            cursor->last = std::chrono::steady_clock::now();
            cursor->frame = f.bytes;
            return true;
          }
          session->events().wait_after(session->events().last_id(), std::chrono::milliseconds(100));
        }
        // Nothing changed for a second: the last frame again. Browsers show a part only once the
        // following one starts, and a dead client is noticed here.
        if (cursor->frame) {
          const std::string head =
              "Content-Type: image/jpeg\r\nContent-Length: " + std::to_string(cursor->frame->size()) + "\r\n\r\n";
          static const std::string again_tail = "\r\n--levelsetframe\r\n";
          if (!sink.write(head.data(), head.size()) || !sink.write(cursor->frame->data(), cursor->frame->size()) ||
              !sink.write(again_tail.data(), again_tail.size()))
            return false;
        }
        return true;
      },
      [&svc](bool) { --svc.streams_open; });
}

void upload(RouteContext& c) {
  const std::string format = query_text(c.req, "format", "");
  if (!c.req.has_header("Content-Length"))
    throw ApiError(411, "length_required", "send the file with a Content-Length");
  // A declared length over the limit is refused before reading (httplib's payload limit would
  // otherwise end the read at once and the empty file be validated as "empty").
  const std::uint64_t limit = c.service.config().max_upload_bytes;
  const std::string length = c.req.get_header_value("Content-Length");
  if (length.size() > 19 || std::strtoull(length.c_str(), nullptr, 10) > limit)
    throw ApiError(413, "payload_too_large", "the upload has " + length.substr(0, 20) + " bytes, more than " +
                                                 std::to_string(limit) + " (max_upload_bytes)");
  auto writer = c.service.uploads().begin(c.service.config().replica, format);
  bool refused = false;  // by the writer: over the limit or a failed write (finish says which)
  const bool complete = (*c.reader)([&](const char* data, std::size_t n) {
    if (writer->write(data, n)) return true;
    refused = true;
    return false;
  });
  if (!complete && !refused)
    throw ApiError(400, "incomplete_body", "the upload ended before its Content-Length");
  const json stored = c.service.uploads().finish(*writer);
  c.reply(201, stored, "/api/v1/uploads/" + stored["id"].get<std::string>());
}

}  // namespace

void add_session_routes(std::vector<Route>& r) {
  // ---- uploads
  {
    Route u{"POST", "/api/v1/uploads", "Upload a file as the raw body; validated by the strict readers", true, true,
            {"format"}, kBinary, {{"201", "stored: id, format, bytes, kind, summary"}, {"400", "malformed file"},
                                  {"413", "too large"}, {"415", "unknown format"}}, upload};
    r.push_back(u);
  }
  r.push_back({"GET", "/api/v1/uploads", "List uploads", false, false, {}, nullptr, {{"200", "uploads"}},
               [](RouteContext& c) { c.reply(200, {{"uploads", c.service.uploads().list()}}); }});
  r.push_back({"GET", "/api/v1/uploads/{id}", "One upload's description", false, false, {}, nullptr,
               {{"200", "the upload"}, {"404", "unknown"}},
               [](RouteContext& c) { c.reply(200, c.service.uploads().get(c.param(1))); }});
  r.push_back({"DELETE", "/api/v1/uploads/{id}", "Delete an upload", true, false, {}, nullptr,
               {{"204", "deleted"}, {"404", "unknown"}}, [](RouteContext& c) {
                 c.service.uploads().remove(c.param(1));
                 c.res.status = 204;
               }});
  // ---- sessions
  r.push_back({"GET", "/api/v1/sessions",
               "List the sessions of every replica (with peers configured; ?local=1: this replica's only)", false,
               false, {"local"}, nullptr, {{"200", "sessions"}}, [](RouteContext& c) {
                 json list = c.service.list_sessions();
                 if (c.routing != nullptr && c.routing->enabled() && !c.req.has_param("local")) {
                   for (json& s : list["sessions"]) s["replica"] = c.service.config().replica;
                   json unreachable;
                   for (json& s : c.routing->peer_sessions(c.req.get_header_value("Authorization"), unreachable))
                     list["sessions"].push_back(std::move(s));
                   list["unreachable"] = unreachable;
                 }
                 c.reply(200, list);
               }});
  r.push_back({"POST", "/api/v1/sessions",
               "Create a session: {\"primitive\": NAME, \"raster\": {...}} or {\"upload\": ID, ...op parameters}", true,
               false, {}, kJson, {{"201", "the session (primitive, band upload)"}, {"202", "a job creates it"}},
               [](RouteContext& c) { c.reply(c.service.create_session(c.body())); }});
  r.push_back({"GET", "/api/v1/sessions/{id}", "One session: name, version, band summary, running job", false, false,
               {}, nullptr, {{"200", "the session"}, {"404", "unknown"}},
               [](RouteContext& c) { c.reply(200, c.service.sessions().get(c.param(1))->describe()); }});
  r.push_back({"PATCH", "/api/v1/sessions/{id}", "Rename ({\"name\": NEW}) and/or show a point upload with the session ({\"points\": UPLOAD_ID}, null: none)", true, false, {}, kJson,
               {{"200", "the session"}}, [](RouteContext& c) { c.reply(200, c.service.patch_session(c.param(1), c.body())); }});
  r.push_back({"DELETE", "/api/v1/sessions/{id}", "Delete a session and its files", true, false, {}, nullptr,
               {{"204", "deleted"}, {"409", "a job runs on it"}}, [](RouteContext& c) {
                 c.service.sessions().remove(c.param(1));
                 c.res.status = 204;
               }});
  r.push_back({"GET", "/api/v1/sessions/{id}/history", "The operations that made each version", false, false, {},
               nullptr, {{"200", "history"}},
               [](RouteContext& c) { c.reply(200, {{"history", c.service.sessions().get(c.param(1))->history()}}); }});
  r.push_back({"POST", "/api/v1/sessions/{id}/snapshots", "Snapshot the current version: {\"name\": ...}", true, false,
               {}, kJson, {{"201", "the snapshot"}},
               [](RouteContext& c) { c.reply(c.service.snapshot(c.param(1), c.body())); }});
  r.push_back({"GET", "/api/v1/sessions/{id}/snapshots", "List snapshots", false, false, {}, nullptr,
               {{"200", "snapshots"}},
               [](RouteContext& c) { c.reply(200, {{"snapshots", c.service.sessions().get(c.param(1))->snapshots()}}); }});
  r.push_back({"POST", "/api/v1/sessions/{id}/snapshots/{sid}/restore", "Make a snapshot the next version", true,
               false, {}, nullptr, {{"200", "the session"}, {"404", "unknown snapshot"}},
               [](RouteContext& c) { c.reply(200, c.service.restore(c.param(1), c.param(2))); }});
  r.push_back({"GET", "/api/v1/sessions/{id}/events", "Server-Sent Events: version changes, job states and progress",
               false, false, {}, nullptr, {{"200", "text/event-stream"}}, [](RouteContext& c) {
                 auto s = c.service.sessions().get(c.param(1));
                 stream_events(c, s, s->events(), [s] { return s->describe(); });
               }});
  // ---- the view and frames
  r.push_back({"GET", "/api/v1/sessions/{id}/view", "The camera and display settings of the session's frames", false,
               false, {}, nullptr, {{"200", "view settings"}},
               [](RouteContext& c) { c.reply(200, c.service.sessions().get(c.param(1))->view()); }});
  r.push_back({"PUT", "/api/v1/sessions/{id}/view",
               "Move the camera and change display settings of the session's frames and streams (merged)", true, false,
               {}, kJson, {{"200", "the view settings"}, {"422", "a setting out of range"}}, [](RouteContext& c) {
                 const json body = c.body();
                 if (!body.is_object()) throw service::unprocessable("body", "expected an object of view settings");
                 auto s = c.service.sessions().get(c.param(1));
                 c.reply(200, c.service.sessions().update_view(*s, body));
               }});
  r.push_back({"GET", "/api/v1/sessions/{id}/frame",
               "The session rendered offscreen (its view, then the query's settings over it) as JPEG or PNG", false,
               false, {"width", "height", "format", "quality", "shading", "yaw", "pitch", "zoom", "slice", "volume"},
               nullptr, {{"200", "the image"}, {"422", "a size or setting out of range"}, {"503", "rendering is off"}},
               [](RouteContext& c) {
                 const service::EncodedFrame f = c.service.frame(c.param(1), frame_settings(c.req));
                 c.res.set_content(std::string(*f.bytes), f.content_type);
               }});
  r.push_back({"GET", "/api/v1/sessions/{id}/stream",
               "The session rendered live as MJPEG (multipart/x-mixed-replace): a frame after every step, view or "
               "version change, at most stream_fps a second; a slow client gets the newest frame",
               false, false, {"width", "height", "quality", "shading", "yaw", "pitch", "zoom", "slice", "volume"}, nullptr,
               {{"200", "multipart/x-mixed-replace; boundary=levelsetframe"}, {"503", "rendering is off or too many streams"}},
               stream_frames});
  // ---- results
  r.push_back({"GET", "/api/v1/sessions/{id}/mesh", "The surface as a mesh (chunked; ETag from version and query)",
               false, false, {"iso", "method", "format"}, nullptr,
               {{"200", "the mesh"}, {"304", "not modified"}, {"422", "iso beyond the band"}}, [](RouteContext& c) {
                 service::MeshQuery q;
                 q.iso = query_number(c.req, "iso", 0.0);
                 q.method = query_text(c.req, "method", "mc");
                 q.format = query_text(c.req, "format", "ply");
                 send_blob(c, c.service.mesh(c.param(1), q));
               }});
  r.push_back({"GET", "/api/v1/sessions/{id}/band", "The committed band as an .lsg file", false, false, {}, nullptr,
               {{"200", "the .lsg"}}, [](RouteContext& c) { send_blob(c, c.service.band(c.param(1))); }});
  r.push_back({"GET", "/api/v1/sessions/{id}/voxels",
               "Active voxels with value in [min, max] as little-endian float32 records (paged: offset, limit; "
               "X-Fields names them, X-Total-Count counts all)",
               false, false, {"min", "max", "fields", "offset", "limit"}, nullptr, {{"200", "records"}},
               [](RouteContext& c) {
                 service::VoxelQuery q;
                 q.min = query_number(c.req, "min", -1e300);
                 q.max = query_number(c.req, "max", 1e300);
                 q.offset = std::uint64_t(std::max(0.0, query_number(c.req, "offset", 0)));
                 q.limit = std::uint64_t(std::max(0.0, query_number(c.req, "limit", double(1 << 20))));
                 if (c.req.has_param("fields")) {
                   q.fields.clear();
                   std::string f = query_text(c.req, "fields", "value");
                   for (std::size_t start = 0; start <= f.size();) {
                     const std::size_t comma = std::min(f.find(',', start), f.size());
                     if (comma > start) q.fields.push_back(f.substr(start, comma - start));
                     start = comma + 1;
                   }
                 }
                 std::uint64_t total = 0;
                 std::string fields;
                 const service::Blob b = c.service.voxels(c.param(1), q, total, fields);
                 c.res.set_header("X-Total-Count", std::to_string(total));
                 c.res.set_header("X-Fields", fields);
                 if (q.offset + q.limit < total) c.res.set_header("X-Next-Offset", std::to_string(q.offset + q.limit));
                 c.res.set_content(*b.bytes, b.content_type);
               }});
  r.push_back({"GET", "/api/v1/sessions/{id}/points", "The session's point cloud, as uploaded (format: describe()'s points.format)",
               false, false, {}, nullptr, {{"200", "the point cloud file"}, {"404", "the session has none"}},
               [](RouteContext& c) { send_blob(c, c.service.points(c.param(1))); }});
  // ---- region of influence (thesis table 4.1 B, D; appended: fuzz_api's seeds index routes)
  r.push_back({"PUT", "/api/v1/sessions/{id}/roi",
               "Store a region of influence: a copy of the session's committed band ({}) or of a snapshot "
               "({\"snapshot\": SID}) or of another session's committed band ({\"session\": ID}) that speed formulas read "
               "as roi and frames show with roi=on",
               true, false, {}, kJson, {{"200", "the session"}, {"404", "unknown snapshot"}},
               [](RouteContext& c) { c.reply(200, c.service.put_roi(c.param(1), c.body())); }});
  r.push_back({"DELETE", "/api/v1/sessions/{id}/roi", "Remove the session's region of influence", true, false, {},
               nullptr, {{"204", "removed"}}, [](RouteContext& c) {
                 auto s = c.service.sessions().get(c.param(1));
                 c.service.sessions().remove_roi(*s);
                 c.reply(204, nullptr);
               }});
  r.push_back({"GET", "/api/v1/sessions/{id}/roi", "The session's region of influence, as a band (.lsg)", false, false,
               {}, nullptr, {{"200", "the band"}, {"404", "the session has none"}},
               [](RouteContext& c) { send_blob(c, c.service.roi(c.param(1))); }});
}

}  // namespace levelset::api
