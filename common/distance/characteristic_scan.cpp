#include "distance/characteristic_scan.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "core/huge_pages.hpp"
#include "distance/brick_set.hpp"
#include "distance/polyhedron_scan.hpp"
#include "distance/collinear_segments.hpp"
#include "distance/welded_adjacency.hpp"

namespace levelset {

namespace {

using namespace scan_detail;

// Wedges opening wider than this (cosine of the opening; 120 degrees) are scanned over the
// cylinder's box.
constexpr double kWideCos = -0.5;

// The box of p0 + R d over a 2D cone of unit directions (between d1 and d2 through mid, angle
// with cosine cos_theta) and both edge ends, or the whole cylinder's box when the cone is wide.
void wedge_box(Polyhedron& p, const Vec3d& p0, const Vec3d& p1, const Vec3d& d1, const Vec3d& d2, const Vec3d& mid,
               double cos_theta, double r) {
  if (cos_theta < kWideCos) {  // the cylinder's box
    const Vec3d e{r, r, r};
    p.lo = min(p0, p1) - e;
    p.hi = max(p0, p1) + e;
    return;
  }
  const double bulge = r / std::max(0.5, std::sqrt(0.5 * (1.0 + cos_theta)));  // r / cos(theta / 2)
  const Vec3d pts[8] = {p0, p1, p0 + d1 * r, p0 + d2 * r, p1 + d1 * r, p1 + d2 * r, p0 + mid * bulge, p1 + mid * bulge};
  p.box_of(pts, 8);
}

// The face's prism: the points that project into it, within W h of its plane; with `cover` > 0
// its edge planes move out by that much (scan_triangle_features: it then also holds thin
// wedges of its edges).
void scan_prism(const TriangleFrame& tf, std::uint32_t t, double cover, Scanner& scanner) {
  const double r = scanner.radius(), eps = scanner.slack();
  Polyhedron p;
  for (int k = 0; k < 3; ++k) p.add_through(tf.m[k], tf.v[k], eps + cover);
  p.add_through(tf.n, tf.v[0], r + eps);
  p.add_through(tf.n * -1.0, tf.v[0], r + eps);
  // Corner k of the offset triangle: w . m_(k-1) = w . m_k = the offset.
  Vec3d corner[3];
  for (int k = 0; k < 3; ++k) {
    const Vec3d& before = tf.m[(k + 2) % 3];
    corner[k] = cover > 0 ? tf.v[k] + (before + tf.m[k]) * ((eps + cover) / (1.0 + dot(before, tf.m[k]))) : tf.v[k];
  }
  const Vec3d off = tf.n * (r + eps);
  const Vec3d pts[6] = {corner[0] + off, corner[1] + off, corner[2] + off, corner[0] - off, corner[1] - off, corner[2] - off};
  p.box_of(pts, 6);
  scanner.scan(p, t, tf.n, tf.plane_margin);
}

// The outward in-plane normal of `other` at the edge (p0, axis), or nothing when `other` is
// degenerate.
bool other_face_normal(const TriangleMesh& mesh, const WeldedAdjacency& adj, std::uint32_t other, const Vec3d& p0,
                       const Vec3d& axis, std::uint32_t a, std::uint32_t b, double scale, Vec3d& out) {
  const auto& g = mesh.triangles[other];
  const Vec3d w[3] = {mesh.vertices[g[0]], mesh.vertices[g[1]], mesh.vertices[g[2]]};
  const Vec3d nb = cross(w[1] - w[0], w[2] - w[0]);
  const double nl = length(nb);
  if (!(nl > 1e-12 * scale * scale)) return false;
  // In its plane, perpendicular to the edge, pointing away from its third vertex.
  out = unit(cross(axis, nb / nl));
  int third = 0;
  while (third < 3 && (adj.welded[g[third]] == a || adj.welded[g[third]] == b)) ++third;
  if (third < 3 && dot(w[third] - p0, out) > 0) out = out * -1.0;
  return true;
}

// Edge k of a face: its direction and, where the edge is manifold, the in-plane outward normal
// of the face across it.
struct EdgeWedge {
  bool point = false;  // zero length: the vertices' cones cover it
  bool bounded = false;  // the face across gives the wedge's second side (m2)
  Vec3d axis, m2;
};

EdgeWedge edge_wedge(const TriangleMesh& mesh, const WeldedAdjacency& adj, const TriangleFrame& tf, std::uint32_t t, int k) {
  EdgeWedge w;
  const Vec3d &p0 = tf.v[k], &p1 = tf.v[(k + 1) % 3];
  if (length(p1 - p0) == 0.0) {
    w.point = true;
    return w;
  }
  w.axis = unit(p1 - p0);
  if (!tf.flat) return w;
  const auto& f = mesh.triangles[t];
  const std::uint32_t other = adj.across[3 * std::size_t(t) + std::size_t(k)];
  w.bounded = other != kNoAdjacent &&
              other_face_normal(mesh, adj, other, p0, w.axis, adj.welded[f[k]], adj.welded[f[(k + 1) % 3]], tf.scale, w.m2);
  return w;
}

// The wedge's two sides in cross-section: directions perpendicular to the edge with u.m >= 0
// and u.m2 >= 0, bounded by d1 (perpendicular to m) and d2 (perpendicular to m2).
void wedge_sides(const Vec3d& axis, const Vec3d& m, const Vec3d& m2, Vec3d& d1, Vec3d& d2) {
  d1 = unit(cross(axis, m));
  d2 = unit(cross(axis, m2));
  if (dot(d1, m2) < 0) d1 = d1 * -1.0;
  if (dot(d2, m) < 0) d2 = d2 * -1.0;
}

// How far beyond the face's edge plane (along m_k) the wedge of edge k reaches within r of the
// edge. In cross-section the wedge {u . m >= 0, u . m2 >= 0} opens by psi = pi - angle(m, m2)
// (0 for coplanar faces, pi for a face folded back onto its neighbour); for psi < 60 degrees
// its farthest point from the plane u . m = 0 is on the side u . m2 = 0 at distance r, so the
// reach is r sin(psi). +inf for unbounded edges and wider wedges; 0 for a zero-length edge.
double wedge_reach(const TriangleFrame& tf, int k, const EdgeWedge& w, double r) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (w.point) return 0.0;
  if (!w.bounded) return kInf;
  const double c = dot(tf.m[k], w.m2);  // cos(pi - psi)
  if (!(c < -0.5)) return kInf;
  return r * std::sqrt(std::max(0.0, 1.0 - c * c));
}

// The rounding margin of a feature bound (FeatureBound) over a triangle's band: the
// cancellation in a line distance (squared length less squared projection: sqrt(u) times the
// lengths involved), the coordinates' rounding, and 1e-4 h to spare.
double feature_rounding(const TriangleFrame& tf, double r, double h) {
  double coords = 0;
  for (const Vec3d& v : tf.v) coords = std::max({coords, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  return 1e-4 * h + 1e-7 * (tf.scale + r) + 1e-14 * (coords + r);
}

// Edge k's wedge: beyond the edge as seen from this face (and from the face across it, when the
// edge is manifold), between the planes through its ends.
void scan_wedge(const TriangleFrame& tf, std::uint32_t t, int k, const EdgeWedge& w, Scanner& scanner) {
  const double r = scanner.radius(), eps = scanner.slack();
  const Vec3d &p0 = tf.v[k], &p1 = tf.v[(k + 1) % 3];
  if (w.point) return;  // a point: its vertices' cones cover it
  Polyhedron p;
  p.add_through(w.axis * -1.0, p0, eps);
  p.add_through(w.axis, p1, eps);
  const Vec3d e{r + eps, r + eps, r + eps};
  p.lo = min(p0, p1) - e;  // the cylinder's box unless the wedge is narrower
  p.hi = max(p0, p1) + e;
  bool wide = true;  // scanned over the cylinder's box
  if (tf.flat) {
    p.add_through(tf.m[k] * -1.0, p0, eps);
    if (w.bounded) {
      p.add_through(w.m2 * -1.0, p0, eps);
      Vec3d d1, d2;
      wedge_sides(w.axis, tf.m[k], w.m2, d1, d2);
      const Vec3d sum = tf.m[k] + w.m2;
      // Coplanar faces: the wedge is the plane through the edge along n, whose points project
      // onto the edge, on both prisms' boundaries (within their slack): nothing to add.
      if (length(sum) < 1e-9) return;
      // The opening's cosine from the in-plane normals (pi - angle(m, m2)), not from d1 . d2:
      // for a face folded back onto its neighbour (m2 ~ m) the sides' flips above are
      // ambiguous, and d1 . d2 could read a half-space as a thin wedge.
      const double cos_theta = std::clamp(-dot(tf.m[k], w.m2), -1.0, 1.0);
      wedge_box(p, p0, p1, d1, d2, unit(sum), cos_theta, r + eps);
      wide = cos_theta < kWideCos;
    }
  }
  // Flat faces: x in the wedge has (x - p0) . m_k >= -eps, so its distance to the face is at
  // least its distance to the edge's line less eps (only the in-plane part across the line
  // can be nearer, by at most eps). Only for wide wedges (see FeatureBound).
  FeatureBound line;
  if (tf.flat && wide) {
    line.kind = FeatureBound::Kind::line;
    line.origin = p0;
    line.axis = w.axis;
    line.margin = eps + feature_rounding(tf, r, scanner.voxel_size());
  }
  scanner.scan(p, t, tf.n, tf.plane_margin, line);
}

// All rays on one line (the cone of a flat vertex is the normal line, +-n).
bool is_line(const Vec3d* rays, int nr) {
  for (int i = 1; i < nr; ++i)
    if (std::abs(dot(rays[i], rays[0])) < 1.0 - 1e-9) return false;
  return true;
}

// The directions, perpendicular to `axis`, leave no gap of half a turn around it: the vertex is
// surrounded by its edges in their plane (not a border vertex, whose cone is a half-plane).
bool surrounds(const Vec3d* dirs, int nd, const Vec3d& axis) {
  const Vec3d a = unit(std::abs(axis.x) < 0.9 ? cross(axis, Vec3d{1, 0, 0}) : cross(axis, Vec3d{0, 1, 0}));
  const Vec3d b = cross(axis, a);
  double angles[64];
  for (int i = 0; i < nd; ++i) angles[i] = std::atan2(dot(dirs[i], b), dot(dirs[i], a));
  std::sort(angles, angles + nd);
  double gap = angles[0] + 2.0 * M_PI - angles[nd - 1];
  for (int i = 1; i < nd; ++i) gap = std::max(gap, angles[i] - angles[i - 1]);
  return gap < M_PI - 1e-6;
}

// The cone's bound: with every edge at v as a constraint (x - v) . u <= eps (u unit), face t's
// two edges among them (u1, u2, angle alpha at v), a point y = v + a u1 + b u2 of t (a, b >= 0)
// has (x - v) . (y - v) <= eps (a + b) <= eps K |y - v|, K = 1 / cos(alpha / 2), so
// |x - y|^2 >= |x - v|^2 - (eps K)^2: the distance is at least |x - v| - eps K. None for
// degenerate faces, rings past the polyhedron's 24 planes, or angles within 0.1 degree of pi.
FeatureBound cone_bound(const TriangleFrame& tf, int k, double eps, std::uint32_t ring, double r, double h) {
  FeatureBound bound;
  if (!tf.flat || ring > 24) return bound;
  const Vec3d& v = tf.v[k];
  const Vec3d u1 = unit(tf.v[(k + 1) % 3] - v), u2 = unit(tf.v[(k + 2) % 3] - v);
  const double half_cos = std::sqrt(std::max(0.0, 0.5 * (1.0 + dot(u1, u2))));
  if (!(half_cos > 1e-3)) return bound;
  bound.kind = FeatureBound::Kind::point;
  bound.origin = v;
  bound.margin = eps / half_cos + feature_rounding(tf, r, h);
  return bound;
}

// Vertex k's cone: the points for which every edge at the vertex points away (the polar cone of
// its welded edges), scanned once per welded vertex, by its lowest-index triangle.
void scan_cone(const TriangleMesh& mesh, const WeldedAdjacency& adj, const TriangleFrame& tf, std::uint32_t t, int k,
               Scanner& scanner) {
  const auto& f = mesh.triangles[t];
  const std::uint32_t w = adj.welded[f[k]];
  if (adj.first_triangle[w] != t) return;
  for (int j = 0; j < k; ++j)
    if (adj.welded[f[j]] == w) return;  // a repeated vertex of a degenerate face
  const double r = scanner.radius(), eps = scanner.slack();
  const Vec3d& v = tf.v[k];
  Polyhedron p;
  Vec3d dirs[64];
  int nd = 0;
  for (std::uint32_t i = adj.ring_offsets[w]; i < adj.ring_offsets[w + 1]; ++i) {
    const Vec3d d = unit(mesh.vertices[adj.ring_vertices[i]] - v);
    if (nd < 64) dirs[nd++] = d;
    p.add_through(d, v, eps);
  }
  const bool capped = adj.ring_offsets[w + 1] - adj.ring_offsets[w] > 24 || nd < 3;
  // A vertex whose ring lies in face t's plane (to rounding; flat regions of CAD meshes,
  // subdivided facets): the ray search below would find exactly +-n, so decide the flat case
  // (nothing to scan when its edges surround it) without that O(nd^3) search.
  if (!capped && tf.flat) {
    bool in_plane = true;
    for (int i = 0; i < nd && in_plane; ++i) in_plane = std::abs(dot(dirs[i], tf.n)) <= 1e-12;
    if (in_plane && surrounds(dirs, nd, tf.n)) return;
  }
  // Extreme rays of {x : x . d_i <= 0}: cross products of pairs that satisfy every constraint
  // (deduplicated); the box of v + R' rays (R' covers the cap between them), else the ball's.
  Vec3d rays[64];
  int nr = 0;
  bool overflow = false;
  for (int i = 0; i < nd && !capped; ++i)
    for (int j = i + 1; j < nd; ++j) {
      Vec3d c = unit(cross(dirs[i], dirs[j]));
      if (length(c) == 0.0) continue;
      for (int s = 0; s < 2; ++s, c = c * -1.0) {
        bool ok = true;
        for (int l = 0; l < nd && ok; ++l) ok = dot(c, dirs[l]) <= 1e-9;
        if (!ok) continue;
        bool known = false;
        for (int q = 0; q < nr && !known; ++q) known = dot(rays[q], c) > 1.0 - 1e-12;
        if (known) continue;
        if (nr == 64) overflow = true;
        else rays[nr++] = c;
      }
    }
  double min_cos = 1.0;  // the cosine of the widest angle between two rays
  for (int i = 0; i < nr; ++i)
    for (int j = i + 1; j < nr; ++j) min_cos = std::min(min_cos, dot(rays[i], rays[j]));
  // A flat vertex surrounded by its edges: its cone is the normal line, whose points project
  // onto the vertex, on every adjacent prism's boundary (within their slack): nothing to add.
  if (!capped && !overflow && nr >= 1 && is_line(rays, nr) && surrounds(dirs, nd, rays[0])) return;
  // No extreme ray: the edges positively span space, so the cone is the vertex alone (a saddle
  // vertex: every point near it is closer to one of its faces or edges, whose polyhedra hold
  // it). Nothing to scan; its box would otherwise be the whole ball of radius W h. (Every
  // extreme ray of a cone with more than the apex lies on two constraint planes, so the pair
  // search above finds it, its tolerance being lenient.)
  if (!capped && !overflow && nr == 0) return;
  const Vec3d e{r + eps, r + eps, r + eps};
  p.lo = v - e;
  p.hi = v + e;
  const bool wide = !(!capped && !overflow && nr >= 2 && min_cos >= -0.4);  // the ball's box
  if (!wide) {  // rays at most ~114 degrees apart
    const double reach = 1.5 * (r + eps) / std::sqrt(0.5 * (1.0 + min_cos));  // 1.5 R / cos(angle / 2)
    Vec3d pts[65];
    pts[0] = v;
    for (int i = 0; i < nr; ++i) pts[i + 1] = v + rays[i] * reach;
    Polyhedron box;
    box.box_of(pts, nr + 1);
    p.lo = max(box.lo, p.lo);
    p.hi = min(box.hi, p.hi);
  }
  const std::uint32_t ring = adj.ring_offsets[w + 1] - adj.ring_offsets[w];
  scanner.scan(p, t, tf.n, tf.plane_margin, wide ? cone_bound(tf, k, eps, ring, r, scanner.voxel_size()) : FeatureBound{});
}

// A degenerate face (not flat) whose vertices lie within 1e-6 h of its longest edge's line: that
// edge (its index), or -1.
int collinear_longest_edge(const Vec3d* v, double h) {
  const Vec3d big = cross(v[1] - v[0], v[2] - v[0]);
  const double twice_area = length(big);
  int longest = 0;
  double scale = 0;
  for (int k = 0; k < 3; ++k) {
    const double l = length(v[(k + 1) % 3] - v[k]);
    if (l > scale) scale = l, longest = k;
  }
  const bool flat = twice_area > 1e-12 * scale * scale;  // as triangle_frame decides
  return !flat && scale > 0 && twice_area / scale <= 1e-6 * h ? longest : -1;
}

// The collinear degenerate faces (by index) and the parts of their longest edges that no
// lower-numbered one on the same line covers (collinear_segments.hpp): only those parts'
// cylinders are scanned. Subdivided degenerate faces overlap many times over on their line.
class CollinearFaces {
 public:
  CollinearFaces(const TriangleMesh& mesh, double h) {
    // (face, its longest edge) of every collinear face, in face order (the reduction joins
    // left to right).
    using Found = std::vector<std::pair<std::uint32_t, std::array<Vec3d, 2>>>;
    const Found found = tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(0, std::uint32_t(mesh.triangles.size()), 4096), Found{},
        [&](const tbb::blocked_range<std::uint32_t>& range, Found part) {
          for (std::uint32_t t = range.begin(); t != range.end(); ++t) {
            const auto& f = mesh.triangles[t];
            const Vec3d v[3] = {mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]};
            if (const int k = collinear_longest_edge(v, h); k >= 0) part.push_back({t, {v[k], v[(k + 1) % 3]}});
          }
          return part;
        },
        [](Found left, const Found& right) {
          left.insert(left.end(), right.begin(), right.end());
          return left;
        });
    std::vector<std::array<Vec3d, 2>> segments;
    faces_.reserve(found.size());
    segments.reserve(found.size());
    for (const auto& [t, segment] : found) {
      faces_.push_back(t);
      segments.push_back(segment);
    }
    parts_ = uncovered_segment_parts(segments, 1e-7 * h);
  }
  // The parts of face t's longest edge to scan (t must be a collinear face).
  std::span<const std::array<Vec3d, 2>> parts_of(std::uint32_t t) const {
    const std::size_t i = std::size_t(std::lower_bound(faces_.begin(), faces_.end(), t) - faces_.begin());
    return {parts_.parts.data() + parts_.offsets[i], parts_.parts.data() + parts_.offsets[i + 1]};
  }

 private:
  std::vector<std::uint32_t> faces_;  // ascending
  SegmentParts parts_;
};

// The cylinder of radius W h about segment [a, b] between its end planes (a degenerate face's).
void scan_cylinder(const Vec3d& a, const Vec3d& b, std::uint32_t t, const TriangleFrame& tf, Scanner& scanner) {
  const Vec3d axis = unit(b - a);
  if (length(axis) == 0.0) return;  // a rounding-length part: its neighbours' slack covers it
  const double r = scanner.radius(), eps = scanner.slack();
  Polyhedron p;
  p.add_through(axis * -1.0, a, eps);
  p.add_through(axis, b, eps);
  const Vec3d e{r + eps, r + eps, r + eps};
  p.lo = min(a, b) - e;
  p.hi = max(a, b) + e;
  scanner.scan(p, t, tf.n, tf.plane_margin);
}

// Thin wedges (nearly coplanar neighbours: smooth, densely triangulated surfaces) are scanned as
// part of the face's prism, its edge planes moved out by the wedges' reach: a wedge's point x =
// p + a m_k + b n (p on edge k, 0 <= a <= reach) has (x - v_j) . m_j <= a |m_k . m_j| <= reach
// for every edge j, and |b| <= r. A wedge polyhedron's box mostly misses it (slanted slivers),
// so its columns cost far more than the prism's extra rim. Not for faces with an angle under
// ~18 degrees, whose offset corners would move far.
constexpr double kMaxWedgeCover = 0.25;  // voxels (measured: 1 and a tenth of the shortest edge gain no more)

void scan_triangle_features(const TriangleMesh& mesh, const WeldedAdjacency& adj, const CollinearFaces& collinear,
                            std::uint32_t t, Scanner& scanner) {
  const TriangleFrame tf = triangle_frame(mesh, t, scanner.radius(), scanner.voxel_size());
  EdgeWedge wedges[3];
  for (int k = 0; k < 3; ++k) wedges[k] = edge_wedge(mesh, adj, tf, t, k);
  bool covered[3] = {false, false, false};
  double cover = 0.0;
  if (tf.flat) {
    bool sharp = false;
    for (int k = 0; k < 3; ++k) sharp |= 1.0 + dot(tf.m[(k + 2) % 3], tf.m[k]) < 0.05;
    const double r = scanner.radius() + scanner.slack();
    for (int k = 0; k < 3 && !sharp; ++k) {
      const double reach = wedge_reach(tf, k, wedges[k], r);
      if (reach > kMaxWedgeCover * scanner.voxel_size()) continue;
      covered[k] = true;
      cover = std::max(cover, reach + 2 * scanner.slack());
    }
    scan_prism(tf, t, cover, scanner);
  } else if (const int longest = collinear_longest_edge(tf.v, scanner.voxel_size()); longest >= 0) {
    // A degenerate face whose vertices lie within 1e-6 h of its longest edge's line: that
    // edge's cylinder holds its closest points to within that (the shorter edges are on it),
    // less the parts lower-numbered collinear faces scan (CollinearFaces).
    for (int k = 0; k < 3; ++k) covered[k] = true;
    for (const auto& [a, b] : collinear.parts_of(t)) scan_cylinder(a, b, t, tf, scanner);
  }
  for (int k = 0; k < 3; ++k)
    if (!covered[k]) scan_wedge(tf, t, k, wedges[k], scanner);
  for (int k = 0; k < 3; ++k) scan_cone(mesh, adj, tf, t, k, scanner);
}

}  // namespace

CharacteristicScanResult characteristic_scan(const TriangleMesh& mesh, const std::vector<Coord>& shell_bricks,
                                             const CharacteristicScanOptions& options) {
  CharacteristicScanResult result;
  const int reach = int(std::ceil((options.frame.half_width + 1.0) / kBrickDim));
  const BrickSet set = dilate_bricks(shell_bricks, reach);
  MinField field(set);
  const WeldedAdjacency adj = build_adjacency(mesh);
  const CollinearFaces collinear(mesh, options.frame.voxel_size);
  std::atomic<std::uint64_t> evaluations{0}, polyhedra{0};
  const std::size_t nt = mesh.triangles.size(), batch = 1 << 16;
  for (std::size_t start = 0; start < nt; start += batch) {
    const std::size_t end = std::min(nt, start + batch);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(start, end, 64), [&](const tbb::blocked_range<std::size_t>& range) {
      Scanner scanner(mesh, field, options.frame);
      for (std::size_t t = range.begin(); t != range.end(); ++t)
        scan_triangle_features(mesh, adj, collinear, std::uint32_t(t), scanner);
      evaluations += scanner.evaluations;
      polyhedra += scanner.polyhedra;
    });
    options.progress.step(double(end) / double(nt), "characteristic scan");
  }
  result.evaluations = evaluations.load();
  result.polyhedra = polyhedra.load();
  result.odd_edges = adj.odd_edges;
  ClosestTriangleField& out = result.field;
  out.bricks = set.bricks;
  resize_with_huge_pages(out.distance, field.size());  // every cell written below
  resize_with_huge_pages(out.owner, field.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, field.size(), 1 << 14), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const std::uint64_t value = field.load(i);
      const bool empty = value == MinField::kEmpty;
      out.distance[i] = empty ? std::numeric_limits<float>::infinity() : std::bit_cast<float>(std::uint32_t(value >> 32));
      out.owner[i] = empty ? kNoTriangle : std::uint32_t(value);
    }
  });
  return result;
}

}  // namespace levelset
