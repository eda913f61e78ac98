#include "distance/redistance_near.hpp"

#include <cmath>
#include <cstdint>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "grid/band_accessor.hpp"

namespace levelset {

namespace {

// Marks in `to` every allocated brick within one brick (26-neighbourhood) of a brick marked in
// `from`; returns how many it marked.
std::size_t dilate_bricks(const NarrowBand& band, const std::vector<std::uint8_t>& from, std::vector<std::uint8_t>& to) {
  std::size_t marked = 0;
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) {
    if (!from[b]) continue;
    const Coord c = band.bricks()[b].coord;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const std::uint32_t n = band.find_brick(c + Coord{dx, dy, dz});
          if (n != kNoBrick && !to[n]) {
            to[n] = 1;
            ++marked;
          }
        }
  }
  return marked;
}

// The bricks marked in `region` as a band of their own (the same frame, topology, signs and
// values; bricks are kept in key order, as the band holds them).
NarrowBand sub_band(const NarrowBand& band, const std::vector<std::uint8_t>& region) {
  std::vector<BrickRecord> records;
  std::vector<float> values;
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) {
    if (!region[b]) continue;
    const Brick& br = band.bricks()[b];
    records.push_back({br.coord, br.active, band.inside_mask(b)});
    const auto v = band.brick_values(b);
    values.insert(values.end(), v.begin(), v.end());
  }
  return NarrowBand::assemble(band.frame(), std::move(records), std::move(values), band.far_inside());
}

}  // namespace

RedistanceNearResult redistance_near(NarrowBand band, const std::vector<Coord>& changed,
                                     const RedistanceNearOptions& options) {
  const double W = band.half_width();
  if (!(W <= 8.0))
    throw Error(ErrorCode::InvalidArgument, "redistance_near",
                "band half-width " + std::to_string(W) + " exceeds the one-brick reach (8 voxels)");
  RedistanceNearResult result;
  if (changed.empty()) {
    result.band = std::move(band);
    return result;
  }
  std::vector<std::uint8_t> seed(band.brick_count(), 0), inner(band.brick_count(), 0), region(band.brick_count(), 0);
  for (const Coord& c : changed) {
    const std::uint32_t b = band.find_brick(brick_of(c));
    if (b == kNoBrick)
      throw Error(ErrorCode::InvalidArgument, "redistance_near",
                  "changed voxel (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " + std::to_string(c.z) +
                      ") lies outside the band's bricks");
    seed[b] = 1;
  }
  result.bricks_redistanced = dilate_bricks(band, seed, inner);
  if (double(dilate_bricks(band, inner, region)) > options.max_share * double(band.brick_count())) {
    std::fill(inner.begin(), inner.end(), std::uint8_t{1});
    std::fill(region.begin(), region.end(), std::uint8_t{1});
    result.bricks_redistanced = band.brick_count();
  }
  RedistanceOptions ro;
  ro.order = options.order;
  ro.tolerance = options.tolerance;
  ro.progress = options.progress;
  const NarrowBand redone = redistance(sub_band(band, region), ro).band;
  std::vector<float> values(band.values().begin(), band.values().end());
  const float edge = float(W * band.voxel_size());
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), 16),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      BandAccessor acc(redone);
                      for (std::uint32_t b = r.begin(); b != r.end(); ++b) {
                        if (!inner[b]) continue;
                        std::size_t i = band.bricks()[b].value_offset;
                        band.for_each_active_in_brick(b, [&](const Coord& c, float old) {
                          const bool inside = old < 0.0f;
                          const std::optional<float> v = acc.probe(c);
                          // Beyond W in the sub-band: the band's edge, on the voxel's side.
                          float next = v ? *v : (inside ? -edge : edge);
                          if ((next < 0.0f) != inside) next = old;  // (redistance keeps signs)
                          values[i++] = next;
                        });
                      }
                    });
  band.swap_values(values);
  result.band = std::move(band);
  return result;
}

}  // namespace levelset
