#include "service/api_error.hpp"

#include "core/text.hpp"

namespace levelset::service {

namespace {
// Messages never echo unbounded input.
std::string bounded(const std::string& s) {
  constexpr std::size_t kMax = 2000;
  return sanitize_utf8(s.size() > kMax ? s.substr(0, kMax) + "..." : s);
}
}  // namespace

ApiError::ApiError(int status, std::string code, std::string message, nlohmann::json details)
    : std::runtime_error(message), status_(status), code_(std::move(code)), message_(bounded(message)),
      details_(std::move(details)) {}

nlohmann::json ApiError::body() const {
  return {{"error", {{"code", code_}, {"message", message_}, {"details", details_}}}};
}

ApiError ApiError::from_error(const Error& e) {
  int status = 500;
  switch (e.code()) {
    case ErrorCode::ParseError:
    case ErrorCode::Truncated:
    case ErrorCode::Corrupt: status = 400; break;
    case ErrorCode::InvalidArgument:
    case ErrorCode::NonFinite: status = 422; break;
    case ErrorCode::UnsupportedFormat:
    case ErrorCode::UnsupportedVersion: status = 415; break;
    case ErrorCode::LimitExceeded: status = 507; break;
    case ErrorCode::Cancelled: status = 409; break;
    case ErrorCode::IoError:
      status = e.reason().find("No space") != std::string::npos || e.reason().find("quota") != std::string::npos ||
                       e.reason().find("File too large") != std::string::npos
                   ? 507
                   : 500;
      break;
  }
  return ApiError(status, std::string(to_string(e.code())), e.where().empty() ? e.reason() : e.where() + ": " + e.reason(),
                  {{"where", bounded(e.where())}, {"reason", bounded(e.reason())}});
}

ApiError not_found(const std::string& what, const std::string& id) {
  return ApiError(404, "not_found", "no " + what + " '" + bounded(id.substr(0, 80)) + "'");
}
ApiError bad_request(const std::string& message, nlohmann::json details) {
  return ApiError(400, "bad_request", message, std::move(details));
}
ApiError unprocessable(const std::string& field, const std::string& message) {
  return ApiError(422, "invalid_argument", field + ": " + message, {{"field", field}});
}
ApiError conflict(const std::string& message) { return ApiError(409, "conflict", message); }

}  // namespace levelset::service
