#include "lib/api.hpp"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>

#include <httplib.h>

#include "lib/client_error.hpp"
#include "lib/sse.hpp"

namespace levelset::client {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using Kind = ClientError::Kind;

ClientError transport_error(const std::string& server, httplib::Error e) {
  if (e == httplib::Error::Connection || e == httplib::Error::ConnectionTimeout)
    return ClientError(Kind::Connect, "cannot_connect", "cannot connect to " + server + " (" + httplib::to_string(e) + ")");
  return ClientError(Kind::Connect, "connection_failed", server + ": " + httplib::to_string(e));
}

json parse_answer(const std::string& body) {
  if (body.empty()) return nullptr;
  json j = json::parse(body, nullptr, false);
  if (j.is_discarded()) throw ClientError(Kind::Server, "bad_response", "the server's answer is not JSON: " + body.substr(0, 80));
  return j;
}

}  // namespace

Api::Api(std::string server, std::string token) : server_(std::move(server)), token_(std::move(token)) {
  while (!server_.empty() && server_.back() == '/') server_.pop_back();
  const std::size_t scheme = server_.find("://");
  if (scheme == std::string::npos || (server_.substr(0, scheme) != "http" && server_.substr(0, scheme) != "https") ||
      scheme + 3 >= server_.size())
    throw ClientError(Kind::Usage, "bad_server", "expected --server http://HOST:PORT, found '" + server_ + "'");
  const std::size_t path = server_.find('/', scheme + 3);
  origin_ = server_.substr(0, path);
  if (path != std::string::npos) prefix_ = server_.substr(path);
  if (!httplib::Client(origin_).is_valid())
    throw ClientError(Kind::Usage, "bad_server", "expected --server http://HOST:PORT, found '" + server_ + "'");
}

std::string Api::encode(const std::string& text) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : text) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      out += char(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

namespace {

std::unique_ptr<httplib::Client> make_client(const std::string& origin, const std::string& token, time_t read_timeout) {
  auto c = std::make_unique<httplib::Client>(origin);
  c->set_connection_timeout(10);
  c->set_read_timeout(read_timeout);
  c->set_write_timeout(120);
  c->set_keep_alive(false);
  if (!token.empty()) c->set_bearer_token_auth(token);
  return c;
}

json answer(const std::string& server, const httplib::Result& r) {
  if (!r) throw transport_error(server, r.error());
  if (r->status >= 400) throw ClientError::from_response(r->status, r->body);
  return parse_answer(r->body);
}

}  // namespace

json Api::get(const std::string& path) const {
  auto c = make_client(origin_, token_, 120);
  return answer(server_, c->Get(prefix_ + path));
}

json Api::post(const std::string& path, const json& body, int* status) const {
  auto c = make_client(origin_, token_, 120);
  auto r = c->Post(prefix_ + path, body.dump(), "application/json");
  json j = answer(server_, r);
  if (status != nullptr) *status = r->status;
  return j;
}

json Api::patch(const std::string& path, const json& body) const {
  auto c = make_client(origin_, token_, 120);
  return answer(server_, c->Patch(prefix_ + path, body.dump(), "application/json"));
}

json Api::put(const std::string& path, const json& body) const {
  auto c = make_client(origin_, token_, 120);
  return answer(server_, c->Put(prefix_ + path, body.dump(), "application/json"));
}

json Api::del(const std::string& path) const {
  auto c = make_client(origin_, token_, 120);
  return answer(server_, c->Delete(prefix_ + path));
}

json Api::upload(const std::string& file, const std::string& format) const {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw ClientError(Kind::Local, "io_error", "no such file: " + file);
  const std::uint64_t size = fs::file_size(file, ec);
  auto in = std::make_shared<std::ifstream>(file, std::ios::binary);
  if (ec || !*in) throw ClientError(Kind::Local, "io_error", "cannot read " + file);
  if (size > (1u << 20)) {
    const json info = get("/api/v1");
    const json formats = info.value("upload_formats", json::array());
    if (formats.is_array() && !formats.empty() && std::find(formats.begin(), formats.end(), format) == formats.end())
      throw ClientError(Kind::Server, "unsupported_format",
                        "unknown upload format '" + format + "' (known: " + formats.dump() + ")", 415);
    const json limits = info.value("limits", json::object());
    if (limits.contains("max_upload_bytes") && limits["max_upload_bytes"].is_number() &&
        size > limits["max_upload_bytes"].get<std::uint64_t>())
      throw ClientError(Kind::Server, "payload_too_large",
                        file + " has " + std::to_string(size) + " bytes, more than the server's max_upload_bytes (" +
                            std::to_string(limits["max_upload_bytes"].get<std::uint64_t>()) + ")",
                        413);
  }
  const std::string path = "/api/v1/uploads?format=" + encode(format);
  bool read_failed = false;
  auto c = make_client(origin_, token_, 600);  // the server validates the whole file before it answers
  auto r = c->Post(
      prefix_ + path, size,
      [in, &read_failed](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
        static thread_local std::string buffer(1 << 16, '\0');
        in->seekg(std::streamoff(offset));
        in->read(buffer.data(), std::streamsize(std::min(length, buffer.size())));
        const std::streamsize n = in->gcount();
        if (n <= 0) {
          read_failed = true;
          return false;
        }
        return sink.write(buffer.data(), std::size_t(n));
      },
      "application/octet-stream");
  if (read_failed) throw ClientError(Kind::Local, "io_error", "cannot read " + file + " (it changed while it was sent?)");
  return answer(server_, r);
}

std::uint64_t Api::download(const std::string& path, const std::string& file) const {
  const std::string temp = file + ".part-" + std::to_string(::getpid());
  std::ofstream out;
  int status = 0;
  std::string error_body;
  std::uint64_t bytes = 0;
  bool write_failed = false;
  auto c = make_client(origin_, token_, 120);
  auto r = c->Get(
      prefix_ + path, httplib::Headers{},
      [&](const httplib::Response& res) {
        status = res.status;
        if (status < 400) {
          out.open(temp, std::ios::binary | std::ios::trunc);
          if (!out) {
            write_failed = true;
            return false;
          }
        }
        return true;
      },
      [&](const char* data, std::size_t n) {
        if (status >= 400) {
          if (error_body.size() < (1 << 16)) error_body.append(data, n);
          return true;
        }
        out.write(data, std::streamsize(n));
        bytes += n;
        if (!out) write_failed = true;
        return !write_failed;
      });
  if (out.is_open()) out.close();
  std::error_code ec;
  if (write_failed || (status < 400 && status != 0 && !out)) {
    fs::remove(temp, ec);
    throw ClientError(Kind::Local, "io_error", "cannot write " + file);
  }
  if (!r) {
    fs::remove(temp, ec);
    throw transport_error(server_, r.error());
  }
  if (status >= 400) throw ClientError::from_response(status, error_body);
  fs::rename(temp, file, ec);
  if (ec) {
    fs::remove(temp, ec);
    throw ClientError(Kind::Local, "io_error", "cannot write " + file + ": " + ec.message());
  }
  return bytes;
}

void Api::events(const std::string& path, const std::string& last_event_id,
                 const std::function<bool(const SseEvent&)>& on_event, const std::atomic<bool>* stop) const {
  httplib::Headers headers{{"Accept", "text/event-stream"}};
  if (!last_event_id.empty()) headers.emplace("Last-Event-ID", last_event_id);
  int status = 0;
  std::string error_body;
  bool stopped = false;
  SseParser parser;
  // The server writes at least a keep-alive a second: 30 s of silence is a dead connection.
  auto c = make_client(origin_, token_, 30);
  auto r = c->Get(
      prefix_ + path, headers,
      [&](const httplib::Response& res) {
        status = res.status;
        return true;
      },
      [&](const char* data, std::size_t n) {
        if (status >= 400) {
          if (error_body.size() < (1 << 16)) error_body.append(data, n);
          return true;
        }
        if (!parser.feed(std::string_view(data, n), on_event)) stopped = true;
        if (stop != nullptr && stop->load()) stopped = true;
        return !stopped;
      });
  if (stopped) return;
  if (!r) throw transport_error(server_, r.error());
  if (status >= 400) throw ClientError::from_response(status, error_body);
}

Api::Raw Api::get_raw(const std::string& path, const std::string& etag) const {
  httplib::Headers headers;
  if (!etag.empty()) headers.emplace("If-None-Match", etag);
  auto c = make_client(origin_, token_, 120);
  auto r = c->Get(prefix_ + path, headers);
  if (!r) throw transport_error(server_, r.error());
  if (r->status >= 400) throw ClientError::from_response(r->status, r->body);
  Raw raw;
  raw.status = r->status;
  raw.etag = r->get_header_value("ETag");
  raw.content_type = r->get_header_value("Content-Type");
  if (r->status != 304) raw.body = std::move(r->body);
  return raw;
}

void Api::get_stream(const std::string& path, std::string* content_type,
                     const std::function<bool(const char* data, std::size_t n)>& on_bytes) const {
  int status = 0;
  std::string error_body;
  bool stopped = false;
  auto c = make_client(origin_, token_, 30);  // a stream repeats its last frame every second
  auto r = c->Get(
      prefix_ + path, httplib::Headers{},
      [&](const httplib::Response& res) {
        status = res.status;
        if (content_type != nullptr) *content_type = res.get_header_value("Content-Type");
        return true;
      },
      [&](const char* data, std::size_t n) {
        if (status >= 400) {
          if (error_body.size() < (1 << 16)) error_body.append(data, n);
          return true;
        }
        stopped = !on_bytes(data, n);
        return !stopped;
      });
  if (stopped) return;
  if (!r) throw transport_error(server_, r.error());
  if (status >= 400) throw ClientError::from_response(status, error_body);
}

}  // namespace levelset::client
