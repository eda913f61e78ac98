// Huge blocks: large buffers (at least kHugeBlockMinBytes, 1 MiB) served from anonymous
// mappings of their own, aligned to 2 MiB and sized in whole 2 MiB pages with transparent huge
// pages advised, and kept for reuse when freed (up to a cache limit).
//
// Why: a fresh buffer is paid for page by page on first touch, and on the virtual machines this
// runs on a 4 KiB fault costs ~10 us (populating in one call, prefault_for_write, ~2-3 us a
// page). A block inside glibc's heap starts and ends at arbitrary addresses, so on average 1 MiB
// at each end lies outside any whole huge page and faults in 4 KiB at a time. A fresh
// `levelsetd mesh` of knot.off at R = 256 (2 threads) spent 10-13 ms of its ~30 ms extraction
// so; armadillo's three 3.7 MB output arrays took 8-10 ms to size (0.8-1.3 ms as blocks here).
// Aligned blocks fault in 2 MiB at a time. glibc's own aligned blocks (memalign) were tried:
// they split the heap around them, and resident size grew 110 -> 282 MB over 20 extractions.
// Blocks here never share a mapping with glibc's heap, so they cannot fragment it. Rounding to
// 2 MiB costs at most 2 MiB of address space per block (and at most as much resident).
//
// Reuse: a request takes the smallest cached block that fits (splitting off the rest when the
// block is at least twice the request); if none fits, the largest cached block grows by mremap
// (its resident pages move, only the extension is fresh: an evolution whose band grows a little
// each step faults in only the growth); only then is a new mapping made. Freed blocks beyond the
// cache limit are unmapped, oldest first.
//
// Used through operator new (core/huge_block_new.cpp, linked into levelsetd, the benches and the
// unit tests) once enable_huge_blocks has been called (keep_freed_memory does). Linux only;
// elsewhere allocate_huge_block returns nullptr and the caller uses malloc.
// Threading: every function is thread-safe (one mutex; large allocations are rare, and each
// call scans a table of at most 1024 blocks).
#pragma once

#include <cstddef>
#include <cstdint>

namespace levelset {

inline constexpr std::size_t kHugeBlockMinBytes = std::size_t{1} << 20;
inline constexpr std::size_t kHugeBlockAlignment = std::size_t{2} << 20;

// Turns the pool on; freed blocks are kept while they total at most cache_bytes.
void enable_huge_blocks(std::size_t cache_bytes) noexcept;
// Turns it off for new requests (A/B measurements, tests); live blocks stay valid and are
// unmapped when freed.
void disable_huge_blocks() noexcept;
bool huge_blocks_enabled() noexcept;

// A 2 MiB-aligned block of at least `bytes`, or nullptr when the pool is off, `bytes` is below
// kHugeBlockMinBytes, the block table is full or the system has no memory: the caller then uses
// malloc. Contents are unspecified (a reused block keeps old data).
void* allocate_huge_block(std::size_t bytes) noexcept;

// Takes back a block from allocate_huge_block and returns true; returns false (and does
// nothing) for any other pointer.
bool release_huge_block(void* block) noexcept;

// Whether p could be a huge block at all (its alignment): the cheap test before release.
inline bool maybe_huge_block(const void* p) noexcept {
  return p != nullptr && (reinterpret_cast<std::uintptr_t>(p) & (kHugeBlockAlignment - 1)) == 0;
}

struct HugeBlockStats {
  std::size_t live_blocks = 0, live_bytes = 0;      // handed out, not yet released
  std::size_t cached_blocks = 0, cached_bytes = 0;  // released, kept for reuse
  std::uint64_t mapped = 0;   // requests served by a new mapping
  std::uint64_t reused = 0;   // requests served by a cached block as it was (or split)
  std::uint64_t grown = 0;    // requests served by growing a cached block
  std::uint64_t unmapped = 0; // cached blocks given back to the system
};
HugeBlockStats huge_block_stats() noexcept;

}  // namespace levelset
