#include "io/validate_mesh.hpp"

#include <string>

#include "core/error.hpp"

namespace levelset {

void validate_mesh(const TriangleMesh& mesh) {
  const std::size_t nv = mesh.vertices.size();
  for (std::size_t i = 0; i < nv; ++i)
    if (!isfinite(mesh.vertices[i]))
      throw Error(ErrorCode::NonFinite, "vertex " + std::to_string(i), "non-finite coordinate");
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (std::uint32_t v : mesh.triangles[t])
      if (v >= nv)
        throw Error(ErrorCode::InvalidArgument, "triangle " + std::to_string(t),
                    "vertex index " + std::to_string(v) + " out of range");
}

}  // namespace levelset
