// One-sided derivatives for many centres at once (evolve's spatial operator): one_side
// (derivatives.hpp) for every centre, bit for bit.
//
// one_sided_batch(samples, count, scheme, minus, plus)
//   Inputs: samples.at[j][k], the sample at offset j - 3 along the line through centre k, for
//   k in [0, count), count <= kBrickVoxels (gathered by the caller: 7 samples a centre, of
//   which the scheme reads stencil_reach(scheme) on each side). minus / plus: count doubles
//   each, or null for "not wanted".
//   Output: minus[k] = D-u and plus[k] = D+u at centre k, value units per voxel, equal to
//   one_side(c, 1, scheme, true / false) on those 7 samples.
// Method: Weno5 evaluates all centres' differences, candidates, smoothness indicators and
//   weighted sums in loops without branches, which the compiler turns into vector
//   instructions (one vector division per 2-8 centres instead of a scalar one each); the rare
//   centres whose weighted sum under- or overflows take the plain form, as one_side does.
//   Upwind1 and Eno2 call one_side per centre.
// Cost: about 60 flops per centre and side (vector), no allocation. Threading: pure function.
#pragma once

#include <array>

#include "evolve/derivatives.hpp"
#include "grid/coord.hpp"

namespace levelset::evolve {

struct CentreSamples {
  static constexpr int kCount = 2 * kStencilReach + 1;
  // kBrickDim spare entries per sample: a caller may write whole brick rows of 8 and count
  // only the active ones (axis_lines' row gather).
  std::array<std::array<float, kBrickVoxels + kBrickDim>, kCount> at;
};

void one_sided_batch(const CentreSamples& samples, int count, Scheme scheme, double* minus, double* plus);

}  // namespace levelset::evolve
