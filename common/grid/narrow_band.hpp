// NarrowBand: a sparse signed-distance level set stored only near its zero level.
//
// Contract
// - Grid: voxel (i,j,k) sits at world position origin + h*(i,j,k); h = voxel_size > 0.
// - Band: voxels whose value is stored are "active". half_width W (in voxels, >= 1) is the
//   band's half-width; background() = W*h is the value reported for inactive voxels, with
//   their sign. Values are float32 world distances, negative inside.
// - Sign everywhere: every voxel of an allocated brick carries an inside bit; voxels in
//   unallocated bricks take the sign of the nearest allocated brick along their x-row
//   (or far_inside() when the row is empty). This is exact under the band invariant:
//   two 6-adjacent voxels of opposite sign are both active (|u| <= h <= W*h), so a run of
//   inactive voxels never crosses the zero level.
// - Storage: bricks of 8^3 voxels in (z,y,x) key order (grid/brick.hpp): per brick an active
//   mask, packed per-word rank bases, 6 face-neighbour indices (stencils that leave a brick
//   never hash) and a compact sign rule for inactive voxels (a 512-bit mask only for bricks
//   whose inactive voxels lie on both sides). Values of active voxels only, packed brick
//   after brick in one vector: about 4.8 bytes per active voxel on thin bands.
// - Cost: value lookup O(1) (hash + popcount); set_value on an active voxel O(1), on an
//   inactive one O(active voxels) (packed arrays shift; bulk changes go through
//   BandBuilder); sign query in an unallocated brick O(log bricks).
// - Threading: const methods are safe to call concurrently; parallel_for_bricks runs one
//   brick per task, so per-brick work gives bit-identical results for any thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/bbox.hpp"
#include "core/vec3.hpp"
#include "grid/brick.hpp"
#include "grid/brick_mask.hpp"
#include "grid/brick_table.hpp"
#include "grid/coord.hpp"

namespace levelset {

struct GridFrame {
  double voxel_size = 1.0;
  Vec3d origin{};
  double half_width = 3.0;  // voxels
};

class NarrowBand {
 public:
  NarrowBand() = default;
  // Throws Error{InvalidArgument} unless voxel_size > 0, origin finite, half_width >= 1.
  explicit NarrowBand(const GridFrame& frame);

  const GridFrame& frame() const { return frame_; }
  double voxel_size() const { return frame_.voxel_size; }
  const Vec3d& origin() const { return frame_.origin; }
  double half_width() const { return frame_.half_width; }
  float background() const { return background_; }
  bool far_inside() const { return far_inside_; }
  void set_far_inside(bool inside) { far_inside_ = inside; }

  Vec3d world(const Coord& c) const {
    return frame_.origin + Vec3d{double(c.x), double(c.y), double(c.z)} * frame_.voxel_size;
  }
  Vec3d to_index_space(const Vec3d& p) const { return (p - frame_.origin) / frame_.voxel_size; }

  std::size_t brick_count() const { return bricks_.size(); }
  std::size_t active_voxel_count() const { return values_.size(); }
  // Heap and object bytes held by this band (capacities, hash table and all).
  std::size_t memory_bytes() const;

  std::span<const Brick> bricks() const { return bricks_; }
  std::span<const float> values() const { return values_; }
  std::span<const float> brick_values(std::uint32_t b) const {
    return {values_.data() + bricks_[b].value_offset, std::size_t(bricks_[b].active_count())};
  }
  std::span<float> brick_values(std::uint32_t b) {
    return {values_.data() + bricks_[b].value_offset, std::size_t(bricks_[b].active_count())};
  }
  // Brick index for brick coordinates, kNoBrick if not allocated (one hash lookup).
  std::uint32_t find_brick(const Coord& brick) const {
    return brick_in_range(brick) ? table_.find(brick, bricks_) : kNoBrick;
  }
  std::uint32_t neighbor(std::uint32_t b, Face f) const { return bricks_[b].neighbor[int(f)]; }

  // Stored sign of voxel n of a brick, for inactive voxels (active ones: value < 0).
  bool stored_inside(const Brick& br, int n) const {
    if (br.signs == kSignsAllOutside) return false;
    if (br.signs == kSignsAllInside) return true;
    return sign_masks_[br.signs].test(n);
  }
  // stored_inside for the 64 voxels of z-slice w of a brick at once (bit = local_index & 63).
  std::uint64_t stored_inside_word(const Brick& br, int w) const {
    if (br.signs == kSignsAllOutside) return 0;
    if (br.signs == kSignsAllInside) return ~std::uint64_t{0};
    return sign_masks_[br.signs].words[std::size_t(w)];
  }
  // Sign of voxel n of brick b, active or not.
  bool voxel_inside(std::uint32_t b, int n) const {
    const Brick& br = bricks_[b];
    return br.active.test(n) ? values_[br.value_offset + br.slot(n)] < 0.0f : stored_inside(br, n);
  }
  // The full inside mask of brick b (all 512 voxels).
  BrickMask inside_mask(std::uint32_t b) const;
  // Number of bricks that own a sign mask (inactive voxels on both sides).
  std::size_t mixed_sign_bricks() const { return sign_masks_.size(); }

  // Point access by voxel index (convenience; hot loops use BandAccessor or tiles).
  bool is_active(const Coord& c) const;
  std::optional<float> value(const Coord& c) const;     // nullopt outside the band
  float value_or_background(const Coord& c) const;      // +-background() outside the band
  bool is_inside(const Coord& c) const;                 // sign anywhere, band or not
  // Sign of a voxel in an unallocated brick (the x-row rule above).
  bool is_inside_unallocated(const Coord& c) const;
  // The same when allocated brick `lower` is the -x neighbour of c's (unallocated) brick: the
  // search then ends at lower + 1 (keys run along x), so it is O(1) instead of O(log bricks).
  bool is_inside_unallocated_next_to(std::uint32_t lower, const Coord& c) const {
    const Coord bc = brick_of(c);
    if (!brick_in_range(bc)) return far_inside_;
    const int ly = c.y & 7, lz = c.z & 7;
    const std::uint32_t next = lower + 1;
    if (next < bricks_.size() && bricks_[next].coord.y == bc.y && bricks_[next].coord.z == bc.z)
      return voxel_inside(next, local_index(0, ly, lz));  // next brick along +x: first column
    return voxel_inside(lower, local_index(7, ly, lz));   // the lower neighbour: last column
  }

  // Sets a value, activating the voxel if needed (see cost above). Rejects non-finite values
  // and coordinates outside the index range with Error{InvalidArgument}.
  void set_value(const Coord& c, float v);
  // Makes a voxel inactive, keeping the sign of its last value. No-op when inactive.
  void deactivate(const Coord& c);

  IndexBox active_index_bounds() const;
  BBox active_world_bounds() const;

  // Bitwise equality of frame, topology, signs and values.
  bool identical(const NarrowBand& other) const;

  // f(Coord voxel, float value) for every active voxel, bricks in key order, serial.
  template <typename F>
  void for_each_active(F&& f) const {
    for (std::uint32_t b = 0; b < bricks_.size(); ++b) for_each_active_in_brick(b, f);
  }
  // f(Coord voxel, Vec3d world_position, float value) for every active voxel, serial.
  template <typename F>
  void for_each_active_world(F&& f) const {
    for_each_active([&](const Coord& c, float v) { f(c, world(c), v); });
  }
  template <typename F>
  void for_each_active_in_brick(std::uint32_t b, F&& f) const {
    const Brick& br = bricks_[b];
    const Coord o = brick_origin(br.coord);
    const float* v = values_.data() + br.value_offset;
    br.active.for_each_set([&](int n) { f(o + local_coord(n), *v++); });
  }

  // f(int n, float old) -> float for every active voxel n of brick b; stores the result
  // (whose sign is the voxel's sign). Topology is unchanged. Safe in parallel for distinct
  // bricks.
  template <typename F>
  void update_active_in_brick(std::uint32_t b, F&& f) {
    const Brick& br = bricks_[b];
    float* v = values_.data() + br.value_offset;
    br.active.for_each_set([&](int n) {
      *v = f(n, *v);
      ++v;
    });
  }

  // Exchanges the active values with `values` (same size, band value order) in O(1): the
  // topology and the stored signs of inactive voxels stay; active voxels take the signs of
  // their new values, so callers keep the band invariant (no sign change at the band's
  // edge). For time stepping. Error{InvalidArgument} when the sizes differ.
  void swap_values(std::vector<float>& values);

  // Raw construction for BandBuilder and the file reader: records sorted by brick key
  // without duplicates, values packed record after record in active-mask order. Throws
  // Error{InvalidArgument} when the records break these rules.
  static NarrowBand assemble(const GridFrame& frame, std::vector<BrickRecord> records,
                             std::vector<float> values, bool far_inside);

 private:
  void rebuild_index();  // rank bases, hash table, neighbour tables
  // Sign rule for a brick from its full inside mask (allocating a side mask if mixed).
  std::uint32_t compress_signs(const BrickMask& active, const BrickMask& inside);

  GridFrame frame_{};
  float background_ = 3.0f;
  bool far_inside_ = false;
  std::vector<Brick> bricks_;
  std::vector<float> values_;
  std::vector<BrickMask> sign_masks_;
  BrickTable table_;
};

// Runs f(brick_index) for every brick, in parallel (TBB), one brick per call.
template <typename F>
void parallel_for_bricks(const NarrowBand& band, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), 16),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      for (std::uint32_t b = r.begin(); b != r.end(); ++b) f(b);
                    });
}

}  // namespace levelset
