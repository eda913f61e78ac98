// propagate_closest_triangles: extends exact closest-triangle distances from a thin shell
// around a triangle mesh to the whole narrow band, in O(band voxels) time.
//
// Inputs: the triangle mesh (world units, the same the shell was computed from), a shell
//   field (bricks sorted by brick_key, per voxel the unsigned distance and the closest
//   triangle, or +inf / kNoTriangle) holding the exact values of every voxel within
//   options.shell_radius voxels of the mesh, and options.frame (voxel size h, origin, band
//   half-width W in voxels).
// Output: the field over every brick the band reaches (sorted by key), with every voxel within
//   W*h of the mesh holding its distance (float of the double value) and closest triangle; all
//   other voxels +inf / kNoTriangle. Stats: layers, point-triangle evaluations, walk steps.
// Method: voxels are finalised in increasing distance, in buckets options.bucket_width voxels
//   wide (Dial's shortest paths with the exact point-triangle distance as the weight): when a
//   bucket is final, each of its non-final neighbours evaluates the closest triangles of its
//   neighbours finalised there, and keeps the best as a tentative value in a later bucket; a
//   voxel being finalised descends over the mesh (every triangle around the best one's
//   vertices, positions welded, while one is nearer). The neighbour towards a voxel's closest
//   point is nearer by more than a bucket, so it is final first. Not exact: where the distance
//   over the mesh has a basin that no finalised neighbour reached (noise, folds, triangles
//   much smaller than a voxel whose regions slip between voxel centres) a voxel keeps a
//   triangle that is slightly too far (measured on CGAL's meshes, test_cpt_propagation), and a
//   voxel at the band's rim can then be left out. Each phase reads only finalised voxels, so
//   the result is identical for any thread count.
// Cost: O(band voxels * (26 + candidates)) plus a sort of the dilated brick keys; memory 17
//   bytes per voxel of every brick within ceil((W + 1) / 8) bricks of a shell brick.
// Threading: TBB within each layer. Progress: one step per layer, cancellable.
// Errors: Error{InvalidArgument} when the shell field's arrays do not match its bricks;
//   Error{Cancelled} via the progress hook.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

inline constexpr std::uint32_t kNoTriangle = 0xffffffffu;

// Per-voxel unsigned distance and closest triangle over a sorted set of bricks.
struct ClosestTriangleField {
  std::vector<Coord> bricks;           // sorted by brick_key
  std::vector<float> distance;         // bricks.size() * kBrickVoxels; +inf: not in the band
  std::vector<std::uint32_t> owner;    // closest triangle per voxel, or kNoTriangle
};

struct PropagateOptions {
  GridFrame frame;            // h, origin, band half-width W (voxels)
  double shell_radius = 1.0;  // voxels: the shell's values are exact up to this distance
  double bucket_width = 0.3;  // voxels: voxels are finalised in distance buckets this wide
  // Then check every propagated voxel exactly (nearest-triangle queries bounded by the
  // propagated distance, and the band's rim): the result equals the exact scan's.
  bool exact = true;
  ProgressHook progress;
};

struct PropagateResult {
  ClosestTriangleField field;
  std::uint64_t layers = 0;       // distance buckets that finalised voxels
  std::uint64_t evaluations = 0;  // point-triangle distance evaluations
  std::uint64_t walk_steps = 0;   // moves to a better triangle around an edge or vertex
  std::uint64_t verified = 0;     // propagated voxels checked by the exact pass
  std::uint64_t corrected = 0;    // ... whose triangle it replaced (propagation's misses)
  std::uint64_t rim_added = 0;    // voxels within W*h that propagation had left out
};

PropagateResult propagate_closest_triangles(const TriangleMesh& mesh, ClosestTriangleField shell,
                                            const PropagateOptions& options);

}  // namespace levelset
