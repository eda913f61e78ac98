// Global operator new for programs that allocate large transient buffers (levelsetd, the
// benches): a block of 2 MiB or more is aligned to 2 MiB, rounded up to a multiple of it and
// advised for transparent huge pages (core/huge_pages.hpp), so its fresh memory faults in 2 MiB
// at a time over the whole block; smaller blocks are plain malloc. Every delete is free().
//
// Why: with keep_freed_memory() every block comes from glibc's heap at an arbitrary address,
// and only the huge pages that happen to lie inside a block can be advised; its ends (all of
// a 4 MB block, often) fault in 4 KiB at a time, which on this project's virtual machines
// costs ~10 us per page. The first marching cubes extraction of a fresh `levelsetd mesh`
// writes 14 MB of vertex, normal and triangle arrays (knot.off, R = 256) that std::vector
// allocates through here. The default aligned forms (align_val_t) are left to the library.
//
// Linked into executables only (target levelset_huge_page_new), never into the core library:
// replacing operator new is a program's choice. Not built under AddressSanitizer, whose own
// operator new checks every allocation.
#if !defined(__SANITIZE_ADDRESS__)

#include <cstddef>
#include <cstdlib>
#include <new>

#include "core/huge_pages.hpp"

namespace {

constexpr std::size_t kHuge = std::size_t{2} << 20;

void* allocate(std::size_t n) noexcept {
  if (n < kHuge) return std::malloc(n > 0 ? n : 1);
  if (n > std::size_t(-1) - kHuge) return nullptr;
  const std::size_t bytes = (n + kHuge - 1) & ~(kHuge - 1);
  void* p = std::aligned_alloc(kHuge, bytes);
  if (p != nullptr) levelset::advise_huge_pages(p, bytes);
  return p;
}

void* allocate_or_throw(std::size_t n) {
  for (;;) {
    if (void* p = allocate(n)) return p;
    const std::new_handler handler = std::get_new_handler();
    if (handler == nullptr) throw std::bad_alloc();
    handler();
  }
}

void* allocate_nothrow(std::size_t n) noexcept {
  try {
    return allocate_or_throw(n);
  } catch (...) {
    return nullptr;
  }
}

}  // namespace

void* operator new(std::size_t n) { return allocate_or_throw(n); }
void* operator new[](std::size_t n) { return allocate_or_throw(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return allocate_nothrow(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return allocate_nothrow(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

#endif
