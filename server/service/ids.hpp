// Ids the server names things by: "<replica>-<kind>-<16 hex>" (kind s: session, j: job,
// n: snapshot; uploads add their format's extension, "<replica>-u-<hex>.off"), so any replica
// can tell which one owns a session. is_valid_id refuses anything else before it reaches the
// filesystem (no client path ever does). now_iso(): UTC time, ISO 8601.
#pragma once

#include <string>
#include <string_view>

namespace levelset::service {

std::string new_id(const std::string& replica, char kind);
bool is_valid_id(std::string_view id, char kind);
std::string replica_of(std::string_view id);
std::string now_iso();

}  // namespace levelset::service
