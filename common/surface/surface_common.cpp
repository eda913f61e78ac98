#include "surface/surface_common.hpp"

#include <algorithm>
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

void for_brick_batches(std::uint32_t bricks, const ProgressHook& progress, std::string_view stage,
                       const std::function<void(std::uint32_t)>& f) {
  constexpr std::uint32_t kBatch = 4096;
  for (std::uint32_t lo = 0; lo < bricks; lo += kBatch) {
    progress.step(double(lo) / double(bricks), stage);
    const std::uint32_t hi = std::min(bricks, lo + kBatch);
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(lo, hi, 8),
                      [&](const tbb::blocked_range<std::uint32_t>& r) {
                        for (std::uint32_t b = r.begin(); b != r.end(); ++b) f(b);
                      });
  }
  progress.step(1.0, stage);
}

}  // namespace levelset::surface_detail
