// bin_triangles_to_bricks: which triangles come within a distance of which 8^3 brick.
//
// Inputs: a triangle mesh (world units), a grid frame (voxel size h, origin), and a margin
//   (world units, >= 0). A brick's box is the box spanned by its 512 voxel centres.
// Output: every brick whose box lies within `margin` of at least one triangle, sorted by brick
//   key, each with the indices of those triangles in increasing order (CSR layout). Bricks are
//   found by scan-converting each triangle's margin-inflated slab (plane distance <= margin)
//   column by column at brick resolution, then culled by the exact box-triangle distance bound;
//   the lists are a superset of the triangles truly within the margin only where the exact
//   test is conservative (it never misses one).
// Cost: O(triangles * bricks touched per triangle) to make the pairs, O(pairs) expected to
//   group them by brick (a hash table of the distinct bricks) and O(B log B) to order the B
//   distinct bricks.
// Threading: TBB; the result is identical for any thread count.
// Errors: Error{LimitExceeded} when a triangle would touch more than options.max_pairs
//   brick-triangle pairs in total (a mesh far larger than the grid allows) or indices leave the
//   index range; Error{NonFinite} for non-finite vertices; Error{InvalidArgument} for
//   triangle indices out of range. Cancellable through the progress hook.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

struct BrickTriangleLists {
  std::vector<Coord> bricks;             // sorted by brick_key
  std::vector<std::uint64_t> offsets;    // bricks.size() + 1 entries
  std::vector<std::uint32_t> triangles;  // triangles of brick i: [offsets[i], offsets[i+1])
  double margin = 0.0;  // world units: every triangle within it of a listed brick is listed
};

struct BinTrianglesOptions {
  GridFrame frame;
  double margin = 0.0;  // world units
  std::uint64_t max_pairs = std::uint64_t{1} << 31;
  ProgressHook progress;
};

BrickTriangleLists bin_triangles_to_bricks(const TriangleMesh& mesh, const BinTrianglesOptions& options);

}  // namespace levelset
