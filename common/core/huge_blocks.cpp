#include "core/huge_blocks.hpp"

#include <atomic>
#include <mutex>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace levelset {

namespace {

constexpr std::size_t kHuge = kHugeBlockAlignment;
// The largest request served (anything above is refused here and by malloc alike).
constexpr std::size_t kMaxBytes = std::size_t{1} << 46;
// Blocks tracked at once (live and cached); a full table sends requests to malloc.
constexpr int kSlots = 1024;

struct Block {
  char* addr = nullptr;  // nullptr: free slot
  std::size_t bytes = 0;
  std::uint64_t freed_at = 0;  // 0: live
};

struct Pool {
  std::mutex mutex;
  Block blocks[kSlots];
  std::size_t cache_limit = 0;
  std::uint64_t clock = 0;
  HugeBlockStats stats;
};

constinit Pool g_pool;
constinit std::atomic<bool> g_enabled{false};

std::size_t round_up(std::size_t bytes) { return (bytes + kHuge - 1) & ~(kHuge - 1); }

#if defined(__linux__)

// [p, p + bytes + kHuge) trimmed to its 2 MiB-aligned middle of `bytes`.
char* trim_to_aligned(char* p, std::size_t bytes) {
  char* a = reinterpret_cast<char*>((reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1));
  if (a > p) munmap(p, std::size_t(a - p));
  char* end = p + bytes + kHuge;
  if (end > a + bytes) munmap(a + bytes, std::size_t(end - (a + bytes)));
  return a;
}

char* map_aligned(std::size_t bytes) {
  void* p = mmap(nullptr, bytes + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) return nullptr;
  char* a = trim_to_aligned(static_cast<char*>(p), bytes);
  madvise(a, bytes, MADV_HUGEPAGE);
  return a;
}

// The block's pages moved to a new 2 MiB-aligned range of `bytes` (> its size); nullptr on
// failure, the block unchanged.
char* grow_aligned(const Block& b, std::size_t bytes) {
  void* reserve = mmap(nullptr, bytes + kHuge, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (reserve == MAP_FAILED) return nullptr;
  char* target = trim_to_aligned(static_cast<char*>(reserve), bytes);
  // MREMAP_FIXED replaces the reservation; whole huge pages move as they are.
  void* moved = mremap(b.addr, b.bytes, bytes, MREMAP_MAYMOVE | MREMAP_FIXED, target);
  if (moved == MAP_FAILED) {
    munmap(target, bytes);
    return nullptr;
  }
  madvise(target, bytes, MADV_HUGEPAGE);
  return target;
}

void unmap(const Block& b) { munmap(b.addr, b.bytes); }

#else

char* map_aligned(std::size_t) { return nullptr; }
char* grow_aligned(const Block&, std::size_t) { return nullptr; }
void unmap(const Block&) {}

#endif

Block* free_slot(Pool& pool) {
  for (Block& b : pool.blocks)
    if (b.addr == nullptr) return &b;
  return nullptr;
}

void take_from_cache(Pool& pool, Block& b) {
  pool.stats.cached_blocks -= 1;
  pool.stats.cached_bytes -= b.bytes;
  b.freed_at = 0;
}

void mark_live(Pool& pool, const Block& b) {
  pool.stats.live_blocks += 1;
  pool.stats.live_bytes += b.bytes;
}

// Unmaps the oldest cached blocks until the cache fits its limit.
void evict(Pool& pool) {
  while (pool.stats.cached_bytes > pool.cache_limit) {
    Block* oldest = nullptr;
    for (Block& b : pool.blocks)
      if (b.addr != nullptr && b.freed_at != 0 && (oldest == nullptr || b.freed_at < oldest->freed_at)) oldest = &b;
    if (oldest == nullptr) return;
    take_from_cache(pool, *oldest);
    unmap(*oldest);
    pool.stats.unmapped += 1;
    *oldest = Block{};
  }
}

// The smallest cached block of at least `bytes`, else the largest cached one (nullptr: none).
Block* pick_cached(Pool& pool, std::size_t bytes) {
  Block* fit = nullptr;
  Block* largest = nullptr;
  for (Block& b : pool.blocks) {
    if (b.addr == nullptr || b.freed_at == 0) continue;
    if (b.bytes >= bytes && (fit == nullptr || b.bytes < fit->bytes)) fit = &b;
    if (largest == nullptr || b.bytes > largest->bytes) largest = &b;
  }
  return fit != nullptr ? fit : largest;
}

void* serve_from_cache(Pool& pool, Block& b, std::size_t bytes) {
  if (b.bytes >= bytes) {
    take_from_cache(pool, b);
    if (b.bytes >= 2 * bytes) {
      // Split: the rest stays cached, a block of its own (sub-ranges of a mapping unmap alike).
      if (Block* rest = free_slot(pool)) {
        *rest = Block{b.addr + bytes, b.bytes - bytes, ++pool.clock};
        pool.stats.cached_blocks += 1;
        pool.stats.cached_bytes += rest->bytes;
        b.bytes = bytes;
      }
    }
    pool.stats.reused += 1;
    mark_live(pool, b);
    return b.addr;
  }
  char* grown = grow_aligned(b, bytes);
  if (grown == nullptr) return nullptr;
  take_from_cache(pool, b);
  b.addr = grown;
  b.bytes = bytes;
  pool.stats.grown += 1;
  mark_live(pool, b);
  return grown;
}

}  // namespace

void enable_huge_blocks(std::size_t cache_bytes) noexcept {
  {
    std::lock_guard<std::mutex> lock(g_pool.mutex);
    g_pool.cache_limit = cache_bytes;
    evict(g_pool);
  }
  g_enabled.store(true, std::memory_order_release);
}

void disable_huge_blocks() noexcept {
  g_enabled.store(false, std::memory_order_release);
  std::lock_guard<std::mutex> lock(g_pool.mutex);
  g_pool.cache_limit = 0;
  evict(g_pool);
}

bool huge_blocks_enabled() noexcept { return g_enabled.load(std::memory_order_acquire); }

void* allocate_huge_block(std::size_t bytes) noexcept {
  if (bytes < kHugeBlockMinBytes || bytes > kMaxBytes || !g_enabled.load(std::memory_order_relaxed)) return nullptr;
  const std::size_t size = round_up(bytes);
  std::lock_guard<std::mutex> lock(g_pool.mutex);
  if (Block* cached = pick_cached(g_pool, size)) {
    if (void* p = serve_from_cache(g_pool, *cached, size)) return p;
  }
  Block* slot = free_slot(g_pool);
  if (slot == nullptr) return nullptr;
  char* p = map_aligned(size);
  if (p == nullptr) return nullptr;
  *slot = Block{p, size, 0};
  g_pool.stats.mapped += 1;
  mark_live(g_pool, *slot);
  return p;
}

bool release_huge_block(void* block) noexcept {
  if (!maybe_huge_block(block)) return false;
  std::lock_guard<std::mutex> lock(g_pool.mutex);
  for (Block& b : g_pool.blocks) {
    if (b.addr != block || b.freed_at != 0) continue;
    g_pool.stats.live_blocks -= 1;
    g_pool.stats.live_bytes -= b.bytes;
    b.freed_at = ++g_pool.clock;
    g_pool.stats.cached_blocks += 1;
    g_pool.stats.cached_bytes += b.bytes;
    evict(g_pool);
    return true;
  }
  return false;
}

HugeBlockStats huge_block_stats() noexcept {
  std::lock_guard<std::mutex> lock(g_pool.mutex);
  return g_pool.stats;
}

}  // namespace levelset
