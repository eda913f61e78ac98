// The API's routes as one table: each route's method, path (OpenAPI style, "{id}" for a path
// parameter), summary, query parameters, request and response descriptions, whether it needs a
// read-write token, and its handler. http_server.cpp registers exactly these and openapi.cpp
// documents exactly these, so the two cannot drift apart.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "service/service.hpp"

namespace levelset::api {

class ReplicaRouting;

struct RouteContext {
  service::Service& service;
  const httplib::Request& req;
  httplib::Response& res;
  const httplib::ContentReader* reader = nullptr;  // uploads: the body, streamed
  std::string body_text;                           // other POST / PATCH routes: the body, read
  const ReplicaRouting* routing = nullptr;         // the other replicas, when configured
  std::string param(std::size_t i) const { return req.matches.size() > i ? std::string(req.matches[i]) : ""; }
  nlohmann::json body() const;  // the JSON body: ApiError 400 (malformed, with line and column) or 413
  void reply(int status, const nlohmann::json& j, const std::string& location = "") const;
  void reply(const service::Reply& r) const { reply(r.status, r.body, r.location); }
};

struct Route {
  std::string method;  // GET POST PATCH DELETE
  std::string path;    // "/api/v1/sessions/{id}"
  std::string summary;
  bool writes = false;  // needs a read-write token
  bool streams_body = false;  // the handler reads the body itself (uploads)
  std::vector<std::string> query;  // documented query parameters
  nlohmann::json request = nullptr;  // request body schema (OpenAPI), or null
  nlohmann::json responses;          // {"200": "description", ...}
  std::function<void(RouteContext&)> handler;
};

const std::vector<Route>& api_routes();
// Runs the route's handler; a JSON field of the wrong type (a number where a name belongs)
// becomes ApiError 422 naming it. Anything but ApiError and levelset::Error escaping is a bug.
void run_handler(const Route& route, RouteContext& ctx);
void add_system_routes(std::vector<Route>& routes);
void add_session_routes(std::vector<Route>& routes);
void add_job_routes(std::vector<Route>& routes);

// Server-Sent Events of one log; state() gives the current state sent first to late joiners.
// `owner` keeps the log alive while the stream is open.
void stream_events(RouteContext& ctx, std::shared_ptr<const void> owner, service::EventLog& log,
                   std::function<nlohmann::json()> state);
// A large body sent in chunks (meshes, bands) with its ETag; If-None-Match gives 304.
void send_blob(RouteContext& ctx, const service::Blob& blob);

}  // namespace levelset::api
