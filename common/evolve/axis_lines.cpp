#include "evolve/axis_lines.hpp"

#include <algorithm>
#include <bit>

namespace levelset::evolve::detail {

namespace {

constexpr int kLen = AxisLines::kLen;
constexpr std::uint32_t kAll = (1u << kLen) - 1;
constexpr std::uint32_t kOwn = ((1u << kBrickDim) - 1) << (-kLo);  // the brick's samples

// The polynomial through the last active sample before a gap and up to two more behind it
// (away from the gap): (0, p1), (-1, p2), (-2, p3), evaluated t steps into the gap.
struct GapPolynomial {
  int run = 0;  // active samples it passes through (1-3); 0: no active sample on that side
  double p1 = 0, p2 = 0, a = 0, b = 0;
  GapPolynomial(const float* v, std::uint32_t active, int last, int dir) {
    run = 1;
    while (run < 3) {
      const int q = last - dir * run;
      if (q < 0 || q >= kLen || !((active >> q) & 1u)) break;
      ++run;
    }
    p1 = v[last];
    p2 = run >= 2 ? v[last - dir] : p1;
    const double p3 = run >= 3 ? v[last - 2 * dir] : p2;
    a = 1.5 * p1 - 2.0 * p2 + 0.5 * p3;
    b = p1 - 2.0 * p2 + p3;
  }
  GapPolynomial() = default;
  double at(double t) const {
    if (run == 2) return p1 + t * (p1 - p2);
    if (run >= 3) return p1 + t * a + 0.5 * t * t * b;
    return p1;
  }
};

// Fills the `need`ed inactive samples of one line (`active` bit k: sample k is in the band):
// each from the nearer side of its gap (the left on a tie), when that side's last active
// sample is at most `reach` away; samples of a gap with no active side stay as they are.
void extrapolate_line(float* v, std::uint32_t active, std::uint32_t need, int reach) {
  while (need) {
    const int g0 = std::countr_zero(need);
    // The gap [k, e) around g0.
    const std::uint32_t below = active & ((1u << g0) - 1), above = active & ~((1u << g0) - 1);
    const int k = below ? 32 - std::countl_zero(below) : 0, e = above ? std::countr_zero(above) : kLen;
    const bool left = k > 0, right = e < kLen;
    const GapPolynomial from_l = left ? GapPolynomial(v, active, k - 1, 1) : GapPolynomial();
    const GapPolynomial from_r = right ? GapPolynomial(v, active, e, -1) : GapPolynomial();
    const std::uint32_t gap = (e < 32 ? (1u << e) - 1 : ~0u) & ~((1u << k) - 1);
    for (std::uint32_t in = need & gap; in; in &= in - 1) {
      const int g = std::countr_zero(in);
      const int dl = g - k + 1, dr = e - g;  // distance to the last active sample on each side
      const bool use_left = left && (!right || dl <= dr);
      if ((use_left ? dl : dr) > reach || (!left && !right)) continue;
      v[g] = float(use_left ? from_l.at(dl) : from_r.at(dr));
    }
    need &= ~gap;
  }
}

// The inactive samples an upwind stencil of half-width `reach` around an active brick sample
// reads.
std::uint32_t needed_samples(std::uint32_t active, int reach) {
  const std::uint32_t centres = active & kOwn;
  std::uint32_t spread = centres;
  for (int r = 1; r <= reach; ++r) spread |= (centres << r) | (centres >> r);
  return spread & ~active & kAll;
}

void fill_line(float* l, std::uint32_t active, int reach) {
  if (active == kAll) return;
  const std::uint32_t need = needed_samples(active, reach);
  if (need) extrapolate_line(l, active, need, reach);
}

}  // namespace

void fill_axis_lines(const float* tile, const std::uint32_t* rows, int reach, AxisLines& lines) {
  auto row = [&](int ty, int tz) { return rows[std::size_t(ty + kDim * tz)]; };  // tile-index rows
  for (int i = 0; i < kBrickDim; ++i)
    for (int j = 0; j < kBrickDim; ++j) {
      const int ti = i - kLo, tj = j - kLo;
      // x lines: (y, z) = (i, j): one row.
      if (const std::uint32_t act = row(ti, tj); act & kOwn) {
        float* l = lines.line(0, i, j);
        std::copy_n(tile + tile_index(kLo, i, j), kLen, l);
        fill_line(l, act, reach);
      }
      // y lines: (x, z) = (i, j); z lines: (x, y) = (i, j).
      std::uint32_t ay = 0, az = 0;
      for (int k = 0; k < kLen; ++k) {
        ay |= ((row(k, tj) >> ti) & 1u) << k;
        az |= ((row(tj, k) >> ti) & 1u) << k;
      }
      if (ay & kOwn) {
        float* l = lines.line(1, i, j);
        for (int k = 0; k < kLen; ++k) l[k] = tile[tile_index(i, k + kLo, j)];
        fill_line(l, ay, reach);
      }
      if (az & kOwn) {
        float* l = lines.line(2, i, j);
        for (int k = 0; k < kLen; ++k) l[k] = tile[tile_index(i, j, k + kLo)];
        fill_line(l, az, reach);
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
