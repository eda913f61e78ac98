// levelset::Error: the one exception type the core throws.
//
// Every failure carries a code (what kind), a place (file + line, byte offset, column,
// or a name) and a reason (why), so the CLI and later the server can answer with a
// clear, structured message instead of crashing. Place and reason are always valid UTF-8
// (bytes that are not become \xNN; core/text.hpp). Readers of untrusted input throw it
// for every malformed case; algorithms throw it for invalid options and cancellation.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace levelset {

enum class ErrorCode {
  InvalidArgument,     // options out of range, bad parameters
  IoError,             // cannot open / read / write / rename
  ParseError,          // malformed text or binary input
  Truncated,           // input ends before its header says it should
  Corrupt,             // checksum mismatch, inconsistent structure
  UnsupportedVersion,  // file written by a newer format version
  UnsupportedFormat,   // unknown extension or magic
  LimitExceeded,       // absurd counts or sizes, memory / voxel budgets
  NonFinite,           // NaN or Inf where a finite number is required
  Cancelled,           // a cancellation token fired
};

std::string_view to_string(ErrorCode code);

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, std::string where, std::string reason);

  ErrorCode code() const noexcept { return code_; }
  const std::string& where() const noexcept { return where_; }
  const std::string& reason() const noexcept { return reason_; }

 private:
  ErrorCode code_;
  std::string where_;
  std::string reason_;
};

// Helpers for the common places: "file.off:12", "file.lsg @ byte 4096".
std::string at_line(std::string_view file, std::uint64_t line);
std::string at_byte(std::string_view file, std::uint64_t offset);

}  // namespace levelset
