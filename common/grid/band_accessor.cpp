#include "grid/band_accessor.hpp"

namespace levelset {

namespace {
// Follows face links along each axis where step is non-zero. Returns kNoBrick when the
// path leaves the allocated bricks.
std::uint32_t walk_faces(const NarrowBand& band, std::uint32_t b, const Coord& step) {
  for (int a = 0; a < 3 && b != kNoBrick; ++a) {
    if (step[a] != 0) b = band.neighbor(b, Face(2 * a + (step[a] > 0 ? 1 : 0)));
  }
  return b;
}
}  // namespace

std::uint32_t BandAccessor::locate(const Coord& brick) {
  if (has_cache_ && brick == cached_coord_) return cached_;
  std::uint32_t found = kNoBrick;
  bool resolved = false;
  // Walk from the last allocated brick seen (the anchor), so that stencils poking into
  // unallocated space at the band's edge come back without hashing.
  if (anchor_ != kNoBrick) {
    const Coord d = brick - anchor_coord_;
    if (d.x >= -1 && d.x <= 1 && d.y >= -1 && d.y <= 1 && d.z >= -1 && d.z <= 1) {
      found = walk_faces(*band_, anchor_, d);
      const int axes = (d.x != 0) + (d.y != 0) + (d.z != 0);
      // A face link (or the anchor itself) is authoritative; a broken diagonal path may
      // still hide a brick.
      resolved = found != kNoBrick || axes <= 1;
    }
  }
  if (!resolved) {
    ++hash_lookups_;
    found = band_->find_brick(brick);
  }
  cached_coord_ = brick;
  cached_ = found;
  has_cache_ = true;
  if (found != kNoBrick) {
    anchor_ = found;
    anchor_coord_ = brick;
  }
  return found;
}

}  // namespace levelset
