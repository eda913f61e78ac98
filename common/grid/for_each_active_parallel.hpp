// for_each_active_parallel: every active voxel of a band, in parallel, with its value index.
//
// Calls f(acc, b, c, value, slot) for every active voxel c of `band` (brick b, value index
// slot), TBB over chunks of `grain` bricks, with one BandAccessor of `accessed` per chunk (a
// band on the same grid: the band itself, or the one a result is compared with). f may write
// per-voxel outputs at `slot` and per-brick ones at `b` without locks. Cost O(active voxels).
#pragma once

#include <cstddef>
#include <cstdint>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "grid/band_accessor.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

template <typename F>
void for_each_active_parallel(const NarrowBand& band, const NarrowBand& accessed, std::uint32_t grain, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), grain),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      BandAccessor acc(accessed);
                      for (std::uint32_t b = r.begin(); b != r.end(); ++b) {
                        std::size_t slot = band.bricks()[b].value_offset;
                        band.for_each_active_in_brick(b, [&](const Coord& c, float v) { f(acc, b, c, v, slot++); });
                      }
                    });
}

}  // namespace levelset
