#include "grid/interpolate.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace levelset {

float sample_trilinear(BandAccessor& accessor, const NarrowBand& band, const Vec3d& p) {
  if (!isfinite(p)) throw Error(ErrorCode::NonFinite, "sample point", "non-finite coordinate");
  const Vec3d q = band.to_index_space(p);
  const double limit = double(kVoxelCoordLimit) + 16.0;
  Coord base;
  double t[3];
  for (int a = 0; a < 3; ++a) {
    if (!(q[a] > -limit && q[a] < limit)) return band.far_inside() ? -band.background() : band.background();
    // Snap round-off from the world -> index transform so voxel centres sample exactly.
    const double r = std::round(q[a]);
    const double qa = std::abs(q[a] - r) < 1e-9 ? r : q[a];
    const double f = std::floor(qa);
    base[a] = static_cast<std::int32_t>(f);
    t[a] = qa - f;
  }
  double acc = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
    const double w = (dx ? t[0] : 1 - t[0]) * (dy ? t[1] : 1 - t[1]) * (dz ? t[2] : 1 - t[2]);
    if (w == 0.0) continue;
    acc += w * accessor.value(base + Coord{dx, dy, dz});
  }
  return static_cast<float>(acc);
}

}  // namespace levelset
