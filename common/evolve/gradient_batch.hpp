// Central-difference gradient norms of a whole brick at once (evolve's spatial operator, the
// parabolic part's |grad u|, the drift near the front and the speeds that read it).
//
// central_gradient_norms(centre, stride_y, stride_z, h, out)
//   Inputs: centre, the tile sample of brick-local voxel (0, 0, 0) in a tile with unit x
//   stride and strides stride_y, stride_z, holding at least one sample beyond the brick on
//   every side (inactive samples hold their +-W h fill: finite); h the voxel size.
//   Output: out[x + 8 (y + 8 z)] = |g| for every voxel of the brick, active or not, with g =
//   (u(x+1) - u(x-1), u(y+1) - u(y-1), u(z+1) - u(z-1)) * (0.5 / h), each difference in double
//   and |g| = sqrt(gx gx + gy gy + gz gz): the scalar form's operations in its order, so the
//   values equal it bit for bit.
// Method: row by row, 8 voxels at a time with contiguous loads (no gathers), which the
//   compiler turns into vector code; inactive voxels cost a little extra work where the band's
//   bricks are mostly full.
// Cost: 512 gradients (~10 flops each) per call, no allocation. Threading: pure function.
#pragma once

#include <cstddef>

namespace levelset::evolve {

void central_gradient_norms(const float* centre, std::ptrdiff_t stride_y, std::ptrdiff_t stride_z, double h,
                            double* out);

}  // namespace levelset::evolve
