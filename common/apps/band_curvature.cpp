#include "apps/band_curvature.hpp"

#include <cmath>
#include <cstddef>

#include "core/error.hpp"
#include "evolve/curvature.hpp"

namespace levelset::apps {

namespace {

double voxel_mean_curvature(BandAccessor& accessor, const Coord& c, double h) {
  float v[27];
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        v[(dx + 1) + 3 * (dy + 1) + 9 * (dz + 1)] = accessor.value(c + Coord{dx, dy, dz});
  const std::ptrdiff_t stride[3] = {1, 3, 9};
  return evolve::mean_curvature_at(v + 13, stride, h);
}

}  // namespace

double band_mean_curvature(BandAccessor& accessor, const NarrowBand& band, const Vec3d& p) {
  if (!isfinite(p)) throw Error(ErrorCode::NonFinite, "band_mean_curvature", "non-finite point");
  const Vec3d q = band.to_index_space(p);
  const Vec3d f{std::floor(q.x), std::floor(q.y), std::floor(q.z)};
  const Vec3d t = q - f;
  const Coord base{int(f.x), int(f.y), int(f.z)};
  double sum = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const int cx = corner & 1, cy = (corner >> 1) & 1, cz = corner >> 2;
    const double w = (cx ? t.x : 1 - t.x) * (cy ? t.y : 1 - t.y) * (cz ? t.z : 1 - t.z);
    if (w == 0.0) continue;
    sum += w * voxel_mean_curvature(accessor, base + Coord{cx, cy, cz}, band.voxel_size());
  }
  return sum;
}

}  // namespace levelset::apps
