#include "evolve/curvature_batch.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "evolve/curvature.hpp"

namespace levelset::evolve {

namespace {

constexpr int kChunk = 64;

// The 19 stencil samples: centre, x-, x+, y-, y+, z-, z+, then the cross terms' corners in
// the order central_derivs reads them (xy, xz, yz; each ++, +-, -+, --).
enum Sample { C, XM, XP, YM, YP, ZM, ZP, XY_PP, XY_PM, XY_MP, XY_MM, XZ_PP, XZ_PM, XZ_MP, XZ_MM, YZ_PP, YZ_PM, YZ_MP, YZ_MM, kSamples };

std::array<std::ptrdiff_t, kSamples> sample_offsets(const std::ptrdiff_t stride[3]) {
  const std::ptrdiff_t sx = stride[0], sy = stride[1], sz = stride[2];
  return {0,       -sx,      sx,       -sy,      sy,       -sz,      sz,       sx + sy, sx - sy, -sx + sy,
          -sx - sy, sx + sz, sx - sz, -sx + sz, -sx - sz, sy + sz, sy - sz, -sy + sz, -sy - sz};
}

// One chunk: s[k][i] holds sample k of centre i; valid[i] says whether it has a centre.
void chunk_curvature(const double (&s)[kSamples][kChunk], const double* valid, int n, double h, double* mean,
                     double* gauss) {
  const double inv2h = 0.5 / h, invh2 = 1.0 / (h * h), inv4h2 = 0.25 * invh2;
  for (int i = 0; i < n; ++i) {
    const double c = s[C][i];
    const double xp = s[XP][i], xm = s[XM][i], yp = s[YP][i], ym = s[YM][i], zp = s[ZP][i], zm = s[ZM][i];
    const double gx = (xp - xm) * inv2h, gy = (yp - ym) * inv2h, gz = (zp - zm) * inv2h;
    const double xx = (xp - 2.0 * c + xm) * invh2, yy = (yp - 2.0 * c + ym) * invh2, zz = (zp - 2.0 * c + zm) * invh2;
    const double xy = ((s[XY_PP][i] - s[XY_PM][i]) - (s[XY_MP][i] - s[XY_MM][i])) * inv4h2;
    const double xz = ((s[XZ_PP][i] - s[XZ_PM][i]) - (s[XZ_MP][i] - s[XZ_MM][i])) * inv4h2;
    const double yz = ((s[YZ_PP][i] - s[YZ_PM][i]) - (s[YZ_MP][i] - s[YZ_MM][i])) * inv4h2;
    const double g2 = gx * gx + gy * gy + gz * gz;
    const double gn = std::sqrt(g2);
    const double trace = xx + yy + zz;
    const double hx = xx * gx + xy * gy + xz * gz, hy = xy * gx + yy * gy + yz * gz, hz = xz * gx + yz * gy + zz * gz;
    const double ghg = gx * hx + gy * hy + gz * hz;
    const double axx = yy * zz - yz * yz, ayy = xx * zz - xz * xz, azz = xx * yy - xy * xy;
    const double axy = xz * yz - xy * zz, axz = xy * yz - xz * yy, ayz = xy * xz - xx * yz;
    const double gag = axx * gx * gx + ayy * gy * gy + azz * gz * gz + 2.0 * (axy * gx * gy + axz * gx * gz + ayz * gy * gz);
    const bool ok = valid[i] != 0.0 && gn > kMinGradNorm;  // also false for NaN
    const double m = (g2 * trace - ghg) / (g2 * gn), k = gag / (g2 * g2);
    mean[i] = ok ? m : 0.0;
    gauss[i] = ok ? k : 0.0;
  }
}

}  // namespace

void mean_gauss_curvature_batch(const float* tile, const int* at, int count, const std::ptrdiff_t stride[3], double h,
                                float* mean, float* gauss) {
  const std::array<std::ptrdiff_t, kSamples> offset = sample_offsets(stride);
  double s[kSamples][kChunk], valid[kChunk], m[kChunk], k[kChunk];
  for (int first = 0; first < count; first += kChunk) {
    const int n = std::min(kChunk, count - first);
    for (int i = 0; i < n; ++i) {
      const int a = at[first + i];
      valid[i] = a >= 0 ? 1.0 : 0.0;
      if (a < 0) {
        for (int j = 0; j < kSamples; ++j) s[j][i] = 0.0;
        continue;
      }
      const float* v = tile + a;
      for (int j = 0; j < kSamples; ++j) s[j][i] = v[offset[std::size_t(j)]];
    }
    chunk_curvature(s, valid, n, h, m, k);
    for (int i = 0; i < n; ++i) {
      mean[first + i] = float(m[i]);
      gauss[first + i] = float(k[i]);
    }
  }
}

}  // namespace levelset::evolve
