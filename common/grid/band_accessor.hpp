// BandAccessor: voxel reads with a cached brick, for stencils and scattered queries.
//
// The accessor remembers the last brick it touched. A query in the same brick costs a
// mask test and a popcount; a query in a brick that shares a face, edge or corner with the
// last allocated one walks the per-brick neighbour tables (no hash lookup); only a jump
// further away, or a diagonal step whose face path is unallocated, hashes. hash_lookups() counts
// them so tests can check the common case. One accessor per thread (it is mutable state);
// the band must not change topology while accessors are alive.
#pragma once

#include <cstdint>
#include <optional>

#include "grid/narrow_band.hpp"

namespace levelset {

class BandAccessor {
 public:
  explicit BandAccessor(const NarrowBand& band) : band_(&band) {}

  // Value in the band, +-background() outside it.
  float value(const Coord& c) {
    const std::uint32_t b = locate(brick_of(c));
    const int n = local_index(c);
    if (b == kNoBrick) return band_->is_inside_unallocated(c) ? -bg() : bg();
    const Brick& br = band_->bricks()[b];
    if (br.active.test(n)) return band_->values()[br.value_offset + br.slot(n)];
    return band_->stored_inside(br, n) ? -bg() : bg();
  }
  std::optional<float> probe(const Coord& c) {
    const std::uint32_t b = locate(brick_of(c));
    if (b == kNoBrick) return std::nullopt;
    const Brick& br = band_->bricks()[b];
    const int n = local_index(c);
    if (!br.active.test(n)) return std::nullopt;
    return band_->values()[br.value_offset + br.slot(n)];
  }
  bool is_active(const Coord& c) {
    const std::uint32_t b = locate(brick_of(c));
    return b != kNoBrick && band_->bricks()[b].active.test(local_index(c));
  }
  bool is_inside(const Coord& c) {
    const std::uint32_t b = locate(brick_of(c));
    if (b == kNoBrick) return band_->is_inside_unallocated(c);
    return band_->voxel_inside(b, local_index(c));
  }

  // Brick index for brick coordinates, using the cache and neighbour tables.
  std::uint32_t locate(const Coord& brick);

  std::uint64_t hash_lookups() const { return hash_lookups_; }

 private:
  float bg() const { return band_->background(); }

  const NarrowBand* band_;
  Coord cached_coord_{};
  std::uint32_t cached_ = kNoBrick;
  bool has_cache_ = false;
  Coord anchor_coord_{};
  std::uint32_t anchor_ = kNoBrick;  // last allocated brick located
  std::uint64_t hash_lookups_ = 0;
};

}  // namespace levelset
