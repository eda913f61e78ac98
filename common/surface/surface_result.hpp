// SurfaceResult: the output of the surface extractors (marching_cubes, surface_nets).
// mesh: indexed triangles in world units, oriented with normals towards the positive side;
// normals: one unit vector per vertex (level set gradient direction).
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec3.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

struct SurfaceResult {
  TriangleMesh mesh;
  std::vector<Vec3f> normals;
  std::uint64_t cells_with_surface = 0;  // cells that emitted at least one loop
  std::uint64_t extra_vertices = 0;      // loop-centre vertices (marching cubes, see header)
  double seconds = 0.0;
};

}  // namespace levelset
