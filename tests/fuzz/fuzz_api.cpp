// Fuzz target: the daemon's request handling (server/api routes over server/service). The
// input picks a route (first byte, or a first line "@METHOD PATH S" naming it: the seeds do, so
// that new routes do not move them) and a path id (second byte, or S: a live session, a live
// job, an upload, or text from the input); the rest is "QUERY\nBODY": the query string and the body,
// handed to the route's handler exactly as the HTTP layer does, minus the socket. An answer,
// an ApiError or a levelset::Error are the only allowed outcomes. Streaming routes (events)
// are skipped: they need a live connection. Jobs that the inputs start are cancelled after
// each input, so background work stays bounded; the limits are small (a 64^3-ish box).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include "api/route.hpp"
#include "core/error.hpp"
#include "service/api_error.hpp"
#include "service/service.hpp"

namespace {

using levelset::service::Service;

struct World {
  std::unique_ptr<Service> service;
  std::string session, job, upload;
};

World& world() {
  static World w = [] {
    World x;
    levelset::service::ServiceConfig c;
    c.data_dir = (std::filesystem::temp_directory_path() / ("levelset-fuzz-api-" + std::to_string(::getpid()))).string();
    std::filesystem::remove_all(c.data_dir);
    c.max_session_voxels = 1 << 16;  // bands built from shapes: boxes of at most 2^22 voxels
    c.max_sessions = 64;
    c.max_queued_jobs = 4;
    c.max_jobs = 1;
    c.max_upload_bytes = 1 << 16;
    c.replica = "fuzz";
    levelset::service::finalize(c);
    x.service = std::make_unique<Service>(c);
    // The data directory goes when the process ends (one per run of the target).
    static const std::string data_dir = c.data_dir;
    std::atexit([] { std::filesystem::remove_all(data_dir); });
    x.session = x.service->create_session({{"primitive", "sphere"}, {"raster", {{"resolution", 16}}}}).body["id"];
    x.job = x.service->submit(x.session, {{"op", "measure"}}).body["id"];
    return x;
  }();
  return w;
}

std::string route_regex(const std::string& path) {
  return std::regex_replace(path, std::regex(R"(\{[a-z]+\})"), "([^/]+)");
}

}  // namespace

// A seed may name its route, so that adding routes does not move it: "@METHOD PATH S\n" then
// the rest as below, S the id selector digit (the second byte of the binary form).
const levelset::api::Route* named_route(const std::string& line, std::uint8_t& selector) {
  const std::size_t space = line.find(' '), last = line.rfind(' ');
  if (space == std::string::npos || last == space) return nullptr;
  const std::string method = line.substr(1, space - 1), path = line.substr(space + 1, last - space - 1);
  selector = std::uint8_t(line[last + 1 < line.size() ? last + 1 : last]);
  for (const auto& r : levelset::api::api_routes())
    if (r.method == method && r.path == path) return &r;
  return nullptr;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  World& w = world();
  const auto& routes = levelset::api::api_routes();
  const levelset::api::Route* chosen = &routes[data[0] % routes.size()];
  std::uint8_t selector = data[1];
  std::size_t skip = 2;
  if (data[0] == '@') {  // the named form
    const std::string all(reinterpret_cast<const char*>(data), size);
    const std::size_t eol = all.find('\n');
    if (eol == std::string::npos) return 0;
    chosen = named_route(all.substr(0, eol), selector);
    // The seeds' check (ctest fuzz_api_seeds) wants every named route to exist; mutations may
    // name none.
    if (chosen == nullptr && std::getenv("LEVELSET_FUZZ_API_STRICT") != nullptr)
      throw std::runtime_error("no route '" + all.substr(0, eol) + "'");
    if (chosen == nullptr) return 0;
    skip = eol + 1;
  }
  const levelset::api::Route& route = *chosen;
  if (route.path.size() >= 7 && route.path.compare(route.path.size() - 7, 7, "/events") == 0) return 0;
  const std::string rest(reinterpret_cast<const char*>(data + skip), size - skip);
  const std::size_t newline = rest.find('\n');
  const std::string query = rest.substr(0, std::min(newline, std::size_t(512)));
  const std::string body = newline == std::string::npos ? "" : rest.substr(newline + 1);
  std::string id;
  switch (selector % 4) {
    case 0: id = w.session; break;
    case 1: id = w.job; break;
    case 2: id = "fuzz-u-0123456789abcdef.off"; break;
    default: id = query.substr(0, 40); break;
  }
  std::string path = std::regex_replace(route.path, std::regex(R"(\{[a-z]+\})"), id.empty() ? "x" : id);

  httplib::Request req;
  req.method = route.method;
  req.path = path;
  httplib::detail::parse_query_text(query, req.params);
  std::smatch m;
  const std::regex re(route_regex(route.path));
  std::regex_match(req.path, req.matches, re);
  httplib::Response res;
  httplib::ContentReader reader(
      [&](httplib::ContentReceiver receiver) { return receiver(body.data(), body.size()); },
      [&](httplib::MultipartContentHeader, httplib::ContentReceiver) { return false; });
  req.set_header("Content-Length", std::to_string(body.size()));
  levelset::api::RouteContext ctx{*w.service, req, res, route.streams_body ? &reader : nullptr, body, nullptr};
  try {
    levelset::api::run_handler(route, ctx);
  } catch (const levelset::service::ApiError&) {
  } catch (const levelset::Error&) {
  }
  // Bounded background work: whatever the input started is cancelled.
  for (const auto& job : w.service->jobs().list())
    if (!levelset::service::is_final(job->state())) job->cancel->cancel();
  return 0;
}
