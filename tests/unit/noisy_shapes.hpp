// Test helper: analytic shapes with smooth random bumps (fixed seed), as redistanced bands.
#pragma once

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "distance/redistance.hpp"
#include "grid/build_from_sdf.hpp"

namespace levelset::test {

// Sum of `waves` plane waves of wavelength `wavelength` (world), random directions and
// phases, each of amplitude amplitude * sqrt(2 / waves): the bumps' RMS is `amplitude`.
struct Bumps {
  std::vector<std::array<double, 4>> waves;  // direction (unit) * k, phase
  double amplitude_each = 0;

  Bumps(int count, double amplitude, double wavelength, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> g(0.0, 1.0);
    std::uniform_real_distribution<double> u(0.0, 2 * std::numbers::pi);
    const double k = 2 * std::numbers::pi / wavelength;
    for (int i = 0; i < count; ++i) {
      Vec3d d{g(rng), g(rng), g(rng)};
      d = d / length(d);
      waves.push_back({d.x * k, d.y * k, d.z * k, u(rng)});
    }
    amplitude_each = amplitude * std::sqrt(2.0 / count);
  }
  double operator()(const Vec3d& p) const {
    double s = 0;
    for (const auto& w : waves) s += std::sin(w[0] * p.x + w[1] * p.y + w[2] * p.z + w[3]);
    return amplitude_each * s;
  }
  // Lipschitz bound of the bumps (for scaling the SDF to stay 1-Lipschitz).
  double lipschitz() const { return amplitude_each * double(waves.size()) * std::sqrt(waves[0][0] * waves[0][0] + waves[0][1] * waves[0][1] + waves[0][2] * waves[0][2]); }
};

// sdf(p) + bumps(p), scaled to stay 1-Lipschitz, sampled on the frame, then redistanced.
template <typename Sdf>
NarrowBand noisy_band(const Sdf& sdf, const Bumps& bumps, const BBox& bounds, const GridFrame& frame) {
  const double scale = 1.0 + bumps.lipschitz();
  SdfBuildOptions o;
  o.frame = frame;
  BBox grown = bounds;
  const double a = bumps.amplitude_each * double(bumps.waves.size());
  grown.min -= Vec3d{a, a, a};
  grown.max += Vec3d{a, a, a};
  const NarrowBand raw = build_from_sdf([&](const Vec3d& p) { return (sdf(p) + bumps(p)) / scale; }, grown, o).band;
  return redistance(raw, {}).band;
}

}  // namespace levelset::test
