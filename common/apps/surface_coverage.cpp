#include "apps/surface_coverage.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "grid/interpolate.hpp"

namespace levelset::apps {

SurfaceCoverageResult surface_coverage(const NarrowBand& band, std::span<const Vec3d> points,
                                       const SurfaceCoverageOptions& o) {
  if (!(o.distance > 0.0) || !std::isfinite(o.distance))
    throw Error(ErrorCode::InvalidArgument, "surface_coverage", "the distance must be a positive number");
  if (o.samples == 0) throw Error(ErrorCode::InvalidArgument, "surface_coverage", "samples must be > 0");
  const double r = std::min(o.distance, 0.99 * double(band.background()));
  const std::size_t stride = std::max<std::size_t>(1, (points.size() + o.samples - 1) / o.samples);
  BandAccessor acc(band);
  SurfaceCoverageResult result;
  std::size_t near = 0;
  for (std::size_t i = 0; i < points.size(); i += stride) {
    const Vec3d& p = points[i];
    if (o.within && !(p.x >= o.within->min.x && p.y >= o.within->min.y && p.z >= o.within->min.z &&
                      p.x <= o.within->max.x && p.y <= o.within->max.y && p.z <= o.within->max.z))
      continue;
    ++result.tested;
    if (std::abs(double(sample_trilinear(acc, band, p))) <= r) ++near;
  }
  if (result.tested > 0) result.fraction = double(near) / double(result.tested);
  return result;
}

}  // namespace levelset::apps
