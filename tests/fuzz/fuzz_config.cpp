// Fuzz target: the configuration / job file reader (config/config_file.hpp).
// The input is the file text; when it parses, check_keys runs against a small schema and a
// --set override derived from the input's first line is applied. Only levelset::Error may
// leave the reader; anything else escapes to the driver as a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "config/config_file.hpp"
#include "core/error.hpp"

namespace {

std::size_t count(const levelset::config::Set& s) {
  std::size_t n = 0;
  for (const auto& e : s.entries) n += 1 + (e.is_set ? count(e.set) : 0);
  return n;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  levelset::config::ParseOptions options;
  options.limits.max_bytes = 1 << 16;
  options.limits.max_entries = 4096;
  try {
    levelset::config::Set root = levelset::config::parse_config(text, options);
    if (count(root) > options.limits.max_entries) __builtin_trap();
    try {
      levelset::config::check_keys(root, {"tmfile", "pcfile", "raster", "PDE", "renderer", "files"}, "fuzz");
    } catch (const levelset::Error&) {
    }
    const std::size_t nl = text.find('\n');
    levelset::config::set_override(root, text.substr(0, nl == std::string_view::npos ? text.size() : nl));
  } catch (const levelset::Error&) {
  }
  return 0;
}
