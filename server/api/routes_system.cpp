// GET /healthz, /readyz, /metrics, /api/v1, /api/v1/openapi.json.
#include "api/openapi.hpp"
#include "api/route.hpp"
#include "service/api_error.hpp"

namespace levelset::api {

using nlohmann::json;

extern const std::string_view kViewerPage;

void add_system_routes(std::vector<Route>& r) {
  r.push_back({"GET", "/", "The browser viewer (one static page over this API)", false, false, {}, nullptr,
               {{"200", "text/html"}},
               [](RouteContext& c) { c.res.set_content(std::string(kViewerPage), "text/html; charset=utf-8"); }});
  r.push_back({"GET", "/healthz", "Liveness: the process answers", false, false, {}, nullptr,
               {{"200", "alive"}}, [](RouteContext& c) { c.reply(200, {{"status", "ok"}}); }});
  r.push_back({"GET", "/readyz", "Readiness: sessions loaded and not shutting down", false, false, {}, nullptr,
               {{"200", "ready"}, {"503", "starting or shutting down"}}, [](RouteContext& c) {
                 if (!c.service.ready()) throw service::ApiError(503, "not_ready", "the server is shutting down");
                 c.reply(200, {{"status", "ready"}, {"sessions", c.service.sessions().count()}});
               }});
  r.push_back({"GET", "/metrics", "Prometheus metrics (text format 0.0.4)", false, false, {}, nullptr,
               {{"200", "metrics"}}, [](RouteContext& c) {
                 c.res.set_content(c.service.metrics(), "text/plain; version=0.0.4; charset=utf-8");
               }});
  r.push_back({"GET", "/api/v1", "Version, limits and operations", false, false, {}, nullptr, {{"200", "the API"}},
               [](RouteContext& c) { c.reply(200, c.service.api_info()); }});
  r.push_back({"GET", "/api/v1/openapi.json", "This API as an OpenAPI 3.0 document", false, false, {}, nullptr,
               {{"200", "OpenAPI document"}}, [](RouteContext& c) { c.reply(200, openapi_document(api_routes())); }});
}

}  // namespace levelset::api
