// keep_freed_memory: a process-wide malloc setting for programs that run long computations
// with large transient buffers (levelsetd, the benches): freed buffers stay in the process for
// the next step or the next request instead of going back to the kernel.
//
// Why: glibc serves a block of at least its mmap threshold (128 KiB at first, raised
// dynamically up to 32 MiB as such blocks are freed) as a mapping of its own, unmapped again on
// free, and trims the heap's top beyond twice that threshold, so each evolution stage, each
// extraction and each redistance faulted its decode buffers, rates, scratch and outputs in
// afresh; on the virtual machines this runs on a fault costs ~10 us and the kernel zeroes every
// page again. Measured here, interleaved runs: Table 5.1's work (2 threads) 0.52-0.55 s with the
// defaults, 0.47-0.49 s with these settings; marching cubes of knot.off at R = 512 (2 threads,
// 90 MB of arrays per call, above any threshold glibc accepts) 0.106-0.122 s -> 0.095 s.
// What it sets: no separate mappings (M_MMAP_MAX 0: every block comes from a heap, where a
// freed one is reused by the next request) and a trim threshold of `keep_bytes`, the free memory
// at the main heap's top that is kept. Peak resident size: knot.off R = 512 extractions 142 ->
// 165 MB, a 20k-point reconstruction at R = 512 351 -> 323 MB.
// Blocks of 1 MiB and more go to the huge block pool (core/huge_blocks.hpp) in programs that
// link its operator new: 2 MiB-aligned mappings of their own, kept for reuse up to `keep_bytes`.
// The environment variable LEVELSET_KEEP_FREED_MEMORY=0 leaves glibc's defaults and no pool (a
// machine short of memory; A/B measurements); LEVELSET_HUGE_BLOCKS=0 leaves only the pool off.
// Returns whether the allocator took the settings (false where malloc is not glibc's, or
// left by the variable).
// Threading: call once at the start of main, before threads allocate.
#pragma once

#include <cstddef>

namespace levelset {

bool keep_freed_memory(std::size_t keep_bytes = std::size_t{1} << 30);

}  // namespace levelset
