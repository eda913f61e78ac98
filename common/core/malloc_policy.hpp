// keep_freed_memory: a process-wide malloc setting for programs that run long computations
// with large transient buffers (levelsetd, the benches): freed buffers stay in the process for
// the next step or the next request instead of going back to the kernel.
//
// Why: glibc hands a freed block of at least its mmap threshold (128 KiB at first, raised
// dynamically up to 32 MiB as such blocks are freed) straight back with munmap, and trims the
// heap's top beyond twice that threshold, so each evolution stage, each extraction and each
// redistance faults its decode buffers, rates and scratch in afresh; on the virtual machines
// this runs on a fault costs ~10 us and the kernel zeroes every page again. Table 5.1's work
// (bench_evolve --table-5-1, 2 threads) ran 0.63 s with the defaults and 0.56 s with these
// settings on the same machine.
// What it sets: the mmap threshold fixed at 32 MiB (the largest glibc accepts; larger blocks
// are still mapped and returned on free) and the trim threshold at `keep_bytes`, the free
// memory at the heap's top that is kept. Memory in use is unchanged; the resident size stays
// near its peak until blocks are freed beyond keep_bytes.
// Returns whether the allocator took the settings (false where malloc is not glibc's).
// Threading: call once at the start of main, before threads allocate.
#pragma once

#include <cstddef>

namespace levelset {

bool keep_freed_memory(std::size_t keep_bytes = std::size_t{1} << 30);

}  // namespace levelset
