// CLI11 validators for numeric options, with messages that read well: numbers in short form
// ("0 to 1.8e+308" was 309 digits), NaN and infinities named as such (NaN was "negative"),
// and integral values in any spelling accepted by an integer option (`--resolution 1e3` was
// refused): an integral value is rewritten to plain digits before CLI11 converts it.
//
// in_range(lo, hi): lo <= v <= hi; integer bounds make an integer option (2.5 refused by name).
// positive() / non_negative(): v > 0 / v >= 0 and finite; positive_int() / non_negative_int()
// also require a whole number.
#pragma once

#include <CLI/CLI.hpp>

namespace levelset::cli {

CLI::Validator in_range(double lo, double hi);
CLI::Validator in_range(int lo, int hi);
CLI::Validator positive();
CLI::Validator non_negative();
CLI::Validator positive_int();
CLI::Validator non_negative_int();

}  // namespace levelset::cli
