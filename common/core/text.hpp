// Text helpers for messages: short numbers and valid UTF-8.
//
// Every message the project emits (errors, logs, JSON bodies) must be valid UTF-8, yet it
// often quotes untrusted bytes (a formula, a job file, a file name). These helpers quote such
// bytes safely: a whole UTF-8 character stays as it is, anything else becomes \xNN.
// Pure functions; thread-safe; no allocation beyond the returned string.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace levelset {

// A number in short form, like printf's %.6g ("1000", "1e-12", "0.25", "nan", "inf").
std::string format_number(double value);

// Length in bytes of the well-formed UTF-8 sequence starting at text[at] (1-4), or 0 when
// the bytes there are not one (a stray continuation byte, an overlong form, a surrogate, a
// code point above U+10FFFF, or a sequence cut short by the end of the text).
std::size_t utf8_sequence_length(std::string_view text, std::size_t at);

bool is_valid_utf8(std::string_view text);

// 1-based column of byte offset `at` counted in characters (UTF-8 lead bytes and stray bytes
// count one each), for carets under a line of text.
std::size_t utf8_column(std::string_view text, std::size_t at);

// `text` with every byte that is not part of a well-formed UTF-8 sequence written as \xNN;
// valid text is returned unchanged.
std::string sanitize_utf8(std::string_view text);

// The character starting at text[at] for a message: "'é' (U+00E9)" for a UTF-8 character
// beyond ASCII, "'x'" for a printable ASCII one, "byte 0xC3" for a byte that starts no
// well-formed sequence, and "U+0009" style for control characters. Also its length in bytes
// (1 for a lone byte), so a tokenizer can skip the whole character.
struct QuotedCharacter {
  std::string text;
  std::size_t bytes = 1;
};
QuotedCharacter quote_character(std::string_view text, std::size_t at);

}  // namespace levelset
