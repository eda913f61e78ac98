// ClientError: why a levelsetctl request did not work, typed so the CLI can pick its exit code.
//   Server:  the server refused the request or the job failed; code/message are the server's
//            {"error": {"code", "message"}} (status = the HTTP status, 0 for a failed job).
//   Connect: no connection, or it broke and could not be resumed.
//   Usage:   the command line or the job file is wrong before anything was sent.
//   Local:   a local file could not be read or written.
#pragma once

#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace levelset::client {

class ClientError : public std::runtime_error {
 public:
  enum class Kind { Server, Connect, Usage, Local };
  ClientError(Kind kind, std::string code, std::string message, int status = 0);

  Kind kind() const { return kind_; }
  const std::string& code() const { return code_; }
  const std::string& message() const { return message_; }
  int status() const { return status_; }
  // The server's "details" object when it sent one (a formula error's field and column), else null.
  const nlohmann::json& details() const { return details_; }
  int exit_code() const;  // Server 1, Usage 2, Connect 3, Local 4

  // From an HTTP error response: the server's JSON error, or "http_STATUS" and the body's start.
  static ClientError from_response(int status, const std::string& body);
  // From a failed job's "error" object ({"code", "message"}).
  static ClientError from_job_error(const nlohmann::json& error, const std::string& state);

 private:
  Kind kind_;
  std::string code_, message_;
  int status_;
  nlohmann::json details_;
};

}  // namespace levelset::client
