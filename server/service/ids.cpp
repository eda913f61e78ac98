#include "service/ids.hpp"

#include <cctype>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <mutex>
#include <random>

namespace levelset::service {

std::string new_id(const std::string& replica, char kind) {
  static std::mutex mutex;
  static std::mt19937_64 rng{std::random_device{}() ^ (std::uint64_t(std::random_device{}()) << 32)};
  std::uint64_t r;
  {
    std::lock_guard lock(mutex);
    r = rng();
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(r));
  return replica + "-" + kind + "-" + hex;
}

bool is_valid_id(std::string_view id, char kind) {
  if (id.size() > 128) return false;
  const std::size_t mark = id.rfind(std::string("-") + kind + "-");
  if (mark == std::string_view::npos || mark == 0) return false;
  for (std::size_t i = 0; i < mark; ++i)
    if (!std::isalnum(static_cast<unsigned char>(id[i])) && id[i] != '-') return false;
  std::string_view rest = id.substr(mark + 3);
  if (kind == 'u') {  // "<hex>.<ext>"
    const std::size_t dot = rest.find('.');
    if (dot == std::string_view::npos) return false;
    std::string_view ext = rest.substr(dot + 1);
    if (ext.empty() || ext.size() > 8) return false;
    for (char c : ext)
      if (!std::islower(static_cast<unsigned char>(c)) && !std::isdigit(static_cast<unsigned char>(c))) return false;
    rest = rest.substr(0, dot);
  }
  if (rest.size() != 16) return false;
  for (char c : rest)
    if (!std::isxdigit(static_cast<unsigned char>(c)) || std::isupper(static_cast<unsigned char>(c))) return false;
  return true;
}

std::string replica_of(std::string_view id) {
  for (char kind : {'s', 'j', 'u', 'n'}) {
    const std::size_t mark = id.rfind(std::string("-") + kind + "-");
    if (mark != std::string_view::npos && is_valid_id(id, kind)) return std::string(id.substr(0, mark));
  }
  return {};
}

std::string now_iso() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char buf[96];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                tm.tm_hour, tm.tm_min, tm.tm_sec, int(ms));
  return buf;
}

}  // namespace levelset::service
