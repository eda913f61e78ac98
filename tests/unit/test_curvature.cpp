// Curvature from dense samples (evolve/curvature.hpp) against analytic answers: sphere,
// cylinder, plane, torus, saddle, convergence order, degenerate gradient, and the agreement of
// mean_curvature_at with curvature_at().mean, and mean_gauss_curvature_at with its mean and gauss;
// the brick form (curvature_batch.hpp) against the single one, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <vector>

#include "core/error.hpp"
#include "core/vec3.hpp"
#include "evolve/curvature.hpp"
#include "evolve/curvature_batch.hpp"

namespace levelset::evolve {
namespace {

using Field = std::function<double(const Vec3d&)>;

// Dense n^3 float samples of f at origin + h * (i, j, k), x fastest (the tile layout).
struct DenseGrid {
  int n = 0;
  double h = 1;
  Vec3d origin{};
  std::vector<float> values;
  std::ptrdiff_t stride[3] = {1, 0, 0};

  DenseGrid(const Field& f, Vec3d origin_, double h_, int n_) : n(n_), h(h_), origin(origin_) {
    stride[1] = n;
    stride[2] = std::ptrdiff_t(n) * n;
    values.resize(std::size_t(n) * n * n);
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) values[index(i, j, k)] = float(f(world(i, j, k)));
  }
  std::size_t index(int i, int j, int k) const {
    return std::size_t(i + n * (j + std::size_t(n) * k));
  }
  Vec3d world(int i, int j, int k) const {
    return origin + Vec3d{double(i), double(j), double(k)} * h;
  }
  const float* at(int i, int j, int k) const { return values.data() + index(i, j, k); }
  // Every interior voxel (all neighbours valid) where pred(world point, sample) holds.
  template <typename Fn>
  void for_each_interior(Fn&& fn) const {
    for (int k = 1; k < n - 1; ++k)
      for (int j = 1; j < n - 1; ++j)
        for (int i = 1; i < n - 1; ++i) fn(world(i, j, k), at(i, j, k));
  }
};

Vec3d normalized(const Vec3d& v) {
  return v / length(v);
}

// Both forms at one voxel; checks the mean agrees (1e-9 relative to the curvature scale) and
// that everything is finite.
Curvature both(const float* v, const std::ptrdiff_t stride[3], double h) {
  const Curvature c = curvature_at(v, stride, h);
  const double m = mean_curvature_at(v, stride, h);
  EXPECT_TRUE(std::isfinite(c.grad_norm) && isfinite(c.normal) && std::isfinite(c.mean) &&
              std::isfinite(c.gauss) && std::isfinite(c.k1) && std::isfinite(c.k2) &&
              std::isfinite(m));
  EXPECT_GE(c.k1, c.k2);
  const double scale = std::max({std::abs(c.k1), std::abs(c.k2), 1e-300});
  EXPECT_LE(std::abs(m - c.mean), 1e-9 * scale) << m << " vs " << c.mean;
  // The closed forms without the eigen-solve (speeds reading K but not k1, k2).
  const MeanGauss mg = mean_gauss_curvature_at(v, stride, h);
  EXPECT_LE(std::abs(mg.mean - c.mean), 1e-9 * scale) << mg.mean << " vs " << c.mean;
  EXPECT_LE(std::abs(mg.gauss - c.gauss), 1e-8 * scale * scale) << mg.gauss << " vs " << c.gauss;
  return c;
}

struct MaxErr {
  double v = 0;
  void add(double e) { v = std::max(v, e); }
};

// ---------------------------------------------------------------------------------------------

void check_sphere(double r_voxels) {
  const double h = 0.05;
  const double r = r_voxels * h;
  const Vec3d c{0.37 * h, -0.21 * h, 0.13 * h};  // off-grid centre
  const int n = 2 * int(r_voxels + 4) + 1;
  const Vec3d origin = Vec3d{1, 1, 1} * (-(n / 2) * h);
  const DenseGrid g([&](const Vec3d& p) { return length(p - c) - r; }, origin, h, n);
  MaxErr eh, ek, e12, egn;
  int count = 0;
  g.for_each_interior([&](const Vec3d& p, const float* v) {
    const double rho = length(p - c);
    if (std::abs(rho - r) > 1.5 * h) return;  // near the surface
    const Curvature cv = both(v, g.stride, h);
    const double H = 2 / rho, K = 1 / (rho * rho);
    eh.add(std::abs(cv.mean - H) / H);
    ek.add(std::abs(cv.gauss - K) / K);
    e12.add(std::abs(cv.k1 - cv.k2) * rho);
    egn.add(std::abs(cv.grad_norm - 1));
    EXPECT_NEAR(dot(cv.normal, normalized(p - c)), 1.0, 1e-3);
    ++count;
  });
  std::printf(
      "[ sphere r=%2.0fh ] %d voxels: max rel err H %.2e, K %.2e, |k1-k2|*rho %.2e, |grad|-1 "
      "%.2e\n",
      r_voxels, count, eh.v, ek.v, e12.v, egn.v);
  EXPECT_GT(count, 100);
  EXPECT_LT(eh.v, 0.02);
  EXPECT_LT(ek.v, 0.03);
  EXPECT_LT(e12.v, 0.02);
}

TEST(Curvature, SphereR10) {
  check_sphere(10);
}
TEST(Curvature, SphereR20) {
  check_sphere(20);
}

TEST(Curvature, CylinderInGenericDirection) {
  const double h = 0.1;
  for (double r_voxels : {10.0, 20.0}) {
    const double r = r_voxels * h;
    const Vec3d a = normalized({1, 2, 3});
    const Vec3d p0{0.31 * h, 0.17 * h, -0.44 * h};
    auto rho_of = [&](const Vec3d& p) {
      const Vec3d q = p - p0;
      return length(q - a * dot(q, a));
    };
    const int n = 2 * int(r_voxels + 4) + 1;
    const Vec3d origin = Vec3d{1, 1, 1} * (-(n / 2) * h);
    const DenseGrid g([&](const Vec3d& p) { return rho_of(p) - r; }, origin, h, n);
    MaxErr e1, e2, ek, eh, en;
    int count = 0;
    g.for_each_interior([&](const Vec3d& p, const float* v) {
      const double rho = rho_of(p);
      if (std::abs(rho - r) > 1.5 * h) return;
      const Curvature cv = both(v, g.stride, h);
      const double k = 1 / rho;
      e1.add(std::abs(cv.k1 - k) / k);
      e2.add(std::abs(cv.k2) / cv.k1);
      ek.add(std::abs(cv.gauss) / (k * k));
      eh.add(std::abs(cv.mean - k) / k);
      en.add(std::abs(dot(cv.normal, a)));
      ++count;
    });
    std::printf(
        "[ cylinder r=%2.0fh ] %d voxels: max rel err k1 %.2e, |k2|/k1 %.2e, |K|*rho^2 %.2e, H "
        "%.2e, "
        "|n.axis| %.1e\n",
        r_voxels, count, e1.v, e2.v, ek.v, eh.v, en.v);
    EXPECT_GT(count, 100);
    EXPECT_LT(e1.v, 0.02);
    EXPECT_LT(e2.v, 0.02);
    EXPECT_LT(ek.v, 0.02);
    EXPECT_LT(eh.v, 0.02);
    EXPECT_LT(en.v, 5e-3);  // the normal is second order too: 1.3e-3 at r = 10h
  }
}

TEST(Curvature, PlaneInGenericDirection) {
  for (double h : {1.0, 0.01}) {
    const Vec3d nrm = normalized({0.3, -0.7, 0.55});
    const double d = 0.123 * h;
    const int n = 13;
    const Vec3d origin = Vec3d{1, 1, 1} * (-(n / 2) * h);
    const DenseGrid g([&](const Vec3d& p) { return dot(nrm, p) - d; }, origin, h, n);
    MaxErr ec, egn, en;
    int count = 0;
    g.for_each_interior([&](const Vec3d& p, const float* v) {
      if (std::abs(dot(nrm, p) - d) > 2 * h) return;
      const Curvature cv = both(v, g.stride, h);
      ec.add(std::max({std::abs(cv.mean), std::abs(cv.k1), std::abs(cv.k2),
                       std::sqrt(std::abs(cv.gauss))}) *
             h);
      egn.add(std::abs(cv.grad_norm - 1));
      en.add(length(cv.normal - nrm));
      ++count;
    });
    std::printf(
        "[ plane h=%g ] %d voxels: max |curvature|*h %.2e, |grad|-1 %.2e, |n - n_exact| %.2e\n", h,
        count, ec.v, egn.v, en.v);
    EXPECT_GT(count, 50);
    EXPECT_LT(ec.v, 1e-6);
    EXPECT_LT(egn.v, 1e-5);
    EXPECT_LT(en.v, 1e-5);
  }
}

TEST(Curvature, TorusEquators) {
  const double h = 0.05;
  const double R = 20 * h, r = 8 * h;
  const Vec3d c{0.23 * h, -0.41 * h, 0.07 * h};
  const Vec3d w = normalized({0.2, -0.3, 1.0});  // tilted axis
  struct Local {
    double rho_axis, height;
  };
  auto local = [&](const Vec3d& p) {
    const Vec3d q = p - c;
    const double z = dot(q, w);
    return Local{length(q - w * z), z};
  };
  auto sdf = [&](const Vec3d& p) {
    const Local l = local(p);
    return std::hypot(l.rho_axis - R, l.height) - r;
  };
  const int n = 2 * int((R + r) / h + 4) + 1;
  const Vec3d origin = Vec3d{1, 1, 1} * (-(n / 2) * h);
  const DenseGrid g(sdf, origin, h, n);
  MaxErr e_out1, e_out2, e_in1, e_in2;
  int outer = 0, inner = 0;
  g.for_each_interior([&](const Vec3d& p, const float* v) {
    const double u = sdf(p);
    if (std::abs(u) > 1.0 * h) return;
    const Local l = local(p);
    const double tube = r + u;  // tube radius of the level set through p
    const double cos_t = (l.rho_axis - R) / tube;
    if (std::abs(cos_t) < 0.97) return;  // within ~14 degrees of an equator
    const Curvature cv = both(v, g.stride, h);
    const double k_tube = 1 / tube, k_ring = cos_t / (R + tube * cos_t);
    const double k1 = std::max(k_tube, k_ring), k2 = std::min(k_tube, k_ring);
    const double e1 = std::abs(cv.k1 - k1) / std::abs(k1), e2 = std::abs(cv.k2 - k2) / std::abs(k2);
    EXPECT_LT(std::abs(cv.mean - (k1 + k2)) / std::abs(k1 + k2), 0.03);
    EXPECT_LT(std::abs(cv.gauss - k1 * k2) / std::abs(k1 * k2), 0.05);
    if (cos_t > 0) {
      e_out1.add(e1), e_out2.add(e2), ++outer;
    } else {
      EXPECT_LT(cv.k2, 0.0);  // inner equator: saddle-shaped
      EXPECT_LT(cv.gauss, 0.0);
      e_in1.add(e1), e_in2.add(e2), ++inner;
    }
  });
  std::printf(
      "[ torus R=20h r=8h ] outer %d voxels: max rel err k1 %.2e k2 %.2e; inner %d voxels: k1 %.2e "
      "k2 %.2e\n",
      outer, e_out1.v, e_out2.v, inner, e_in1.v, e_in2.v);
  EXPECT_GT(outer, 50);
  EXPECT_GT(inner, 50);
  EXPECT_LT(std::max({e_out1.v, e_out2.v, e_in1.v, e_in2.v}), 0.03);
}

// u = z - (x^2 - y^2) / (2a): quadratic, so central differences are exact (up to float samples).
TEST(Curvature, SaddleIsExact) {
  const double h = 0.25, a = 3.0;
  const Field f = [&](const Vec3d& p) { return p.z - (p.x * p.x - p.y * p.y) / (2 * a); };
  const int n = 9;
  const Vec3d origin = Vec3d{1, 1, 1} * (-(n / 2) * h);
  const DenseGrid g(f, origin, h, n);
  {  // the origin: n = +z, k = +-1/a
    const Curvature cv = both(g.at(n / 2, n / 2, n / 2), g.stride, h);
    std::printf("[ saddle origin ] k1*a-1 %.2e, k2*a+1 %.2e, H*a %.2e, K*a^2+1 %.2e\n",
                cv.k1 * a - 1, cv.k2 * a + 1, cv.mean * a, cv.gauss * a * a + 1);
    EXPECT_NEAR(cv.k1 * a, 1.0, 1e-6);
    EXPECT_NEAR(cv.k2 * a, -1.0, 1e-6);
    EXPECT_NEAR(cv.mean * a, 0.0, 1e-6);
    EXPECT_NEAR(cv.gauss * a * a, -1.0, 1e-6);
    EXPECT_NEAR(cv.grad_norm, 1.0, 1e-6);
    EXPECT_NEAR(cv.normal.z, 1.0, 1e-12);
  }
  // Off the origin (|grad u| != 1): against H = (|g|^2 tr Hess - g.Hess.g) / |g|^3 and
  // K = g.adj(Hess).g / |g|^4 from the analytic derivatives.
  for (int i : {1, 3, 6}) {
    for (int j : {2, 4, 7}) {
      const int k = n / 2;
      const Vec3d p = g.world(i, j, k);
      const Vec3d gr{-p.x / a, p.y / a, 1.0};
      const double hxx = -1 / a, hyy = 1 / a;  // hzz = hxy = hxz = hyz = 0
      const double g2 = dot(gr, gr), gn = std::sqrt(g2);
      const double H = (g2 * (hxx + hyy) - (hxx * gr.x * gr.x + hyy * gr.y * gr.y)) / (g2 * gn);
      const double K =
          (hxx * hyy * gr.z * gr.z) / (g2 * g2);  // adj(diag(hxx, hyy, 0)) = diag(0, 0, hxx hyy)
      const double disc = std::sqrt(H * H / 4 - K);
      const Curvature cv = both(g.at(i, j, k), g.stride, h);
      const double tol = 1e-6 / a;
      EXPECT_NEAR(cv.grad_norm, gn, 1e-6 * gn);
      EXPECT_NEAR(cv.mean, H, tol);
      EXPECT_NEAR(cv.gauss, K, tol / a);
      EXPECT_NEAR(cv.k1, H / 2 + disc, tol);
      EXPECT_NEAR(cv.k2, H / 2 - disc, tol);
      EXPECT_NEAR(length(cv.normal - gr / gn), 0.0, 1e-6);
    }
  }
}

// Error of H at a fixed world point for h, h/2, h/4: second order.
TEST(Curvature, SecondOrderConvergenceOnSphere) {
  const Vec3d p{0, 0, 0};  // a grid node at every h below
  const Vec3d c{-0.71, -0.43, -0.52};
  const double rho = length(p - c);
  const double r = rho - 0.003;  // p just outside the zero level
  const double H = 2 / rho;
  double err[3];
  double mean_err[3];
  const double hs[3] = {0.1, 0.05, 0.025};
  for (int s = 0; s < 3; ++s) {
    const double h = hs[s];
    const int n = 5;
    const DenseGrid g([&](const Vec3d& q) { return length(q - c) - r; }, Vec3d{1, 1, 1} * (-2 * h),
                      h, n);
    const Curvature cv = both(g.at(2, 2, 2), g.stride, h);
    err[s] = std::abs(cv.mean - H);
    mean_err[s] = std::abs(mean_curvature_at(g.at(2, 2, 2), g.stride, h) - H);
  }
  const double o1 = std::log2(err[0] / err[1]), o2 = std::log2(err[1] / err[2]);
  std::printf("[ convergence ] rho = %.2fh..%.1fh, |H - 2/rho|: %.3e %.3e %.3e, orders %.2f %.2f\n",
              rho / hs[0], rho / hs[2], err[0], err[1], err[2], o1, o2);
  EXPECT_GE(o1, 1.8);
  EXPECT_GE(o2, 1.8);
  EXPECT_GE(std::log2(mean_err[0] / mean_err[1]), 1.8);
  EXPECT_GE(std::log2(mean_err[1] / mean_err[2]), 1.8);
}

TEST(Curvature, DegenerateGradientGivesZeros) {
  const std::ptrdiff_t stride[3] = {1, 3, 9};
  auto expect_zero = [&](const std::vector<float>& vals) {
    const float* v = vals.data() + 13;
    const Curvature cv = curvature_at(v, stride, 0.5);
    EXPECT_EQ(cv.grad_norm, 0.0);
    EXPECT_EQ(cv.normal, Vec3d{});
    EXPECT_EQ(cv.mean, 0.0);
    EXPECT_EQ(cv.gauss, 0.0);
    EXPECT_EQ(cv.k1, 0.0);
    EXPECT_EQ(cv.k2, 0.0);
    EXPECT_EQ(mean_curvature_at(v, stride, 0.5), 0.0);
    const MeanGauss mg = mean_gauss_curvature_at(v, stride, 0.5);
    EXPECT_EQ(mg.mean, 0.0);
    EXPECT_EQ(mg.gauss, 0.0);
  };
  expect_zero(std::vector<float>(27, 0.75f));  // constant
  expect_zero(std::vector<float>(27, 0.0f));
  // Sphere centred on the voxel (a skeleton point): central differences cancel exactly.
  std::vector<float> centre(27);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        centre[std::size_t(i + 3 * j + 9 * k)] = float(
            0.5 * std::sqrt(double((i - 1) * (i - 1) + (j - 1) * (j - 1) + (k - 1) * (k - 1))) -
            1.0);
  expect_zero(centre);
}

// The brick form gives mean_gauss_curvature_at's values as floats, bit for bit, for every
// active voxel of a brick: rows that take their own curvature (curvature of both signs,
// saddles, a flat region with zero gradient: 0), voxels taking a neighbour's centre inside
// the brick (read from that centre's row) or in its halo on either side, and voxels without
// one (-1: 0).
TEST(Curvature, BrickFormEqualsSingleBitForBit) {
  const int n = 12;  // the brick at grid 2..9, its stencils within 1..10
  const double h = 0.3;
  const DenseGrid g(
      [](const Vec3d& p) {
        if (p.x > 1.0) return 0.25;  // flat: zero gradient
        return std::sin(1.3 * p.x) * std::cos(0.7 * p.y) + 0.4 * p.z * p.z - 0.2 * p.x * p.y + 0.1 * p.y * p.z;
      },
      Vec3d{-1.0, -1.2, -0.9}, h, n);
  BrickMask active;
  std::vector<int> at;
  int own = 0, other = 0, none = 0;
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        const int pattern = (3 * x + 5 * y + 7 * z) % 11;
        if (pattern == 0) continue;  // inactive
        active.set(x + 8 * (y + 8 * z));
        const int self = int(g.index(x + 2, y + 2, z + 2));
        if (pattern == 1) {
          at.push_back(-1);
          ++none;
        } else if (pattern == 2) {
          at.push_back(int(g.index(x + 2, y + 2, z + (z < 4 ? 3 : 1))));  // a neighbour along z
          ++other;
        } else if (pattern == 3) {
          // A neighbour along -x, or -z on the brick's lowest layers: in the halo at x = 0 or
          // z = 0 (below the brick's origin), else a centre whose row the brick form computes.
          at.push_back(int(z < 2 ? g.index(x + 2, y + 2, z + 1) : g.index(x + 1, y + 2, z + 2)));
          ++other;
        } else {
          at.push_back(self);
          ++own;
        }
      }
  ASSERT_GT(own, 0);
  ASSERT_GT(other, 0);
  ASSERT_GT(none, 0);
  std::vector<float> mean(at.size(), -7.0f), gauss(at.size(), -7.0f);
  mean_gauss_curvature_brick(g.values.data(), std::ptrdiff_t(g.index(2, 2, 2)), g.stride, active, at.data(), h,
                             mean.data(), gauss.data());
  int flat = 0;
  for (std::size_t i = 0; i < at.size(); ++i) {
    const MeanGauss single = at[i] >= 0 ? mean_gauss_curvature_at(g.values.data() + at[i], g.stride, h) : MeanGauss{};
    EXPECT_EQ(mean[i], float(single.mean)) << "voxel " << i;
    EXPECT_EQ(gauss[i], float(single.gauss)) << "voxel " << i;
    flat += at[i] >= 0 && single.mean == 0.0 && single.gauss == 0.0;
  }
  EXPECT_GT(flat, 0);
  const std::ptrdiff_t strided[3] = {2, 24, 288};
  EXPECT_THROW(mean_gauss_curvature_brick(g.values.data(), 0, strided, active, at.data(), h, mean.data(), gauss.data()),
               Error);
}

}  // namespace
}  // namespace levelset::evolve
