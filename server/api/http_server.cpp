#include "api/http_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <chrono>
#include <cctype>
#include <regex>

#include <spdlog/spdlog.h>

#include "api/route.hpp"
#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/text.hpp"
#include "service/api_error.hpp"
#include "service/ids.hpp"

namespace levelset::api {

using nlohmann::json;
using service::ApiError;

namespace {

bool is_loopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

// "/api/v1/sessions/{id}" -> "/api/v1/sessions/([^/]+)"
std::string route_regex(const std::string& path) {
  std::string out;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (path[i] == '{') {
      out += "([^/]+)";
      i = path.find('}', i);
    } else if (std::string_view(".+*?()[]^$|\\").find(path[i]) != std::string_view::npos) {
      out += '\\';
      out += path[i];
    } else {
      out += path[i];
    }
  }
  return out;
}

std::string request_id_of(const httplib::Request& req) {
  const std::string given = req.get_header_value("X-Request-Id");
  bool sane = !given.empty() && given.size() <= 64;
  for (char c : given) sane = sane && (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_');
  return sane ? given : service::new_id("r", 'q').substr(4);
}

// Constant-time comparison: the time taken does not depend on where the strings differ.
bool same_token(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < b.size(); ++i) diff |= static_cast<unsigned char>((i < a.size() ? a[i] : 0) ^ b[i]);
  return diff == 0;
}

void write_error(httplib::Response& res, const ApiError& e) {
  res.status = e.status();
  if (e.status() == 401) res.set_header("WWW-Authenticate", "Bearer realm=\"levelsetd\"");
  res.set_content(e.body().dump(-1, ' ', false, json::error_handler_t::replace), "application/json");
}

}  // namespace

std::map<std::string, Role> load_tokens(const std::string& file, const std::string& list) {
  std::map<std::string, Role> tokens;
  auto add = [&](std::string token, const std::string& role, const std::string& where) {
    if (token.size() < 16)
      throw Error(ErrorCode::InvalidArgument, where, "a token needs at least 16 characters");
    if (role != "" && role != "rw" && role != "ro")
      throw Error(ErrorCode::InvalidArgument, where, "a token's role is rw or ro, found '" + role.substr(0, 20) + "'");
    tokens[std::move(token)] = role == "ro" ? Role::ReadOnly : Role::ReadWrite;
  };
  if (!file.empty()) {
    const std::string text = read_file_bytes(file, 1 << 20);
    std::size_t line_no = 0;
    for (std::size_t start = 0; start < text.size();) {
      const std::size_t end = std::min(text.find('\n', start), text.size());
      std::string line = text.substr(start, end - start);
      start = end + 1;
      ++line_no;
      if (const std::size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
      std::string token, role;
      std::size_t i = 0;
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) token += line[i++];
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) role += line[i++];
      if (!token.empty()) add(token, role, file + ":" + std::to_string(line_no));
    }
  }
  for (std::size_t start = 0; start < list.size();) {
    const std::size_t end = std::min(list.find(',', start), list.size());
    std::string item = list.substr(start, end - start);
    start = end + 1;
    if (item.empty()) continue;
    std::string role;
    if (item.size() > 3 && (item.substr(item.size() - 3) == ":ro" || item.substr(item.size() - 3) == ":rw")) {
      role = item.substr(item.size() - 2);
      item.resize(item.size() - 3);
    }
    add(item, role, "LEVELSET_TOKENS");
  }
  return tokens;
}

HttpServer::HttpServer(service::Service& service) : service_(service) {
  const service::ServiceConfig& c = service.config();
  tokens_ = load_tokens(c.token_file, c.tokens);
  routing_ = std::make_unique<ReplicaRouting>(c.replica, c.peers);
  loopback_ = is_loopback(c.host);
  if (!loopback_ && tokens_.empty() && !c.insecure_no_auth)
    throw Error(ErrorCode::InvalidArgument, "--host " + c.host,
                "listening beyond loopback needs bearer tokens (--token-file or LEVELSET_TOKENS); "
                "--insecure-no-auth overrides this");
  if (!c.tls_cert.empty()) {
    auto ssl = std::make_unique<httplib::SSLServer>(c.tls_cert.c_str(), c.tls_key.c_str());
    if (!ssl->is_valid()) throw Error(ErrorCode::InvalidArgument, c.tls_cert, "cannot load the TLS certificate and key");
    server_ = std::move(ssl);
  } else {
    server_ = std::make_unique<httplib::Server>();
  }
  install();
}

HttpServer::~HttpServer() = default;

void HttpServer::install() {
  const service::ServiceConfig& c = service_.config();
  httplib::Server& svr = *server_;
  const int threads = c.max_streams + 16;
  svr.new_task_queue = [threads] { return new httplib::ThreadPool(std::size_t(threads)); };
  svr.set_payload_max_length(std::max<std::uint64_t>(c.max_upload_bytes, c.max_body_bytes));
  svr.set_read_timeout(std::chrono::milliseconds(std::int64_t(c.read_timeout * 1000)));
  svr.set_write_timeout(std::chrono::seconds(30));
  svr.set_keep_alive_timeout(5);
  svr.set_keep_alive_max_count(1000);  // the library default (5) reconnects every fifth request
  // Headers and body go out in separate writes: without TCP_NODELAY, Nagle's algorithm holds
  // the body until the client's delayed ACK (40 ms a request on a kept-alive connection).
  svr.set_tcp_nodelay(true);
  svr.set_socket_options([this](socket_t fd) {
    int yes = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    listen_fd_ = fd;
  });

  for (const Route& route : api_routes()) {
    const std::string pattern = route_regex(route.path);
    auto run = [this, &route](const httplib::Request& req, httplib::Response& res, const httplib::ContentReader* reader) {
      handle(route, req, res, reader);
    };
    auto plain = [run](const httplib::Request& req, httplib::Response& res) { run(req, res, nullptr); };
    auto with_body = [run](const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader) {
      run(req, res, &reader);
    };
    if (route.method == "GET") svr.Get(pattern, plain);
    else if (route.method == "DELETE") svr.Delete(pattern, plain);
    else if (route.method == "POST") svr.Post(pattern, with_body);
    else if (route.method == "PATCH") svr.Patch(pattern, with_body);
    else if (route.method == "PUT") svr.Put(pattern, with_body);
  }
  if (!c.cors_origin.empty())
    svr.Options(".*", [origin = c.cors_origin](const httplib::Request&, httplib::Response& res) {
      res.set_header("Access-Control-Allow-Origin", origin);
      res.set_header("Access-Control-Allow-Methods", "GET, POST, PUT, PATCH, DELETE, OPTIONS");
      res.set_header("Access-Control-Allow-Headers", "Authorization, Content-Type, Idempotency-Key, Last-Event-ID");
      res.status = 204;
    });
  // Anything the routes did not answer (no such route, httplib's own 413 / 400): JSON too.
  svr.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    std::string code = "error", message = "request refused";
    if (res.status == 404) code = "no_route", message = "no route " + req.method + " " + sanitize_utf8(req.path.substr(0, 200));
    if (res.status == 413) code = "payload_too_large", message = "the body is larger than the server accepts";
    if (res.status == 400) code = "bad_request", message = "malformed HTTP request";
    if (res.status == 405) code = "method_not_allowed", message = "method not allowed";
    res.set_content(json{{"error", {{"code", code}, {"message", message}, {"details", json::object()}}}}.dump(),
                    "application/json");
  });
}

// One request: its id, CORS, the token, idempotency, the body, the handler, the JSON error,
// the counters and one log line.
void HttpServer::handle(const Route& route, const httplib::Request& req, httplib::Response& res,
                        const httplib::ContentReader* reader) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string request_id = request_id_of(req);
  res.set_header("X-Request-Id", request_id);
  const service::ServiceConfig& cfg = service_.config();
  if (!cfg.cors_origin.empty() && req.get_header_value("Origin") == cfg.cors_origin)
    res.set_header("Access-Control-Allow-Origin", cfg.cors_origin);
  std::string idempotency;
  try {
    authenticate(route, req);
    if (route.writes && !service_.ready()) throw ApiError(503, "shutting_down", "the server is shutting down");
    bool replayed = false;
    if (route.method == "POST" && req.has_header("Idempotency-Key")) {
      idempotency = req.get_header_value("Authorization") + "|" + req.path + "|" +
                    req.get_header_value("Idempotency-Key").substr(0, 200);
      if (auto previous = service_.replay(idempotency)) {
        res.status = previous->first;
        res.set_content(previous->second, "application/json");
        res.set_header("Idempotent-Replayed", "true");
        idempotency.clear();
        replayed = true;
      }
    }
    // Another replica's session or job: redirected there (307 keeps the method and body).
    if (routing_->enabled() && req.matches.size() > 1 &&
        (route.path.find("{id}") != std::string::npos || route.path.find("{jid}") != std::string::npos)) {
      if (auto url = routing_->redirect_for(std::string(req.matches[1]), req.target)) {
        res.status = 307;
        res.set_header("Location", *url);
        res.set_content(json{{"redirect", *url}}.dump(), "application/json");
        replayed = true;
      }
    }
    if (!replayed) {
      RouteContext ctx{service_, req, res, nullptr, {}, routing_.get()};
      if (reader != nullptr && route.streams_body) ctx.reader = reader;
      else if (reader != nullptr) ctx.body_text = read_body(req, *reader);
      run_handler(route, ctx);
    }
  } catch (const ApiError& e) {
    write_error(res, e);
  } catch (const Error& e) {
    write_error(res, ApiError::from_error(e));
  } catch (const std::bad_alloc&) {
    write_error(res, ApiError(507, "out_of_memory", "the server ran out of memory for this request"));
  } catch (const std::exception& e) {
    write_error(res, ApiError(500, "internal", e.what()));
  }
  if (!idempotency.empty() && res.status < 500 && res.content_length_ == 0 && !res.body.empty())
    service_.remember(idempotency, res.status, res.body);
  ++service_.requests_total;
  if (res.status >= 400) ++service_.request_errors_total;
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (cfg.log_format == "json")
    spdlog::info(json{{"request_id", request_id}, {"method", req.method}, {"path", sanitize_utf8(req.path)},
                      {"status", res.status}, {"ms", ms}}
                     .dump(-1, ' ', false, json::error_handler_t::replace));
  else
    spdlog::info("{} {} {} {:.1f} ms [{}]", req.method, sanitize_utf8(req.path.substr(0, 200)), res.status, ms, request_id);
}

// Tokens when configured (always beyond loopback). Probes and the viewer page (static; the
// token is typed into it) need none. Browsers cannot set headers on <img> and EventSource:
// GET routes also take ?access_token=.
void HttpServer::authenticate(const Route& route, const httplib::Request& req) const {
  const bool open = route.path == "/healthz" || route.path == "/readyz" || route.path == "/";
  if (tokens_.empty() || open) return;
  const std::string auth = req.get_header_value("Authorization");
  std::string given;
  if (auth.rfind("Bearer ", 0) == 0) given = auth.substr(7);
  else if (route.method == "GET" && req.has_param("access_token")) given = req.get_param_value("access_token");
  const Role* role = nullptr;
  if (!given.empty())
    for (const auto& [token, r] : tokens_)
      if (same_token(given, token)) role = &r;
  if (role == nullptr) throw ApiError(401, "unauthorized", "a valid bearer token is required");
  if (route.writes && *role == Role::ReadOnly)
    throw ApiError(403, "forbidden", "this token is read-only; " + route.method + " needs a read-write token");
}

// A JSON body, read up to max_body_bytes (413 past it, before reading when the length says so).
std::string HttpServer::read_body(const httplib::Request& req, const httplib::ContentReader& reader) const {
  const std::uint64_t limit = service_.config().max_body_bytes;
  const std::string length = req.get_header_value("Content-Length");
  if (!length.empty() && std::strtoull(length.c_str(), nullptr, 10) > limit)
    throw ApiError(413, "payload_too_large",
                   "the body has " + length + " bytes, more than max_body_bytes (" + std::to_string(limit) + ")");
  std::string body;
  bool over = false;
  reader([&](const char* data, std::size_t n) {
    if (body.size() + n > limit) {
      over = true;
      return false;
    }
    body.append(data, n);
    return true;
  });
  if (over) throw ApiError(413, "payload_too_large", "the body is larger than max_body_bytes (" + std::to_string(limit) + ")");
  return body;
}

int HttpServer::bind() {
  const service::ServiceConfig& c = service_.config();
  int port = c.port;
  if (port == 0) {
    port = server_->bind_to_any_port(c.host);
    if (port <= 0) throw Error(ErrorCode::IoError, c.host, "cannot bind to any port");
  } else if (!server_->bind_to_port(c.host, port)) {
    throw Error(ErrorCode::IoError, c.host + ":" + std::to_string(port), "cannot bind (in use, or not an address of this host)");
  }
  // Raise the backlog the library compiled in (5): 64 clients connecting at once otherwise
  // wait a second each for SYN retries.
  if (listen_fd_ >= 0) ::listen(listen_fd_, 1024);
  return port;
}

void HttpServer::listen() { server_->listen_after_bind(); }

void HttpServer::stop() { server_->stop(); }

}  // namespace levelset::api
