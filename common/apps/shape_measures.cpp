#include "apps/shape_measures.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "apps/band_curvature.hpp"
#include "grid/band_accessor.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::apps {

namespace {

// Solves the 4x4 system a x = b by Gaussian elimination with partial pivoting; false when
// singular.
bool solve4(std::array<std::array<double, 4>, 4> a, std::array<double, 4> b, std::array<double, 4>& x) {
  for (int col = 0; col < 4; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 4; ++r)
      if (std::abs(a[r][col]) > std::abs(a[pivot][col])) pivot = r;
    if (!(std::abs(a[pivot][col]) > 1e-300)) return false;
    std::swap(a[col], a[pivot]);
    std::swap(b[col], b[pivot]);
    for (int r = col + 1; r < 4; ++r) {
      const double f = a[r][col] / a[col][col];
      for (int c = col; c < 4; ++c) a[r][c] -= f * a[col][c];
      b[r] -= f * b[col];
    }
  }
  for (int r = 3; r >= 0; --r) {
    double s = b[r];
    for (int c = r + 1; c < 4; ++c) s -= a[r][c] * x[c];
    x[r] = s / a[r][r];
  }
  return true;
}

}  // namespace

SphereFit fit_sphere(std::span<const Vec3d> points) {
  SphereFit fit;
  if (points.size() < 4) return fit;
  // Centre the points first: the normal equations stay well conditioned far from the origin.
  Vec3d mean{};
  for (const Vec3d& p : points) mean += p;
  mean = mean / double(points.size());
  std::array<std::array<double, 4>, 4> ata{};
  std::array<double, 4> atb{};
  for (const Vec3d& p : points) {
    const Vec3d q = p - mean;
    const std::array<double, 4> row{2 * q.x, 2 * q.y, 2 * q.z, 1.0};
    const double rhs = dot(q, q);
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) ata[i][j] += row[i] * row[j];
      atb[i] += row[i] * rhs;
    }
  }
  std::array<double, 4> x{};
  if (!solve4(ata, atb, x)) return fit;
  const Vec3d c{x[0], x[1], x[2]};
  const double r2 = x[3] + dot(c, c);
  if (!(r2 > 0)) return fit;
  fit.center = c + mean;
  fit.radius = std::sqrt(r2);
  double s2 = 0;
  for (const Vec3d& p : points) {
    const double d = length(p - fit.center) - fit.radius;
    s2 += d * d;
    fit.max_deviation = std::max(fit.max_deviation, std::abs(d));
  }
  fit.rms_deviation = std::sqrt(s2 / double(points.size()));
  return fit;
}

std::vector<double> vertex_mean_curvatures(const NarrowBand& band, const TriangleMesh& mesh) {
  std::vector<double> h(mesh.vertices.size(), 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, h.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    BandAccessor accessor(band);
    for (std::size_t i = r.begin(); i != r.end(); ++i) h[i] = band_mean_curvature(accessor, band, mesh.vertices[i]);
  });
  return h;
}

CurvatureStats weighted_curvature_stats(const TriangleMesh& mesh, std::span<const double> h) {
  std::vector<double> weight(mesh.vertices.size(), 0.0);
  for (const auto& t : mesh.triangles) {
    const Vec3d& a = mesh.vertices[t[0]];
    const double third = length(cross(mesh.vertices[t[1]] - a, mesh.vertices[t[2]] - a)) / 6.0;
    for (std::uint32_t v : t) weight[v] += third;
  }
  CurvatureStats stats;
  double w_sum = 0, s = 0;
  for (std::size_t i = 0; i < h.size() && i < weight.size(); ++i) {
    w_sum += weight[i];
    s += weight[i] * h[i];
    stats.max_abs = std::max(stats.max_abs, std::abs(h[i]));
  }
  if (!(w_sum > 0)) return stats;
  stats.mean = s / w_sum;
  double v = 0;
  for (std::size_t i = 0; i < h.size() && i < weight.size(); ++i) v += weight[i] * (h[i] - stats.mean) * (h[i] - stats.mean);
  stats.variance = v / w_sum;
  return stats;
}

ShapeMeasures measure_shape(const NarrowBand& band) {
  ShapeMeasures m;
  const TriangleMesh mesh = marching_cubes(band).mesh;
  if (mesh.triangles.empty()) return m;
  const MeshMeasures mm = measure_mesh(mesh);
  m.area = mm.area;
  m.volume = mm.volume;
  m.components = mm.components;
  m.genus = mm.genus;
  m.vertices = mesh.vertices.size();
  m.triangles = mesh.triangles.size();
  m.watertight = mm.watertight;
  m.sphere = fit_sphere(mesh.vertices);
  const std::vector<double> h = vertex_mean_curvatures(band, mesh);
  m.curvature = weighted_curvature_stats(mesh, h);
  return m;
}

}  // namespace levelset::apps
