#include "evolve/gradient_batch.hpp"

#include <cmath>

namespace levelset::evolve {

// Built for three instruction sets, picked when the program loads (the same IEEE operations
// in the same order, without contraction: the results do not depend on which).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
void central_gradient_norms(const float* centre, std::ptrdiff_t stride_y, std::ptrdiff_t stride_z, double h,
                            double* out) {
  const double scale = 0.5 / h;
  for (int z = 0; z < 8; ++z) {
    for (int y = 0; y < 8; ++y) {
      const float* v = centre + y * stride_y + z * stride_z;
      double* o = out + 8 * (y + 8 * z);
      for (int x = 0; x < 8; ++x) {
        const double gx = (double(v[x + 1]) - double(v[x - 1])) * scale;
        const double gy = (double(v[x + stride_y]) - double(v[x - stride_y])) * scale;
        const double gz = (double(v[x + stride_z]) - double(v[x - stride_z])) * scale;
        o[x] = std::sqrt(gx * gx + gy * gy + gz * gz);
      }
    }
  }
}

}  // namespace levelset::evolve
