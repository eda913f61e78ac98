#include "surface/surface_common.hpp"

#include <algorithm>
#include <bit>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"

namespace levelset::surface_detail {

void check_iso(const NarrowBand& band, double iso, std::string_view where) {
  if (!std::isfinite(iso) || !(std::abs(iso) < double(band.background())))
    throw Error(ErrorCode::InvalidArgument, std::string(where),
                "iso must be finite with |iso| < the band limit " + std::to_string(band.background()));
}

std::vector<std::uint8_t> bricks_with_crossings(const NarrowBand& band, double iso) {
  const std::size_t nb = band.brick_count();
  // Bit 0: some active value < iso; bit 1: some active value >= iso.
  std::vector<std::uint8_t> sides(nb);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nb, 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const std::span<const float> v = band.brick_values(std::uint32_t(b));
      bool below = false, above = false;
      for (const float x : v) {
        below |= double(x) < iso;
        above |= !(double(x) < iso);
      }
      sides[b] = std::uint8_t((below ? 1 : 0) | (above ? 2 : 0));
    }
  });
  return bricks_with_crossings(band, sides);
}

std::vector<std::uint8_t> bricks_with_crossings(const NarrowBand& band, std::span<const std::uint8_t> sides) {
  const std::size_t nb = band.brick_count();
  std::vector<std::uint8_t> work(nb);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nb, 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      std::uint8_t s = 0;
      for (int d = 0; d < 8 && s != 3; ++d) {
        std::uint32_t cur = std::uint32_t(b);
        for (int a = 0; a < 3 && cur != kNoBrick; ++a)
          if ((d >> a) & 1) cur = band.neighbor(cur, Face(2 * a + 1));
        if (cur == kNoBrick && std::popcount(unsigned(d)) > 1)
          cur = band.find_brick(band.bricks()[b].coord + Coord{d & 1, (d >> 1) & 1, (d >> 2) & 1});
        if (cur != kNoBrick) s |= sides[cur];
      }
      work[b] = s == 3 ? 1 : 0;
    }
  });
  return work;
}

void for_brick_batches(std::uint32_t bricks, const ProgressHook& progress, std::string_view stage,
                       const std::function<void(std::uint32_t)>& f, double from, double to) {
  constexpr std::uint32_t kBatch = 4096;
  for (std::uint32_t lo = 0; lo < bricks; lo += kBatch) {
    progress.step(from + (to - from) * double(lo) / double(bricks), stage);
    const std::uint32_t hi = std::min(bricks, lo + kBatch);
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(lo, hi, 8),
                      [&](const tbb::blocked_range<std::uint32_t>& r) {
                        for (std::uint32_t b = r.begin(); b != r.end(); ++b) f(b);
                      });
  }
  progress.step(to, stage);
}

void size_result(SurfaceResult& r, std::size_t vertices, std::size_t triangles) {
  tbb::parallel_invoke([&] { resize_with_huge_pages(r.mesh.vertices, vertices); },
                       [&] { resize_with_huge_pages(r.normals, vertices); },
                       [&] { resize_with_huge_pages(r.mesh.triangles, triangles); });
}

}  // namespace levelset::surface_detail
