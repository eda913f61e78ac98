// ApiError: a refusal with its HTTP status, a stable code and a readable message, raised by the
// service layer (plain C++) and turned into {"error": {"code", "message", "details"}} by the
// HTTP layer. from_error maps the core's typed levelset::Error onto a status:
//   ParseError, Truncated, Corrupt -> 400; InvalidArgument, NonFinite -> 422;
//   UnsupportedFormat, UnsupportedVersion -> 415; LimitExceeded -> 507; Cancelled -> 409;
//   IoError -> 500 (507 when the disk is full).
#pragma once

#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.hpp"

namespace levelset::service {

class ApiError : public std::runtime_error {
 public:
  ApiError(int status, std::string code, std::string message, nlohmann::json details = nlohmann::json::object());

  int status() const { return status_; }
  const std::string& code() const { return code_; }
  const std::string& message() const { return message_; }
  const nlohmann::json& details() const { return details_; }
  nlohmann::json body() const;  // {"error": {...}}

  static ApiError from_error(const Error& e);

 private:
  int status_;
  std::string code_, message_;
  nlohmann::json details_;
};

// The usual refusals.
ApiError not_found(const std::string& what, const std::string& id);
ApiError bad_request(const std::string& message, nlohmann::json details = nlohmann::json::object());
ApiError unprocessable(const std::string& field, const std::string& message);
ApiError conflict(const std::string& message);

}  // namespace levelset::service
