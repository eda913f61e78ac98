// Huge pages and prefaulting for large buffers that are about to be written once (surface
// meshes, decoded bricks): first touching fresh memory costs one page fault per 4 KiB page;
// with transparent huge pages in "madvise" mode (Debian's default) an advised range faults in
// 2 MiB at a time (surface_nets, knot.off R = 512: 0.019 s -> 0.009 s to size the 48 MB of
// output arrays), and the pages the advice cannot cover (a buffer's unaligned ends) are
// populated by one call instead of a trap each. Linux only; elsewhere a plain resize.
// Threading: none; call before the buffer is shared.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace levelset {

// Advises huge pages for the whole 2 MiB pages inside [data, data + bytes). Best effort.
inline void advise_huge_pages(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{1} << 21;
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

// Faults in the pages of [data, data + bytes) for writing, huge pages advised first where
// whole 2 MiB pages fit: the 4 KiB pages outside them in one system call (MADV_POPULATE_WRITE,
// Linux 5.14+) instead of one trap each on first touch; the whole huge pages are left to fault
// in 2 MiB at a time on first write (populating them too made a fresh extraction's decode 12
// ms instead of 4-9). On the virtual machines this runs on a trap costs ~10 us: 4 MB sized
// by first touch 12 ms, advised and populated 3 ms; 48 MB 140 ms -> 7 ms.
// Best effort (older kernels: advice only). Small ranges (< 256 KiB) are left alone.
inline void prefault_for_write(const void* data, std::size_t bytes) {
  if (bytes < (std::size_t{256} << 10)) return;
  advise_huge_pages(data, bytes);
#if defined(__linux__)
#if !defined(MADV_POPULATE_WRITE)
  constexpr int MADV_POPULATE_WRITE = 23;
#endif
  constexpr std::uintptr_t kPage = 4096, kHuge = std::uintptr_t{1} << 21;
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + kPage - 1) & ~(kPage - 1);
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kPage - 1);
  // The whole huge pages fault in 2 MiB at a time on first touch; populate the rest.
  const std::uintptr_t huge_begin = (reinterpret_cast<std::uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t huge_end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kHuge - 1);
  auto populate = [](std::uintptr_t b, std::uintptr_t e) {
    if (e > b) madvise(reinterpret_cast<void*>(b), e - b, MADV_POPULATE_WRITE);
  };
  if (huge_end > huge_begin) {
    populate(begin, huge_begin);
    populate(huge_end, end);
  } else {
    populate(begin, end);
  }
#endif
}

// v.reserve(n) for an empty vector (or string) about to be filled, its pages faulted in
// first (prefault_for_write): the fill then runs without page faults.
template <typename Vector>
void reserve_with_huge_pages(Vector& v, std::size_t n) {
  v.reserve(n);
  prefault_for_write(v.data(), n * sizeof(typename Vector::value_type));
}

// v.resize(n) the same way: the resize's zero-fill (none for an UninitializedVector) runs
// without page faults.
template <typename Vector>
void resize_with_huge_pages(Vector& v, std::size_t n) {
  reserve_with_huge_pages(v, n);
  v.resize(n);
}

}  // namespace levelset
