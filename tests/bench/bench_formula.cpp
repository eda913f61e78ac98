// bench_formula: the compiled speed formula against the same formula hand-written in C++,
// over >= 10^7 samples in brick-sized batches of 512 (issue 6: within 1.5x).
// Formula: the thesis's mean-Gaussian speed '-sign(H)*sqrt(K+abs(K))'. Inputs: random H, K
// (fixed seed). Prints seconds for both, the ratio formula / C++ and the largest difference.
// Usage: bench_formula [--quick]   (--quick: 10^5 samples, one run, for ctest)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "bench_support.hpp"
#include "formula/formula.hpp"

namespace {

using namespace levelset;
using levelset::bench::best_of;

}  // namespace

int main(int argc, char** argv) {
  const bool quick = bench::is_quick(argc, argv);
  const std::size_t n = quick ? 100000 : 10240000;
  const int runs = quick ? 1 : 5;
  std::vector<float> H(n), K(n), a(n), b(n);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  for (std::size_t i = 0; i < n; ++i) {
    H[i] = u(rng);
    K[i] = u(rng);
  }
  const char* text = "-sign(H)*sqrt(K+abs(K))";
  return bench::run_bench("bench_formula", "results differ", [&] {
    const formula::Program p = formula::compile(text);
    formula::Workspace ws;
    const double t_formula = best_of(runs, [&] {
      std::array<const float*, formula::kVarCount> in{};
      for (std::size_t s = 0; s < n; s += formula::kMaxSamples) {
        in[int(formula::Var::H)] = H.data() + s;
        in[int(formula::Var::K)] = K.data() + s;
        p.evaluate(in, int(std::min<std::size_t>(formula::kMaxSamples, n - s)), a.data() + s, ws);
      }
    });
    const double t_cpp = best_of(runs, [&] {
      for (std::size_t i = 0; i < n; ++i) {
        const float h = H[i], k = K[i];
        b[i] = -(h > 0.0f ? 1.0f : (h < 0.0f ? -1.0f : 0.0f)) * std::sqrt(k + std::abs(k));
      }
    });
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i) worst = std::max(worst, double(std::abs(a[i] - b[i])));
    std::printf("bench_formula: '%s' over %zu samples (batches of %d), best of %d\n", text, n, formula::kMaxSamples, runs);
    std::printf("%-10s %10s %10s %8s %12s %6s\n", "case", "formula_s", "cpp_s", "ratio", "max_diff", "instr");
    std::printf("%-10s %10.4f %10.4f %7.3fx %12.3g %6d\n", "mean-gauss", t_formula, t_cpp, t_formula / t_cpp, worst,
                p.instruction_count());
    return worst == 0.0;
  });
}
