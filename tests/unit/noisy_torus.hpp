// Test helper: points on a torus about the z axis (major radius R, minor r), sampled by area,
// with isotropic Gaussian noise sigma (a scan-like cloud with a known surface).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "core/vec3.hpp"

namespace levelset::test {

// The torus point at angle phi about the z axis and theta about the tube.
inline Vec3d torus_point(double R, double r, double phi, double theta) {
  return {(R + r * std::cos(theta)) * std::cos(phi), (R + r * std::cos(theta)) * std::sin(phi), r * std::sin(theta)};
}

inline std::vector<Vec3d> noisy_torus_points(double R, double r, std::size_t n, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi), unit(0.0, 1.0);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<Vec3d> points;
  points.reserve(n);
  while (points.size() < n) {
    const double phi = angle(rng), theta = angle(rng);
    if (unit(rng) * (R + r) > R + r * std::cos(theta)) continue;  // area element ~ R + r cos(theta)
    const Vec3d p = torus_point(R, r, phi, theta);
    points.push_back(p + Vec3d{g(rng), g(rng), g(rng)});
  }
  return points;
}

}  // namespace levelset::test
