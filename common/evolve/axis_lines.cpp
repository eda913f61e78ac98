#include "evolve/axis_lines.hpp"

#include <algorithm>


namespace levelset::evolve::detail {

namespace {

// Fills one line: `active` bit k says sample k is in the band.
void extrapolate_line(float* v, std::uint32_t active, int reach) {
  constexpr int n = AxisLines::kLen;
  int k = 0;
  while (k < n) {
    if ((active >> k) & 1u) {
      ++k;
      continue;
    }
    // Inactive run [k, e).
    int e = k;
    while (e < n && !((active >> e) & 1u)) ++e;
    const bool left = k > 0, right = e < n;
    for (int g = k; g < e; ++g) {
      const int dl = g - k + 1, dr = e - g;  // distance to the nearest active sample on each side
      const bool from_left = left && (!right || dl <= dr);
      if ((from_left ? dl : dr) > reach || (!left && !right)) continue;
      const int dir = from_left ? 1 : -1, last = from_left ? k - 1 : e;  // last active sample
      // Active samples behind `last`, away from the gap (at most 3).
      int run = 1;
      while (run < 3) {
        const int q = last - dir * run;
        if (q < 0 || q >= n || !((active >> q) & 1u)) break;
        ++run;
      }
      const double p1 = v[last], p2 = run >= 2 ? v[last - dir] : p1, p3 = run >= 3 ? v[last - 2 * dir] : p2;
      const double t = from_left ? dl : dr;  // steps beyond `last`
      // Polynomial through (0, p1), (-1, p2), (-2, p3) evaluated at t.
      double value = p1;
      if (run == 2) value = p1 + t * (p1 - p2);
      if (run >= 3) value = p1 + t * (1.5 * p1 - 2.0 * p2 + 0.5 * p3) + 0.5 * t * t * (p1 - 2.0 * p2 + p3);
      v[g] = float(value);
    }
    k = e;
  }
}

}  // namespace

void fill_axis_lines(const float* tile, const std::uint32_t* rows, int reach, AxisLines& lines) {
  constexpr int n = AxisLines::kLen;
  constexpr std::uint32_t all = (1u << n) - 1, own = ((1u << kBrickDim) - 1) << (-kLo);  // brick samples
  auto row = [&](int ty, int tz) { return rows[std::size_t(ty + kDim * tz)]; };  // tile-index rows
  for (int i = 0; i < kBrickDim; ++i)
    for (int j = 0; j < kBrickDim; ++j) {
      const int ti = i - kLo, tj = j - kLo;
      // x lines: (y, z) = (i, j): one row.
      {
        const std::uint32_t act = row(ti, tj);
        if (act & own) {
          float* l = lines.line(0, i, j);
          std::copy_n(tile + tile_index(kLo, i, j), n, l);
          if (act != all) extrapolate_line(l, act, reach);
        }
      }
      // y lines: (x, z) = (i, j); z lines: (x, y) = (i, j).
      std::uint32_t ay = 0, az = 0;
      for (int k = 0; k < n; ++k) {
        ay |= ((row(k, tj) >> ti) & 1u) << k;
        az |= ((row(tj, k) >> ti) & 1u) << k;
      }
      if (ay & own) {
        float* l = lines.line(1, i, j);
        for (int k = 0; k < n; ++k) l[k] = tile[tile_index(i, k + kLo, j)];
        if (ay != all) extrapolate_line(l, ay, reach);
      }
      if (az & own) {
        float* l = lines.line(2, i, j);
        for (int k = 0; k < n; ++k) l[k] = tile[tile_index(i, j, k + kLo)];
        if (az != all) extrapolate_line(l, az, reach);
      }
    }
}

void upwind_sides(const AxisLines& lines, const BrickMask& active, Scheme scheme, const SidesWanted& want,
                  UpwindSides& sides) {
  for (int a = 0; a < 3; ++a) {
    const bool minus = want.minus[std::size_t(a)], plus = want.plus[std::size_t(a)];
    if (!minus && !plus) continue;
    int k = 0;
    active.for_each_set([&](int n) {
      const Coord l = local_coord(n);
      // Line (i, j) across the axis and the position along it (AxisLines' layout).
      const float* c = a == 0 ? lines.line(0, l.y, l.z) + (l.x - kLo)
                       : a == 1 ? lines.line(1, l.x, l.z) + (l.y - kLo)
                                : lines.line(2, l.x, l.y) + (l.z - kLo);
      for (int j = 0; j < CentreSamples::kCount; ++j) sides.samples.at[std::size_t(j)][std::size_t(k)] = c[j - kStencilReach];
      ++k;
    });
    one_sided_batch(sides.samples, k, scheme, minus ? sides.minus[std::size_t(a)].data() : nullptr,
                    plus ? sides.plus[std::size_t(a)].data() : nullptr);
  }
}

}  // namespace levelset::evolve::detail
