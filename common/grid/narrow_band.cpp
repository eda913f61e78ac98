#include "grid/narrow_band.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/error.hpp"
#include "core/text.hpp"

namespace levelset {

namespace {

void validate_frame(const GridFrame& f) {
  if (!(std::isfinite(f.voxel_size) && f.voxel_size > 0))
    throw Error(ErrorCode::InvalidArgument, "voxel_size",
                "must be finite and > 0, got " + format_number(f.voxel_size));
  if (!isfinite(f.origin)) throw Error(ErrorCode::InvalidArgument, "origin", "must be finite");
  if (!(std::isfinite(f.half_width) && f.half_width >= 1.0 && f.half_width <= 1024.0))
    throw Error(ErrorCode::InvalidArgument, "half_width",
                "band half-width must be in [1, 1024] voxels, got " + format_number(f.half_width));
  const double bg = f.half_width * f.voxel_size;
  if (!(bg < 1e30))
    throw Error(ErrorCode::InvalidArgument, "voxel_size", "band width overflows float");
}

void check_coord(const Coord& c) {
  if (brick_in_range(brick_of(c))) return;
  char msg[128];
  std::snprintf(msg, sizeof msg, "(%d,%d,%d) is outside the index range +-%d", c.x, c.y, c.z,
                kVoxelCoordLimit);
  throw Error(ErrorCode::InvalidArgument, "voxel index", msg);
}

bool brick_key_less(const Brick& a, const Brick& b) {
  return brick_key(a.coord) < brick_key(b.coord);
}

}  // namespace

NarrowBand::NarrowBand(const GridFrame& frame) : frame_(frame) {
  validate_frame(frame);
  background_ = static_cast<float>(frame.half_width * frame.voxel_size);
}

NarrowBand NarrowBand::assemble(const GridFrame& frame, std::vector<BrickRecord> records,
                                std::vector<float> values, bool far_inside) {
  NarrowBand band(frame);
  band.far_inside_ = far_inside;
  band.bricks_.resize(records.size());
  std::uint64_t offset = 0;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const BrickRecord& r = records[i];
    if (!brick_in_range(r.coord))
      throw Error(ErrorCode::InvalidArgument, "assemble", "brick " + std::to_string(i) + " out of range");
    if (i > 0 && brick_key(records[i - 1].coord) >= brick_key(r.coord))
      throw Error(ErrorCode::InvalidArgument, "assemble",
                  "bricks not sorted or duplicated at brick " + std::to_string(i));
    Brick& b = band.bricks_[i];
    b.coord = r.coord;
    b.active = r.active;
    b.value_offset = static_cast<std::uint32_t>(offset);
    b.signs = band.compress_signs(r.active, r.inside);
    offset += static_cast<std::uint64_t>(r.active.count());
    if (offset >= 0xffffffffull)
      throw Error(ErrorCode::LimitExceeded, "assemble", "more than 2^32-1 active voxels");
  }
  if (offset != values.size())
    throw Error(ErrorCode::InvalidArgument, "assemble",
                "active masks hold " + std::to_string(offset) + " voxels but " +
                    std::to_string(values.size()) + " values were given");
  band.values_ = std::move(values);
  band.sign_masks_.shrink_to_fit();
  band.rebuild_index();
  return band;
}

std::uint32_t NarrowBand::compress_signs(const BrickMask& active, const BrickMask& inside) {
  bool any_in = false, any_out = false;
  for (int w = 0; w < 8; ++w) {
    const std::uint64_t inactive = ~active.words[w];
    any_in |= (inactive & inside.words[w]) != 0;
    any_out |= (inactive & ~inside.words[w]) != 0;
  }
  if (!any_in) return kSignsAllOutside;
  if (!any_out) return kSignsAllInside;
  if (sign_masks_.size() >= kSignsAllInside)
    throw Error(ErrorCode::LimitExceeded, "signs", "too many mixed-sign bricks");
  sign_masks_.push_back(inside);
  return static_cast<std::uint32_t>(sign_masks_.size() - 1);
}

void NarrowBand::rebuild_index() {
  for (Brick& b : bricks_) {
    std::uint64_t packed = 0, base = 0;
    for (int w = 1; w < 8; ++w) {
      base += static_cast<std::uint64_t>(std::popcount(b.active.words[w - 1]));
      packed |= base << (9 * (w - 1));
    }
    b.packed_ranks = packed;
  }
  table_.rebuild(bricks_);
  static constexpr Coord kFaceStep[6] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0},
                                         {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};
  for (Brick& b : bricks_) {
    for (int f = 0; f < 6; ++f) b.neighbor[f] = find_brick(b.coord + kFaceStep[f]);
  }
}

BrickMask NarrowBand::inside_mask(std::uint32_t b) const {
  const Brick& br = bricks_[b];
  BrickMask m;
  if (br.signs == kSignsAllInside) m.words.fill(~std::uint64_t{0});
  if (br.signs < kSignsAllInside) m = sign_masks_[br.signs];
  const float* v = values_.data() + br.value_offset;
  br.active.for_each_set([&](int n) { m.assign(n, *v++ < 0.0f); });
  return m;
}

std::size_t NarrowBand::memory_bytes() const {
  return sizeof(*this) + bricks_.capacity() * sizeof(Brick) +
         values_.capacity() * sizeof(float) + sign_masks_.capacity() * sizeof(BrickMask) +
         table_.memory_bytes();
}

bool NarrowBand::is_active(const Coord& c) const {
  const std::uint32_t b = find_brick(brick_of(c));
  return b != kNoBrick && bricks_[b].active.test(local_index(c));
}

std::optional<float> NarrowBand::value(const Coord& c) const {
  const std::uint32_t b = find_brick(brick_of(c));
  if (b == kNoBrick) return std::nullopt;
  const Brick& br = bricks_[b];
  const int n = local_index(c);
  if (!br.active.test(n)) return std::nullopt;
  return values_[br.value_offset + br.slot(n)];
}

float NarrowBand::value_or_background(const Coord& c) const {
  const std::uint32_t b = find_brick(brick_of(c));
  if (b == kNoBrick) return is_inside_unallocated(c) ? -background_ : background_;
  const Brick& br = bricks_[b];
  const int n = local_index(c);
  if (br.active.test(n)) return values_[br.value_offset + br.slot(n)];
  return stored_inside(br, n) ? -background_ : background_;
}

void NarrowBand::swap_values(std::vector<float>& values) {
  if (values.size() != values_.size())
    throw Error(ErrorCode::InvalidArgument, "swap_values",
                "expected " + std::to_string(values_.size()) + " values, got " + std::to_string(values.size()));
  values_.swap(values);
}

bool NarrowBand::is_inside(const Coord& c) const {
  const std::uint32_t b = find_brick(brick_of(c));
  if (b == kNoBrick) return is_inside_unallocated(c);
  return voxel_inside(b, local_index(c));
}

bool NarrowBand::is_inside_unallocated(const Coord& c) const {
  const Coord bc = brick_of(c);
  if (!brick_in_range(bc)) return far_inside_;
  const std::uint64_t key = brick_key(bc);
  auto it = std::lower_bound(bricks_.begin(), bricks_.end(), key,
                             [](const Brick& b, std::uint64_t k) { return brick_key(b.coord) < k; });
  const int ly = c.y & 7, lz = c.z & 7;
  const auto index = static_cast<std::uint32_t>(it - bricks_.begin());
  if (it != bricks_.end() && it->coord.y == bc.y && it->coord.z == bc.z)
    return voxel_inside(index, local_index(0, ly, lz));  // next brick along +x: first column
  if (it != bricks_.begin()) {
    const Brick& prev = *(it - 1);
    if (prev.coord.y == bc.y && prev.coord.z == bc.z)
      return voxel_inside(index - 1, local_index(7, ly, lz));  // previous brick: last column
  }
  return far_inside_;
}

void NarrowBand::set_value(const Coord& c, float v) {
  if (!std::isfinite(v))
    throw Error(ErrorCode::InvalidArgument, "set_value", "value must be finite");
  check_coord(c);
  const Coord bc = brick_of(c);
  std::uint32_t b = find_brick(bc);
  if (b == kNoBrick) {
    // New brick: its inactive voxels keep the sign they had while unallocated.
    Brick nb;
    nb.coord = bc;
    nb.signs = is_inside_unallocated(c) ? kSignsAllInside : kSignsAllOutside;
    auto it = std::lower_bound(bricks_.begin(), bricks_.end(), nb, brick_key_less);
    nb.value_offset = it == bricks_.end() ? std::uint32_t(values_.size()) : it->value_offset;
    it = bricks_.insert(it, nb);
    b = static_cast<std::uint32_t>(it - bricks_.begin());
    rebuild_index();
  }
  Brick& br = bricks_[b];
  const int n = local_index(c);
  if (br.active.test(n)) {
    values_[br.value_offset + br.slot(n)] = v;
    return;
  }
  if (values_.size() >= 0xffffffffu)
    throw Error(ErrorCode::LimitExceeded, "set_value", "more than 2^32-1 active voxels");
  const std::size_t pos = br.value_offset + br.slot(n);
  values_.insert(values_.begin() + std::ptrdiff_t(pos), v);
  br.active.set(n);
  for (int w = (n >> 6) + 1; w < 8; ++w) br.packed_ranks += std::uint64_t{1} << (9 * (w - 1));
  for (std::size_t i = b + 1; i < bricks_.size(); ++i) ++bricks_[i].value_offset;
}

void NarrowBand::deactivate(const Coord& c) {
  const std::uint32_t b = find_brick(brick_of(c));
  if (b == kNoBrick) return;
  Brick& br = bricks_[b];
  const int n = local_index(c);
  if (!br.active.test(n)) return;
  const std::size_t pos = br.value_offset + br.slot(n);
  const bool inside = values_[pos] < 0.0f;
  // Record the voxel's sign; a uniform brick that gains the other sign becomes mixed.
  if (br.signs < kSignsAllInside) {
    sign_masks_[br.signs].assign(n, inside);
  } else if (inside != (br.signs == kSignsAllInside)) {
    BrickMask m;
    if (br.signs == kSignsAllInside) m.words.fill(~std::uint64_t{0});
    m.assign(n, inside);
    br.signs = compress_signs(BrickMask{}, m);
  }
  values_.erase(values_.begin() + std::ptrdiff_t(pos));
  br.active.reset(n);
  for (int w = (n >> 6) + 1; w < 8; ++w) br.packed_ranks -= std::uint64_t{1} << (9 * (w - 1));
  for (std::size_t i = b + 1; i < bricks_.size(); ++i) --bricks_[i].value_offset;
}

IndexBox NarrowBand::active_index_bounds() const {
  IndexBox box;
  for (const Brick& br : bricks_) {
    if (br.active.none()) continue;
    // Tight per brick: extents of set bits along each axis.
    int lo[3] = {8, 8, 8}, hi[3] = {-1, -1, -1};
    br.active.for_each_set([&](int n) {
      const Coord l = local_coord(n);
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], l[a]);
        hi[a] = std::max(hi[a], l[a]);
      }
    });
    const Coord o = brick_origin(br.coord);
    box.extend(o + Coord{lo[0], lo[1], lo[2]});
    box.extend(o + Coord{hi[0], hi[1], hi[2]});
  }
  return box;
}

BBox NarrowBand::active_world_bounds() const {
  const IndexBox ib = active_index_bounds();
  BBox box;
  if (ib.empty()) return box;
  box.extend(world(ib.min));
  box.extend(world(ib.max));
  return box;
}

bool NarrowBand::identical(const NarrowBand& o) const {
  if (std::memcmp(&frame_.voxel_size, &o.frame_.voxel_size, sizeof(double)) != 0 ||
      std::memcmp(&frame_.half_width, &o.frame_.half_width, sizeof(double)) != 0 ||
      !(frame_.origin == o.frame_.origin) || far_inside_ != o.far_inside_ ||
      bricks_.size() != o.bricks_.size() || values_.size() != o.values_.size())
    return false;
  for (std::uint32_t i = 0; i < bricks_.size(); ++i) {
    const Brick &a = bricks_[i], &b = o.bricks_[i];
    if (!(a.coord == b.coord) || !(a.active == b.active) || a.value_offset != b.value_offset ||
        !(inside_mask(i) == o.inside_mask(i)))
      return false;
  }
  return values_.empty() ||
         std::memcmp(values_.data(), o.values_.data(), values_.size() * sizeof(float)) == 0;
}

}  // namespace levelset
