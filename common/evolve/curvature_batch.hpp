// Mean and Gaussian curvature for the active voxels of one brick at once (evolve's spatial
// operator): mean_gauss_curvature_at (curvature.hpp) for every voxel, bit for bit.
//
// mean_gauss_curvature_brick(tile, origin, stride, active, at, h, mean, gauss)
//   Inputs: tile, a dense float array with the given strides (x fastest: stride[0] = 1), holding the brick and at least
//   one voxel around it; origin, the tile index of brick-local voxel (0, 0, 0); active, the
//   brick's voxels to evaluate, taken in ascending local index (x fastest, then y, z); at[k],
//   the tile index of the centre whose curvature active voxel k takes (its own index, another
//   voxel's whose 19-point stencil lies in the tile, or -1 for none); h the voxel size.
//   Output: mean[k], gauss[k] as floats (H = k1 + k2 and K = k1 k2, curvature.hpp's
//   conventions); 0 for at[k] < 0 and for |grad u| <= kMinGradNorm.
//   Error{InvalidArgument} when stride[0] != 1.
// Method: a brick row whose voxels take their own curvature is evaluated for its 8 voxels at
//   once: each of the 19 stencil samples is 8 consecutive tile values, widened to double, and
//   one loop without branches does mean_gauss_curvature_at's arithmetic in the same order,
//   which the compiler turns into vector instructions. Voxels taking another centre's
//   curvature (near the band's edge) read that centre's lane where its row was evaluated
//   (the centre lies in the brick and takes its own curvature: 83 % of them on Table 5.1's
//   sphere), else use mean_gauss_curvature_at itself.
// Cost: about 90 flops per row voxel (vector), no allocation. Threading: pure function.
#pragma once

#include <cstddef>

#include "grid/brick_mask.hpp"
#include "grid/coord.hpp"

namespace levelset::evolve {

void mean_gauss_curvature_brick(const float* tile, std::ptrdiff_t origin, const std::ptrdiff_t stride[3],
                                const BrickMask& active, const int* at, double h, float* mean, float* gauss);

}  // namespace levelset::evolve
