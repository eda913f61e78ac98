// Fuzz target: the speed-formula language (formula::compile, Program::evaluate,
// evaluate_scalar, compile_split_by_curvature) on arbitrary text.
//
// The whole input is the formula (capped at 8 KiB; the default limits refuse more than 4096
// characters anyway), compiled with the constants eps = 0.1 and c = 2 and default limits.
// levelset::Error is the expected outcome for bad formulas; anything else escaping, a crash, a
// hang or a broken invariant (__builtin_trap) is a bug. When the formula compiles it is
// evaluated over a batch of 1..16 samples whose values come deterministically from the input's
// hash (with zeros, negatives, huge and tiny values among them); every variable the program
// does not use gets a null pointer (the documented contract), every used one exactly n floats
// on the heap (so AddressSanitizer sees reads past n).
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string_view>

#include "core/error.hpp"
#include "formula/formula.hpp"

namespace {

namespace fm = levelset::formula;

constexpr std::size_t kMaxInputBytes = 8 << 10;
constexpr int kMaxBatch = 16;
constexpr float kCanary = -12345.678f;

constexpr std::uint32_t kAllVarBits = (1u << fm::kVarCount) - 1u;
constexpr std::uint32_t kCurvatureBits = (1u << int(fm::Var::H)) | (1u << int(fm::Var::K)) |
                                         (1u << int(fm::Var::k1)) | (1u << int(fm::Var::k2)) |
                                         (1u << int(fm::Var::kavg));

const fm::CompileOptions& options() {
  static const fm::CompileOptions o = [] {
    fm::CompileOptions opts;
    opts.constants = {{"eps", 0.1}, {"c", 2.0}};
    return opts;
  }();
  return o;
}

std::uint64_t fnv1a(std::string_view s) {
  std::uint64_t h = 1469598103934665603ull;
  for (const char ch : s) h = (h ^ static_cast<unsigned char>(ch)) * 1099511628211ull;
  return h;
}

// Deterministic sample values: mostly moderate, some special.
struct Values {
  explicit Values(std::uint64_t seed) : state(seed | 1u) {}
  std::uint64_t state;
  float next() {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    static constexpr float kSpecial[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 1e30f, -1e30f,
                                         1e-30f, 3.0e38f, -2.5f, 100.0f, 1e-3f};
    const std::uint32_t r = static_cast<std::uint32_t>(state >> 32);
    if ((r & 7u) == 0) return kSpecial[(r >> 3) % std::size(kSpecial)];
    return (static_cast<float>(r >> 8) / 16777216.0f) * 8.0f - 4.0f;  // [-4, 4)
  }
};

bool same_bits(const float* a, const float* b, int n) {
  return std::memcmp(a, b, sizeof(float) * static_cast<std::size_t>(n)) == 0;
}

void check_program(const fm::Program& p, const fm::Limits& limits) {
  if ((p.uses() & ~kAllVarBits) != 0) __builtin_trap();
  for (int v = 0; v < fm::kVarCount; ++v)
    if (p.uses_var(static_cast<fm::Var>(v)) != (((p.uses() >> v) & 1u) != 0)) __builtin_trap();
  if (p.instruction_count() < 0 || p.instruction_count() > limits.max_instructions)
    __builtin_trap();
  if (p.is_constant() && p.uses() != 0) __builtin_trap();
}

// Evaluates p over n samples (twice: the result must not depend on the workspace's history)
// and once per scalar reference; traps on writes past n.
void run_program(const fm::Program& p, int n, std::uint64_t seed) {
  thread_local fm::Workspace ws;
  Values values(seed);
  std::array<std::unique_ptr<float[]>, fm::kVarCount> storage;
  std::array<const float*, fm::kVarCount> inputs{};
  std::array<double, fm::kVarCount> scalar{};
  for (int v = 0; v < fm::kVarCount; ++v) {
    const float first = values.next();
    scalar[static_cast<std::size_t>(v)] = first;
    if (!p.uses_var(static_cast<fm::Var>(v))) continue;
    storage[static_cast<std::size_t>(v)] = std::make_unique<float[]>(static_cast<std::size_t>(n));
    float* data = storage[static_cast<std::size_t>(v)].get();
    data[0] = first;
    for (int i = 1; i < n; ++i) data[i] = values.next();
    inputs[static_cast<std::size_t>(v)] = data;
  }
  float out[kMaxBatch + 4];
  float again[kMaxBatch + 4];
  for (float& f : out) f = kCanary;
  for (float& f : again) f = kCanary;
  p.evaluate(inputs, n, out, ws);
  for (int i = n; i < kMaxBatch + 4; ++i)
    if (std::memcmp(&out[i], &kCanary, sizeof(float)) != 0) __builtin_trap();
  p.evaluate(inputs, n, again, ws);
  if (!same_bits(out, again, n)) __builtin_trap();
  (void)p.evaluate_scalar(scalar);
  if (p.is_constant()) {
    const double c = p.constant_value();
    const double s = p.evaluate_scalar(scalar);
    if (!(c == s || (std::isnan(c) && std::isnan(s)))) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > kMaxInputBytes) size = kMaxInputBytes;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const fm::CompileOptions& opts = options();
  const std::uint64_t seed = fnv1a(text);
  const int n = 1 + static_cast<int>(seed % kMaxBatch);

  try {
    const fm::Program p = fm::compile(text, opts);
    check_program(p, opts.limits);
    run_program(p, n, seed);
    // Copies evaluate like the original.
    const fm::Program copy = p;
    if (copy.uses() != p.uses() || copy.instruction_count() != p.instruction_count())
      __builtin_trap();
    run_program(copy, kMaxBatch, seed ^ 0x9e3779b97f4a7c15ull);
  } catch (const levelset::Error&) {
  }

  try {
    const fm::SplitProgram split = fm::compile_split_by_curvature(text, opts);
    check_program(split.without_curvature, opts.limits);
    check_program(split.with_curvature, opts.limits);
    if ((split.without_curvature.uses() & kCurvatureBits) != 0) __builtin_trap();
    run_program(split.without_curvature, n, seed + 1);
    run_program(split.with_curvature, n, seed + 2);
  } catch (const levelset::Error&) {
  }
  return 0;
}
