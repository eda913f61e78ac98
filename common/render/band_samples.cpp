#include "render/band_samples.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "apps/band_curvature.hpp"
#include "grid/band_accessor.hpp"

namespace levelset::render {

BandPoints sample_band_points(const NarrowBand& band, const Vec3d& origin, std::size_t max_points) {
  BandPoints s;
  const std::size_t total = band.active_voxel_count();
  const std::size_t stride = max_points == 0 ? total + 1 : std::max<std::size_t>(1, (total + max_points - 1) / max_points);
  BandAccessor acc(band);
  const double h = band.voxel_size();
  std::size_t n = 0;
  auto push = [&](std::vector<float>& out, const Vec3d& p) {
    out.push_back(float(p.x)), out.push_back(float(p.y)), out.push_back(float(p.z));
  };
  band.for_each_active_world([&](const Coord& c, const Vec3d& world, float value) {
    const bool take = n++ % stride == 0;
    const Vec3d p = world - origin;
    bool edge = false;
    for (int axis = 0; axis < 3 && !edge; ++axis)
      for (int d = -1; d <= 1 && !edge; d += 2) {
        Coord q = c;
        (axis == 0 ? q.x : axis == 1 ? q.y : q.z) += d;
        edge = !acc.is_active(q);
      }
    if (edge && take) push(s.boundary, p);
    if (!take) return;
    const Vec3d g{acc.value({c.x + 1, c.y, c.z}) - acc.value({c.x - 1, c.y, c.z}),
                  acc.value({c.x, c.y + 1, c.z}) - acc.value({c.x, c.y - 1, c.z}),
                  acc.value({c.x, c.y, c.z + 1}) - acc.value({c.x, c.y, c.z - 1})};
    const double gl = length(g) / (2 * h);
    const Vec3d q = gl > 1e-12 ? p - g * (double(value) / (2 * h * gl)) : p;
    push(s.positions, p);
    s.values.push_back(value);
    push(s.closest, q);
  });
  return s;
}

DenseVolume sample_dense_volume(const NarrowBand& band, int max_side) {
  DenseVolume v;
  v.background = band.background();
  v.voxel_size = band.voxel_size();
  const IndexBox box = band.active_index_bounds();
  if (box.empty()) return v;
  const int ex = box.max.x - box.min.x + 1, ey = box.max.y - box.min.y + 1, ez = box.max.z - box.min.z + 1;
  const int longest = std::max({ex, ey, ez});
  const int s = std::max(1, (longest + std::max(1, max_side) - 1) / std::max(1, max_side));
  v.nx = (ex + s - 1) / s, v.ny = (ey + s - 1) / s, v.nz = (ez + s - 1) / s;
  const double h = band.voxel_size();
  v.box_min = band.world(box.min) - Vec3d{1, 1, 1} * (0.5 * s * h);
  v.box_max = v.box_min + Vec3d{double(v.nx), double(v.ny), double(v.nz)} * (s * h);
  v.values.resize(std::size_t(v.nx) * v.ny * v.nz);
  tbb::parallel_for(0, v.nz, [&](int k) {
    BandAccessor acc(band);
    float* out = v.values.data() + std::size_t(k) * v.nx * v.ny;
    for (int j = 0; j < v.ny; ++j)
      for (int i = 0; i < v.nx; ++i)
        *out++ = acc.value({box.min.x + i * s, box.min.y + j * s, box.min.z + k * s});
  });
  return v;
}

std::vector<float> vertex_curvature(const TriangleMesh& mesh, const NarrowBand& band) {
  std::vector<float> h(mesh.vertices.size(), 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, h.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    BandAccessor acc(band);
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const double k = apps::band_mean_curvature(acc, band, mesh.vertices[i]);
      h[i] = std::isfinite(k) ? float(k) : 0.0f;
    }
  });
  return h;
}

}  // namespace levelset::render
