#include "lib/client_error.hpp"

namespace levelset::client {

using nlohmann::json;

ClientError::ClientError(Kind kind, std::string code, std::string message, int status)
    : std::runtime_error(code + ": " + message), kind_(kind), code_(std::move(code)), message_(std::move(message)),
      status_(status) {}

int ClientError::exit_code() const {
  switch (kind_) {
    case Kind::Server: return 1;
    case Kind::Usage: return 2;
    case Kind::Connect: return 3;
    case Kind::Local: return 4;
  }
  return 1;
}

namespace {

// One line: control characters become spaces (a message must not break the "one line" rule).
std::string one_line(std::string s, std::size_t max = 2000) {
  if (s.size() > max) s = s.substr(0, max) + "...";
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  return s;
}

}  // namespace

ClientError ClientError::from_response(int status, const std::string& body) {
  const json j = json::parse(body, nullptr, false);
  if (j.is_object() && j.contains("error") && j["error"].is_object()) {
    const json& e = j["error"];
    ClientError error(Kind::Server, one_line(e.value("code", "http_" + std::to_string(status))),
                      one_line(e.value("message", "HTTP " + std::to_string(status))), status);
    if (e.contains("details") && e["details"].is_object()) error.details_ = e["details"];
    return error;
  }
  std::string text = one_line(body, 200);
  if (text.empty()) text = "HTTP " + std::to_string(status);
  return ClientError(Kind::Server, "http_" + std::to_string(status), text, status);
}

ClientError ClientError::from_job_error(const json& error, const std::string& state) {
  if (error.is_object())
    return ClientError(Kind::Server, one_line(error.value("code", "job_" + state)),
                       one_line(error.value("message", "the job " + state)), error.value("status", 0));
  return ClientError(Kind::Server, "job_" + state, "the job ended " + state, 0);
}

}  // namespace levelset::client
