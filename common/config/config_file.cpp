#include "config/config_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <unordered_set>

#include "core/error.hpp"
#include "core/text.hpp"
#include "core/file_io.hpp"
#include "core/suggest.hpp"

namespace levelset::config {

const Entry* Set::find(std::string_view key) const {
  for (const Entry& e : entries)
    if (e.key == key) return &e;
  return nullptr;
}

Entry* Set::find(std::string_view key) {
  for (Entry& e : entries)
    if (e.key == key) return &e;
  return nullptr;
}

namespace {

bool is_key_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_key_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool is_word_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("_./-+:").find(c) != std::string_view::npos;
}

// A strict number: strtod over the whole token, finite.
bool parse_number(std::string_view s, double& out) {
  if (s.empty() || s.size() > 64) return false;
  const std::string copy(s);
  char* end = nullptr;
  out = std::strtod(copy.c_str(), &end);
  return end == copy.c_str() + copy.size() && std::isfinite(out) &&
         (std::isdigit(static_cast<unsigned char>(copy[0])) || copy[0] == '-' || copy[0] == '+' || copy[0] == '.');
}

class Parser {
 public:
  // A UTF-8 byte order mark (editors on Windows write one) is skipped; lines and columns count
  // from after it.
  Parser(std::string_view text, const ParseOptions& options)
      : text_(text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text), options_(options) {}

  Set parse_root() {
    if (text_.size() > options_.limits.max_bytes)
      throw Error(ErrorCode::LimitExceeded, options_.name,
                  std::to_string(text_.size()) + " bytes, more than " + std::to_string(options_.limits.max_bytes));
    Set root = parse_set(0);
    skip_blank();
    if (pos_ < text_.size()) fail("unexpected " + quote_character(text_, pos_).text + " (a '}' without its set?)");
    return root;
  }

  // Parses one value from the current position to the end of its line (or a closing '}').
  Value parse_value() {
    skip_spaces();
    Value v;
    if (pos_ >= text_.size() || text_[pos_] == '\n' || starts_comment()) fail("expected a value after '='");
    const char c = text_[pos_];
    if (c == '"') {
      v.kind = Value::Kind::String;
      ++pos_;
      while (true) {
        if (pos_ >= text_.size() || text_[pos_] == '\n') fail("unterminated string");
        const char d = text_[pos_++];
        if (d == '"') break;
        if (d == '\\') {
          if (pos_ >= text_.size() || (text_[pos_] != '"' && text_[pos_] != '\\'))
            fail_at(pos_ - 1, "unknown escape in a string (use \\\" or \\\\)");
          v.text += text_[pos_++];
          continue;
        }
        v.text += d;
      }
      end_of_value();
      return v;
    }
    if (c == '(') {
      v.kind = Value::Kind::Tuple;
      const std::size_t start = pos_;
      ++pos_;
      while (true) {
        skip_spaces();
        const std::size_t s = pos_;
        while (pos_ < text_.size() && text_[pos_] != ',' && text_[pos_] != ')' && text_[pos_] != '\n') ++pos_;
        std::string_view item = text_.substr(s, pos_ - s);
        while (!item.empty() && std::isspace(static_cast<unsigned char>(item.back()))) item.remove_suffix(1);
        double x = 0;
        if (!parse_number(item, x)) fail_at(s, "expected a number in the tuple, found '" + std::string(item) + "'");
        if (v.tuple.size() >= 4096) fail_at(s, "tuple longer than 4096 numbers");
        v.tuple.push_back(x);
        if (pos_ >= text_.size() || text_[pos_] == '\n') fail("unterminated tuple: expected ')'");
        if (text_[pos_++] == ')') break;
      }
      v.text = std::string(text_.substr(start, pos_ - start));
      end_of_value();
      return v;
    }
    // A number or a word when the whole rest of the value is one; else raw text.
    const std::size_t start = pos_;
    std::size_t end = start;
    while (end < text_.size() && text_[end] != '\n' && !(text_[end] == '/' && end + 1 < text_.size() && text_[end + 1] == '/') &&
           text_[end] != '}' && !((text_[end] == ' ' || text_[end] == '\t') && entry_follows(end)))
      ++end;
    std::string_view raw = text_.substr(start, end - start);
    while (!raw.empty() && std::isspace(static_cast<unsigned char>(raw.back()))) raw.remove_suffix(1);
    pos_ = start + raw.size();
    v.text = std::string(raw);
    double x = 0;
    if (parse_number(raw, x)) {
      v.kind = Value::Kind::Number;
      v.number = x;
    } else if (std::all_of(raw.begin(), raw.end(), is_word_char)) {
      v.kind = Value::Kind::Word;
    } else {
      v.kind = Value::Kind::Text;
    }
    return v;
  }

 private:
  [[noreturn]] void fail_at(std::size_t at, const std::string& why) const {
    int line = 1, column = 1;
    for (std::size_t i = 0; i < at && i < text_.size(); ++i) {
      if (text_[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    throw Error(ErrorCode::ParseError, options_.name + ":" + std::to_string(line) + ":" + std::to_string(column), why);
  }
  [[noreturn]] void fail(const std::string& why) const { fail_at(pos_, why); }

  bool starts_comment() const { return pos_ + 1 < text_.size() && text_[pos_] == '/' && text_[pos_ + 1] == '/'; }

  void skip_spaces() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\r')) ++pos_;
  }
  // Spaces, newlines and comments.
  void skip_blank() {
    while (pos_ < text_.size()) {
      if (std::isspace(static_cast<unsigned char>(text_[pos_]))) {
        ++pos_;
      } else if (starts_comment()) {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else {
        break;
      }
    }
  }
  // Whether the blanks at `at` are followed by the next entry on the same line: a key, then '='
  // (not '==') or '{'. Entries may share a line (`raster { resolution = 128  band = 3 }`, as
  // the thesis's format allows); formulas never contain a lone '=', so they are not cut.
  bool entry_follows(std::size_t at) const {
    while (at < text_.size() && (text_[at] == ' ' || text_[at] == '\t')) ++at;
    if (at >= text_.size() || !is_key_start(text_[at])) return false;
    while (at < text_.size() && is_key_char(text_[at])) ++at;
    while (at < text_.size() && (text_[at] == ' ' || text_[at] == '\t')) ++at;
    if (at >= text_.size()) return false;
    if (text_[at] == '{') return true;
    return text_[at] == '=' && (at + 1 >= text_.size() || text_[at + 1] != '=');
  }

  // After a value: only spaces, a comment, the end of the line, a closing '}' or (after a
  // blank) the next entry.
  void end_of_value() {
    const std::size_t value_end = pos_;
    skip_spaces();
    if (pos_ > value_end && entry_follows(value_end)) return;
    if (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '}' && !starts_comment())
      fail("unexpected " + quote_character(text_, pos_).text + " after the value");
  }

  Set parse_set(int depth) {
    if (depth > options_.limits.max_depth)
      fail("sets nested deeper than " + std::to_string(options_.limits.max_depth));
    Set set;
    std::unordered_set<std::string> keys;  // duplicates in O(1) per entry
    while (true) {
      skip_blank();
      if (pos_ >= text_.size() || text_[pos_] == '}') return set;
      Entry e;
      advance_place(pos_);
      e.line = place_line_;
      e.column = place_column_;
      if (!is_key_start(text_[pos_])) fail("expected a key (a name such as 'depth'), found " + quote_character(text_, pos_).text);
      const std::size_t key_start = pos_;
      while (pos_ < text_.size() && is_key_char(text_[pos_])) ++pos_;
      e.key = std::string(text_.substr(key_start, pos_ - key_start));
      if (!keys.insert(e.key).second) fail_at(key_start, "duplicate key '" + e.key + "'");
      if (++entries_ > options_.limits.max_entries)
        throw Error(ErrorCode::LimitExceeded, options_.name, "more than " + std::to_string(options_.limits.max_entries) + " entries");
      skip_spaces();
      if (pos_ < text_.size() && text_[pos_] == '{') {
        ++pos_;
        e.is_set = true;
        e.set = parse_set(depth + 1);
        if (pos_ >= text_.size()) fail_at(key_start, "set '" + e.key + "' is not closed with '}'");
        ++pos_;  // '}'
      } else if (pos_ < text_.size() && text_[pos_] == '=') {
        ++pos_;
        e.value = parse_value();
      } else {
        fail("expected '=' or '{' after '" + e.key + "'");
      }
      set.entries.push_back(std::move(e));
    }
  }

  // Line and column of `at`, counted forward from the last place asked for (entries come in
  // order, so the whole file is scanned once).
  void advance_place(std::size_t at) {
    for (; place_pos_ < at; ++place_pos_) {
      if (text_[place_pos_] == '\n') {
        ++place_line_;
        place_column_ = 1;
      } else {
        ++place_column_;
      }
    }
  }

  std::string_view text_;
  const ParseOptions& options_;
  std::size_t pos_ = 0;
  std::size_t entries_ = 0;
  std::size_t place_pos_ = 0;
  int place_line_ = 1, place_column_ = 1;
};

}  // namespace

Set parse_config(std::string_view text, const ParseOptions& options) {
  Parser parser(text, options);
  return parser.parse_root();
}

Set read_config_file(const std::string& path, const Limits& limits) {
  ParseOptions options;
  options.name = path;
  options.limits = limits;
  const std::string bytes = read_file_bytes(path, limits.max_bytes);
  return parse_config(bytes, options);
}

std::string place_of(const Entry& entry, std::string_view name) {
  // Entries from a JSON request (the daemon) carry their field path, "body.evolve.speed".
  if (entry.override_text.rfind("body.", 0) == 0) return entry.override_text;
  if (!entry.override_text.empty()) return "--set " + entry.override_text;
  if (entry.line == 0) return "--set";  // a set created by an override
  return std::string(name) + ":" + std::to_string(entry.line) + ":" + std::to_string(entry.column);
}

void check_keys(const Set& set, const std::vector<std::string>& allowed, std::string_view name) {
  for (const Entry& e : set.entries) {
    if (std::find(allowed.begin(), allowed.end(), e.key) != allowed.end()) continue;
    const std::string best = closest_name(e.key, allowed);
    std::string known;
    for (const std::string& a : allowed) known += (known.empty() ? "" : ", ") + a;
    throw Error(ErrorCode::InvalidArgument, place_of(e, name),
                "unknown key '" + e.key + "'" + (best.empty() ? "" : " (did you mean '" + best + "'?)") +
                    "; known here: " + known);
  }
}

void set_override(Set& root, std::string_view assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string_view::npos)
    throw Error(ErrorCode::ParseError, "--set", "expected KEY=VALUE (e.g. raster.depth=7), got '" + std::string(assignment) + "'");
  std::string_view path = assignment.substr(0, eq);
  while (!path.empty() && std::isspace(static_cast<unsigned char>(path.back()))) path.remove_suffix(1);
  // The value, parsed like a file's.
  ParseOptions options;
  options.name = "--set";
  const Set parsed = parse_config("v = " + std::string(assignment.substr(eq + 1)), options);
  if (parsed.entries.size() != 1 || parsed.entries[0].is_set)
    throw Error(ErrorCode::ParseError, "--set", "bad value in '" + std::string(assignment) + "'");
  Set* set = &root;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = path.find('.', start);
    const std::string_view key = path.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start);
    if (key.empty() || !is_key_start(key[0]) || !std::all_of(key.begin(), key.end(), is_key_char))
      throw Error(ErrorCode::ParseError, "--set", "bad key '" + std::string(path) + "'");
    Entry* e = set->find(key);
    if (dot == std::string_view::npos) {
      if (e && e->is_set) throw Error(ErrorCode::ParseError, "--set", "'" + std::string(path) + "' is a set, not a value");
      if (!e) {
        set->entries.push_back(Entry{std::string(key), 0, 0, false, {}, {}, {}});
        e = &set->entries.back();
      }
      e->value = parsed.entries[0].value;
      e->line = e->column = 0;
      e->override_text = std::string(assignment);
      return;
    }
    if (e && !e->is_set) throw Error(ErrorCode::ParseError, "--set", "'" + std::string(key) + "' is a value, not a set");
    if (!e) {
      set->entries.push_back(Entry{std::string(key), 0, 0, true, {}, {}, {}});
      e = &set->entries.back();
    }
    set = &e->set;
    start = dot + 1;
  }
}

}  // namespace levelset::config
