// IndexHashTable: open addressing over 32-bit ids whose keys live elsewhere (positions,
// vertex triples): the caller hashes a key and says whether a stored id holds it. Linear
// probing in a power-of-two table at most half full; no deletion. Used to group equal keys in
// one pass where a sort would cost O(n log n) (weld_exact, unique_faces,
// bin_triangles_to_bricks). Each table salts its hashes with a random seed, so input crafted
// to collide (files come from the network) cannot force quadratic probing; the ids returned
// do not depend on the seed (a key maps to the first id inserted for it).
//
// find_or_insert(hash, id, equal): the stored id whose key equal(stored) says is the same, or
//   `id`, stored now, when there is none (so inserting in increasing id order maps every key to
//   its lowest id). Cost: O(1) expected. The table holds at most `capacity` ids (the
//   constructor's); with an unknown count, grow(hash_of) doubles it whenever full() says so.
// Threading: none (one table per caller).
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "core/huge_pages.hpp"

namespace levelset {

class IndexHashTable {
 public:
  explicit IndexHashTable(std::size_t capacity) : seed_(random_seed()) {
    std::size_t size = 16;
    while (size < 2 * capacity) size *= 2;
    reserve_with_huge_pages(slots_, size);
    slots_.assign(size, kEmpty);
    mask_ = size - 1;
  }

  template <typename Equal>
  std::uint32_t find_or_insert(std::uint64_t hash, std::uint32_t id, Equal&& equal) {
    for (std::size_t s = mix(hash ^ seed_) & mask_;; s = (s + 1) & mask_) {
      const std::uint32_t stored = slots_[s];
      if (stored == kEmpty) {
        slots_[s] = id;
        ++stored_;
        return id;
      }
      if (equal(stored)) return stored;
    }
  }

  // Whether `capacity` ids are stored: grow before the next insertion.
  bool full() const { return stored_ * 2 >= slots_.size(); }
  // Twice the capacity; every stored id is placed again by hash_of(id), its key's hash.
  template <typename HashOf>
  void grow(HashOf&& hash_of) {
    std::vector<std::uint32_t> old(2 * slots_.size(), kEmpty);
    old.swap(slots_);
    mask_ = slots_.size() - 1;
    for (const std::uint32_t id : old) {
      if (id == kEmpty) continue;
      std::size_t s = mix(hash_of(id) ^ seed_) & mask_;
      while (slots_[s] != kEmpty) s = (s + 1) & mask_;
      slots_[s] = id;
    }
  }

  // A 64-bit finaliser (the murmur3 one): keys that differ in few bits land far apart.
  static std::uint64_t mix(std::uint64_t h) {
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ull;
    return h ^ (h >> 33);
  }

 private:
  static std::uint64_t random_seed() {
    std::random_device device;
    return (std::uint64_t{device()} << 32) ^ device();
  }
  static constexpr std::uint32_t kEmpty = 0xffffffffu;
  std::uint64_t seed_;
  std::vector<std::uint32_t> slots_;
  std::size_t mask_ = 0, stored_ = 0;
};

}  // namespace levelset
