// Job and configuration files in the thesis's format (4.8, A.3), extended as the jobs need.
//
//   // a comment (to the end of the line)
//   pcfile = knot                      a word: letters, digits, _ . / - + :
//   depth = 6                          a number
//   bbmin = (-0.12, 0.01, -0.08)       a tuple of numbers
//   formula = -sign(H)*sqrt(K+abs(K))  anything else: the rest of the line, trimmed (the
//                                      thesis writes formulas bare)
//   name = "a string"                  a quoted string (\" and \\ escapes)
//   raster { depth = 6 }               a set of entries; sets nest
//
// Entries are `key = value` or `key { ... }`, one per line (a set's `}` may follow entries
// on the same line). Keys are identifiers; a key appears at most once per set.
// parse_config: the tree, each entry with its 1-based line and column. Errors: Error{ParseError}
//   at "NAME:LINE:COLUMN" (NAME = options.name, e.g. the file) with the reason;
//   Error{LimitExceeded} for text over limits.max_bytes, sets nested deeper than
//   limits.max_depth or more than limits.max_entries entries.
// check_keys: Error{InvalidArgument} at the entry's place for a key not in `allowed`, with a
//   "did you mean" when a known key is within two edits.
// set_override: applies "a.b.c=value" (the CLI's --set) to the tree, creating sets as needed;
//   the value is parsed like a file's. Errors as parse_config, at "--set".
// Cost: O(text). Threading: plain data, no shared state.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace levelset::config {

struct Value {
  enum class Kind { Number, Word, String, Tuple, Text } kind = Kind::Word;
  double number = 0;            // Number
  std::string text;             // Word, String, Text (and the source text of a Number / Tuple)
  std::vector<double> tuple;    // Tuple
};

struct Entry;

struct Set {
  std::vector<Entry> entries;
  const Entry* find(std::string_view key) const;
  Entry* find(std::string_view key);
};

struct Entry {
  std::string key;
  int line = 0, column = 0;
  bool is_set = false;
  Value value;   // when !is_set
  Set set;       // when is_set
  std::string override_text;  // "a.b=v" when set_override gave the value (line = column = 0)
};

// Where an entry is, for errors: "NAME:LINE:COLUMN", or "--set a.b=v" for an override.
std::string place_of(const Entry& entry, std::string_view name);

struct Limits {
  std::size_t max_bytes = std::size_t{1} << 20;
  int max_depth = 32;
  std::size_t max_entries = 100000;
};

struct ParseOptions {
  std::string name = "config";  // where errors say they are (a file name)
  Limits limits;
};

Set parse_config(std::string_view text, const ParseOptions& options = {});

// Reads and parses a file (errors name the file; Error{IoError} when it cannot be read).
Set read_config_file(const std::string& path, const Limits& limits = {});

void check_keys(const Set& set, const std::vector<std::string>& allowed, std::string_view name);

void set_override(Set& root, std::string_view assignment);

}  // namespace levelset::config
