// TriangleMesh and PointCloud: the flat arrays that readers produce and hot code consumes.
//
// A mesh is a triangle soup with shared vertices: no connectivity structure is imposed,
// so non-manifold, open, self-intersecting and inconsistently oriented input survives
// reading unchanged (the distance code must see it as it is).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/bbox.hpp"
#include "core/vec3.hpp"

namespace levelset {

struct TriangleMesh {
  std::vector<Vec3d> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // indices into vertices

  BBox bounds() const {
    BBox b;
    for (const auto& v : vertices) b.extend(v);
    return b;
  }
};

struct PointCloud {
  std::vector<Vec3d> points;
  std::vector<Vec3d> normals;  // empty, or one per point

  bool has_normals() const { return !normals.empty(); }
  BBox bounds() const {
    BBox b;
    for (const auto& p : points) b.extend(p);
    return b;
  }
};

}  // namespace levelset
