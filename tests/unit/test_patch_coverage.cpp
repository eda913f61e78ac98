// patch_coverage (apps/patch_coverage.hpp): a position in a gap between the samples of a
// plane is inside the patch; beyond the patch's edge, well above it, or midway between two
// parallel sheets it is not. And the smallest eigenpair behind the plane fit
// (geometry/symmetric_eigen.hpp) against a rotated diagonal matrix.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "apps/patch_coverage.hpp"
#include "geometry/symmetric_eigen.hpp"

namespace levelset::apps {
namespace {

// A square lattice of spacing s in the plane z = z0 over [-1, 1]^2, without the points within
// `hole` of the origin's column.
std::vector<Vec3d> lattice(double s, double z0, double hole) {
  std::vector<Vec3d> p;
  const int n = int(std::lround(1.0 / s));
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) {
      const Vec3d q{i * s, j * s, z0};
      if (std::hypot(q.x, q.y) >= hole) p.push_back(q);
    }
  return p;
}

TEST(PatchCoverage, AGapInAPlaneIsInsideItsEdgeAndAboveItAreNot) {
  const PointIndex plane(lattice(0.05, 0.0, 0.12));  // a hole 2.4 spacings wide at the origin
  const PatchCoverageResult gap = patch_coverage(plane, {0.0, 0.0, 0.03});
  EXPECT_TRUE(gap.inside) << gap.offset << " " << gap.residual << " " << gap.angular_gap;
  EXPECT_NEAR(gap.residual, 0.0, 1e-9);
  EXPECT_NEAR(gap.offset, 0.03, 1e-9);
  // Beyond the lattice's edge at x = 1: all neighbours on one side.
  const PatchCoverageResult edge = patch_coverage(plane, {1.1, 0.0, 0.0});
  EXPECT_FALSE(edge.inside);
  EXPECT_GE(edge.angular_gap, std::numbers::pi - 1e-9);
  // Well above the hole: nearer the plane's points than their plane only by its height.
  EXPECT_FALSE(patch_coverage(plane, {0.0, 0.0, 0.2}).inside);
}

TEST(PatchCoverage, MidwayBetweenTwoSheetsIsNotAPatch) {
  // Sheets 0.04 apart (closer than their spacing 0.05): the fit is their mid-plane, through
  // x, but its residual is half their distance, as large as the nearest point's distance.
  auto sheets = [](double half_distance) {
    std::vector<Vec3d> two = lattice(0.05, -half_distance, 0.0);
    const std::vector<Vec3d> upper = lattice(0.05, half_distance, 0.0);
    two.insert(two.end(), upper.begin(), upper.end());
    return two;
  };
  const PointIndex close(sheets(0.02));
  const PatchCoverageResult mid = patch_coverage(close, {0.004, 0.003, 0.0});
  EXPECT_FALSE(mid.inside);
  EXPECT_NEAR(mid.residual, 0.02, 1e-9);
  EXPECT_GT(mid.residual, 0.5 * mid.nearest);
  // Sheets 0.16 apart: the 12 nearest points form a column (taller than wide), and the
  // points seen in its plane leave a gap of more than 120 degrees.
  const PointIndex apart(sheets(0.08));
  EXPECT_FALSE(patch_coverage(apart, {0.013, 0.021, 0.0}).inside);
}

TEST(SymmetricEigen, SmallestPairOfARotatedDiagonalMatrix) {
  // M = R diag(3, 2, 0.5) R^T, R a rotation by 0.7 about (1, 2, 2) / 3.
  const Vec3d axis{1.0 / 3, 2.0 / 3, 2.0 / 3};
  const double t = 0.7, c = std::cos(t), s = std::sin(t);
  double R[3][3];
  const double a[3] = {axis.x, axis.y, axis.z};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      R[i][j] = (i == j ? c : 0.0) + (1 - c) * a[i] * a[j];
      if (i != j) {
        const int k = 3 - i - j;
        const double sign = ((i + 1) % 3 == j) ? -1.0 : 1.0;
        R[i][j] += sign * s * a[k];
      }
    }
  const double lam[3] = {3.0, 2.0, 0.5};
  double M[3][3] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) M[i][j] += R[i][k] * lam[k] * R[j][k];
  const double l = smallest_eigenvalue(M[0][0], M[1][1], M[2][2], M[0][1], M[0][2], M[1][2]);
  EXPECT_NEAR(l, 0.5, 1e-12);
  const Vec3d v = eigenvector_of(M[0][0], M[1][1], M[2][2], M[0][1], M[0][2], M[1][2], l);
  const Vec3d expected{R[0][2], R[1][2], R[2][2]};
  EXPECT_NEAR(std::abs(dot(v, expected)), 1.0, 1e-12);
  EXPECT_NEAR(length(v), 1.0, 1e-12);
}

}  // namespace
}  // namespace levelset::apps
