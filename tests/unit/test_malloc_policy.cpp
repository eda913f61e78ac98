// keep_freed_memory (core/malloc_policy.hpp): with it a freed 48 MB buffer stays in the
// process and the next one of that size reuses it, where glibc's defaults map it on its own
// (above any mmap threshold glibc accepts) and unmap it on free.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <numeric>
#include <cstring>

#include "core/malloc_policy.hpp"
#include "core/uninitialized_vector.hpp"

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

// UninitializedVector places a block of 2 MiB or more on whole huge pages (aligned to 2 MiB,
// its size rounded up); smaller ones stay plain. Growth across the threshold keeps the data
// and frees each block through the path that allocated it.
TEST(HugePagePlacement, LargeUninitializedVectorsStartOnAHugePageBoundary) {
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  UninitializedVector<float> small(1000);
  std::iota(small.begin(), small.end(), 0.0f);
  UninitializedVector<float> large(std::size_t{3} << 20);  // 12 MB
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large.data()) % kHuge, 0u);
  large[large.size() - 1] = 7.0f;  // the whole range is writable
  for (int round = 0; round < 2; ++round) {
    small.resize(small.size() * 64);  // 64 000 floats (256 KB), then 4 096 000 (16 MB)
    EXPECT_EQ(small[999], 999.0f);
  }
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % kHuge, 0u);
  const UninitializedArray<std::uint64_t> raw(std::size_t{1} << 19);  // 4 MB
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(raw.data()) % kHuge, 0u);
  EXPECT_EQ(large[large.size() - 1], 7.0f);
}

}  // namespace
}  // namespace levelset
