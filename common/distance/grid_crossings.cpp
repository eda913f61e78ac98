#include "distance/grid_crossings.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "distance/exact_predicates.hpp"

namespace levelset {

namespace {

inline double abs_of(double v) {
  return v < 0.0 ? -v : v;
}
inline int sign_of(double v) {
  return v > 0.0 ? 1 : (v < 0.0 ? -1 : 0);
}

// orient2d(a, b, P) with P = p - (du, dv) equals orient2d(a, b, p) + du (bv - av) + dv (au - bu);
// the larger infinitesimal decides first.
inline int tie_2d(double au, double av, double bu, double bv, bool u_first) {
  const int su = sign_of(bv - av);
  const int sv = sign_of(au - bu);
  return u_first ? (su != 0 ? su : sv) : (sv != 0 ? sv : su);
}

// One edge function of the 2D test, in Shewchuk's operation order so that its value and
// magnitude also feed the 3D filter as the cofactor of the opposite corner.
struct EdgeValue {
  double value;
  double magnitude;  // |left| + |right|
  int sign;          // exact, perturbed: never 0 for a non-degenerate projected edge
};

inline EdgeValue edge_value(double au, double av, double bu, double bv, double pu, double pv,
                            bool u_first) {
  const double left = (au - pu) * (bv - pv);
  const double right = (av - pv) * (bu - pu);
  EdgeValue e{left - right, abs_of(left) + abs_of(right), 0};
  const double bound = kOrient2dErrorBound * e.magnitude;
  if (e.value > bound) {
    e.sign = 1;
  } else if (-e.value > bound) {
    e.sign = -1;
  } else {
    e.sign = orient2d_exact(au, av, bu, bv, pu, pv);
    if (e.sign == 0) e.sign = tie_2d(au, av, bu, bv, u_first);
  }
  return e;
}

// Everything one line-triangle hit needs to place its crossing along axis w.
struct Hit {
  Vec3d a, b, c;            // corners in (u, v, w) coordinates
  double pu, pv;            // the line
  EdgeValue ebc, eca, eab;  // cofactors of a, b, c
  int tie;                  // sign of orient3d at a perturbed point exactly on the plane
};

// Exact sign of orient3d(a, b, c, P_m) at the perturbed centre m on the line: > 0 when the
// centre lies behind the triangle.
inline int side(const Hit& h, double m, bool& on_plane) {
  const double adw = h.a.z - m, bdw = h.b.z - m, cdw = h.c.z - m;
  const double det = adw * h.ebc.value + bdw * h.eca.value + cdw * h.eab.value;
  const double permanent =
      h.ebc.magnitude * abs_of(adw) + h.eca.magnitude * abs_of(bdw) + h.eab.magnitude * abs_of(cdw);
  const double bound = kOrient3dErrorBound * permanent;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  const int s = orient3d_exact(h.a, h.b, h.c, Vec3d{h.pu, h.pv, m});
  if (s != 0) return s;
  on_plane = true;
  return h.tie;
}


// The triangle's corners in the (u, v, w) frame of axis w, with its tie sign.
inline Hit axis_frame(const GridTriangle& t, int w) {
  const int u = (w + 1) % 3, v = (w + 2) % 3;
  Hit h;
  h.a = {t.corner[0][u], t.corner[0][v], t.corner[0][w]};
  h.b = {t.corner[1][u], t.corner[1][v], t.corner[1][w]};
  h.c = {t.corner[2][u], t.corner[2][v], t.corner[2][w]};
  h.tie = t.normal_sign[0] != 0 ? t.normal_sign[0]
                                : (t.normal_sign[1] != 0 ? t.normal_sign[1] : t.normal_sign[2]);
  return h;
}

// Does the perturbed line (pu, pv) along w hit the triangle (its projection, normal sign
// sigma != 0)? Fills the edge values `side` needs.
inline bool line_hits(Hit& h, double pu, double pv, int sigma, bool u_first) {
  h.pu = pu;
  h.pv = pv;
  h.eab = edge_value(h.a.x, h.a.y, h.b.x, h.b.y, pu, pv, u_first);
  if (h.eab.sign != sigma) return false;
  h.ebc = edge_value(h.b.x, h.b.y, h.c.x, h.c.y, pu, pv, u_first);
  if (h.ebc.sign != sigma) return false;
  h.eca = edge_value(h.c.x, h.c.y, h.a.x, h.a.y, pu, pv, u_first);
  return h.eca.sign == sigma;
}

// Is (pu, pv) inside the triangle's projected bounding box (inclusive)?
inline bool in_projected_box(const Hit& h, double pu, double pv) {
  return pu >= std::min({h.a.x, h.b.x, h.c.x}) && pu <= std::max({h.a.x, h.b.x, h.c.x}) &&
         pv >= std::min({h.a.y, h.b.y, h.c.y}) && pv <= std::max({h.a.y, h.b.y, h.c.y});
}

}  // namespace

std::vector<Vec3d> to_grid_vertices(const TriangleMesh& mesh, const GridFrame& frame) {
  const std::size_t nv = mesh.vertices.size();
  std::vector<Vec3d> g(nv);
  const double h = frame.voxel_size;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, 4096), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) g[i] = (mesh.vertices[i] - frame.origin) / h;
  });
  return g;
}

GridTriangle make_grid_triangle(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  GridTriangle t;
  t.corner = {a, b, c};
  for (int w = 0; w < 3; ++w) {
    const int u = (w + 1) % 3, v = (w + 2) % 3;
    t.normal_sign[w] = std::int8_t(orient2d_sign(a[u], a[v], b[u], b[v], c[u], c[v]));
  }
  return t;
}

std::vector<GridTriangle> to_grid_triangles(const TriangleMesh& mesh, std::span<const Vec3d> g) {
  const std::size_t nt = mesh.triangles.size();
  std::vector<GridTriangle> out(nt);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nt, 1024), [&](const auto& r) {
    for (std::size_t t = r.begin(); t != r.end(); ++t) {
      const auto& f = mesh.triangles[t];
      out[t] = make_grid_triangle(g[f[0]], g[f[1]], g[f[2]]);
    }
  });
  return out;
}

void brick_crossings(std::span<const GridTriangle> triangles, std::span<const std::uint32_t> ids,
                     const Coord& brick, const LineSet& lines, BrickCrossings& out) {
  const Coord o = brick_origin(brick);
  for (std::uint32_t id : ids) {
    const GridTriangle& t = triangles[id];
    // Triangles listed for the margin but missing the brick's voxel-centre box cross none of
    // its edges.
    {
      bool misses = false;
      for (int a = 0; a < 3 && !misses; ++a) {
        const double lo = double(o[a]), hi = double(o[a] + kBrickDim - 1);
        misses = std::max({t.corner[0][a], t.corner[1][a], t.corner[2][a]}) < lo ||
                 std::min({t.corner[0][a], t.corner[1][a], t.corner[2][a]}) > hi;
      }
      if (misses) continue;
    }
    for (int w = 0; w < 3; ++w) {
      const int sigma = t.normal_sign[w];
      if (sigma == 0 || lines[w] == 0) continue;
      const int u = (w + 1) % 3, v = (w + 2) % 3;
      // Global x > y > z infinitesimal order, seen in this axis's (u, v) plane.
      const bool u_first = w != 1;
      Hit h = axis_frame(t, w);
      const double wlo = double(o[w]), whi = double(o[w] + kBrickDim - 1);
      if (std::max({h.a.z, h.b.z, h.c.z}) < wlo || std::min({h.a.z, h.b.z, h.c.z}) > whi) continue;
      // Lines of this brick inside the projected bounding box.
      const double umin = std::max(std::ceil(std::min({h.a.x, h.b.x, h.c.x})), double(o[u]));
      const double umax =
          std::min(std::floor(std::max({h.a.x, h.b.x, h.c.x})), double(o[u] + kBrickDim - 1));
      const double vmin = std::max(std::ceil(std::min({h.a.y, h.b.y, h.c.y})), double(o[v]));
      const double vmax =
          std::min(std::floor(std::max({h.a.y, h.b.y, h.c.y})), double(o[v] + kBrickDim - 1));
      if (umin > umax || vmin > vmax) continue;
      const int ju0 = int(umin) - o[u], ju1 = int(umax) - o[u];
      const int jv0 = int(vmin) - o[v], jv1 = int(vmax) - o[v];
      for (int jv = jv0; jv <= jv1; ++jv) {
        for (int ju = ju0; ju <= ju1; ++ju) {
          if (!((lines[w] >> (ju + 8 * jv)) & 1u)) continue;
          if (!line_hits(h, double(o[u] + ju), double(o[v] + jv), sigma, u_first)) continue;
          // Centre m is before the crossing (going +w) when side(m) == sigma. Every probed
          // centre found exactly on the plane lies on the triangle (the line hits it there).
          std::uint8_t on = 0;  // bit e: local centre e exactly on the triangle
          auto side = [&](int e) {
            bool tie = false;
            const int sd = levelset::side(h, wlo + e, tie);
            if (tie) on |= std::uint8_t(1u << e);
            return sd;
          };
          int lo = 0, hi = kBrickDim - 1;
          const int s0 = side(lo), s7 = side(hi);
          auto mark_on_surface = [&] {
            for (int e = 0; e < kBrickDim; ++e) {
              if (!((on >> e) & 1u)) continue;
              Coord cell;
              cell[u] = ju;
              cell[v] = jv;
              cell[w] = e;
              out.on_surface.set(local_index(cell.x, cell.y, cell.z));
            }
          };
          if (s0 != sigma || s7 == sigma) {
            mark_on_surface();
            continue;
          }
          // Guess from the plane, then bisect: side(lo) == sigma, side(hi) != sigma.
          const double denom = h.ebc.value + h.eca.value + h.eab.value;
          const double s =
              (h.a.z * h.ebc.value + h.b.z * h.eca.value + h.c.z * h.eab.value) / denom - wlo;
          if (s > 0.0 && s < double(kBrickDim - 1)) {
            const int g = int(s);
            if (g > lo) (side(g) == sigma ? lo : hi) = g;
            if (g + 1 > lo && g + 1 < hi) (side(g + 1) == sigma ? lo : hi) = g + 1;
          }
          while (hi - lo > 1) {
            const int mid = (lo + hi) / 2;
            (side(mid) == sigma ? lo : hi) = mid;
          }
          mark_on_surface();
          out.delta[w][ju + 8 * jv][lo] -= sigma;
          Coord cell;
          cell[u] = ju;
          cell[v] = jv;
          cell[w] = lo;
          out.near.set(local_index(cell.x, cell.y, cell.z));
          cell[w] = lo + 1;
          out.near.set(local_index(cell.x, cell.y, cell.z));
        }
      }
    }
  }
}

int edge_jump(std::span<const GridTriangle> triangles, std::span<const std::uint32_t> ids_a,
              std::span<const std::uint32_t> ids_b, const Coord& voxel, int w) {
  const int u = (w + 1) % 3, v = (w + 2) % 3;
  const bool u_first = w != 1;
  const double pu = voxel[u], pv = voxel[v], m = voxel[w];
  int jump = 0;
  auto add = [&](std::uint32_t id) {
    const GridTriangle& t = triangles[id];
    const int sigma = t.normal_sign[w];
    if (sigma == 0) return;
    Hit h = axis_frame(t, w);
    if (std::max({h.a.z, h.b.z, h.c.z}) < m || std::min({h.a.z, h.b.z, h.c.z}) > m + 1.0) return;
    if (!in_projected_box(h, pu, pv) || !line_hits(h, pu, pv, sigma, u_first)) return;
    bool on_plane = false;
    if (side(h, m, on_plane) == sigma && side(h, m + 1.0, on_plane) != sigma) jump -= sigma;
  };
  // Both lists are sorted: walk them as one set (a triangle in both counts once).
  std::size_t i = 0, j = 0;
  while (i < ids_a.size() || j < ids_b.size()) {
    if (j == ids_b.size() || (i < ids_a.size() && ids_a[i] < ids_b[j])) {
      add(ids_a[i++]);
    } else {
      if (i < ids_a.size() && ids_a[i] == ids_b[j]) ++i;
      add(ids_b[j++]);
    }
  }
  return jump;
}

int ray_winding(std::span<const GridTriangle> triangles, const Coord& voxel) {
  const double pu = voxel.y, pv = voxel.z, m = voxel.x;
  int winding = 0;
  for (const GridTriangle& t : triangles) {
    const int sigma = t.normal_sign[0];
    if (sigma == 0) continue;
    if (std::max({t.corner[0].x, t.corner[1].x, t.corner[2].x}) < m) continue;
    Hit h = axis_frame(t, 0);
    if (!in_projected_box(h, pu, pv) || !line_hits(h, pu, pv, sigma, true)) continue;
    bool on_plane = false;
    if (side(h, m, on_plane) == sigma) winding += sigma;
  }
  return winding;
}

}  // namespace levelset
