// keep_freed_memory (core/malloc_policy.hpp): with it a freed 48 MB buffer stays in the
// process and the next one of that size reuses it, where glibc's defaults map it on its own
// (above any mmap threshold glibc accepts) and unmap it on free.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

#include "core/malloc_policy.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace levelset {
namespace {

TEST(MallocPolicy, FreedLargeBuffersStayInTheProcess) {
#if !defined(__GLIBC__) || defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "glibc's malloc only (AddressSanitizer replaces it)";
#else
  ASSERT_TRUE(keep_freed_memory());
  constexpr std::size_t kBytes = std::size_t{48} << 20;
  const std::size_t mapped_before = mallinfo2().hblkhd;
  char* first = static_cast<char*>(std::malloc(kBytes));
  ASSERT_NE(first, nullptr);
  std::memset(first, 1, kBytes);
  // Served from a heap, not mapped on its own.
  EXPECT_LT(mallinfo2().hblkhd, mapped_before + kBytes);
  std::free(first);
  // Kept as free heap memory (the trim threshold is 1 GiB), ready for the next buffer.
  EXPECT_GE(mallinfo2().fordblks, kBytes);
  char* second = static_cast<char*>(std::malloc(kBytes));
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(second, first);
  std::free(second);
#endif
}

}  // namespace
}  // namespace levelset
