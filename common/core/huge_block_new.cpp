// The replaceable global operator new and delete, routing blocks of at least
// kHugeBlockMinBytes to the huge block pool (core/huge_blocks.hpp) while it is enabled, and
// everything else to malloc as libstdc++'s own do. Linked only into programs (levelsetd, the
// benches, the unit tests: the levelset_huge_new object library), never into the core library,
// so that linking levelset_core alone changes no allocator. Not under AddressSanitizer, whose
// own operator new checks every block.
// The aligned (std::align_val_t) and nothrow forms keep libstdc++'s definitions: the aligned
// ones use aligned_alloc and free and never see a pool block; the nothrow ones call these.
#include <cstdlib>
#include <new>

#include "core/huge_blocks.hpp"

#if !defined(__SANITIZE_ADDRESS__)

namespace {

void* allocate(std::size_t bytes) {
  if (bytes >= levelset::kHugeBlockMinBytes) {
    if (void* p = levelset::allocate_huge_block(bytes)) return p;
  }
  for (;;) {
    if (void* p = std::malloc(bytes != 0 ? bytes : 1)) return p;
    std::new_handler handler = std::get_new_handler();
    if (handler == nullptr) throw std::bad_alloc();
    handler();
  }
}

void release(void* p) noexcept {
  if (levelset::maybe_huge_block(p) && levelset::release_huge_block(p)) return;
  std::free(p);
}

}  // namespace

void* operator new(std::size_t bytes) { return allocate(bytes); }
void* operator new[](std::size_t bytes) { return allocate(bytes); }
void operator delete(void* p) noexcept { release(p); }
void operator delete[](void* p) noexcept { release(p); }
void operator delete(void* p, std::size_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t) noexcept { release(p); }

#endif
