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
// - Storage: bricks of 8^3 voxels in (z,y,x) key order; per brick an active mask, an inside
//   mask, per-word rank bases and 6 face-neighbour indices (stencils that leave a brick
//   never hash). Values of active voxels only, packed brick after brick in one vector:
//   about 4.2-5 bytes per active voxel on thin bands.
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
#include "grid/brick_mask.hpp"
#include "grid/brick_table.hpp"
#include "grid/coord.hpp"

namespace levelset {

struct Brick {
  Coord coord;                        // brick coordinates (voxel index >> 3)
  std::uint32_t value_offset = 0;     // first value of this brick in NarrowBand::values()
  BrickMask active;                   // voxel holds a value
  BrickMask inside;                   // voxel is inside (value < 0); kept for inactive voxels too
  std::array<std::uint16_t, 8> rank_base{};  // active voxels in words before word w
  std::array<std::uint32_t, 6> neighbor{};   // -x,+x,-y,+y,-z,+z brick index or kNoBrick

  int active_count() const { return rank_base[7] + std::popcount(active.words[7]); }
  // Slot of active voxel n within this brick's values.
  int slot(int n) const { return rank_base[n >> 6] + active.rank_in_word(n); }
};

enum class Face : int { MinusX = 0, PlusX, MinusY, PlusY, MinusZ, PlusZ };

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
    return brick_in_range(brick) ? table_.find(brick_key(brick)) : kNoBrick;
  }
  std::uint32_t neighbor(std::uint32_t b, Face f) const { return bricks_[b].neighbor[int(f)]; }

  // Point access by voxel index (convenience; hot loops use BandAccessor or tiles).
  bool is_active(const Coord& c) const;
  std::optional<float> value(const Coord& c) const;     // nullopt outside the band
  float value_or_background(const Coord& c) const;      // +-background() outside the band
  bool is_inside(const Coord& c) const;                 // sign anywhere, band or not
  // Sign of a voxel in an unallocated brick (the x-row rule above).
  bool is_inside_unallocated(const Coord& c) const;

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
  template <typename F>
  void for_each_active_in_brick(std::uint32_t b, F&& f) const {
    const Brick& br = bricks_[b];
    const Coord o = brick_origin(br.coord);
    const float* v = values_.data() + br.value_offset;
    br.active.for_each_set([&](int n) { f(o + local_coord(n), *v++); });
  }

  // f(int n, float old) -> float for every active voxel n of brick b; stores the result and
  // its sign. Topology is unchanged. Safe in parallel for distinct bricks.
  template <typename F>
  void update_active_in_brick(std::uint32_t b, F&& f) {
    Brick& br = bricks_[b];
    float* v = values_.data() + br.value_offset;
    br.active.for_each_set([&](int n) {
      *v = f(n, *v);
      br.inside.assign(n, *v < 0.0f);
      ++v;
    });
  }

  // Raw construction for BandBuilder and the file reader: bricks sorted by key with
  // masks set and value_offset consistent; derives rank bases, hash and neighbours.
  static NarrowBand assemble(const GridFrame& frame, std::vector<Brick> bricks,
                             std::vector<float> values, bool far_inside);

 private:
  void rebuild_index();  // rank bases, hash table, neighbour tables

  GridFrame frame_{};
  float background_ = 3.0f;
  bool far_inside_ = false;
  std::vector<Brick> bricks_;
  std::vector<float> values_;
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
