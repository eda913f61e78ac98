// Test and benchmark helpers: 1-to-4 subdivision of a triangle mesh, and subdividing until a
// mesh has about one triangle per surface voxel (scans, meshes extracted from grids).
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <utility>

#include "io/triangle_mesh.hpp"

namespace levelset::test {

// Every triangle split into four at its edge midpoints (shared through an edge map).
inline TriangleMesh subdivide(const TriangleMesh& in) {
  TriangleMesh out;
  out.vertices = in.vertices;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
  auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
    const auto key = std::minmax(a, b);
    const auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    out.vertices.push_back((in.vertices[a] + in.vertices[b]) * 0.5);
    const auto id = std::uint32_t(out.vertices.size() - 1);
    mid.emplace(key, id);
    return id;
  };
  for (const auto& f : in.triangles) {
    const std::uint32_t ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
    out.triangles.push_back({f[0], ab, ca});
    out.triangles.push_back({ab, f[1], bc});
    out.triangles.push_back({ca, bc, f[2]});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

inline double surface_area(const TriangleMesh& m) {
  double area = 0;
  for (const auto& f : m.triangles)
    area += 0.5 * length(cross(m.vertices[f[1]] - m.vertices[f[0]], m.vertices[f[2]] - m.vertices[f[0]]));
  return area;
}

// Subdivided until it has at least as many triangles as surface voxels (area / h^2).
inline TriangleMesh densify(TriangleMesh mesh, double voxel_size) {
  const double surface_voxels = surface_area(mesh) / (voxel_size * voxel_size);
  while (double(mesh.triangles.size()) < surface_voxels) mesh = subdivide(mesh);
  return mesh;
}

}  // namespace levelset::test
