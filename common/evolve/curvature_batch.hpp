// Mean and Gaussian curvature for many voxels of one dense tile at once (evolve's spatial
// operator): mean_gauss_curvature_at (curvature.hpp) for every centre, bit for bit.
//
// mean_gauss_curvature_batch(tile, at, count, stride, h, mean, gauss)
//   Inputs: tile, a dense float array with the given strides; at[i], the tile index of
//   centre i (its 19-point stencil must lie in the tile), or -1 for none; h the voxel size.
//   Output: mean[i], gauss[i] as floats (H = k1 + k2 and K = k1 k2, curvature.hpp's
//   conventions); 0 for at[i] < 0 and for |grad u| <= kMinGradNorm.
// Method: the stencils are copied into per-sample rows of 64 centres, then one loop without
//   branches does the double arithmetic of mean_gauss_curvature_at in the same order, which
//   the compiler turns into vector instructions (two doubles a lane pair with SSE2).
// Cost: 19 loads and about 90 flops per centre, no allocation. Threading: pure function.
#pragma once

#include <cstddef>

namespace levelset::evolve {

void mean_gauss_curvature_batch(const float* tile, const int* at, int count, const std::ptrdiff_t stride[3], double h,
                                float* mean, float* gauss);

}  // namespace levelset::evolve
