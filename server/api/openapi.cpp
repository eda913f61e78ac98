#include "api/openapi.hpp"

#include <cctype>

#ifndef LEVELSET_VERSION
#define LEVELSET_VERSION "0.0.0"
#endif

namespace levelset::api {

using nlohmann::json;

namespace {

std::string operation_id(const Route& r) {
  std::string id;
  bool upper = false;
  for (char c : r.method + r.path) {
    if (!std::isalnum(static_cast<unsigned char>(c))) {
      upper = true;
      continue;
    }
    id += upper ? char(std::toupper(static_cast<unsigned char>(c))) : char(std::tolower(static_cast<unsigned char>(c)));
    upper = false;
  }
  return id;
}

}  // namespace

json openapi_document(const std::vector<Route>& routes) {
  json paths = json::object();
  for (const Route& r : routes) {
    json op = {{"summary", r.summary}, {"operationId", operation_id(r)}};
    json params = json::array();
    for (std::size_t i = r.path.find('{'); i != std::string::npos; i = r.path.find('{', i + 1)) {
      const std::string name = r.path.substr(i + 1, r.path.find('}', i) - i - 1);
      params.push_back({{"name", name}, {"in", "path"}, {"required", true}, {"schema", {{"type", "string"}}}});
    }
    for (const std::string& q : r.query)
      params.push_back({{"name", q}, {"in", "query"}, {"required", false}, {"schema", {{"type", "string"}}}});
    if (!params.empty()) op["parameters"] = params;
    if (!r.request.is_null()) op["requestBody"] = {{"required", true}, {"content", r.request}};
    json responses = json::object();
    for (const auto& [code, description] : r.responses.items())
      responses[code] = {{"description", description}};
    responses["default"] = {{"description", "an error"},
                            {"content", {{"application/json", {{"schema", {{"$ref", "#/components/schemas/Error"}}}}}}}};
    op["responses"] = responses;
    if (r.writes) op["security"] = json::array({{{"bearer", json::array()}}});
    std::string method = r.method;
    for (char& c : method) c = char(std::tolower(static_cast<unsigned char>(c)));
    paths[r.path][method] = op;
  }
  return {{"openapi", "3.0.3"},
          {"info", {{"title", "levelsetd"}, {"version", LEVELSET_VERSION},
                    {"description", "Narrow-band level-set sessions, jobs and results"}}},
          {"paths", paths},
          {"components",
           {{"securitySchemes", {{"bearer", {{"type", "http"}, {"scheme", "bearer"}}}}},
            {"schemas",
             {{"Error",
               {{"type", "object"},
                {"properties",
                 {{"error",
                   {{"type", "object"},
                    {"properties", {{"code", {{"type", "string"}}}, {"message", {{"type", "string"}}}, {"details", {{"type", "object"}}}}}}}}}}}}}}}};
}

}  // namespace levelset::api
