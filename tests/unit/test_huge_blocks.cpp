// The huge block pool (core/huge_blocks.hpp): alignment, reuse, splitting, growth by mremap,
// the cache limit, and the global operator new that routes large blocks to it.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "core/huge_blocks.hpp"

namespace levelset {
namespace {

constexpr std::size_t kMiB = std::size_t{1} << 20;

bool aligned(const void* p) { return reinterpret_cast<std::uintptr_t>(p) % kHugeBlockAlignment == 0; }

// Each test starts from an enabled pool with an empty cache of the given limit.
void reset_pool(std::size_t cache_bytes) {
  disable_huge_blocks();  // unmaps every cached block
  enable_huge_blocks(cache_bytes);
}

#if defined(__linux__)

TEST(HugeBlocks, LargeRequestsGetAlignedBlocksInWholeHugePages) {
  reset_pool(64 * kMiB);
  const HugeBlockStats before = huge_block_stats();
  void* p = allocate_huge_block(5 * kMiB + 3);
  ASSERT_NE(p, nullptr);
  EXPECT_TRUE(aligned(p));
  std::memset(p, 7, 5 * kMiB + 3);  // writable over the whole request
  const HugeBlockStats live = huge_block_stats();
  EXPECT_EQ(live.live_blocks, before.live_blocks + 1);
  EXPECT_EQ(live.live_bytes, before.live_bytes + 6 * kMiB);  // rounded up to 2 MiB pages
  EXPECT_EQ(live.mapped, before.mapped + 1);
  EXPECT_TRUE(release_huge_block(p));
  EXPECT_EQ(huge_block_stats().live_bytes, before.live_bytes);
  // Small requests, and pointers that are not blocks, are left to malloc.
  EXPECT_EQ(allocate_huge_block(kHugeBlockMinBytes - 1), nullptr);
  int local = 0;
  EXPECT_FALSE(release_huge_block(&local));
  EXPECT_FALSE(release_huge_block(nullptr));
}

TEST(HugeBlocks, AFreedBlockServesTheNextRequestThatFits) {
  reset_pool(64 * kMiB);
  void* first = allocate_huge_block(8 * kMiB);
  ASSERT_NE(first, nullptr);
  ASSERT_TRUE(release_huge_block(first));
  EXPECT_EQ(huge_block_stats().cached_bytes, 8 * kMiB);
  const HugeBlockStats before = huge_block_stats();
  void* second = allocate_huge_block(7 * kMiB);  // rounds to 8 MiB: the same block
  EXPECT_EQ(second, first);
  const HugeBlockStats after = huge_block_stats();
  EXPECT_EQ(after.reused, before.reused + 1);
  EXPECT_EQ(after.mapped, before.mapped);
  EXPECT_EQ(after.cached_bytes, 0u);
  EXPECT_TRUE(release_huge_block(second));
}

TEST(HugeBlocks, ABlockTwiceTheRequestIsSplit) {
  reset_pool(64 * kMiB);
  void* big = allocate_huge_block(20 * kMiB);
  ASSERT_NE(big, nullptr);
  ASSERT_TRUE(release_huge_block(big));
  void* head = allocate_huge_block(6 * kMiB);
  EXPECT_EQ(head, big);
  EXPECT_EQ(huge_block_stats().cached_bytes, 14 * kMiB);
  // The rest is a block of its own, aligned, served next without a new mapping.
  const HugeBlockStats before = huge_block_stats();
  void* tail = allocate_huge_block(14 * kMiB);
  EXPECT_EQ(tail, static_cast<char*>(big) + 6 * kMiB);
  EXPECT_TRUE(aligned(tail));
  EXPECT_EQ(huge_block_stats().mapped, before.mapped);
  std::memset(head, 1, 6 * kMiB);
  std::memset(tail, 2, 14 * kMiB);
  EXPECT_EQ(static_cast<unsigned char*>(head)[6 * kMiB - 1], 1);
  EXPECT_TRUE(release_huge_block(head));
  EXPECT_TRUE(release_huge_block(tail));
}

TEST(HugeBlocks, ALargerRequestGrowsACachedBlockKeepingItsPages) {
  reset_pool(64 * kMiB);
  auto* block = static_cast<unsigned char*>(allocate_huge_block(8 * kMiB));
  ASSERT_NE(block, nullptr);
  for (std::size_t i = 0; i < 8 * kMiB; i += 4096) block[i] = static_cast<unsigned char>(i / 4096);
  ASSERT_TRUE(release_huge_block(block));
  const HugeBlockStats before = huge_block_stats();
  auto* grown = static_cast<unsigned char*>(allocate_huge_block(12 * kMiB));
  ASSERT_NE(grown, nullptr);
  EXPECT_TRUE(aligned(grown));
  const HugeBlockStats after = huge_block_stats();
  EXPECT_EQ(after.grown, before.grown + 1);
  EXPECT_EQ(after.mapped, before.mapped);
  EXPECT_EQ(after.cached_bytes, 0u);
  EXPECT_EQ(after.live_bytes, before.live_bytes + 12 * kMiB);
  // The old pages moved with it (mremap), and the extension is usable.
  bool kept = true;
  for (std::size_t i = 0; i < 8 * kMiB; i += 4096) kept &= grown[i] == static_cast<unsigned char>(i / 4096);
  EXPECT_TRUE(kept);
  std::memset(grown + 8 * kMiB, 3, 4 * kMiB);
  EXPECT_TRUE(release_huge_block(grown));
}

TEST(HugeBlocks, TheCacheKeepsAtMostItsLimitOldestOut) {
  reset_pool(10 * kMiB);
  void* a = allocate_huge_block(6 * kMiB);
  void* b = allocate_huge_block(6 * kMiB);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  const HugeBlockStats before = huge_block_stats();
  ASSERT_TRUE(release_huge_block(a));
  ASSERT_TRUE(release_huge_block(b));  // 12 MiB cached > 10: a, the older, is unmapped
  const HugeBlockStats after = huge_block_stats();
  EXPECT_EQ(after.cached_bytes, 6 * kMiB);
  EXPECT_EQ(after.unmapped, before.unmapped + 1);
  EXPECT_EQ(allocate_huge_block(6 * kMiB), b);
  EXPECT_TRUE(release_huge_block(b));
  // Off: new requests go to malloc, the cache empties.
  disable_huge_blocks();
  EXPECT_EQ(allocate_huge_block(6 * kMiB), nullptr);
  EXPECT_EQ(huge_block_stats().cached_bytes, 0u);
}

TEST(HugeBlocks, ThreadsAllocatingAndFreeingAtOnceKeepTheBooks) {
  reset_pool(256 * kMiB);
  const HugeBlockStats before = huge_block_stats();
  std::atomic<bool> ok{true};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([t, &ok] {
      for (int i = 0; i < 40; ++i) {
        const std::size_t bytes = (4 + std::size_t((t * 7 + i * 3) % 11)) * kMiB;
        auto* p = static_cast<unsigned char*>(allocate_huge_block(bytes));
        if (p == nullptr || !aligned(p)) {
          ok = false;
          continue;
        }
        const auto mark = static_cast<unsigned char>(t * 40 + i);
        p[0] = mark;
        p[bytes - 1] = mark;
        if (p[0] != mark || p[bytes - 1] != mark) ok = false;
        if (!release_huge_block(p)) ok = false;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_TRUE(ok.load());
  const HugeBlockStats after = huge_block_stats();
  EXPECT_EQ(after.live_blocks, before.live_blocks);
  EXPECT_EQ(after.live_bytes, before.live_bytes);
  EXPECT_LE(after.cached_bytes, 256 * kMiB);
  // Most requests were served from the cache: at most one mapping per thread and size.
  EXPECT_LT(after.mapped - before.mapped, 4u * 11u);
}

// A random sequence of requests and releases (sizes 1-40 MiB, so every path runs: fresh
// mappings, reuse, splits, growth, eviction) against a model: live blocks never overlap, each
// keeps what was written to it until released, and the books add up.
TEST(HugeBlocks, RandomRequestsAndReleasesKeepBlocksApartAndIntact) {
  reset_pool(48 * kMiB);
  const HugeBlockStats start = huge_block_stats();
  std::mt19937 rng(20261128);
  struct Live {
    std::size_t bytes;
    unsigned char mark;
  };
  std::map<unsigned char*, Live> live;  // by address, for the overlap check
  auto intact = [](unsigned char* p, const Live& l) {
    // First and last byte of every 4 KiB page (touching each page once).
    for (std::size_t i = 0; i < l.bytes; i += 4096)
      if (p[i] != l.mark || p[std::min(i + 4095, l.bytes - 1)] != l.mark) return false;
    return true;
  };
  std::size_t live_rounded = 0;
  bool ok = true;
  for (int step = 0; step < 600 && ok; ++step) {
    const bool release = !live.empty() && (live.size() >= 6 || rng() % 2 == 0);
    if (release) {
      auto it = std::next(live.begin(), std::ptrdiff_t(rng() % live.size()));
      ok &= intact(it->first, it->second);
      live_rounded -= (it->second.bytes + kHugeBlockAlignment - 1) / kHugeBlockAlignment * kHugeBlockAlignment;
      ok &= release_huge_block(it->first);
      live.erase(it);
    } else {
      const std::size_t bytes = kMiB + std::size_t(rng() % (39 * kMiB));
      auto* p = static_cast<unsigned char*>(allocate_huge_block(bytes));
      ok &= p != nullptr && aligned(p);
      if (p == nullptr) break;
      const auto mark = static_cast<unsigned char>(step);
      for (std::size_t i = 0; i < bytes; i += 4096) {
        p[i] = mark;
        p[std::min(i + 4095, bytes - 1)] = mark;
      }
      // No overlap with the neighbours in address order.
      auto next = live.lower_bound(p);
      if (next != live.end()) ok &= p + bytes <= next->first;
      if (next != live.begin()) {
        auto prev = std::prev(next);
        ok &= prev->first + prev->second.bytes <= p;
      }
      live.emplace(p, Live{bytes, mark});
      live_rounded += (bytes + kHugeBlockAlignment - 1) / kHugeBlockAlignment * kHugeBlockAlignment;
    }
    const HugeBlockStats now = huge_block_stats();
    ok &= now.live_blocks == start.live_blocks + live.size();
    // At least the rounded requests (a reused block smaller than twice a request serves it
    // whole), and all of it mapped or cached within the limit.
    ok &= now.live_bytes >= start.live_bytes + live_rounded;
    ok &= now.cached_bytes <= 48 * kMiB;
    EXPECT_TRUE(ok) << "step " << step;
  }
  for (auto& [p, l] : live) {
    EXPECT_TRUE(intact(p, l));
    EXPECT_TRUE(release_huge_block(p));
  }
  const HugeBlockStats end = huge_block_stats();
  EXPECT_EQ(end.live_bytes, start.live_bytes);
  EXPECT_EQ(end.live_blocks, start.live_blocks);
  // Every path ran.
  EXPECT_GT(end.reused, start.reused);
  EXPECT_GT(end.grown, start.grown);
  EXPECT_GT(end.unmapped, start.unmapped);
}

#if !defined(__SANITIZE_ADDRESS__)
// The unit tests link core/huge_block_new.cpp, as levelsetd does.
TEST(HugeBlocks, OperatorNewRoutesLargeBlocksToThePool) {
  reset_pool(64 * kMiB);
  const HugeBlockStats before = huge_block_stats();
  {
    std::vector<float> big(3 * kMiB);  // 12 MiB
    EXPECT_TRUE(aligned(big.data()));
    EXPECT_EQ(huge_block_stats().live_blocks, before.live_blocks + 1);
    auto small = std::make_unique<char[]>(1000);  // malloc's
    EXPECT_EQ(huge_block_stats().live_blocks, before.live_blocks + 1);
  }
  EXPECT_EQ(huge_block_stats().live_blocks, before.live_blocks);
  EXPECT_EQ(huge_block_stats().cached_bytes, 12 * kMiB);
}
#endif

#endif

}  // namespace
}  // namespace levelset
