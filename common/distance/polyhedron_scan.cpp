#include "distance/polyhedron_scan.hpp"

#include <algorithm>
#include <cmath>

#include "geometry/point_triangle.hpp"

namespace levelset::scan_detail {

namespace {

// The squared distance to the feature.
template <FeatureBound::Kind Kind>
inline double feature_distance2(const FeatureBound& f, const Vec3d& x) {
  const Vec3d q = x - f.origin;
  const double q2 = dot(q, q);
  if constexpr (Kind == FeatureBound::Kind::point) return q2;
  const double along = dot(q, f.axis);
  return q2 - along * along;
}

// Narrows a column's interval [t0, t1] along axis k (at (xu, xv) across it) to the points
// within `reach` of the feature, a superset of those the per-voxel bound keeps; false when
// none is left. The solid is a ball about the point or a cylinder about the line: a
// quadratic along the column.
template <FeatureBound::Kind Kind>
inline bool clip_column(const FeatureBound& f, double reach, int k, int u, int v, double xu, double xv, double& t0,
                        double& t1) {
  if constexpr (Kind == FeatureBound::Kind::none) return true;
  const double qu = xu - f.origin[u], qv = xv - f.origin[v], ok = f.origin[k];
  const double r2 = reach * reach;
  if constexpr (Kind == FeatureBound::Kind::point) {
    const double across = r2 - qu * qu - qv * qv;
    if (across < 0) return false;
    const double s = std::sqrt(across);
    t0 = std::max(t0, ok - s);
    t1 = std::min(t1, ok + s);
    return t0 <= t1;
  }
  // |q|^2 - (q . a)^2 <= r2 with q = (qu, qv, s) in (u, v, k), s = t - ok: A s^2 + B s + C <= 0.
  const Vec3d& a = f.axis;
  const double qa = qu * a[u] + qv * a[v];  // q . a at s = 0
  const double A = 1.0 - a[k] * a[k], B = -2.0 * qa * a[k], C = qu * qu + qv * qv - qa * qa - r2;
  if (A < 1e-6) return C <= 1e-6 * r2;  // a line along the column: nearly constant distance
  const double disc = B * B - 4.0 * A * C;
  if (disc < 0) return false;
  const double root = std::sqrt(disc);
  t0 = std::max(t0, ok + (-B - root) / (2.0 * A));
  t1 = std::min(t1, ok + (-B + root) / (2.0 * A));
  return t0 <= t1;
}

}  // namespace

void Scanner::scan(const Polyhedron& p, std::uint32_t tri, const Vec3d& n, double plane_margin,
                   const FeatureBound& feature) {
  // One loop per kind: the plain scan keeps its inner loop free of the bound's tests.
  switch (feature.kind) {
    case FeatureBound::Kind::none: return scan_with<FeatureBound::Kind::none>(p, tri, n, plane_margin, feature);
    case FeatureBound::Kind::point: return scan_with<FeatureBound::Kind::point>(p, tri, n, plane_margin, feature);
    case FeatureBound::Kind::line: return scan_with<FeatureBound::Kind::line>(p, tri, n, plane_margin, feature);
  }
}

template <FeatureBound::Kind Kind>
void Scanner::scan_with(const Polyhedron& p, std::uint32_t tri, const Vec3d& n, double plane_margin,
                        const FeatureBound& feature) {
  ++polyhedra;
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = int(std::ceil((p.lo[a] - frame_.origin[a]) / h_ - 1e-9));
    hi[a] = int(std::floor((p.hi[a] - frame_.origin[a]) / h_ + 1e-9));
    if (lo[a] > hi[a]) return;
  }
  // Columns along the box's longest axis: fewest columns.
  int k = 0;
  for (int a = 1; a < 3; ++a)
    if (hi[a] - lo[a] > hi[k] - lo[k]) k = a;
  const int u = (k + 1) % 3, v = (k + 2) % 3;
  const auto& f = mesh_.triangles[tri];
  const Vec3d &ta = mesh_.vertices[f[0]], &tb = mesh_.vertices[f[1]], &tc = mesh_.vertices[f[2]];
  // Per column (xu, xv), plane i bounds t along k by (c - g_u xu - g_v xv) / g_k: from above
  // where g_k > 0, from below where g_k < 0; planes parallel to k cut whole columns. Sorted
  // once per polyhedron into branch-free lists, with the reciprocals.
  double up_c[24], up_u[24], up_v[24], up_inv[24], dn_c[24], dn_u[24], dn_v[24], dn_inv[24];
  double par_c[24], par_u[24], par_v[24];
  int nup = 0, ndn = 0, npar = 0;
  for (int i = 0; i < p.planes; ++i) {
    const double s = p.g[i][k];
    if (s > 1e-300) {
      up_c[nup] = p.c[i], up_u[nup] = p.g[i][u], up_v[nup] = p.g[i][v], up_inv[nup++] = 1.0 / s;
    } else if (s < -1e-300) {
      dn_c[ndn] = p.c[i], dn_u[ndn] = p.g[i][u], dn_v[ndn] = p.g[i][v], dn_inv[ndn++] = 1.0 / s;
    } else {
      par_c[npar] = p.c[i], par_u[npar] = p.g[i][u], par_v[npar++] = p.g[i][v];
    }
  }
  // The feature's solid that the per-voxel bound below can keep at all, with room to spare
  // (one voxel: the column clip is only a shortcut, the per-voxel test decides).
  const double feature_reach = (r_ + feature.margin) * (1.0 + 1e-5) + h_;
  for (int jv = lo[v]; jv <= hi[v]; ++jv) {
    const double xv = frame_.origin[v] + jv * h_;
    for (int ju = lo[u]; ju <= hi[u]; ++ju) {
      const double xu = frame_.origin[u] + ju * h_;
      double t0 = frame_.origin[k] + lo[k] * h_, t1 = frame_.origin[k] + hi[k] * h_;
      if (!clip_column<Kind>(feature, feature_reach, k, u, v, xu, xv, t0, t1)) continue;
      bool cut = false;
      for (int i = 0; i < npar; ++i) cut |= par_c[i] - par_u[i] * xu - par_v[i] * xv < 0;
      for (int i = 0; i < nup; ++i) t1 = std::min(t1, (up_c[i] - up_u[i] * xu - up_v[i] * xv) * up_inv[i]);
      for (int i = 0; i < ndn; ++i) t0 = std::max(t0, (dn_c[i] - dn_u[i] * xu - dn_v[i] * xv) * dn_inv[i]);
      if (cut || t0 > t1) continue;
      const int k0 = std::max(lo[k], int(std::ceil((t0 - frame_.origin[k]) / h_ - 1e-9)));
      const int k1 = std::min(hi[k], int(std::floor((t1 - frame_.origin[k]) / h_ + 1e-9)));
      Coord c;
      c[u] = ju;
      c[v] = jv;
      Vec3d x;
      x[u] = xu;
      x[v] = xv;
      for (int kk = k0; kk <= k1; ++kk) {
        c[k] = kk;
        x[k] = frame_.origin[k] + kk * h_;
        const std::size_t cell = cell_of(c);
        if (cell == kNoCell) continue;
        // A lower bound, also under the rounding of the distance itself (relative margin).
        const double plane = std::abs(dot(n, x - ta)) * (1.0 - 1e-6) - plane_margin;
        const double best = double(field_.best(cell));
        if (plane > r_ || plane > best) continue;
        if constexpr (Kind != FeatureBound::Kind::none) {
          // sqrt(d2) (1 - 1e-6) - margin > min(best, r), squared (both sides >= 0).
          const double reach = std::min(best, r_) + feature.margin;
          if (feature_distance2<Kind>(feature, x) * (1.0 - 2e-6) > reach * reach) continue;
        }
        const double d2 = closest_point_on_triangle(x, ta, tb, tc).distance_squared;
        ++evaluations;
        if (!(d2 <= band2_)) continue;
        field_.offer(cell, static_cast<float>(std::sqrt(d2)), tri);
      }
    }
  }
}


// The margin covers the rounding of the computed normal (relative error ~ u times the
// condition scale^2 / area, worse where coordinates are large against the edges) over
// distances up to r + 2 scale, and of the differences; it is used only where it stays below
// h / 10, so that skipping still pays.
double plane_margin(const TriangleFrame& tf, double area2, double r, double h) {
  constexpr double u = 1.2e-16;
  double coords = 0, shortest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    coords = std::max({coords, std::abs(tf.v[k].x), std::abs(tf.v[k].y), std::abs(tf.v[k].z)});
    shortest = std::min(shortest, length(tf.v[(k + 1) % 3] - tf.v[k]));
  }
  if (!(shortest > 0)) return std::numeric_limits<double>::infinity();
  const double normal_error = 8 * u * (tf.scale * tf.scale / area2) * (1 + coords / shortest);
  const double margin = 1e-3 * h + 10 * (normal_error * (r + 2 * tf.scale) + 2 * u * (coords + r + tf.scale));
  return margin <= 0.1 * h ? margin : std::numeric_limits<double>::infinity();
}

TriangleFrame triangle_frame(const TriangleMesh& mesh, std::uint32_t t, double r, double h) {
  const auto& f = mesh.triangles[t];
  TriangleFrame tf;
  for (int k = 0; k < 3; ++k) tf.v[k] = mesh.vertices[f[k]];
  const Vec3d big = cross(tf.v[1] - tf.v[0], tf.v[2] - tf.v[0]);
  const double area2 = length(big);
  tf.scale = std::max({length(tf.v[1] - tf.v[0]), length(tf.v[2] - tf.v[1]), length(tf.v[0] - tf.v[2])});
  tf.flat = area2 > 1e-12 * tf.scale * tf.scale;
  tf.n = tf.flat ? big / area2 : Vec3d{0, 0, 0};
  for (int k = 0; k < 3; ++k) tf.m[k] = tf.flat ? unit(cross(tf.v[(k + 1) % 3] - tf.v[k], tf.n)) : Vec3d{0, 0, 0};
  if (tf.flat) tf.plane_margin = plane_margin(tf, area2, r, h);
  return tf;
}

}  // namespace levelset::scan_detail
