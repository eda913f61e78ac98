// The memory budget: how many bytes one operation on untrusted input may allocate.
//
// Readers and applications that size their allocations from a file's header (image
// dimensions, .lsg counts) estimate what they will allocate and compare it with a budget
// BEFORE allocating, so a small file cannot make the process take gigabytes. The budget is a
// field of each Options struct (LsgReadOptions, ImageReadOptions, SegmentationOptions), whose
// default is the process-wide default below; levelsetd --memory-budget sets that default.
//
// Default: half the physical memory, at most 4 GiB (at least 256 MiB).
// Threading: the process default is an atomic; set it before starting work.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace levelset {

inline constexpr std::uint64_t kMaxDefaultMemoryBudget = std::uint64_t{4} << 30;

// Physical memory of this machine (sysconf), or 0 when unknown.
std::uint64_t physical_memory_bytes();

// The budget that Options structs start with.
std::uint64_t default_memory_budget();
// bytes == 0 restores the built-in default.
void set_default_memory_budget(std::uint64_t bytes);

// "1.50 GiB", "12.0 MiB", "300 B".
std::string budget_bytes_text(std::uint64_t bytes);

// Throws Error{LimitExceeded} at `where` unless needed <= budget; the reason reads
// "<what> needs about N bytes, above the memory budget of M (raise it with --memory-budget)".
void require_within_budget(std::uint64_t needed, std::uint64_t budget, const std::string& where,
                           std::string_view what);

}  // namespace levelset
