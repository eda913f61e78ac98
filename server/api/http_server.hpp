// HttpServer: cpp-httplib serving the route table (route.hpp) for a Service.
//
// Every request gets an X-Request-Id (the client's, if it sent a sane one), one log line
// (text or JSON), a JSON error body for every refusal, and the checks before any handler:
// bearer token (401 with WWW-Authenticate; a read-only token on a writing route 403), 503 while
// shutting down, 413 past the body limit, Idempotency-Key replay for POSTs. Loopback needs no
// token unless tokens are configured; beyond loopback tokens are required (or
// --insecure-no-auth). CORS only for the configured origin.
// The listen backlog is raised to 1024 after bind (the Debian .so compiles in 5; see
// ../shared/notes/stack.md). Threading: httplib's pool (max_streams + 16 threads).
#pragma once

#include <map>
#include <memory>
#include <string>

#include <httplib.h>

#include "api/replica_routing.hpp"
#include "service/service.hpp"

namespace levelset::api {

enum class Role { ReadOnly, ReadWrite };

// Tokens from a file (one per line: TOKEN [rw|ro]; # comments) and "T[:ro],..." text.
std::map<std::string, Role> load_tokens(const std::string& file, const std::string& list);

class HttpServer {
 public:
  explicit HttpServer(service::Service& service);
  ~HttpServer();

  int bind();      // to the configured host and port (0: any); returns the port; Error on failure
  void listen();   // blocks until stop()
  void stop();

 private:
  void install();
  void handle(const struct Route& route, const httplib::Request& req, httplib::Response& res,
              const httplib::ContentReader* reader);
  void authenticate(const struct Route& route, const httplib::Request& req) const;
  std::string read_body(const httplib::Request& req, const httplib::ContentReader& reader) const;

  service::Service& service_;
  std::unique_ptr<httplib::Server> server_;
  std::map<std::string, Role> tokens_;
  std::unique_ptr<ReplicaRouting> routing_;
  bool loopback_ = true;
  int listen_fd_ = -1;
};

}  // namespace levelset::api
