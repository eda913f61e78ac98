#include "render/scene.hpp"

#include <string>

#include <meshoptimizer.h>

#include "core/error.hpp"

namespace levelset::render {

BBox scene_bounds(const SceneData& scene) {
  BBox box = scene.mesh.bounds();
  for (const Vec3d& p : scene.points.points) box.extend(p);
  if (box.empty() && scene.band) box = scene.band->active_world_bounds();
  return box;
}

namespace {

// meshoptimizer's simplification of an index list over float xyz positions (see the header).
std::vector<std::uint32_t> simplify(const std::vector<std::uint32_t>& indices, const std::vector<float>& positions,
                                    const SceneOptions& options) {
  const std::size_t triangles = indices.size() / 3;
  if (triangles <= options.moving_triangle_budget || options.moving_triangle_budget == 0) return {};
  const std::size_t target = options.moving_triangle_budget * 3, nv = positions.size() / 3;
  std::vector<std::uint32_t> out(indices.size());
  std::size_t n = meshopt_simplify(out.data(), indices.data(), indices.size(), positions.data(), nv, 3 * sizeof(float),
                                   target, options.simplify_error, 0, nullptr);
  if (n > target)
    n = meshopt_simplifySloppy(out.data(), indices.data(), indices.size(), positions.data(), nv, 3 * sizeof(float),
                               target, 1.0f, nullptr);
  out.resize(n);
  return out;
}

}  // namespace

std::vector<std::uint32_t> motion_indices(const TriangleMesh& mesh, const SceneOptions& options) {
  if (mesh.triangles.size() <= options.moving_triangle_budget || options.moving_triangle_budget == 0) return {};
  BBox box;
  for (const Vec3d& v : mesh.vertices) box.extend(v);
  const MeshArrays a = prepare_mesh(mesh, box.empty() ? Vec3d{} : box.center(), options, nullptr);
  return a.simplified;
}

MeshArrays prepare_mesh(const TriangleMesh& mesh, const Vec3d& origin, const SceneOptions& options,
                        const std::vector<std::uint32_t>* simplified) {
  MeshArrays a;
  const std::size_t nv = mesh.vertices.size();
  a.positions.resize(nv * 3);
  a.normals.assign(nv * 3, 0.0f);
  for (std::size_t i = 0; i < nv; ++i) {
    const Vec3d q = mesh.vertices[i] - origin;
    a.positions[3 * i] = float(q.x), a.positions[3 * i + 1] = float(q.y), a.positions[3 * i + 2] = float(q.z);
  }
  a.indices.reserve(mesh.triangles.size() * 3);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (std::uint32_t v : tri)
      if (v >= nv)
        throw Error(ErrorCode::InvalidArgument, "mesh triangle " + std::to_string(t),
                    "vertex index " + std::to_string(v) + " out of range (" + std::to_string(nv) + " vertices)");
    const Vec3d fn = cross(mesh.vertices[tri[1]] - mesh.vertices[tri[0]], mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
    for (std::uint32_t v : tri) {
      a.normals[3 * v] += float(fn.x), a.normals[3 * v + 1] += float(fn.y), a.normals[3 * v + 2] += float(fn.z);
      a.indices.push_back(v);
    }
  }
  if (simplified != nullptr) {
    for (std::uint32_t v : *simplified)
      if (v >= nv) throw Error(ErrorCode::InvalidArgument, "simplified mesh", "vertex index out of range");
    a.simplified = *simplified;
  } else {
    a.simplified = simplify(a.indices, a.positions, options);
  }
  return a;
}

}  // namespace levelset::render
