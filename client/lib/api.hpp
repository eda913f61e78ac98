// Api: the levelsetd REST API over HTTP for levelsetctl (cpp-httplib). Every call opens its own
// connection (a CLI makes few requests), sends the bearer token when one is set, and turns a
// status >= 400 into ClientError::from_response and a transport failure into a Connect error.
//
// server: "http://HOST:PORT" or "https://HOST:PORT", optionally with a path prefix (a proxy
// mount: "http://host/levelset"); paths given to the calls start with "/api/v1/...".
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

namespace levelset::client {

struct SseEvent;

class Api {
 public:
  Api(std::string server, std::string token);  // ClientError{Usage} for a malformed URL

  const std::string& server() const { return server_; }

  nlohmann::json get(const std::string& path) const;
  // POST / PATCH / PUT a JSON body; `status` (when given) receives the HTTP status (201 vs 202).
  nlohmann::json post(const std::string& path, const nlohmann::json& body, int* status = nullptr) const;
  nlohmann::json patch(const std::string& path, const nlohmann::json& body) const;
  nlohmann::json put(const std::string& path, const nlohmann::json& body) const;
  nlohmann::json del(const std::string& path) const;  // null for 204

  // POST /api/v1/uploads?format=FORMAT with the file streamed as the raw body (with its
  // Content-Length); the server's JSON answer. A file over 1 MiB is first checked against the
  // server's formats and max_upload_bytes (GET /api/v1): a server refusing before it reads the
  // body closes the connection while the client still sends, and its answer would be lost.
  nlohmann::json upload(const std::string& file, const std::string& format) const;
  // GET into `file`, written to FILE.part-PID and renamed at the end (nothing left on errors).
  std::uint64_t download(const std::string& path, const std::string& file) const;

  // Server-Sent Events of `path`, from after `last_event_id` when not empty. Calls on_event for
  // each event (return false to stop). Returns normally when the stream ends or on_event stopped
  // it; throws ClientError{Server} for a refusal and ClientError{Connect} when the connection
  // could not be made or broke (the caller resumes with the last id it saw).
  // `stop` (optional) is checked on every chunk (the server's keep-alives come each second), so
  // another thread can end a stream that has no events to deliver.
  void events(const std::string& path, const std::string& last_event_id,
              const std::function<bool(const SseEvent&)>& on_event, const std::atomic<bool>* stop = nullptr) const;

  // A GET whose body is kept as bytes (meshes, bands, frames). With `etag` set it is sent as
  // If-None-Match: a 304 answer has status 304 and an empty body. Errors as get().
  struct Raw {
    int status = 0;
    std::string body, etag, content_type;
  };
  Raw get_raw(const std::string& path, const std::string& etag = "") const;
  // A GET streamed to on_bytes as it arrives (the MJPEG stream); on_bytes returns false to end
  // it. `content_type` receives the answer's type before the first bytes. Errors as events().
  void get_stream(const std::string& path, std::string* content_type,
                  const std::function<bool(const char* data, std::size_t n)>& on_bytes) const;

  static std::string encode(const std::string& text);  // percent-encoding for a path or query part

 private:
  std::string server_, origin_, prefix_, token_;
};

}  // namespace levelset::client
