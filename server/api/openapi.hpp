// The OpenAPI 3.0 document of the route table: every route with its path parameters, query
// parameters, request body and responses; the error object shared by all refusals.
#pragma once

#include <vector>

#include <nlohmann/json.hpp>

#include "api/route.hpp"

namespace levelset::api {

nlohmann::json openapi_document(const std::vector<Route>& routes);

}  // namespace levelset::api
