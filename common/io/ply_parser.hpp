// PLY header parsing and body value access, shared by the mesh and point-cloud readers.
// Header-only (inline) because both readers use it and its value reads are hot.
//
// parse_ply_header: reads "ply", "format <ascii|binary_little_endian|binary_big_endian> 1.0",
// comment / obj_info lines, "element <name> <count>", "property <type> <name>",
// "property list <count type> <item type> <name>", "end_header". Types: char uchar short
// ushort int uint float double and int8 uint8 int16 uint16 int32 uint32 float32 float64.
// check_ply_body_size: refuses (Truncated) counts that the bytes after the header could not
// hold, before anything is allocated: each binary item needs its fixed bytes plus one count
// per list; each ascii value needs at least two characters.
// PlyBodyReader: reads values in file order in any of the three encodings, bounds-checked.
// Errors: levelset::Error; where = "name:line" for the header and ascii bodies, "name @ byte N"
// (the start of the offending value) for binary bodies.
// Threading: a PlyBodyReader is a cursor; one per thread.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "core/error.hpp"
#include "core/text.hpp"
#include "io/text_scanner.hpp"

namespace levelset::ply {

enum class Encoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

enum class Type : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

inline std::size_t type_size(Type t) {
  switch (t) {
    case Type::Int8:
    case Type::UInt8:
      return 1;
    case Type::Int16:
    case Type::UInt16:
      return 2;
    case Type::Int32:
    case Type::UInt32:
    case Type::Float32:
      return 4;
    case Type::Float64:
      return 8;
  }
  return 8;
}

inline bool is_integer(Type t) {
  return t != Type::Float32 && t != Type::Float64;
}

// The range of an integer type, as doubles (exact for every type here).
inline double type_min(Type t) {
  switch (t) {
    case Type::Int8: return -128.0;
    case Type::Int16: return -32768.0;
    case Type::Int32: return -2147483648.0;
    default: return 0.0;
  }
}
inline double type_max(Type t) {
  switch (t) {
    case Type::Int8: return 127.0;
    case Type::UInt8: return 255.0;
    case Type::Int16: return 32767.0;
    case Type::UInt16: return 65535.0;
    case Type::Int32: return 2147483647.0;
    default: return 4294967295.0;
  }
}

inline std::string_view type_name(Type t) {
  switch (t) {
    case Type::Int8: return "char";
    case Type::UInt8: return "uchar";
    case Type::Int16: return "short";
    case Type::UInt16: return "ushort";
    case Type::Int32: return "int";
    case Type::UInt32: return "uint";
    case Type::Float32: return "float";
    case Type::Float64: return "double";
  }
  return "?";
}

inline bool parse_type(std::string_view s, Type& t) {
  struct Entry {
    std::string_view name;
    Type type;
  };
  static constexpr Entry kTypes[] = {
      {"char", Type::Int8},      {"int8", Type::Int8},       {"uchar", Type::UInt8},
      {"uint8", Type::UInt8},    {"short", Type::Int16},     {"int16", Type::Int16},
      {"ushort", Type::UInt16},  {"uint16", Type::UInt16},   {"int", Type::Int32},
      {"int32", Type::Int32},    {"uint", Type::UInt32},     {"uint32", Type::UInt32},
      {"float", Type::Float32},  {"float32", Type::Float32}, {"double", Type::Float64},
      {"float64", Type::Float64}};
  for (const Entry& e : kTypes) {
    if (e.name == s) {
      t = e.type;
      return true;
    }
  }
  return false;
}

struct Property {
  std::string name;
  Type type = Type::Float32;  // the item type for lists
  bool is_list = false;
  Type count_type = Type::UInt8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  std::uint64_t line = 0;  // header line that declared it

  // Index of the property with that name, or -1.
  int find(std::string_view property) const {
    for (std::size_t i = 0; i < properties.size(); ++i)
      if (properties[i].name == property) return static_cast<int>(i);
    return -1;
  }
};

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;
  std::uint64_t body_line = 1;  // line on which the body starts (ascii)

  const Element* find(std::string_view element) const {
    for (const Element& e : elements)
      if (e.name == element) return &e;
    return nullptr;
  }
};

// Header caps. Real files have a handful of elements and at most a few hundred properties
// (3D Gaussian splat files: about 60); the caps keep a hostile header from costing more than a
// small, fixed amount of memory and time.
inline constexpr std::size_t kMaxElements = 1024;
inline constexpr std::size_t kMaxPropertiesPerElement = 4096;

// Linear in the header's size: duplicate names are found with hash sets, not by scanning.
inline Header parse_header(std::string_view bytes, std::string_view name) {
  TextScanner sc(bytes, name);
  Header h;
  std::unordered_set<std::string> element_names;
  std::unordered_set<std::string> property_names;  // of the last element
  {
    const std::string_view magic = sc.line_token();
    if (magic != "ply")
      throw Error(ErrorCode::UnsupportedFormat, at_line(name, 1),
                  "expected the PLY magic 'ply', found '" + TextScanner::quote(magic) + "'");
    sc.expect_end_of_line("'ply'");
  }
  bool have_format = false;
  for (;;) {
    if (sc.eof()) sc.fail(ErrorCode::Truncated, "expected 'end_header', found the end of the file");
    const std::string_view kw = sc.line_token();
    if (kw.empty()) {
      sc.consume_newline();
      continue;
    }
    if (kw == "comment" || kw == "obj_info") {
      sc.skip_line();
    } else if (kw == "format") {
      if (have_format) sc.fail(ErrorCode::ParseError, "a second 'format' line");
      if (!h.elements.empty()) sc.fail(ErrorCode::ParseError, "'format' after an element");
      const std::string_view enc = sc.line_token();
      if (enc == "ascii") {
        h.encoding = Encoding::Ascii;
      } else if (enc == "binary_little_endian") {
        h.encoding = Encoding::BinaryLittleEndian;
      } else if (enc == "binary_big_endian") {
        h.encoding = Encoding::BinaryBigEndian;
      } else {
        sc.fail(ErrorCode::UnsupportedFormat,
                "expected ascii, binary_little_endian or binary_big_endian, found '" +
                    TextScanner::quote(enc) + "'");
      }
      const std::string_view version = sc.line_token();
      if (version != "1.0")
        sc.fail(version.empty() ? ErrorCode::ParseError : ErrorCode::UnsupportedVersion,
                "expected PLY version 1.0, found '" + TextScanner::quote(version) + "'");
      sc.expect_end_of_line("the format");
      have_format = true;
    } else if (kw == "element") {
      if (!have_format) sc.fail(ErrorCode::ParseError, "expected 'format' before 'element'");
      Element e;
      e.line = sc.line();
      const std::string_view ename = sc.line_token();
      if (ename.empty()) sc.fail_missing("an element name");
      e.name = std::string(ename);
      if (h.elements.size() >= kMaxElements)
        sc.fail(ErrorCode::LimitExceeded,
                "more than " + std::to_string(kMaxElements) + " elements in the PLY header");
      if (!element_names.insert(e.name).second)
        sc.fail(ErrorCode::ParseError, "element '" + TextScanner::quote(e.name) + "' declared twice");
      property_names.clear();
      e.count = sc.parse_count(sc.line_token(), "the element count");
      sc.expect_end_of_line("the element count");
      h.elements.push_back(std::move(e));
    } else if (kw == "property") {
      if (h.elements.empty()) sc.fail(ErrorCode::ParseError, "'property' before any 'element'");
      Property p;
      std::string_view tname = sc.line_token();
      if (tname == "list") {
        p.is_list = true;
        const std::string_view cname = sc.line_token();
        if (cname.empty()) sc.fail_missing("the list count type");
        if (!parse_type(cname, p.count_type))
          sc.fail(ErrorCode::UnsupportedFormat,
                  "unknown PLY type '" + TextScanner::quote(cname) + "'");
        if (!is_integer(p.count_type))
          sc.fail(ErrorCode::UnsupportedFormat,
                  "a list count type must be an integer type, found '" + TextScanner::quote(cname) +
                      "'");
        tname = sc.line_token();
      }
      if (tname.empty()) sc.fail_missing("a property type");
      if (!parse_type(tname, p.type))
        sc.fail(ErrorCode::UnsupportedFormat,
                "unknown PLY type '" + TextScanner::quote(tname) + "'");
      const std::string_view pname = sc.line_token();
      if (pname.empty()) sc.fail_missing("a property name");
      p.name = std::string(pname);
      Element& e = h.elements.back();
      if (e.properties.size() >= kMaxPropertiesPerElement)
        sc.fail(ErrorCode::LimitExceeded, "more than " + std::to_string(kMaxPropertiesPerElement) +
                                              " properties in element '" + TextScanner::quote(e.name) + "'");
      if (!property_names.insert(p.name).second)
        sc.fail(ErrorCode::ParseError,
                "property '" + TextScanner::quote(p.name) + "' declared twice in element '" + TextScanner::quote(e.name) + "'");
      sc.expect_end_of_line("the property name");
      e.properties.push_back(std::move(p));
    } else if (kw == "end_header") {
      if (!have_format) sc.fail(ErrorCode::ParseError, "no 'format' line before 'end_header'");
      const std::string_view extra = sc.line_token();
      if (!extra.empty())
        sc.fail(ErrorCode::ParseError, "expected the end of the line after 'end_header', found '" +
                                           TextScanner::quote(extra) + "'");
      sc.consume_newline();
      h.body_offset = sc.offset();
      h.body_line = sc.line();
      break;
    } else {
      sc.fail(ErrorCode::ParseError,
              "expected a PLY header keyword, found '" + TextScanner::quote(kw) + "'");
    }
  }
  for (const Element& e : h.elements)
    if (e.count > 0 && e.properties.empty())
      throw Error(
          ErrorCode::ParseError, at_line(name, e.line),
          "element '" + e.name + "' has " + std::to_string(e.count) + " items but no properties");
  return h;
}

inline std::uint64_t saturating_add(std::uint64_t a, std::uint64_t b) {
  return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}
inline std::uint64_t saturating_mul(std::uint64_t a, std::uint64_t b) {
  return b != 0 && a > UINT64_MAX / b ? UINT64_MAX : a * b;
}

// Smallest number of bytes one item of e can take in the given encoding.
inline std::uint64_t min_item_bytes(const Element& e, Encoding enc) {
  std::uint64_t n = 0;
  for (const Property& p : e.properties) {
    if (enc == Encoding::Ascii)
      n += 2;
    else
      n += type_size(p.is_list ? p.count_type : p.type);
  }
  return n;
}

inline void check_body_size(const Header& h, std::string_view bytes, std::string_view name) {
  const std::uint64_t available = bytes.size() - h.body_offset;
  std::uint64_t needed = 0;
  for (const Element& e : h.elements) {
    needed = saturating_add(needed, saturating_mul(e.count, min_item_bytes(e, h.encoding)));
    // An ascii file may omit the final newline.
    const std::uint64_t strict = h.encoding == Encoding::Ascii && needed > 0 ? needed - 1 : needed;
    if (strict > available)
      throw Error(ErrorCode::Truncated, at_line(name, e.line),
                  "element '" + e.name + "' claims " + std::to_string(e.count) +
                      " items; the elements up to it need at least " + std::to_string(strict) +
                      " bytes but only " + std::to_string(available) + " bytes follow the header");
  }
}

// Reads body values in order. "what" strings name the value in error messages.
class BodyReader {
 public:
  BodyReader(const Header& h, std::string_view bytes, std::string_view name)
      : bytes_(bytes),
        name_(name),
        encoding_(h.encoding),
        pos_(h.body_offset),
        scanner_(bytes, name, 0, h.body_offset, h.body_line) {}

  bool ascii() const { return encoding_ == Encoding::Ascii; }

  double fraction() const {
    const std::size_t pos = ascii() ? scanner_.offset() : pos_;
    return bytes_.empty() ? 1.0 : static_cast<double>(pos) / static_cast<double>(bytes_.size());
  }

  // A scalar as a double (any type); not checked for finiteness.
  double read_number(Type t, std::string_view what) {
    if (ascii()) {
      const std::string_view tok = scanner_.next_token();
      const double v = scanner_.parse_any_number(tok, what);
      if (is_integer(t)) check_ascii_range(t, v, tok, what);
      return v;
    }
    start_ = pos_;
    switch (t) {
      case Type::Int8:
        return static_cast<double>(raw<std::int8_t>());
      case Type::UInt8:
        return static_cast<double>(raw<std::uint8_t>());
      case Type::Int16:
        return static_cast<double>(raw<std::int16_t>());
      case Type::UInt16:
        return static_cast<double>(raw<std::uint16_t>());
      case Type::Int32:
        return static_cast<double>(raw<std::int32_t>());
      case Type::UInt32:
        return static_cast<double>(raw<std::uint32_t>());
      case Type::Float32:
        return static_cast<double>(std::bit_cast<float>(raw<std::uint32_t>()));
      case Type::Float64:
        return std::bit_cast<double>(raw<std::uint64_t>());
    }
    return 0.0;
  }

  // An integer value of an integer type (list counts, indices).
  std::int64_t read_integer(Type t, std::string_view what) {
    if (ascii()) {
      const std::string_view tok = scanner_.next_token();
      const std::int64_t v = scanner_.parse_int(tok, what);
      if (is_integer(t)) check_ascii_range(t, static_cast<double>(v), tok, what);
      return v;
    }
    start_ = pos_;
    switch (t) {
      case Type::Int8:
        return raw<std::int8_t>();
      case Type::UInt8:
        return raw<std::uint8_t>();
      case Type::Int16:
        return raw<std::int16_t>();
      case Type::UInt16:
        return raw<std::uint16_t>();
      case Type::Int32:
        return raw<std::int32_t>();
      case Type::UInt32:
        return raw<std::uint32_t>();
      case Type::Float32:
      case Type::Float64:
        break;
    }
    fail(ErrorCode::UnsupportedFormat, std::string(what) + " must have an integer type");
  }

  // A list length, checked against the bytes that remain (items of type item).
  std::uint64_t read_list_count(const Property& p, std::string_view what) {
    const std::int64_t n = read_integer(p.count_type, what);
    if (n < 0)
      fail(ErrorCode::ParseError, "negative " + std::string(what) + " " + std::to_string(n));
    const std::uint64_t count = static_cast<std::uint64_t>(n);
    const std::uint64_t per_item = ascii() ? 2 : type_size(p.type);
    const std::uint64_t left = ascii() ? scanner_.remaining() + 1 : bytes_.size() - pos_;
    if (saturating_mul(count, per_item) > left)
      fail(ErrorCode::Truncated, std::string(what) + " " + std::to_string(count) +
                                     " needs more bytes than the " + std::to_string(left) +
                                     " that remain");
    return count;
  }

  // Reads and discards one property value (a whole list for list properties).
  void skip(const Property& p) {
    if (!p.is_list) {
      skip_value(p.type);
      return;
    }
    const std::uint64_t n = read_list_count(p, "list length");
    if (ascii()) {
      for (std::uint64_t i = 0; i < n; ++i) skip_value(p.type);
    } else {
      pos_ += static_cast<std::size_t>(n * type_size(p.type));  // checked by read_list_count
    }
  }

  // After the last element: nothing but whitespace may follow an ascii body, nothing at all
  // a binary one.
  void finish() {
    if (ascii()) {
      if (scanner_.skip_to_token())
        scanner_.fail(ErrorCode::ParseError,
                      "expected the end of the file after the last element, found '" +
                          TextScanner::quote(scanner_.line_token()) + "'");
      return;
    }
    if (pos_ != bytes_.size()) {
      start_ = pos_;
      fail(ErrorCode::ParseError,
           std::to_string(bytes_.size() - pos_) + " unexpected bytes after the last element");
    }
  }

  // Where the last value started: "name:line" or "name @ byte N".
  std::string where() const { return ascii() ? scanner_.where() : at_byte(name_, start_); }

  [[noreturn]] void fail(ErrorCode code, std::string reason) const {
    throw Error(code, where(), std::move(reason));
  }

 private:
  // ASCII values carry no width: refuse ones outside the declared integer type (300 or -1 for a
  // uchar), as a binary file could not hold them.
  void check_ascii_range(Type t, double v, std::string_view tok, std::string_view what) const {
    if (v >= type_min(t) && v <= type_max(t)) return;
    scanner_.fail(ErrorCode::ParseError,
                  std::string(what) + " '" + TextScanner::quote(tok) + "' does not fit the type " +
                      std::string(type_name(t)) + " (" + format_number(type_min(t)) + " to " +
                      format_number(type_max(t)) + ")");
  }

  void skip_value(Type t) {
    if (ascii()) {
      const std::string_view tok = scanner_.next_token();
      if (tok.empty()) scanner_.fail_missing("a property value");
      if (!TextScanner::is_number(tok)) scanner_.fail_expected("a property value", "a number", tok);
      if (is_integer(t))
        check_ascii_range(t, scanner_.parse_any_number(tok, "a property value"), tok,
                          "a property value");
      return;
    }
    start_ = pos_;
    const std::size_t n = type_size(t);
    if (bytes_.size() - pos_ < n) truncated(n);
    pos_ += n;
  }

  [[noreturn]] void truncated(std::size_t n) const {
    fail(ErrorCode::Truncated, "expected a " + std::to_string(n) + "-byte value, found " +
                                   std::to_string(bytes_.size() - pos_) +
                                   " bytes before the end of the file");
  }

  template <typename T>
  T raw() {
    if (bytes_.size() - pos_ < sizeof(T)) truncated(sizeof(T));
    std::make_unsigned_t<T> u;
    std::memcpy(&u, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    const bool file_big = encoding_ == Encoding::BinaryBigEndian;
    if (file_big != (std::endian::native == std::endian::big)) u = byteswap(u);
    return static_cast<T>(u);
  }

  template <typename U>
  static U byteswap(U u) {
    if constexpr (sizeof(U) == 1) {
      return u;
    } else {
      U out = 0;
      for (std::size_t i = 0; i < sizeof(U); ++i) {
        out = static_cast<U>((out << 8) | (u & 0xff));
        u = static_cast<U>(u >> 8);
      }
      return out;
    }
  }

  std::string_view bytes_;
  std::string_view name_;
  Encoding encoding_;
  std::size_t pos_;        // binary cursor
  std::size_t start_ = 0;  // binary: where the last value started
  TextScanner scanner_;    // ascii cursor
};

}  // namespace levelset::ply
