// Test helpers: small triangle meshes with known geometry.
#pragma once

#include <cmath>
#include <map>
#include <numbers>
#include <utility>

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

// Icosphere: icosahedron subdivided `levels` times, vertices projected on the sphere.
inline TriangleMesh icosphere(const Vec3d& c, double r, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<std::uint32_t, 3>> f = {
      {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
      {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (auto& p : v) p = p / length(p);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      Vec3d p = (v[a] + v[b]) * 0.5;
      v.push_back(p / length(p));
      return mid[key] = std::uint32_t(v.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> g;
    for (const auto& tri : f) {
      const std::uint32_t a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), cc = midpoint(tri[2], tri[0]);
      g.push_back({tri[0], a, cc});
      g.push_back({tri[1], b, a});
      g.push_back({tri[2], cc, b});
      g.push_back({a, b, cc});
    }
    f = std::move(g);
  }
  TriangleMesh m;
  for (const auto& p : v) m.vertices.push_back(c + p * r);
  m.triangles = std::move(f);
  return m;
}

// Exact unsigned distance to a mesh by brute force over all triangles (reference).
double brute_force_distance(const TriangleMesh& m, const Vec3d& p);

}  // namespace levelset::test
