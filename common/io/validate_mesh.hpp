// validate_mesh: the checks every algorithm runs on a TriangleMesh it did not read itself.
//
// Throws Error{NonFinite} naming the first vertex with a NaN or Inf coordinate and
// Error{InvalidArgument} naming the first triangle with a vertex index out of range.
// Cost: O(V + F). Thread-safe.
#pragma once

#include "io/triangle_mesh.hpp"

namespace levelset {

void validate_mesh(const TriangleMesh& mesh);

}  // namespace levelset
