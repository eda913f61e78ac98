#include "core/error.hpp"

#include "core/text.hpp"

namespace levelset {

std::string_view to_string(ErrorCode code) {
  switch (code) {
    case ErrorCode::InvalidArgument: return "invalid_argument";
    case ErrorCode::IoError: return "io_error";
    case ErrorCode::ParseError: return "parse_error";
    case ErrorCode::Truncated: return "truncated";
    case ErrorCode::Corrupt: return "corrupt";
    case ErrorCode::UnsupportedVersion: return "unsupported_version";
    case ErrorCode::UnsupportedFormat: return "unsupported_format";
    case ErrorCode::LimitExceeded: return "limit_exceeded";
    case ErrorCode::NonFinite: return "non_finite";
    case ErrorCode::Cancelled: return "cancelled";
  }
  return "unknown";
}

namespace {
std::string compose(ErrorCode code, const std::string& where, const std::string& reason) {
  std::string msg(to_string(code));
  if (!where.empty()) msg += " at " + where;
  msg += ": " + reason;
  return msg;
}
}  // namespace

// Places and reasons often quote untrusted bytes (file names, formulas, job files): both are
// kept valid UTF-8 (stray bytes as \xNN) so every message can go into JSON as it is.
Error::Error(ErrorCode code, std::string where, std::string reason)
    : std::runtime_error(compose(code, sanitize_utf8(where), sanitize_utf8(reason))),
      code_(code),
      where_(sanitize_utf8(where)),
      reason_(sanitize_utf8(reason)) {}

std::string at_line(std::string_view file, std::uint64_t line) {
  return std::string(file) + ":" + std::to_string(line);
}

std::string at_byte(std::string_view file, std::uint64_t offset) {
  return std::string(file) + " @ byte " + std::to_string(offset);
}

}  // namespace levelset
