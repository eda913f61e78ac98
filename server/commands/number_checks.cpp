#include "commands/number_checks.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <string>

#include "core/text.hpp"

namespace levelset::cli {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Parses the whole string as a number (strtod syntax: 1e3, 0x10, nan, inf): false if it is not.
bool parse_number(const std::string& s, double& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

struct Bounds {
  double lo, hi;
  bool lo_open;  // v > lo rather than v >= lo
  bool integer;
};

std::string describe(const Bounds& b) {
  const std::string what = b.integer ? "a whole number" : "a number";
  if (b.hi == kInf) return what + (b.lo_open ? " > " : " >= ") + format_number(b.lo);
  return what + " from " + format_number(b.lo) + " to " + format_number(b.hi);
}

CLI::Validator number_check(Bounds b) {
  return CLI::Validator(
      [b](std::string& s) -> std::string {
        double v = 0;
        if (!parse_number(s, v))
          return "expected " + describe(b) + ", found '" + sanitize_utf8(s.substr(0, 40)) + (s.size() > 40 ? "...'" : "'");
        if (std::isnan(v)) return "expected " + describe(b) + ", found NaN";
        if (std::isinf(v)) return "expected " + describe(b) + ", found " + (v > 0 ? "infinity" : "-infinity");
        if (v < b.lo || (b.lo_open && v == b.lo) || v > b.hi)
          return "expected " + describe(b) + ", found " + format_number(v);
        if (b.integer && v != std::floor(v)) return "expected " + describe(b) + ", found " + format_number(v);
        // An integral value in any spelling (1e3, 64.0) becomes digits, which an int converts.
        if (v == std::floor(v) && std::abs(v) < 9e15) s = std::to_string(static_cast<long long>(v));
        return {};
      },
      b.hi == kInf ? std::string(b.lo_open ? "> " : ">= ") + format_number(b.lo)
                   : "in [" + format_number(b.lo) + ", " + format_number(b.hi) + "]",
      "");
}

}  // namespace

CLI::Validator in_range(double lo, double hi) { return number_check({lo, hi, false, false}); }
CLI::Validator in_range(int lo, int hi) { return number_check({double(lo), double(hi), false, true}); }
CLI::Validator positive() { return number_check({0.0, kInf, true, false}); }
CLI::Validator non_negative() { return number_check({0.0, kInf, false, false}); }
CLI::Validator positive_int() { return number_check({0.0, kInf, true, true}); }
CLI::Validator non_negative_int() { return number_check({0.0, kInf, false, true}); }

}  // namespace levelset::cli
