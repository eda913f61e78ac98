#include "evolve/upwind_batch.hpp"

namespace levelset::evolve {

namespace {

// WENO5 D-u (Minus) or D+u at `count` centres. Sample j of a centre is offset j - 3, so the
// difference D(q) = u(q + 1) - u(q) is at[q + 4] - at[q + 3].
template <bool Minus>
[[gnu::always_inline]] inline void weno5_batch(const CentreSamples& s, int count, double* out) {
  auto diff = [&](int q, int k) { return double(s.at[std::size_t(q + 4)][std::size_t(k)]) - double(s.at[std::size_t(q + 3)][std::size_t(k)]); };
  // D-: D(-3) .. D(1), farthest upwind first; D+: D(2) .. D(-2).
  auto parts = [&](int k) {
    return Minus ? detail::weno5_parts(diff(-3, k), diff(-2, k), diff(-1, k), diff(0, k), diff(1, k))
                 : detail::weno5_parts(diff(2, k), diff(1, k), diff(0, k), diff(-1, k), diff(-2, k));
  };
  double sum[kBrickVoxels];
  for (int k = 0; k < count; ++k) {
    double num;
    detail::weno5_weighted(parts(k), num, sum[k]);
    out[k] = num / sum[k];
  }
  for (int k = 0; k < count; ++k)
    if (!detail::weno5_sum_usable(sum[k])) out[k] = detail::weno5_plain(parts(k));
}

}  // namespace

// Built for three instruction sets, picked when the program loads (each takes the same IEEE
// operations in the same order, without contraction: the results do not depend on which).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
void one_sided_batch(const CentreSamples& samples, int count, Scheme scheme, double* minus, double* plus) {
  if (scheme != Scheme::Weno5) {
    for (int k = 0; k < count; ++k) {
      float c[CentreSamples::kCount];
      for (int j = 0; j < CentreSamples::kCount; ++j) c[j] = samples.at[std::size_t(j)][std::size_t(k)];
      if (minus) minus[k] = one_side(c + kStencilReach, 1, scheme, true);
      if (plus) plus[k] = one_side(c + kStencilReach, 1, scheme, false);
    }
    return;
  }
  if (minus) weno5_batch<true>(samples, count, minus);
  if (plus) weno5_batch<false>(samples, count, plus);
}

}  // namespace levelset::evolve
