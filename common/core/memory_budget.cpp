#include "core/memory_budget.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>

#include "core/error.hpp"

namespace levelset {

namespace {

std::uint64_t builtin_default() {
  const std::uint64_t physical = physical_memory_bytes();
  const std::uint64_t half = physical ? physical / 2 : kMaxDefaultMemoryBudget;
  return std::clamp<std::uint64_t>(half, std::uint64_t{256} << 20, kMaxDefaultMemoryBudget);
}

std::atomic<std::uint64_t> g_budget{0};  // 0: the built-in default

}  // namespace

std::uint64_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return 0;
  return std::uint64_t(pages) * std::uint64_t(page);
}

std::uint64_t default_memory_budget() {
  const std::uint64_t b = g_budget.load(std::memory_order_relaxed);
  return b ? b : builtin_default();
}

void set_default_memory_budget(std::uint64_t bytes) { g_budget.store(bytes, std::memory_order_relaxed); }

std::string budget_bytes_text(std::uint64_t bytes) {
  char buf[64];
  if (bytes < 1024)
    std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  else if (bytes < (std::uint64_t{1} << 20))
    std::snprintf(buf, sizeof buf, "%.1f KiB", double(bytes) / 1024.0);
  else if (bytes < (std::uint64_t{1} << 30))
    std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / 1048576.0);
  else
    std::snprintf(buf, sizeof buf, "%.2f GiB", double(bytes) / 1073741824.0);
  return buf;
}

void require_within_budget(std::uint64_t needed, std::uint64_t budget, const std::string& where,
                           std::string_view what) {
  if (needed <= budget) return;
  throw Error(ErrorCode::LimitExceeded, where,
              std::string(what) + " needs about " + budget_bytes_text(needed) + " (" + std::to_string(needed) +
                  " bytes), above the memory budget of " + budget_bytes_text(budget) +
                  " (raise it with --memory-budget)");
}

}  // namespace levelset
