// closest_point_on_triangle: exact Euclidean closest point of a triangle to a point.
//
// Inputs: point p, triangle (a, b, c), world units, double precision. Degenerate triangles
// (zero area: collinear or repeated vertices) are handled as the union of their edges.
// Output: the closest point q, its barycentric coordinates (u, v, w) with q = u a + v b + w c,
// and the squared distance |p - q|^2. Cost: ~60 flops, no allocation. Thread-safe.
// Method: Voronoi-region classification of p against the triangle's vertices, edges and face
// (Ericson, Real-Time Collision Detection, 5.1.5), written out here.
//
// triangle_plane: the unit normal of (a, b, c) where rounding leaves it meaningful (twice the
// area above 1e-12 of the longest edge squared, triangle_frame's flatness too), with a bound
// on its error: |n . (x - a)| is then within `error` |x - a| of the distance of x to the
// triangle's plane. Nearly collinear triangles (a sliver or a subdivided degenerate face) get
// none: their computed cross product is rounding noise, a random direction, and a plane test
// with it culls what lies near them (the slab scan's binning and slabs did).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec3.hpp"

namespace levelset {

struct TrianglePlane {
  bool flat = false;   // n is meaningful
  Vec3d n{0, 0, 0};    // unit normal (flat only)
  double error = 0.0;  // bound on the relative error of plane distances with n
};

inline TrianglePlane triangle_plane(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  TrianglePlane p;
  const Vec3d big = cross(b - a, c - a);
  const double len = length(big);
  const double scale2 = std::max({dot(b - a, b - a), dot(c - b, c - b), dot(a - c, a - c)});  // longest edge^2
  if (!(len > 1e-12 * scale2) || !std::isfinite(len)) return p;
  p.flat = true;
  p.n = big / len;
  p.error = 1e-15 * scale2 / len;  // ~8 ulp of the cross product over its length
  return p;
}

struct TrianglePoint {
  Vec3d point;
  Vec3d barycentric;  // weights of a, b, c
  double distance_squared = 0.0;
};

namespace detail {
inline TrianglePoint closest_on_segment(const Vec3d& p, const Vec3d& a, const Vec3d& b, int ia, int ib) {
  const Vec3d ab = b - a;
  const double len2 = dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  TrianglePoint r;
  r.point = a + ab * t;
  r.barycentric[ia] = 1.0 - t;
  r.barycentric[ib] = t;
  const Vec3d d = p - r.point;
  r.distance_squared = dot(d, d);
  return r;
}
}  // namespace detail

inline TrianglePoint closest_point_on_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b,
                                               const Vec3d& c) {
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const Vec3d n = cross(ab, ac);
  const double nn = dot(n, n);
  const double scale = std::max(dot(ab, ab), dot(ac, ac));
  if (!(nn > 1e-24 * scale * scale)) {
    // Degenerate: the closest point lies on one of the edges.
    TrianglePoint best = detail::closest_on_segment(p, a, b, 0, 1);
    const TrianglePoint e1 = detail::closest_on_segment(p, b, c, 1, 2);
    if (e1.distance_squared < best.distance_squared) best = e1;
    const TrianglePoint e2 = detail::closest_on_segment(p, c, a, 2, 0);
    if (e2.distance_squared < best.distance_squared) best = e2;
    return best;
  }
  auto finish = [&](double u, double v, double w) {
    TrianglePoint r;
    r.barycentric = {u, v, w};
    r.point = a * u + b * v + c * w;
    const Vec3d d = p - r.point;
    r.distance_squared = dot(d, d);
    return r;
  };
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return finish(1, 0, 0);  // vertex a
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return finish(0, 1, 0);  // vertex b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {  // edge ab
    const double t = d1 / (d1 - d3);
    return finish(1 - t, t, 0);
  }
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return finish(0, 0, 1);  // vertex c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {  // edge ac
    const double t = d2 / (d2 - d6);
    return finish(1 - t, 0, t);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {  // edge bc
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return finish(0, 1 - t, t);
  }
  const double denom = 1.0 / (va + vb + vc);  // face interior
  const double v = vb * denom, w = vc * denom;
  return finish(1 - v - w, v, w);
}

}  // namespace levelset
