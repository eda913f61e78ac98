#include "core/text.hpp"

#include <cmath>
#include <cstdio>

namespace levelset {

std::string format_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", value);
  return buf;
}

std::size_t utf8_sequence_length(std::string_view text, std::size_t at) {
  if (at >= text.size()) return 0;
  const auto byte = [&](std::size_t i) { return std::uint8_t(text[i]); };
  const std::uint8_t b0 = byte(at);
  if (b0 < 0x80) return 1;
  std::size_t n;
  std::uint32_t cp;
  if (b0 >= 0xC2 && b0 <= 0xDF) {
    n = 2;
    cp = b0 & 0x1Fu;
  } else if (b0 >= 0xE0 && b0 <= 0xEF) {
    n = 3;
    cp = b0 & 0x0Fu;
  } else if (b0 >= 0xF0 && b0 <= 0xF4) {
    n = 4;
    cp = b0 & 0x07u;
  } else {
    return 0;  // continuation byte, overlong lead (C0, C1) or beyond U+10FFFF (F5-FF)
  }
  if (text.size() - at < n) return 0;
  for (std::size_t i = 1; i < n; ++i) {
    const std::uint8_t c = byte(at + i);
    if ((c & 0xC0u) != 0x80u) return 0;
    cp = (cp << 6) | (c & 0x3Fu);
  }
  if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF))) return 0;  // overlong, too big
  if (cp >= 0xD800 && cp <= 0xDFFF) return 0;  // UTF-16 surrogates are not characters
  return n;
}

bool is_valid_utf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_sequence_length(text, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

std::size_t utf8_column(std::string_view text, std::size_t at) {
  std::size_t column = 1;
  for (std::size_t i = 0; i < at && i < text.size();) {
    const std::size_t n = utf8_sequence_length(text, i);
    i += n == 0 ? 1 : n;
    ++column;
  }
  return column;
}

namespace {
std::string hex_byte(std::uint8_t b) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "\\x%02X", unsigned(b));
  return buf;
}

std::uint32_t code_point(std::string_view seq) {
  const auto b = [&](std::size_t i) { return std::uint32_t(std::uint8_t(seq[i])); };
  switch (seq.size()) {
    case 1: return b(0);
    case 2: return (b(0) & 0x1Fu) << 6 | (b(1) & 0x3Fu);
    case 3: return (b(0) & 0x0Fu) << 12 | (b(1) & 0x3Fu) << 6 | (b(2) & 0x3Fu);
    default: return (b(0) & 0x07u) << 18 | (b(1) & 0x3Fu) << 12 | (b(2) & 0x3Fu) << 6 | (b(3) & 0x3Fu);
  }
}
}  // namespace

std::string sanitize_utf8(std::string_view text) {
  if (is_valid_utf8(text)) return std::string(text);
  std::string out;
  out.reserve(text.size() + 16);
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_sequence_length(text, i);
    if (n == 0) {
      out += hex_byte(std::uint8_t(text[i]));
      ++i;
    } else {
      out.append(text.substr(i, n));
      i += n;
    }
  }
  return out;
}

QuotedCharacter quote_character(std::string_view text, std::size_t at) {
  QuotedCharacter q;
  const std::size_t n = utf8_sequence_length(text, at);
  if (n == 0) {
    if (at >= text.size()) {
      q.text = "end of text";
    } else {
      char buf[16];
      std::snprintf(buf, sizeof buf, "byte 0x%02X", unsigned(std::uint8_t(text[at])));
      q.text = buf;
    }
    return q;
  }
  q.bytes = n;
  const std::uint32_t cp = code_point(text.substr(at, n));
  char code[16];
  std::snprintf(code, sizeof code, "U+%04X", unsigned(cp));
  if (cp < 0x20 || cp == 0x7F || (cp >= 0x80 && cp < 0xA0)) {
    q.text = code;  // a control character: its code point only
  } else {
    // Appended piece by piece: gcc 12's -Wrestrict misfires on chained operator+ here.
    q.text.reserve(n + 12);
    q.text.push_back('\'');
    q.text.append(text.substr(at, n));
    q.text.push_back('\'');
    if (n > 1) {
      q.text.append(" (");
      q.text.append(code);
      q.text.push_back(')');
    }
  }
  return q;
}

}  // namespace levelset
