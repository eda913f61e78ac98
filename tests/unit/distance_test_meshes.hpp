// Test meshes for the distance code: icosphere, torus, open hemisphere, subdivided boxes and
// octahedra on grid points, random face flips, CGAL sample meshes, brute-force references.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/vec3.hpp"
#include "geometry/point_triangle.hpp"
#include "io/mesh_reader.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::test {

// Axis-aligned box [lo, hi] as 12 outward-oriented triangles.
inline TriangleMesh box_mesh(const Vec3d& lo, const Vec3d& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

// Appends part's vertices and triangles to `into` (faces reversed when asked): soups of parts.
inline void append_mesh(TriangleMesh& into, const TriangleMesh& part, bool reversed = false) {
  const auto base = std::uint32_t(into.vertices.size());
  into.vertices.insert(into.vertices.end(), part.vertices.begin(), part.vertices.end());
  for (const auto& f : part.triangles)
    into.triangles.push_back(reversed ? std::array<std::uint32_t, 3>{f[0] + base, f[2] + base, f[1] + base}
                                      : std::array<std::uint32_t, 3>{f[0] + base, f[1] + base, f[2] + base});
}

// Exact unsigned distance to a mesh by brute force over all triangles (reference).
inline double brute_force_distance(const TriangleMesh& m, const Vec3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : m.triangles)
    best = std::min(best, closest_point_on_triangle(p, m.vertices[t[0]], m.vertices[t[1]],
                                                    m.vertices[t[2]]).distance_squared);
  return std::sqrt(best);
}

// CGAL's data/meshes: $LEVELSET_CGAL_DATA when set, else the data install-deps.sh unpacked.
inline std::filesystem::path cgal_meshes_dir() {
  const char* env = std::getenv("LEVELSET_CGAL_DATA");
  return (env != nullptr && *env != '\0' ? std::filesystem::path(env) : std::filesystem::path(LEVELSET_CGAL_DATA)) /
         "meshes";
}

inline TriangleMesh load_cgal_mesh(const std::string& name) {
  return read_mesh(std::string(LEVELSET_CGAL_DATA) + "/meshes/" + name).mesh;
}

// Icosahedron subdivided `levels` times, projected to the sphere; outward orientation.
// Faces: 20 * 4^levels.
inline TriangleMesh icosphere(int levels, double radius = 1.0, Vec3d center = {}) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                          {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                          {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<std::uint32_t, 3>> f = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& p : v) p = p / length(p);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      Vec3d m = (v[a] + v[b]) * 0.5;
      v.push_back(m / length(m));
      return mid[key] = std::uint32_t(v.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> g;
    for (const auto& tri : f) {
      const std::uint32_t a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]),
                          c = midpoint(tri[2], tri[0]);
      g.push_back({tri[0], a, c});
      g.push_back({tri[1], b, a});
      g.push_back({tri[2], c, b});
      g.push_back({a, b, c});
    }
    f = std::move(g);
  }
  TriangleMesh m;
  for (const auto& p : v) m.vertices.push_back(center + p * radius);
  m.triangles = f;
  return m;
}

// Torus about the z axis, outward orientation, nu * nv quads split in two.
inline TriangleMesh torus(double major, double minor, int nu, int nv, Vec3d center = {}) {
  TriangleMesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double a = 2 * std::numbers::pi * i / nu, b = 2 * std::numbers::pi * j / nv;
      m.vertices.push_back(center + Vec3d{(major + minor * std::cos(b)) * std::cos(a),
                                          (major + minor * std::cos(b)) * std::sin(a),
                                          minor * std::sin(b)});
    }
  auto id = [&](int i, int j) { return std::uint32_t(((i + nu) % nu) * nv + (j + nv) % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

// Upper half (z >= 0) of a UV sphere, open at z = 0, outward orientation.
inline TriangleMesh hemisphere(int rings, int segments, double radius = 1.0) {
  TriangleMesh m;
  m.vertices.push_back({0, 0, radius});
  for (int r = 1; r <= rings; ++r) {
    const double polar = 0.5 * std::numbers::pi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double az = 2 * std::numbers::pi * s / segments;
      m.vertices.push_back({radius * std::sin(polar) * std::cos(az),
                            radius * std::sin(polar) * std::sin(az), radius * std::cos(polar)});
    }
  }
  auto id = [&](int r, int s) { return std::uint32_t(1 + (r - 1) * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s) m.triangles.push_back({0, id(1, s), id(1, s + 1)});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      m.triangles.push_back({id(r, s), id(r + 1, s), id(r + 1, s + 1)});
      m.triangles.push_back({id(r, s), id(r + 1, s + 1), id(r, s + 1)});
    }
  return m;
}

// Axis-aligned box [lo, hi] with integer corners, every face cut into unit squares (in the
// given step) split along alternating diagonals; outward orientation, watertight.
inline TriangleMesh grid_box(std::array<int, 3> lo, std::array<int, 3> hi, int step = 1) {
  TriangleMesh m;
  std::map<std::array<int, 3>, std::uint32_t> index;
  auto vert = [&](std::array<int, 3> p) {
    auto it = index.find(p);
    if (it != index.end()) return it->second;
    m.vertices.push_back({double(p[0]), double(p[1]), double(p[2])});
    return index[p] = std::uint32_t(m.vertices.size() - 1);
  };
  for (int w = 0; w < 3; ++w) {
    const int u = (w + 1) % 3, v = (w + 2) % 3;  // (u, v, w) right-handed: u x v = w
    for (int side = 0; side < 2; ++side) {
      const int cw = side == 0 ? lo[w] : hi[w];
      for (int a = lo[u]; a < hi[u]; a += step)
        for (int b = lo[v]; b < hi[v]; b += step) {
          const int a1 = std::min(a + step, hi[u]), b1 = std::min(b + step, hi[v]);
          auto P = [&](int pu, int pv) {
            std::array<int, 3> p{};
            p[u] = pu;
            p[v] = pv;
            p[w] = cw;
            return vert(p);
          };
          std::uint32_t q00 = P(a, b), q10 = P(a1, b), q11 = P(a1, b1), q01 = P(a, b1);
          std::array<std::uint32_t, 3> t1, t2;
          if (((a + b) / step) % 2 == 0) {
            t1 = {q00, q10, q11};
            t2 = {q00, q11, q01};
          } else {
            t1 = {q00, q10, q01};
            t2 = {q10, q11, q01};
          }
          if (side == 0) {  // normal -w
            std::swap(t1[1], t1[2]);
            std::swap(t2[1], t2[2]);
          }
          m.triangles.push_back(t1);
          m.triangles.push_back(t2);
        }
    }
  }
  return m;
}

// Octahedron |x - cx| + |y - cy| + |z - cz| <= r with integer centre and radius, each face
// split into 4 (midpoints), outward orientation.
inline TriangleMesh grid_octahedron(std::array<int, 3> c, int r) {
  TriangleMesh m;
  const Vec3d o{double(c[0]), double(c[1]), double(c[2])};
  const double R = r;
  m.vertices = {o + Vec3d{R, 0, 0},  o + Vec3d{-R, 0, 0}, o + Vec3d{0, R, 0},
                o + Vec3d{0, -R, 0}, o + Vec3d{0, 0, R},  o + Vec3d{0, 0, -R}};
  std::vector<std::array<std::uint32_t, 3>> f;
  for (std::uint32_t x : {0u, 1u})
    for (std::uint32_t y : {2u, 3u})
      for (std::uint32_t z : {4u, 5u}) {
        std::array<std::uint32_t, 3> t{x, y, z};
        const Vec3d& a = m.vertices[t[0]];
        const Vec3d n = cross(m.vertices[t[1]] - a, m.vertices[t[2]] - a);
        if (dot(n, a - o) < 0) std::swap(t[1], t[2]);
        f.push_back(t);
      }
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
  auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
    const auto key = std::minmax(a, b);
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    m.vertices.push_back((m.vertices[a] + m.vertices[b]) * 0.5);
    return mid[key] = std::uint32_t(m.vertices.size() - 1);
  };
  for (const auto& t : f) {
    const std::uint32_t a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]),
                        d = midpoint(t[2], t[0]);
    m.triangles.push_back({t[0], a, d});
    m.triangles.push_back({t[1], b, a});
    m.triangles.push_back({t[2], d, b});
    m.triangles.push_back({a, b, d});
  }
  return m;
}

// Flips a random subset (about half) of the faces; returns which.
inline std::vector<bool> flip_random_half(TriangleMesh& m, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<bool> flipped(m.triangles.size());
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    flipped[t] = (rng() & 1u) != 0;
    if (flipped[t]) std::swap(m.triangles[t][0], m.triangles[t][1]);
  }
  return flipped;
}

// Ray parity point-in-polyhedron: crossings of the ray p + s d (s > 0) with all triangles
// (Moeller-Trumbore); d should be a generic direction.
inline bool ray_parity_inside(const TriangleMesh& m, const Vec3d& p, const Vec3d& d) {
  int hits = 0;
  for (const auto& f : m.triangles) {
    const Vec3d& a = m.vertices[f[0]];
    const Vec3d e1 = m.vertices[f[1]] - a, e2 = m.vertices[f[2]] - a;
    const Vec3d q = cross(d, e2);
    const double det = dot(e1, q);
    if (det == 0.0) continue;
    const double inv = 1.0 / det;
    const Vec3d s = p - a;
    const double u = dot(s, q) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const Vec3d r = cross(s, e1);
    const double v = dot(d, r) * inv;
    if (v < 0.0 || u + v > 1.0) continue;
    if (dot(e2, r) * inv > 0.0) ++hits;
  }
  return (hits & 1) != 0;
}

// Signed volume (times 6) of a mesh about the origin.
inline double signed_volume6(const TriangleMesh& m) {
  double v = 0.0;
  for (const auto& f : m.triangles)
    v += dot(m.vertices[f[0]], cross(m.vertices[f[1]], m.vertices[f[2]]));
  return v;
}

}  // namespace levelset::test
