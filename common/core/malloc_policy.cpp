#include "core/malloc_policy.hpp"

#include "core/huge_blocks.hpp"

#include <cstdlib>
#include <cstring>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace levelset {

bool keep_freed_memory(std::size_t keep_bytes) {
  const char* off = std::getenv("LEVELSET_KEEP_FREED_MEMORY");
  if (off != nullptr && std::strcmp(off, "0") == 0) return false;
#if defined(__GLIBC__)
  const int keep = keep_bytes > std::size_t(0x7fffffff) ? 0x7fffffff : int(keep_bytes);
  if (mallopt(M_MMAP_MAX, 0) != 1 || mallopt(M_TRIM_THRESHOLD, keep) != 1) return false;
  const char* huge = std::getenv("LEVELSET_HUGE_BLOCKS");
  if (huge == nullptr || std::strcmp(huge, "0") != 0) enable_huge_blocks(keep_bytes);
  return true;
#else
  (void)keep_bytes;
  return false;
#endif
}

}  // namespace levelset
