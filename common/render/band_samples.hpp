// What the overlays draw from a narrow band, computed on the CPU (no GL here).
//
// sample_band_points: every active voxel (every k-th when there are more than max_points, k
//   the smallest stride that fits) with its position relative to `origin`, its value, its
//   closest surface point (p - value * grad / |grad|, central differences; for the vectors of
//   thesis §4.9) and, separately, the band's boundary voxels (active with an inactive
//   6-neighbour). Cost: O(active voxels), ~7 accessor reads each.
// sample_dense_volume: the band on a dense box of texels (value_or_background at voxel
//   centres, every s-th voxel when the active box is larger than max_side per axis), for the
//   slice and the volume rendering. Cost: O(box voxels / s^3) accessor reads, in parallel over
//   z (TBB); 256^3 texels ~64 MiB as float.
// vertex_curvature: the mean curvature H = k1 + k2 of the band at each mesh vertex
//   (apps/band_curvature.hpp; 1 / world units), in parallel (TBB).
// Threading: pure functions of a const band (each task has its own accessor).
#pragma once

#include <cstddef>
#include <vector>

#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::render {

struct BandPoints {
  std::vector<float> positions;  // xyz per voxel, relative to the origin
  std::vector<float> values;     // world distance per voxel
  std::vector<float> closest;    // xyz per voxel, relative to the origin
  std::vector<float> boundary;   // xyz per boundary voxel, relative to the origin
};

struct DenseVolume {
  int nx = 0, ny = 0, nz = 0;
  Vec3d box_min, box_max;     // world box the texels tile (texel centres at voxel centres)
  std::vector<float> values;  // x fastest
  float background = 0;
  double voxel_size = 1;      // of the band
};

BandPoints sample_band_points(const NarrowBand& band, const Vec3d& origin, std::size_t max_points);
DenseVolume sample_dense_volume(const NarrowBand& band, int max_side);
std::vector<float> vertex_curvature(const TriangleMesh& mesh, const NarrowBand& band);

}  // namespace levelset::render
