// Quantities of evolve() taken from the zero level (evolution_operator.hpp): kavg, the
// area-weighted mean curvature, and the speeds extended from the front.
#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "evolve/axis_lines.hpp"
#include "evolve/curvature.hpp"
#include "evolve/evolution_operator.hpp"
#include "grid/band_accessor.hpp"
#include "grid/interpolate.hpp"
#include "grid/tile.hpp"

namespace levelset::evolve::detail {

// Area-weighted mean of H over the zero level: sum of H delta(u) |grad u| / sum of
// delta(u) |grad u| over the band, with the smeared delta of width 1.5 h.
double mean_curvature_average(const NarrowBand& band) {
  const double h = band.voxel_size(), eps = 1.5 * h;
  struct Acc {
    double num = 0, den = 0;
  };
  tbb::combinable<Acc> acc;
  tbb::enumerable_thread_specific<std::vector<float>> tiles([] { return std::vector<float>(std::size_t(kDim) * kDim * kDim); });
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), 16),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
    std::vector<float>& tile = tiles.local();
    Acc& a = acc.local();
    for (std::uint32_t b = r.begin(); b != r.end(); ++b) {
      const Brick& br = band.bricks()[b];
      const float* vals = band.values().data() + br.value_offset;
      bool any = false;
      for (int i = 0; i < br.active_count() && !any; ++i) any = std::abs(double(vals[i])) < eps;
      if (!any) continue;
      gather_box(band, b, kLo, kHi, tile, {});
      br.active.for_each_set([&](int n) {
        const Coord l = local_coord(n);
        const float* v = tile.data() + tile_index(l.x, l.y, l.z);
        const double u = *v;
        if (std::abs(u) >= eps) return;
        const Vec3d g{(double(v[1]) - double(v[-1])) / (2 * h), (double(v[kDim]) - double(v[-kDim])) / (2 * h),
                      (double(v[kDim * kDim]) - double(v[-kDim * kDim])) / (2 * h)};
        const double w = (1.0 + std::cos(3.141592653589793 * u / eps)) / (2 * eps) * length(g);
        a.num += w * mean_curvature_at(v, kTileStride, h);
        a.den += w;
      });
    }
  });
  const Acc total = acc.combine([](const Acc& x, const Acc& y) { return Acc{x.num + y.num, x.den + y.den}; });
  return total.den > 0 ? total.num / total.den : 0.0;
}

// Speeds extended from the zero level: each voxel takes the speeds at its closest point
// x - u n (trilinear in the band's speeds; all 8 corners there are active for W >= 2).
void extend_speeds(const NarrowBand& band, std::vector<float>& beta_a, std::vector<float>& beta_p) {
  NarrowBand field_a = band, field_p = band;
  std::vector<float> a = beta_a, p = beta_p;
  field_a.swap_values(a);
  field_p.swap_values(p);
  const double h = band.voxel_size();
  std::vector<float> ext_a(beta_a.size()), ext_p(beta_p.size());
  tbb::enumerable_thread_specific<std::vector<float>> tiles([] { return std::vector<float>(std::size_t(kDim) * kDim * kDim); });
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), 8),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
    std::vector<float>& tile = tiles.local();
    BandAccessor acc_a(field_a), acc_p(field_p);
    for (std::uint32_t b = r.begin(); b != r.end(); ++b) {
      gather_box(band, b, kLo, kHi, tile, {});
      const Brick& br = band.bricks()[b];
      const Coord origin = brick_origin(br.coord);
      std::size_t k = br.value_offset;
      br.active.for_each_set([&](int n) {
        const Coord l = local_coord(n);
        const float* v = tile.data() + tile_index(l.x, l.y, l.z);
        const Vec3d g{(double(v[1]) - double(v[-1])) / (2 * h), (double(v[kDim]) - double(v[-kDim])) / (2 * h),
                      (double(v[kDim * kDim]) - double(v[-kDim * kDim])) / (2 * h)};
        const double gn = length(g);
        const Vec3d x = band.world(origin + l);
        const Vec3d c = gn > 1e-12 ? x - g * (double(*v) / (gn * gn)) : x;
        ext_a[k] = sample_trilinear(acc_a, field_a, c);
        ext_p[k] = sample_trilinear(acc_p, field_p, c);
        ++k;
      });
    }
  });
  beta_a.swap(ext_a);
  beta_p.swap(ext_p);
}

}  // namespace levelset::evolve::detail
