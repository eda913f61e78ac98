// TextScanner: the shared tokenizer of the text readers (OFF, tria, PLY ascii, OBJ, STL ascii,
// XYZ). Header-only so its per-character loops inline into the readers' hot paths.
//
// Input: a view of the whole file (not copied; it must outlive the scanner), the name used in
// error messages, and an optional comment character (0 = none). A comment runs from that
// character to the end of the line and counts as whitespace, also directly after a token
// ("0.9 0#red" is two tokens). Whitespace is ' ', '\t', '\r', '\v', '\f'; '\n' ends a line.
// Tokens are maximal runs of other characters.
// Output: tokens as views into the input, numbers through std::from_chars (a leading '+' is
// accepted), and line numbers (1-based, the line of the last token read) for messages.
// Errors: the parse_* and fail_* helpers throw levelset::Error with where = "name:line":
// ParseError for a malformed token, Truncated when the input ends where a token is needed,
// NonFinite for nan/inf (and decimal overflow), LimitExceeded for integers that overflow.
// Cost: O(1) per character, no allocation except in error messages.
// Threading: one scanner per thread; it is a cursor.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>

#include "core/error.hpp"

namespace levelset {

class TextScanner {
 public:
  TextScanner(std::string_view text, std::string_view name, char comment = 0, std::size_t start = 0,
              std::uint64_t start_line = 1)
      : text_(text), name_(name), pos_(start), line_(start_line), comment_(comment) {}

  std::string_view name() const { return name_; }
  std::uint64_t line() const { return line_; }
  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return text_.size() - pos_; }
  bool eof() const { return pos_ >= text_.size(); }
  std::string where() const { return at_line(name_, line_); }

  // Skips blanks and a trailing comment on the current line; stops at '\n' or the end.
  void skip_blanks() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (is_blank(c)) {
        ++pos_;
      } else if (comment_ != 0 && c == comment_) {
        skip_comment();
        return;
      } else {
        return;
      }
    }
  }

  // True when nothing but blanks and a comment remain on the current line.
  bool at_end_of_line() {
    skip_blanks();
    return pos_ >= text_.size() || text_[pos_] == '\n';
  }

  // Skips blanks, comments and newlines up to the next token; false at the end of input.
  bool skip_to_token() {
    for (;;) {
      skip_blanks();
      if (pos_ >= text_.size()) return false;
      if (text_[pos_] != '\n') return true;
      ++pos_;
      ++line_;
    }
  }

  // The next token on the current line; empty at the end of the line (the '\n' stays).
  std::string_view line_token() {
    skip_blanks();
    return take_token();
  }

  // The next token, crossing line ends; empty at the end of input.
  std::string_view next_token() {
    if (!skip_to_token()) return {};
    return take_token();
  }

  // Discards the rest of the current line including its '\n'.
  void skip_line() {
    const void* nl = std::memchr(text_.data() + pos_, '\n', text_.size() - pos_);
    if (nl == nullptr) {
      pos_ = text_.size();
    } else {
      pos_ = static_cast<std::size_t>(static_cast<const char*>(nl) - text_.data()) + 1;
      ++line_;
    }
  }

  // The rest of the current line (without '\n' and a trailing '\r'), consumed with its '\n'.
  std::string_view rest_of_line() {
    const std::size_t begin = pos_;
    const void* nl = std::memchr(text_.data() + pos_, '\n', text_.size() - pos_);
    const std::size_t end =
        nl == nullptr ? text_.size()
                      : static_cast<std::size_t>(static_cast<const char*>(nl) - text_.data());
    std::string_view rest = text_.substr(begin, end - begin);
    if (!rest.empty() && rest.back() == '\r') rest.remove_suffix(1);
    pos_ = end;
    if (pos_ < text_.size()) {
      ++pos_;
      ++line_;
    }
    return rest;
  }

  // Requires the current line to hold nothing more, then moves to the next line.
  void expect_end_of_line(std::string_view after) {
    const std::string_view extra = line_token();
    if (!extra.empty())
      fail(ErrorCode::ParseError, "expected the end of the line after " + std::string(after) +
                                      ", found '" + quote(extra) + "'");
    if (pos_ < text_.size()) {
      ++pos_;  // the '\n'
      ++line_;
    }
  }

  // Moves past the '\n' that ends the current line (call when at_end_of_line()).
  void consume_newline() {
    if (pos_ < text_.size() && text_[pos_] == '\n') {
      ++pos_;
      ++line_;
    }
  }

  // ---- numbers -------------------------------------------------------------------------

  // A finite double. tok empty means "missing": Truncated at the end of input, else
  // ParseError ("found the end of the line").
  double parse_double(std::string_view tok, std::string_view what) const {
    if (tok.empty()) fail_missing(what);
    double value = 0.0;
    if (!to_double(tok, value)) fail_expected(what, "a number", tok);
    if (!std::isfinite(value))
      fail(ErrorCode::NonFinite,
           "expected a finite number for " + std::string(what) + ", found '" + quote(tok) + "'");
    return value;
  }

  // Any number, finite or not (for values that are read and then ignored).
  double parse_any_number(std::string_view tok, std::string_view what) const {
    if (tok.empty()) fail_missing(what);
    double value = 0.0;
    if (!to_double(tok, value)) fail_expected(what, "a number", tok);
    return value;
  }

  std::int64_t parse_int(std::string_view tok, std::string_view what) const {
    if (tok.empty()) fail_missing(what);
    std::string_view digits = tok;
    if (digits.size() > 1 && digits[0] == '+' && digits[1] != '-') digits.remove_prefix(1);
    std::int64_t value = 0;
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec == std::errc::result_out_of_range && ptr == digits.data() + digits.size())
      fail(ErrorCode::LimitExceeded,
           std::string(what) + " '" + quote(tok) + "' does not fit in 64 bits");
    if (ec != std::errc() || ptr != digits.data() + digits.size())
      fail_expected(what, "an integer", tok);
    return value;
  }

  // A non-negative integer (counts, indices).
  std::uint64_t parse_count(std::string_view tok, std::string_view what) const {
    const std::int64_t value = parse_int(tok, what);
    if (value < 0)
      fail(ErrorCode::ParseError,
           "expected a non-negative " + std::string(what) + ", found " + std::to_string(value));
    return static_cast<std::uint64_t>(value);
  }

  static bool is_number(std::string_view tok) {
    double value = 0.0;
    return !tok.empty() && to_double(tok, value);
  }

  // Parses a whole token as a double; false if it is not one. Overflowing decimals give
  // +-inf, underflowing ones the nearest representable value (strtod semantics).
  static bool to_double(std::string_view tok, double& value) {
    std::string_view digits = tok;
    if (digits.size() > 1 && digits[0] == '+' && digits[1] != '-') digits.remove_prefix(1);
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ptr != digits.data() + digits.size()) return false;
    if (ec == std::errc()) return true;
    if (ec != std::errc::result_out_of_range) return false;
    // Rare: let strtod pick +-inf (overflow) or the nearest tiny value (underflow).
    const std::string copy(digits);
    value = std::strtod(copy.c_str(), nullptr);
    return true;
  }

  // ---- errors --------------------------------------------------------------------------

  [[noreturn]] void fail(ErrorCode code, std::string reason) const {
    throw Error(code, where(), std::move(reason));
  }

  [[noreturn]] void fail_missing(std::string_view what) const {
    if (pos_ >= text_.size())
      fail(ErrorCode::Truncated, "expected " + std::string(what) + ", found the end of the file");
    fail(ErrorCode::ParseError, "expected " + std::string(what) + ", found the end of the line");
  }

  [[noreturn]] void fail_expected(std::string_view what, std::string_view kind,
                                  std::string_view tok) const {
    fail(ErrorCode::ParseError, "expected " + std::string(what) + " (" + std::string(kind) +
                                    "), found '" + quote(tok) + "'");
  }

  // A token made printable and short for messages.
  static std::string quote(std::string_view tok) {
    constexpr std::size_t kMax = 40;
    std::string out;
    for (std::size_t i = 0; i < tok.size() && i < kMax; ++i) {
      const auto c = static_cast<unsigned char>(tok[i]);
      if (c >= 0x20 && c < 0x7f) {
        out += static_cast<char>(c);
      } else {
        static constexpr char kHex[] = "0123456789abcdef";
        out += "\\x";
        out += kHex[c >> 4];
        out += kHex[c & 15];
      }
    }
    if (tok.size() > kMax) out += "...";
    return out;
  }

 private:
  static bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
  }

  void skip_comment() {
    const void* nl = std::memchr(text_.data() + pos_, '\n', text_.size() - pos_);
    pos_ = nl == nullptr ? text_.size()
                         : static_cast<std::size_t>(static_cast<const char*>(nl) - text_.data());
  }

  std::string_view take_token() {
    const std::size_t begin = pos_;
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n' || is_blank(c) || (comment_ != 0 && c == comment_)) break;
      ++pos_;
    }
    return text_.substr(begin, pos_ - begin);
  }

  std::string_view text_;
  std::string_view name_;
  std::size_t pos_;
  std::uint64_t line_;
  char comment_;
};

}  // namespace levelset
