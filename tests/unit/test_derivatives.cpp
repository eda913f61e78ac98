#include <gtest/gtest.h>

#include <random>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "evolve/derivatives.hpp"
#include "evolve/upwind_batch.hpp"

namespace levelset::evolve {
namespace {

constexpr Scheme kSchemes[] = {Scheme::Upwind1, Scheme::Eno2, Scheme::Weno5};
const char* name(Scheme s) { return s == Scheme::Upwind1 ? "Upwind1" : s == Scheme::Eno2 ? "Eno2" : "Weno5"; }

// Seven samples u(j), j in [-3, 3], centre at index 3.
template <class T, class F>
std::array<T, 7> line(F&& u) {
  std::array<T, 7> v{};
  for (int j = -3; j <= 3; ++j) v[std::size_t(j + 3)] = T(u(double(j)));
  return v;
}
template <class T>
OneSided at_centre(const std::array<T, 7>& v, Scheme s) {
  return one_sided(v.data() + 3, 1, s);
}

// ---- exactness ----------------------------------------------------------------------------

TEST(Derivatives, AllSchemesExactForLinearData) {
  for (Scheme s : kSchemes) {
    for (double slope : {0.5, -3.25, 0.0, 17.0}) {
      const auto v = line<float>([&](double x) { return 2.5 + slope * x; });  // exact in float
      const OneSided d = at_centre(v, s);
      EXPECT_NEAR(d.minus, slope, 1e-14 * (1 + std::abs(slope))) << name(s);
      EXPECT_NEAR(d.plus, slope, 1e-14 * (1 + std::abs(slope))) << name(s);
      if (s == Scheme::Upwind1) {
        EXPECT_EQ(d.minus, slope);
        EXPECT_EQ(d.plus, slope);
      }
    }
  }
}

TEST(Derivatives, Upwind1IsNotExactForQuadratics) {
  // u = x^2 at 0: D-u = -1, D+u = +1 (first order: the error is h u''/2).
  const auto v = line<float>([](double x) { return x * x; });
  const OneSided d = at_centre(v, Scheme::Upwind1);
  EXPECT_EQ(d.minus, -1.0);
  EXPECT_EQ(d.plus, 1.0);
}

TEST(Derivatives, Eno2ExactForQuadraticsBothSides) {
  // u(x) = a (x + m)^2 + b (x + m) + c, dyadic coefficients: samples exact in float.
  for (double a : {1.0, -0.75, 3.5}) {
    for (double b : {0.0, 2.0, -5.5}) {
      for (double m : {0.0, 1.0, -2.0, 5.0}) {
        const auto v = line<float>([&](double x) { return a * (x + m) * (x + m) + b * (x + m) + 0.25; });
        const double exact = 2 * a * m + b;
        const OneSided d = at_centre(v, Scheme::Eno2);
        EXPECT_EQ(d.minus, exact) << a << " " << b << " " << m;
        EXPECT_EQ(d.plus, exact) << a << " " << b << " " << m;
      }
    }
  }
}

TEST(Derivatives, Eno2IsNotExactForCubics) {
  // u = x^3 at 0 (u' = 0): D-u = 1 + the smaller-magnitude half second difference of
  // {(-8 + 2 + 0)/2 = -3, (-1 - 0 + 1)/2 = 0}, so 1; D+u = 1 by symmetry.
  const auto v = line<float>([](double x) { return x * x * x; });
  const OneSided d = at_centre(v, Scheme::Eno2);
  EXPECT_EQ(d.minus, 1.0);
  EXPECT_EQ(d.plus, 1.0);
}

TEST(Derivatives, Weno5ExactForCubicsWhateverTheWeights) {
  // Each of the three third-order candidates is exact for cubics, so any convex combination is.
  for (double m : {0.0, 1.0, -2.0, 4.0}) {
    const auto v = line<float>([&](double x) {
      const double y = x + m;
      return 0.5 * y * y * y - 1.5 * y * y + 2.0 * y - 1.0;
    });
    const double exact = 1.5 * m * m - 3.0 * m + 2.0;
    const OneSided d = at_centre(v, Scheme::Weno5);
    EXPECT_NEAR(d.minus, exact, 1e-12 * (1 + std::abs(exact))) << m;
    EXPECT_NEAR(d.plus, exact, 1e-12 * (1 + std::abs(exact))) << m;
  }
}

// ---- convergence on smooth data -----------------------------------------------------------

struct Errors {
  double minus[3], plus[3];
};

// Errors of D-u/h and D+u/h against u'(x0) for u = sin(k x), h = 1/16, 1/32, 1/64.
template <class T>
Errors sine_errors(Scheme s, double k, double x0) {
  Errors e{};
  for (int n = 0; n < 3; ++n) {
    const double h = 1.0 / double(16 << n);
    const auto v = line<T>([&](double j) { return std::sin(k * (x0 + j * h)); });
    const OneSided d = at_centre(v, s);
    const double exact = k * std::cos(k * x0);
    e.minus[n] = std::abs(d.minus / h - exact);
    e.plus[n] = std::abs(d.plus / h - exact);
  }
  return e;
}

void expect_orders(const Errors& e, Scheme s, const char* samples, double x0, double lo, double hi) {
  const double om[2] = {std::log2(e.minus[0] / e.minus[1]), std::log2(e.minus[1] / e.minus[2])};
  const double op[2] = {std::log2(e.plus[0] / e.plus[1]), std::log2(e.plus[1] / e.plus[2])};
  std::printf("[  order   ] %-7s (%s samples, x0 = %.2f)  D-: %.2f %.2f  D+: %.2f %.2f  (err at h=1/64: %.1e, %.1e)\n",
              name(s), samples, x0, om[0], om[1], op[0], op[1], e.minus[2], e.plus[2]);
  for (int i = 0; i < 2; ++i) {
    EXPECT_GE(om[i], lo) << name(s) << " D- x0=" << x0;
    EXPECT_LE(om[i], hi) << name(s) << " D- x0=" << x0;
    EXPECT_GE(op[i], lo) << name(s) << " D+ x0=" << x0;
    EXPECT_LE(op[i], hi) << name(s) << " D+ x0=" << x0;
  }
}

TEST(Derivatives, ConvergenceOrdersOnSine) {
  constexpr double k = 2.0;
  for (double x0 : {0.3, 1.1, -0.7}) {
    // Upwind1 and Eno2 through the float API (their errors are far above float rounding).
    expect_orders(sine_errors<float>(Scheme::Upwind1, k, x0), Scheme::Upwind1, "float", x0, 0.8, 1.2);
    expect_orders(sine_errors<float>(Scheme::Eno2, k, x0), Scheme::Eno2, "float", x0, 1.8, 2.6);
    // Weno5's error at h = 1/64 (~1e-9) is below what float samples can carry (rounding
    // 6e-8 / h ~ 4e-6), so its order is measured on double samples (the same code).
    expect_orders(sine_errors<double>(Scheme::Weno5, k, x0), Scheme::Weno5, "double", x0, 4.5, 6.0);
  }
}

TEST(Derivatives, Weno5OnFloatSamplesIsLimitedByInputRounding) {
  // Float samples: the error is the rounding of the samples amplified by 1/h and the stencil
  // (a few units of 6e-8 / h), not the truncation error, and still far below Eno2's.
  const Errors w = sine_errors<float>(Scheme::Weno5, 2.0, 0.3);
  const Errors e = sine_errors<float>(Scheme::Eno2, 2.0, 0.3);
  const double h = 1.0 / 64, rounding = 6e-8 / h;
  EXPECT_LT(w.minus[2], 10 * rounding);
  EXPECT_LT(w.plus[2], 10 * rounding);
  EXPECT_LT(w.minus[2], 0.05 * e.minus[2]);
  EXPECT_LT(w.plus[2], 0.05 * e.plus[2]);
}

// ---- kinks --------------------------------------------------------------------------------

// Piecewise linear: slope sl left of the kink at c, sr right of it.
auto kinked(double c, double sl, double sr) {
  return [=](double x) { return x < c ? sl * (x - c) : sr * (x - c); };
}

TEST(Derivatives, HighOrderSchemesPickTheSmoothSideNearAKink) {
  for (Scheme s : {Scheme::Eno2, Scheme::Weno5}) {
    // |x - c|: the V of a distance, and an asymmetric kink.
    for (auto [sl, sr] : {std::pair{-1.0, 1.0}, std::pair{-0.75, 2.5}, std::pair{3.0, -0.5}}) {
      // Kink between the centre and its right neighbour (or the one after): D- sees the
      // smooth left side.
      for (double c : {0.5, 1.5}) {
        const auto v = line<float>(kinked(c, sl, sr));
        EXPECT_NEAR(at_centre(v, s).minus, sl, 1e-6) << name(s) << " c=" << c;
      }
      // Kink left of the centre: D+ sees the smooth right side.
      for (double c : {-0.5, -1.5}) {
        const auto v = line<float>(kinked(c, sl, sr));
        EXPECT_NEAR(at_centre(v, s).plus, sr, 1e-6) << name(s) << " c=" << c;
      }
    }
  }
}

TEST(Derivatives, LinearWeightsWouldNotPickTheSmoothSide) {
  // Guards the test above: the optimal (linear) WENO weights 0.1, 0.6, 0.3 on |x - 0.5| miss
  // the slope by O(1), so the nonlinear weights are what gets it right.
  const auto v = line<double>(kinked(0.5, -1.0, 1.0));
  // Differences D+u at i-3..i+1: -1, -1, -1, 0 (u(0) = u(1) = 0.5), 1.
  const double phi1 = -1.0, phi2 = -1.0 / 6.0 * -1.0 + 5.0 / 6.0 * -1.0 + 0.0 / 3.0;
  const double phi3 = -1.0 / 3.0 + 0.0 - 1.0 / 6.0;
  const double linear = 0.1 * phi1 + 0.6 * phi2 + 0.3 * phi3;
  EXPECT_GT(std::abs(linear - -1.0), 0.3);
  EXPECT_NEAR(at_centre(v, Scheme::Weno5).minus, -1.0, 1e-9);
}

// ---- Godunov's |grad u| ---------------------------------------------------------------------

// A dense nx * ny * nz float array, x fastest (grid/tile.hpp layout).
struct Dense {
  int nx, ny, nz;
  std::vector<float> v;
  template <class F>
  Dense(int x, int y, int z, F&& u) : nx(x), ny(y), nz(z), v(std::size_t(x) * y * z) {
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) v[index(i, j, k)] = float(u(double(i), double(j), double(k)));
  }
  std::size_t index(int i, int j, int k) const { return std::size_t(i) + std::size_t(nx) * (std::size_t(j) + std::size_t(ny) * k); }
  const float* at(int i, int j, int k) const { return v.data() + index(i, j, k); }
  std::array<std::ptrdiff_t, 3> strides() const { return {1, nx, std::ptrdiff_t(nx) * ny}; }
};

std::array<OneSided, 3> gradient(const Dense& g, int i, int j, int k, Scheme s) {
  std::array<OneSided, 3> d;
  one_sided_xyz(g.at(i, j, k), g.strides().data(), s, d.data());
  return d;
}

TEST(Derivatives, GodunovNormOfPlaneDistanceIsOne) {
  // Axis directions: float-exact data, exactly 1 for every scheme and both signs of beta.
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      const Dense g(9, 10, 11, [&](double x, double y, double z) {
        const double p[3] = {x, y, z};
        return sign * (p[axis] - 4.25);
      });
      for (Scheme s : kSchemes) {
        const auto d = gradient(g, 4, 5, 5, s);
        for (double beta : {1.0, -2.0}) {
          EXPECT_NEAR(godunov_gradient_norm(d.data(), beta), 1.0, 1e-14) << name(s);
          if (s == Scheme::Upwind1) {
            EXPECT_EQ(godunov_gradient_norm(d.data(), beta), 1.0);
          }
        }
      }
    }
  }
  // An oblique normal (2, -3, 6) / 7: 1 up to the float rounding of the samples.
  const Dense g(9, 10, 11, [](double x, double y, double z) { return (2 * x - 3 * y + 6 * z) / 7 - 1.0; });
  for (Scheme s : kSchemes) {
    const auto d = gradient(g, 4, 5, 5, s);
    EXPECT_NEAR(godunov_gradient_norm(d.data(), 1.0), 1.0, 1e-5) << name(s);
    EXPECT_NEAR(godunov_gradient_norm(d.data(), -1.0), 1.0, 1e-5) << name(s);
  }
}

TEST(Derivatives, GodunovNormAtTheKinkOfADistance) {
  // u = |x| (a V, minimum at the centre sample): D-u = -1, D+u = +1.
  // beta > 0 (u_t = -beta |grad u|, level sets expand): max(max(D-,0)^2, min(D+,0)^2) = 0,
  //   the rarefaction: the viscosity solution min over a ball keeps u(0) = 0, u_t = 0.
  // beta < 0: max(min(D-,0)^2, max(D+,0)^2) = 1, the shock: u(0, t) = |beta| t.
  // Upwind1 and Eno2 give these exactly; Weno5 to its weight ratio (~1e-13).
  for (Scheme s : kSchemes) {
    const double tol = s == Scheme::Weno5 ? 1e-9 : 0.0;
    const Dense v(7, 7, 7, [](double x, double, double) { return std::abs(x - 3); });
    const auto d = gradient(v, 3, 3, 3, s);
    EXPECT_NEAR(d[0].minus, -1.0, tol) << name(s);
    EXPECT_NEAR(d[0].plus, 1.0, tol) << name(s);
    EXPECT_EQ(godunov_gradient_norm(d.data(), 1.0), 0.0) << name(s);
    EXPECT_NEAR(godunov_gradient_norm(d.data(), -0.5), 1.0, tol) << name(s);
    EXPECT_EQ(godunov_gradient_norm(d.data(), 0.0), 0.0) << name(s);  // documented: 0
    // -|x| (a ridge): the roles swap.
    const Dense r(7, 7, 7, [](double x, double, double) { return -std::abs(x - 3); });
    const auto dr = gradient(r, 3, 3, 3, s);
    EXPECT_NEAR(godunov_gradient_norm(dr.data(), 1.0), 1.0, tol) << name(s);
    EXPECT_EQ(godunov_gradient_norm(dr.data(), -1.0), 0.0) << name(s);
  }
  // Distance to a point at the centre sample (a cone): every axis has D- = -1, D+ = +1, so
  // beta > 0 gives 0 and beta < 0 gives sqrt(3) (the scheme's value at the apex, not the
  // viscosity solution's 1: first-order smearing of the apex, gone one voxel away).
  const Dense c(7, 7, 7, [](double x, double y, double z) {
    return std::sqrt((x - 3) * (x - 3) + (y - 3) * (y - 3) + (z - 3) * (z - 3));
  });
  const auto d = gradient(c, 3, 3, 3, Scheme::Upwind1);
  EXPECT_EQ(godunov_gradient_norm(d.data(), 1.0), 0.0);
  EXPECT_DOUBLE_EQ(godunov_gradient_norm(d.data(), -1.0), std::sqrt(3.0));
  // One voxel off the apex along x: D-x = D+x = 1; along y and z D- = 1 - sqrt(2) = -t,
  // D+ = t, so beta > 0 takes x only (1), beta < 0 adds t^2 per axis (up to float rounding).
  const auto d1 = gradient(c, 4, 3, 3, Scheme::Upwind1);
  EXPECT_NEAR(godunov_gradient_norm(d1.data(), 1.0), 1.0, 1e-6);
  const double t = std::sqrt(2.0) - 1.0;
  EXPECT_NEAR(godunov_gradient_norm(d1.data(), -1.0), std::sqrt(1.0 + 2 * t * t), 1e-6);
}

// ---- advection and LLF --------------------------------------------------------------------

TEST(Derivatives, UpwindAdvectionTakesTheUpwindSide) {
  const OneSided d[3] = {{1.0, 2.0}, {3.0, 4.0}, {5.0, 6.0}};
  const double v1[3] = {1.0, -1.0, 0.0};
  EXPECT_EQ(upwind_advection(d, v1), 1.0 * 1.0 + -1.0 * 4.0);
  const double v2[3] = {-2.0, 0.5, 3.0};
  EXPECT_EQ(upwind_advection(d, v2), -2.0 * 2.0 + 0.5 * 3.0 + 3.0 * 5.0);
  const double v0[3] = {0.0, 0.0, 0.0};
  EXPECT_EQ(upwind_advection(d, v0), 0.0);
  // On |x| at its kink: wind from the left (V > 0) reads the left slope -1, from the right +1.
  const auto v = line<float>([](double x) { return std::abs(x); });
  for (Scheme s : kSchemes) {
    const OneSided k[3] = {at_centre(v, s), {}, {}};
    const double right[3] = {2.0, 0.0, 0.0}, left[3] = {-2.0, 0.0, 0.0};
    EXPECT_NEAR(upwind_advection(k, right), -2.0, 1e-9) << name(s);
    EXPECT_NEAR(upwind_advection(k, left), -2.0, 1e-9) << name(s);
  }
}

TEST(Derivatives, LlfEqualsHamiltonianOnSmoothLinearData) {
  // D- == D+ (linear data): no dissipation, H(p) = beta |p| + V . p exactly.
  const Dense g(9, 9, 9, [](double x, double y, double z) { return 0.5 * x - 2.0 * y + 0.25 * z; });
  for (Scheme s : kSchemes) {
    const auto d = gradient(g, 4, 4, 4, s);
    const double pn = std::sqrt(0.25 + 4.0 + 0.0625);
    for (double beta : {1.5, -0.5, 0.0}) {
      const double vel[3] = {1.0, 0.5, -3.0};
      double alpha[3];
      llf_alpha(beta, vel, alpha);
      EXPECT_NEAR(llf_hamiltonian(d.data(), beta, vel, alpha), beta * pn + (0.5 - 1.0 - 0.75), 1e-13) << name(s);
    }
  }
}

TEST(Derivatives, LlfAddsDissipationByHand) {
  // p- = (1, -2, 0.5), p+ = (3, -2, 0.5): p = (2, -2, 0.5), |p| = sqrt(8.25).
  // beta = 2, V = (1, -1, 0.5): H(p) = 2 sqrt(8.25) + (2 + 2 + 0.25).
  // alpha = |beta| + |V_a| = (3, 3, 2.5): dissipation 3 * (3 - 1) / 2 = 3.
  const OneSided d[3] = {{1.0, 3.0}, {-2.0, -2.0}, {0.5, 0.5}};
  const double vel[3] = {1.0, -1.0, 0.5};
  double alpha[3];
  llf_alpha(2.0, vel, alpha);
  EXPECT_EQ(alpha[0], 3.0);
  EXPECT_EQ(alpha[2], 2.5);
  EXPECT_DOUBLE_EQ(llf_hamiltonian(d, 2.0, vel, alpha), 2.0 * std::sqrt(8.25) + 4.25 - 3.0);
  // The V-shaped kink of |x| with beta = 1, V = 0: H(0) = 0, minus alpha (1 - (-1)) / 2 = 1,
  // so u_t = -H = +1 there (LLF smooths the V where Godunov gives u_t = 0).
  const OneSided k[3] = {{-1.0, 1.0}, {0.0, 0.0}, {0.0, 0.0}};
  const double v0[3] = {0.0, 0.0, 0.0}, a1[3] = {1.0, 1.0, 1.0};
  EXPECT_EQ(llf_hamiltonian(k, 1.0, v0, a1), -1.0);
}

// ---- scale invariance, mirror symmetry, strides --------------------------------------------

TEST(Derivatives, ScaleInvariance) {
  // Rough data, samples n / 64 with |n| < 1000: times 1e6 (n * 15625 < 2^24) stays exact in
  // float, so only the scheme's arithmetic can break the scaling.
  const int n[4][7] = {{-7, 3, 40, 41, 90, 64, 1},
                       {100, 37, 0, 0, 37, 100, 163},  // a flat-bottomed V
                       {5, -900, 12, 800, -3, 2, 999},
                       {1, 2, 3, 4, 5, 6, 7}};
  for (const auto& row : n) {
    std::array<float, 7> v{}, big{}, tiny{};
    for (int j = 0; j < 7; ++j) {
      v[std::size_t(j)] = float(row[j] / 64.0);
      big[std::size_t(j)] = float(row[j] * 15625.0);  // exactly v * 1e6
      tiny[std::size_t(j)] = float(std::ldexp(row[j] / 64.0, -30));
    }
    for (Scheme s : kSchemes) {
      const OneSided d = at_centre(v, s), db = at_centre(big, s), dt = at_centre(tiny, s);
      EXPECT_NEAR(db.minus, 1e6 * d.minus, 1e-12 * std::abs(1e6 * d.minus)) << name(s);
      EXPECT_NEAR(db.plus, 1e6 * d.plus, 1e-12 * std::abs(1e6 * d.plus)) << name(s);
      // 2^-30: differences ~1e-9, smoothness indicators ~1e-18, far below a fixed 1e-6 epsilon.
      EXPECT_NEAR(dt.minus, std::ldexp(d.minus, -30), 1e-12 * std::ldexp(std::abs(d.minus), -30)) << name(s);
      EXPECT_NEAR(dt.plus, std::ldexp(d.plus, -30), 1e-12 * std::ldexp(std::abs(d.plus), -30)) << name(s);
    }
  }
  // And the kink is still resolved at the tiny scale (a fixed epsilon would blend in the
  // candidates across the kink).
  const auto v = line<float>([](double x) { return std::ldexp(std::abs(x - 0.5), -30); });
  EXPECT_NEAR(at_centre(v, Scheme::Weno5).minus, -std::ldexp(1.0, -30), 1e-6 * std::ldexp(1.0, -30));
}

TEST(Derivatives, ReversedStrideMirrorsTheSides) {
  // Reading the line backwards turns D+ into -D- and vice versa, exactly.
  const auto v = line<float>([](double x) { return std::sin(1.3 * x) + 0.2 * std::abs(x - 0.4); });
  for (Scheme s : kSchemes) {
    const OneSided f = one_sided(v.data() + 3, 1, s), b = one_sided(v.data() + 3, -1, s);
    EXPECT_EQ(b.minus, -f.plus) << name(s);
    EXPECT_EQ(b.plus, -f.minus) << name(s);
  }
}

TEST(Derivatives, StridedAxesMatchContiguousLines) {
  const Dense g(9, 10, 11, [](double x, double y, double z) {
    return std::sin(0.7 * x + 0.2) * std::cos(0.4 * y) + 0.1 * z * z - std::abs(y - 4.5);
  });
  const auto st = g.strides();
  for (int k = 3; k < 8; ++k) {
    for (int j = 3; j < 7; ++j) {
      for (int i = 3; i < 6; ++i) {
        for (int a = 0; a < 3; ++a) {
          std::array<float, 7> copy{};
          for (int q = -3; q <= 3; ++q) {
            const int c[3] = {i + (a == 0) * q, j + (a == 1) * q, k + (a == 2) * q};
            copy[std::size_t(q + 3)] = *g.at(c[0], c[1], c[2]);
          }
          for (Scheme s : kSchemes) {
            const OneSided ds = one_sided(g.at(i, j, k), st[std::size_t(a)], s);
            const OneSided dc = at_centre(copy, s);
            EXPECT_EQ(ds.minus, dc.minus) << name(s) << " axis " << a;
            EXPECT_EQ(ds.plus, dc.plus) << name(s) << " axis " << a;
          }
        }
        // The compile-time variant agrees with the runtime dispatch.
        const OneSided t = one_sided<Scheme::Weno5>(g.at(i, j, k), st[1]);
        const OneSided r = one_sided(g.at(i, j, k), st[1], Scheme::Weno5);
        EXPECT_EQ(t.minus, r.minus);
        EXPECT_EQ(t.plus, r.plus);
      }
    }
  }
}

TEST(Derivatives, CentralGradientNorm) {
  // Central differences are exact for quadratics: u = (x - 2)^2 / 4 - (y - 4) + (z + 1)^2 / 2
  // has gradient (1, -1, 5) at sample (4, 4, 4).
  const Dense g(9, 9, 9, [](double x, double y, double z) {
    return 0.25 * (x - 2) * (x - 2) - (y - 4) + 0.5 * (z + 1) * (z + 1);
  });
  const double expected = std::sqrt(1.0 + 1.0 + 25.0);
  EXPECT_DOUBLE_EQ(central_gradient_norm(g.at(4, 4, 4), g.strides().data()), expected);
  const double c[3] = {central_difference(g.at(4, 4, 4), 1), central_difference(g.at(4, 4, 4), 9),
                       central_difference(g.at(4, 4, 4), 81)};
  EXPECT_EQ(c[0], 1.0);
  EXPECT_EQ(c[1], -1.0);
  EXPECT_EQ(c[2], 5.0);
  EXPECT_DOUBLE_EQ(central_gradient_norm(c), expected);
}

}  // namespace
// one_side gives exactly the side of one_sided it names, for every scheme (random data).
TEST(Derivatives, OneSideMatchesOneSided) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  for (int trial = 0; trial < 2000; ++trial) {
    float line[7];
    for (float& v : line) v = u(rng);
    if (trial % 3 == 0) line[trial % 7] = line[(trial + 1) % 7];  // ties in the ENO choice
    for (Scheme s : {Scheme::Upwind1, Scheme::Eno2, Scheme::Weno5}) {
      const OneSided both = one_sided(line + 3, 1, s);
      EXPECT_EQ(one_side(line + 3, 1, s, true), both.minus);
      EXPECT_EQ(one_side(line + 3, 1, s, false), both.plus);
    }
  }
}

// one_sided_batch equals one_side bit for bit for every scheme and both sides, whatever the
// batch size (vector bodies and remainders), including lines whose WENO weights under- or
// overflow (all-equal samples, huge and tiny values), which take the plain form.
TEST(Derivatives, BatchEqualsOneSideBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  auto batch = std::make_unique<CentreSamples>();
  std::vector<std::array<float, 7>> lines(kBrickVoxels);
  int plain = 0;  // centres whose weighted sum could not divide
  for (int count : {1, 3, 8, 13, 186, kBrickVoxels}) {
    for (int k = 0; k < count; ++k) {
      std::array<float, 7>& c = lines[std::size_t(k)];
      for (float& v : c) v = u(rng);
      switch (k % 7) {
        case 1: c.fill(0.75f); break;                            // all differences 0
        case 2: for (float& v : c) v *= 1.5e38f; break;          // weights overflow
        case 3: for (float& v : c) v *= 1e-40f; break;           // weights underflow (denormal samples)
        case 4: c[std::size_t(k % 5)] = c[std::size_t(k % 5 + 1)]; break;  // ENO ties
        default: break;
      }
      for (int j = 0; j < 7; ++j) batch->at[std::size_t(j)][std::size_t(k)] = c[std::size_t(j)];
    }
    for (Scheme s : kSchemes) {
      std::vector<double> minus(std::size_t(count), -1.0), plus(std::size_t(count), -1.0);
      one_sided_batch(*batch, count, s, minus.data(), plus.data());
      for (int k = 0; k < count; ++k) {
        const float* c = lines[std::size_t(k)].data() + 3;
        const double m = one_side(c, 1, s, true), p = one_side(c, 1, s, false);
        // Bit-for-bit, NaN-free: compare the representations.
        EXPECT_EQ(std::memcmp(&minus[std::size_t(k)], &m, sizeof m), 0) << name(s) << " minus, centre " << k << " of " << count;
        EXPECT_EQ(std::memcmp(&plus[std::size_t(k)], &p, sizeof p), 0) << name(s) << " plus, centre " << k << " of " << count;
        if (s == Scheme::Weno5) {
          double d[6], num = 0, sum = 0;
          for (int j = 0; j < 6; ++j) d[j] = double(c[j - 2]) - double(c[j - 3]);
          detail::weno5_weighted(detail::weno5_parts(d[0], d[1], d[2], d[3], d[4]), num, sum);
          plain += !detail::weno5_sum_usable(sum);
        }
      }
      // One side only: the other array is not touched.
      std::vector<double> only(std::size_t(count), 0.0), untouched(std::size_t(count), 42.0);
      one_sided_batch(*batch, count, s, only.data(), nullptr);
      one_sided_batch(*batch, count, s, nullptr, untouched.data());
      for (int k = 0; k < count; ++k) EXPECT_EQ(std::memcmp(&only[std::size_t(k)], &minus[std::size_t(k)], sizeof(double)), 0);
      for (int k = 0; k < count; ++k) EXPECT_EQ(std::memcmp(&untouched[std::size_t(k)], &plus[std::size_t(k)], sizeof(double)), 0);
    }
  }
  EXPECT_GT(plain, 3);
}

// weno5's plain form takes over where the weighted sum under- or overflows, and is finite.
TEST(Derivatives, Weno5PlainFormIsReached) {
  double num = 0, sum = 0;
  detail::weno5_weighted(detail::weno5_parts(0.0, 0.0, 0.0, 0.0, 0.0), num, sum);
  EXPECT_FALSE(detail::weno5_sum_usable(sum));
  EXPECT_EQ(detail::weno5(0.0, 0.0, 0.0, 0.0, 0.0), 0.0);
  detail::weno5_weighted(detail::weno5_parts(1e40, -2e40, 3e40, 1e40, -1e40), num, sum);
  EXPECT_FALSE(detail::weno5_sum_usable(sum));
  const double big = detail::weno5(1e40, -2e40, 3e40, 1e40, -1e40);
  EXPECT_TRUE(std::isfinite(big));
  // Scale invariance holds through the plain form: 1e40 times the result on unit data.
  EXPECT_NEAR(big / 1e40, detail::weno5(1.0, -2.0, 3.0, 1.0, -1.0), 1e-12);
}

}  // namespace levelset::evolve
