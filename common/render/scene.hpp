// SceneData and its CPU-side preparation for the GPU (no GL here; scene_renderer.hpp uploads).
//
// SceneData: what a frame shows: a surface mesh (world units, indexed triangles), a point cloud
//   and, for the overlays (field points, vectors, curvature, band boundary, slice, volume), the
//   narrow band the mesh came from. Any part may be empty / null.
// prepare_mesh: float positions relative to `origin`, area-weighted vertex normals, the index
//   list and, above options.moving_triangle_budget triangles, a simplified index list over the
//   same vertices (meshoptimizer: meshopt_simplify with relative error simplify_error, then
//   meshopt_simplifySloppy when that cannot reach the budget) drawn while the view is moving.
// motion_indices: that simplified index list alone (empty within the budget), for a caller that
//   makes it off its drawing thread (SceneData::simplified) so that set_scene does not.
// scene_bounds: the box the camera fits: the mesh and the points; the band's active box only
//   when both are empty.
// Cost: prepare_mesh O(triangles), plus the simplification (~1 s for 1M triangles) when above
//   the budget. Threading: pure functions. Errors: Error{InvalidArgument} for a triangle index
//   out of range.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/bbox.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::render {

struct SceneData {
  TriangleMesh mesh;
  PointCloud points;
  std::shared_ptr<const NarrowBand> band;
  std::shared_ptr<const NarrowBand> roi;  // a stored region of influence (thesis table 4.1 D, Point(ROI))
  // The mesh's simplified copy for moving views, made beforehand by motion_indices with the
  // renderer's options; null: set_scene makes it.
  std::shared_ptr<const std::vector<std::uint32_t>> simplified;
};

struct SceneOptions {
  std::size_t moving_triangle_budget = 200000;  // meshes above it get a simplified copy
  float simplify_error = 0.01f;                 // relative to the mesh's extent
  std::size_t max_band_points = 4000000;        // field / vector / boundary voxels (strided above)
  int max_volume_side = 512;                    // texels per side of the slice / volume texture
};

struct MeshArrays {
  std::vector<float> positions, normals;  // xyz per vertex, relative to the origin
  std::vector<std::uint32_t> indices;     // 3 per triangle
  std::vector<std::uint32_t> simplified;  // empty when the mesh is within the budget
};

BBox scene_bounds(const SceneData& scene);
// `simplified`: motion_indices(mesh, options) made beforehand, or null to make it here.
MeshArrays prepare_mesh(const TriangleMesh& mesh, const Vec3d& origin, const SceneOptions& options,
                        const std::vector<std::uint32_t>* simplified = nullptr);
std::vector<std::uint32_t> motion_indices(const TriangleMesh& mesh, const SceneOptions& options);

}  // namespace levelset::render
