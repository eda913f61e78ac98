// The speed-formula language (thesis 4.7, formula/formula.hpp): a table of formulas against
// C++ references (batch float evaluation and the double scalar reference), uses() and
// constant folding, parse errors with their caret lines, limits (length, depth, instructions;
// no crash on hostile input), the split into curvature / non-curvature parts, and evaluation
// from several threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "formula/formula.hpp"

namespace levelset::formula {

namespace {

constexpr int kN = kMaxSamples;  // samples generated (512)
constexpr int kPad = 8;          // room for evaluating from unaligned offsets
constexpr float kSentinel = -12345.625f;

using Values = std::array<double, kVarCount>;

// Named view of one sample for the references.
struct V {
  double d, x, y, z, nx, ny, nz, H, K, k1, k2, grad, t, h, kavg, dist, dgx, dgy, dgz, dn, img, edge, roi;
};

V view(const Values& a) {
  auto g = [&](Var v) { return a[std::size_t(v)]; };
  return V{g(Var::d),    g(Var::x),   g(Var::y),   g(Var::z),    g(Var::nx),   g(Var::ny),
           g(Var::nz),   g(Var::H),   g(Var::K),   g(Var::k1),   g(Var::k2),   g(Var::grad),
           g(Var::t),    g(Var::h),   g(Var::kavg), g(Var::dist), g(Var::dgx), g(Var::dgy),
           g(Var::dgz),  g(Var::dn),  g(Var::img), g(Var::edge), g(Var::roi)};
}

std::uint32_t bit(Var v) { return 1u << int(v); }

// Random inputs: float arrays (what evaluate reads) and the same values as doubles.
struct Samples {
  std::array<std::vector<float>, kVarCount> f;
  std::vector<Values> dbl;
};

Samples make_samples(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto u = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  std::normal_distribution<double> gauss(0.0, 1.0);
  Samples s;
  for (auto& a : s.f) a.assign(kN + kPad, 0.0f);
  s.dbl.resize(kN + kPad);
  for (int i = 0; i < kN + kPad; ++i) {
    std::array<double, kVarCount> raw{};
    auto set = [&](Var v, double value) { raw[std::size_t(v)] = value; };
    set(Var::d, u(-1, 1));
    set(Var::x, u(-2, 2));
    set(Var::y, u(-2, 2));
    set(Var::z, u(-2, 2));
    double n[3];
    double len = 0;
    do {
      for (double& c : n) c = gauss(rng);
      len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    } while (len < 1e-3);
    set(Var::nx, n[0] / len);
    set(Var::ny, n[1] / len);
    set(Var::nz, n[2] / len);
    set(Var::H, u(-5, 5));
    set(Var::K, u(-10, 10));
    set(Var::k1, u(0.5, 1.5));
    set(Var::k2, u(0.5, 1.5));
    set(Var::grad, u(0.5, 1.5));
    set(Var::t, u(0, 1));
    set(Var::h, 0.01);
    set(Var::kavg, u(-1, 1));
    set(Var::dist, u(0, 1));
    set(Var::dgx, u(-1, 1));
    set(Var::dgy, u(-1, 1));
    set(Var::dgz, u(-1, 1));
    set(Var::dn, u(-1, 1));
    set(Var::img, u(0, 255));
    set(Var::edge, u(0, 1));
    set(Var::roi, u(0, 1));
    for (int v = 0; v < kVarCount; ++v) {
      const float fv = float(raw[std::size_t(v)]);
      s.f[std::size_t(v)][std::size_t(i)] = fv;
      s.dbl[std::size_t(i)][std::size_t(v)] = double(fv);  // the references see exactly the floats
    }
  }
  return s;
}

const Samples& samples() {
  static const Samples s = make_samples(0x5eed'f0f0'1234ULL);
  return s;
}

CompileOptions opts() {
  CompileOptions o;
  o.constants = {{"eps", 0.1}, {"c", 2.0}};
  return o;
}

std::array<const float*, kVarCount> inputs_at(const Samples& s, int offset, std::uint32_t mask = ~0u) {
  std::array<const float*, kVarCount> in{};
  for (int v = 0; v < kVarCount; ++v)
    in[std::size_t(v)] = ((mask >> v) & 1u) ? s.f[std::size_t(v)].data() + offset : nullptr;
  return in;
}

// Double references of the functions.
double sgn(double a) { return double((a > 0) - (a < 0)); }
double stp(double edge, double x) { return x >= edge ? 1.0 : 0.0; }
double clampd(double x, double lo, double hi) { return std::min(std::max(x, lo), hi); }
double smooth(double e0, double e1, double x) {
  const double t = clampd((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}
double b(bool v) { return v ? 1.0 : 0.0; }
double frac_dist(double a) { return std::abs(a - std::round(a)); }  // distance to an integer

using Fn = std::function<double(const V&)>;

struct Case {
  Case(const char* t, Fn r) : text(t), ref(std::move(r)) {}
  Case(const char* t, Fn r, Fn n) : text(t), ref(std::move(r)), near(std::move(n)) {}
  const char* text;
  Fn ref;
  Fn near;  // distance to the nearest comparison threshold (skip samples closer than 1e-4)
};

const double kPi = std::numbers::pi;

std::vector<Case> table() {
  return {
      // arithmetic operators, precedence, associativity
      {"x + y", [](const V& v) { return v.x + v.y; }},
      {"x - y - z", [](const V& v) { return (v.x - v.y) - v.z; }},
      {"1-2-3", [](const V&) { return -4.0; }},
      {"x * y + z", [](const V& v) { return v.x * v.y + v.z; }},
      {"x + y * z", [](const V& v) { return v.x + v.y * v.z; }},
      {"x / y / grad", [](const V& v) { return (v.x / v.y) / v.grad; }},
      {"2^3^2", [](const V&) { return 512.0; }},
      {"-2^2", [](const V&) { return -4.0; }},
      {"-x^2", [](const V& v) { return -(v.x * v.x); }},
      {"2*x^2 - y^3", [](const V& v) { return 2 * v.x * v.x - v.y * v.y * v.y; }},
      {"grad^x^2", [](const V& v) { return std::pow(v.grad, v.x * v.x); }},
      {"- -x + -y * -z", [](const V& v) { return v.x + (-v.y) * (-v.z); }},
      {"(x + y) * (z - d)", [](const V& v) { return (v.x + v.y) * (v.z - v.d); }},
      {"1e-3*x + 2.5 - 1.5e2/100", [](const V& v) { return 1e-3 * v.x + 2.5 - 1.5e2 / 100; }},
      // comparisons and logic
      {"x < y", [](const V& v) { return b(v.x < v.y); }},
      {"x <= y", [](const V& v) { return b(v.x <= v.y); }},
      {"x > y", [](const V& v) { return b(v.x > v.y); }},
      {"x >= y", [](const V& v) { return b(v.x >= v.y); }},
      {"floor(x) == floor(y)", [](const V& v) { return b(std::floor(v.x) == std::floor(v.y)); },
       [](const V& v) { return std::min(frac_dist(v.x), frac_dist(v.y)); }},
      {"floor(x) != floor(y)", [](const V& v) { return b(std::floor(v.x) != std::floor(v.y)); },
       [](const V& v) { return std::min(frac_dist(v.x), frac_dist(v.y)); }},
      {"x*x + y*y < 1", [](const V& v) { return b(v.x * v.x + v.y * v.y < 1); },
       [](const V& v) { return std::abs(v.x * v.x + v.y * v.y - 1); }},
      {"x + 1 > y * 2", [](const V& v) { return b(v.x + 1 > v.y * 2); },
       [](const V& v) { return std::abs(v.x + 1 - v.y * 2); }},
      {"!x", [](const V& v) { return b(!(v.x != 0)); }},
      {"!(x > 0) + !!(y > 0) * 2", [](const V& v) { return b(!(v.x > 0)) + b(v.y > 0) * 2; }},
      {"x > 0 && y > 0", [](const V& v) { return b(v.x > 0 && v.y > 0); }},
      {"x > 0 || y > 0", [](const V& v) { return b(v.x > 0 || v.y > 0); }},
      {"x && y", [](const V& v) { return b(v.x != 0 && v.y != 0); }},
      {"x > 0 || y > 0 && z > 0", [](const V& v) { return b(v.x > 0 || (v.y > 0 && v.z > 0)); }},
      {"(x > 0) + (y > 0) * 2 + (z <= 0) * 4",
       [](const V& v) { return b(v.x > 0) + b(v.y > 0) * 2 + b(v.z <= 0) * 4; }},
      {"x > 0 ? H : K", [](const V& v) { return v.x > 0 ? v.H : v.K; }},
      {"x > 1 ? 1 : x > 0 ? 2 : 3", [](const V& v) { return v.x > 1 ? 1.0 : v.x > 0 ? 2.0 : 3.0; }},
      {"(y > 0 ? x : -x) * 2 + 1", [](const V& v) { return (v.y > 0 ? v.x : -v.x) * 2 + 1; }},
      // functions
      {"abs(x) + sign(y) - sign(0)", [](const V& v) { return std::abs(v.x) + sgn(v.y); }},
      {"sqrt(abs(x)) + cbrt(y)", [](const V& v) { return std::sqrt(std::abs(v.x)) + std::cbrt(v.y); }},
      {"exp(-d*d) + exp(x*y)", [](const V& v) { return std::exp(-v.d * v.d) + std::exp(v.x * v.y); }},
      {"log(grad) + log(1 + x^2)", [](const V& v) { return std::log(v.grad) + std::log(1 + v.x * v.x); }},
      {"sin(x) + cos(y) + tan(t)", [](const V& v) { return std::sin(v.x) + std::cos(v.y) + std::tan(v.t); }},
      {"asin(nx) + acos(ny) + atan(z)",
       [](const V& v) { return std::asin(v.nx) + std::acos(v.ny) + std::atan(v.z); }},
      {"floor(x*3)", [](const V& v) { return std::floor(v.x * 3); }, [](const V& v) { return frac_dist(v.x * 3); }},
      {"ceil(y*2.5)", [](const V& v) { return std::ceil(v.y * 2.5); }, [](const V& v) { return frac_dist(v.y * 2.5); }},
      {"atan2(y, x)", [](const V& v) { return std::atan2(v.y, v.x); }},
      {"pow(grad, x) + pow(y, 2)", [](const V& v) { return std::pow(v.grad, v.x) + v.y * v.y; }},
      {"y^3 + 2^x", [](const V& v) { return v.y * v.y * v.y + std::pow(2.0, v.x); }},
      {"min(x, y) + max(H, K)", [](const V& v) { return std::min(v.x, v.y) + std::max(v.H, v.K); }},
      {"step(0.3, t) + step(x, y)", [](const V& v) { return stp(0.3, v.t) + stp(v.x, v.y); },
       [](const V& v) { return std::abs(v.t - 0.3); }},
      {"clamp(x, -0.5, 0.5)", [](const V& v) { return clampd(v.x, -0.5, 0.5); }},
      {"smoothstep(-1, 1, x) + smoothstep(0.2, 0.8, t)",
       [](const V& v) { return smooth(-1, 1, v.x) + smooth(0.2, 0.8, v.t); }},
      {"pi*x + 2*pi", [](const V& v) { return kPi * v.x + 2 * kPi; }},
      {"c*x + eps", [](const V& v) { return 2.0 * v.x + 0.1; }},
      // every variable
      {"d + x + y + z", [](const V& v) { return v.d + v.x + v.y + v.z; }},
      {"nx*ny + nz", [](const V& v) { return v.nx * v.ny + v.nz; }},
      {"k1*k2 - K + (k1+k2)/2 - H", [](const V& v) { return v.k1 * v.k2 - v.K + (v.k1 + v.k2) / 2 - v.H; }},
      {"grad*t + h", [](const V& v) { return v.grad * v.t + v.h; }},
      {"dgx*dgy - dgz", [](const V& v) { return v.dgx * v.dgy - v.dgz; }},
      {"img/255*edge + roi", [](const V& v) { return v.img / 255 * v.edge + v.roi; }},
      // the thesis's speeds
      {"-sign(H)*sqrt(K+abs(K))", [](const V& v) { return -sgn(v.H) * std::sqrt(v.K + std::abs(v.K)); }},
      {"1-eps*H", [](const V& v) { return 1 - 0.1 * v.H; }},
      {"dn + dist*H", [](const V& v) { return v.dn + v.dist * v.H; }},
      {"-(H-kavg)", [](const V& v) { return -(v.H - v.kavg); }},
      // long combined ones
      {"(1 - eps*H) * grad * (1 - step(0.5, edge)) + c*(dgx*nx + dgy*ny + dgz*nz)",
       [](const V& v) {
         return (1 - 0.1 * v.H) * v.grad * (1 - stp(0.5, v.edge)) + 2.0 * (v.dgx * v.nx + v.dgy * v.ny + v.dgz * v.nz);
       },
       [](const V& v) { return std::abs(v.edge - 0.5); }},
      {"clamp(-sign(H)*sqrt(K+abs(K)) + 0.5*(kavg - H), -1, 1) * exp(-img/128)",
       [](const V& v) {
         return clampd(-sgn(v.H) * std::sqrt(v.K + std::abs(v.K)) + 0.5 * (v.kavg - v.H), -1, 1) * std::exp(-v.img / 128);
       }},
      {"smoothstep(0, 1, dist) * (dn + dist*H) + (1 - smoothstep(0, 1, dist)) * (1 - eps*H)",
       [](const V& v) {
         return smooth(0, 1, v.dist) * (v.dn + v.dist * v.H) + (1 - smooth(0, 1, v.dist)) * (1 - 0.1 * v.H);
       }},
      {"roi > 0.5 ? max(min(x*y, 1), -1) + abs(d) : -(H - kavg)*grad",
       [](const V& v) {
         return v.roi > 0.5 ? std::max(std::min(v.x * v.y, 1.0), -1.0) + std::abs(v.d) : -(v.H - v.kavg) * v.grad;
       },
       [](const V& v) { return std::abs(v.roi - 0.5); }},
      {"sqrt(x*x + y*y + z*z) - 1 + 0.1*sin(3*atan2(y, x))",
       [](const V& v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z) - 1 + 0.1 * std::sin(3 * std::atan2(v.y, v.x)); }},
      {"-sign(d)*(1 - eps*H)*grad + t*h*(k1 - k2)/(1 + abs(K))",
       [](const V& v) { return -sgn(v.d) * (1 - 0.1 * v.H) * v.grad + v.t * v.h * (v.k1 - v.k2) / (1 + std::abs(v.K)); }},
  };
}

// Bits of the variable names that occur as identifiers in the text.
std::uint32_t names_in(std::string_view text) {
  std::uint32_t bits = 0;
  std::size_t i = 0;
  while (i < text.size()) {
    const auto is_start = [](char ch) { return std::isalpha(static_cast<unsigned char>(ch)) || ch == '_'; };
    const auto is_part = [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; };
    if (is_start(text[i]) && (i == 0 || !(is_part(text[i - 1]) || text[i - 1] == '.'))) {
      std::size_t j = i;
      while (j < text.size() && is_part(text[j])) ++j;
      const Var v = var_from_name(text.substr(i, j - i));
      if (v != Var::count) bits |= bit(v);
      i = j;
    } else {
      ++i;
    }
  }
  return bits;
}

bool same_value(double got, double ref, double rel, double abs_tol) {
  if (std::isnan(ref) || std::isnan(got)) return std::isnan(ref) && std::isnan(got);
  if (std::isinf(ref) || std::isinf(got)) return got == ref;
  return std::abs(got - ref) <= rel * std::abs(ref) + abs_tol;
}

bool compile_or_report(std::string_view text, const CompileOptions& o, Program& out) {
  try {
    out = compile(text, o);
    return true;
  } catch (const Error& e) {
    ADD_FAILURE() << "'" << text << "' failed to compile: " << e.what();
    return false;
  }
}

}  // namespace

TEST(FormulaVarNames, RoundTripAndCaseSensitive) {
  for (int i = 0; i < kVarCount; ++i) {
    const Var v = Var(i);
    ASSERT_NE(var_name(v), nullptr);
    EXPECT_EQ(var_from_name(var_name(v)), v) << var_name(v);
  }
  EXPECT_STREQ(var_name(Var::kavg), "kavg");
  EXPECT_STREQ(var_name(Var::H), "H");
  EXPECT_EQ(var_from_name("h"), Var::h);
  EXPECT_EQ(var_from_name("H"), Var::H);
  EXPECT_EQ(var_from_name("Kavg"), Var::count);
  EXPECT_EQ(var_from_name("sin"), Var::count);
  EXPECT_EQ(var_from_name(""), Var::count);
  EXPECT_EQ(var_from_name("HH"), Var::count);
}

TEST(FormulaTable, MatchesReferences) {
  const Samples& s = samples();
  const std::vector<Case> cases = table();
  ASSERT_GE(cases.size(), 40u);
  Workspace ws;  // shared across formulas of different register counts on purpose
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    Program p;
    if (!compile_or_report(c.text, opts(), p)) continue;
    EXPECT_EQ(p.text(), c.text);
    EXPECT_EQ(p.uses(), names_in(c.text)) << "uses() should be exactly the variables read";
    for (int v = 0; v < kVarCount; ++v) EXPECT_EQ(p.uses_var(Var(v)), ((names_in(c.text) >> v) & 1u) != 0);
    EXPECT_EQ(p.is_constant(), names_in(c.text) == 0);

    std::vector<double> ref(kN + kPad);
    std::vector<char> skip(kN + kPad, 0);
    double scale = 1.0;
    for (int i = 0; i < kN + kPad; ++i) {
      const V v = view(s.dbl[std::size_t(i)]);
      ref[std::size_t(i)] = c.ref(v);
      if (std::isfinite(ref[std::size_t(i)])) scale = std::max(scale, std::abs(ref[std::size_t(i)]));
      if (c.near && c.near(v) < 1e-4) skip[std::size_t(i)] = 1;
    }
    if (p.is_constant()) { EXPECT_NEAR(p.constant_value(), ref[0], 1e-12 * scale); }

    // Double reference, every sample.
    int scalar_bad = 0;
    for (int i = 0; i < kN + kPad; ++i) {
      if (skip[std::size_t(i)]) continue;
      const double got = p.evaluate_scalar(s.dbl[std::size_t(i)]);
      if (!same_value(got, ref[std::size_t(i)], 1e-12, 1e-14 * scale) && scalar_bad++ < 3)
        ADD_FAILURE() << "evaluate_scalar sample " << i << ": got " << got << " expected " << ref[std::size_t(i)];
    }

    // Batches: n = 200, 1, 512 from the start, and n = 200 from an unaligned offset.
    const std::pair<int, int> runs[] = {{200, 0}, {1, 0}, {512, 0}, {200, 3}, {77, 5}};
    for (const auto& [n, offset] : runs) {
      std::vector<float> out(std::size_t(n) + 16, kSentinel);
      p.evaluate(inputs_at(s, offset), n, out.data(), ws);
      int bad = 0;
      for (int i = 0; i < n; ++i) {
        const int k = i + offset;
        if (skip[std::size_t(k)]) continue;
        const double got = out[std::size_t(i)];
        if (!same_value(got, ref[std::size_t(k)], 1e-5, 1e-6 * scale) && bad++ < 3)
          ADD_FAILURE() << "evaluate n=" << n << " offset=" << offset << " sample " << k << ": got " << got
                        << " expected " << ref[std::size_t(k)];
      }
      for (std::size_t i = std::size_t(n); i < out.size(); ++i)
        if (out[i] != kSentinel) {
          ADD_FAILURE() << "evaluate n=" << n << " wrote past out[n-1] at index " << i;
          break;
        }
    }
  }
}

TEST(FormulaEvaluate, UnusedInputsMayBeNull) {
  const Samples& s = samples();
  struct C {
    const char* text;
    std::uint32_t uses;
    Fn ref;
  };
  const C cases[] = {
      {"1 - eps*H", bit(Var::H), [](const V& v) { return 1 - 0.1 * v.H; }},
      {"x+y", bit(Var::x) | bit(Var::y), [](const V& v) { return v.x + v.y; }},
      {"dn + dist*H", bit(Var::dn) | bit(Var::dist) | bit(Var::H), [](const V& v) { return v.dn + v.dist * v.H; }},
      {"2*pi", 0u, [](const V&) { return 2 * kPi; }},
      {"roi", bit(Var::roi), [](const V& v) { return v.roi; }},
  };
  Workspace ws;
  for (const C& c : cases) {
    SCOPED_TRACE(c.text);
    Program p;
    if (!compile_or_report(c.text, opts(), p)) continue;
    ASSERT_EQ(p.uses(), c.uses);
    std::vector<float> out(kN, kSentinel);
    p.evaluate(inputs_at(s, 0, p.uses()), kN, out.data(), ws);
    for (int i = 0; i < kN; ++i) {
      const double r = c.ref(view(s.dbl[std::size_t(i)]));
      ASSERT_TRUE(same_value(out[std::size_t(i)], r, 1e-5, 1e-6 * std::max(1.0, std::abs(r))))
          << "sample " << i << ": got " << out[std::size_t(i)] << " expected " << r;
    }
  }
}

TEST(FormulaUses, ExactlyTheVariablesRead) {
  EXPECT_EQ(compile("1-eps*H", opts()).uses(), bit(Var::H));
  EXPECT_EQ(compile("x+y", opts()).uses(), bit(Var::x) | bit(Var::y));
  EXPECT_EQ(compile("dn + dist*H", opts()).uses(), bit(Var::dn) | bit(Var::dist) | bit(Var::H));
  EXPECT_EQ(compile("-sign(H)*sqrt(K+abs(K))", opts()).uses(), bit(Var::H) | bit(Var::K));
  EXPECT_EQ(compile("kavg + k1", opts()).uses(), bit(Var::kavg) | bit(Var::k1));
  EXPECT_EQ(compile("eps*c", opts()).uses(), 0u);
  const Program x = compile("x+y", opts());
  EXPECT_TRUE(x.uses_var(Var::x));
  EXPECT_TRUE(x.uses_var(Var::y));
  EXPECT_FALSE(x.uses_var(Var::z));
  EXPECT_FALSE(x.uses_var(Var::H));
  EXPECT_FALSE(x.is_constant());
  // '0*K + 1' may or may not drop K after folding; it must still evaluate to 1.
  const Program zk = compile("0*K + 1", opts());
  EXPECT_EQ(zk.uses() & ~bit(Var::K), 0u);
  Values vals{};
  vals[std::size_t(Var::K)] = 3.0;
  EXPECT_DOUBLE_EQ(zk.evaluate_scalar(vals), 1.0);
}

TEST(FormulaConstant, FoldsToOneValue) {
  const Program p = compile("2*pi");
  EXPECT_TRUE(p.is_constant());
  EXPECT_EQ(p.uses(), 0u);
  EXPECT_DOUBLE_EQ(p.constant_value(), 2 * kPi);
  EXPECT_LE(p.instruction_count(), 2);
  Workspace ws;
  std::vector<float> out(kN + 4, kSentinel);
  p.evaluate(std::array<const float*, kVarCount>{}, kN, out.data(), ws);
  for (int i = 0; i < kN; ++i) ASSERT_FLOAT_EQ(out[std::size_t(i)], float(2 * kPi)) << i;
  EXPECT_EQ(out[kN], kSentinel);
  EXPECT_DOUBLE_EQ(p.evaluate_scalar(Values{}), 2 * kPi);

  const Program q = compile("sin(pi/2) + 2^3 - max(1, c) + eps", opts());
  EXPECT_TRUE(q.is_constant());
  EXPECT_NEAR(q.constant_value(), 1 + 8 - 2 + 0.1, 1e-12);
  EXPECT_LE(q.instruction_count(), 2);

  const Program r = compile("x*(2*3 + 4)", opts());
  EXPECT_FALSE(r.is_constant());
  EXPECT_GE(r.instruction_count(), 1);
  Values vals{};
  vals[std::size_t(Var::x)] = 1.5;
  EXPECT_DOUBLE_EQ(r.evaluate_scalar(vals), 15.0);
  // The folded constant is no bigger than writing the number.
  EXPECT_LE(r.instruction_count(), compile("x*10").instruction_count());
}

TEST(FormulaProgram, CopyAndMoveKeepTheFormula) {
  const Samples& s = samples();
  const char* text = "clamp(-sign(H)*sqrt(K+abs(K)) + 0.5*(kavg - H), -1, 1) * exp(-img/128)";
  const Program p = compile(text, opts());
  Workspace ws;
  std::vector<float> a(kN), b2(kN), c2(kN);
  p.evaluate(inputs_at(s, 0), kN, a.data(), ws);
  Program q = p;  // copy
  q.evaluate(inputs_at(s, 0), kN, b2.data(), ws);
  EXPECT_EQ(std::memcmp(a.data(), b2.data(), a.size() * sizeof(float)), 0);
  Program r = std::move(q);
  EXPECT_EQ(r.text(), text);
  EXPECT_EQ(r.uses(), p.uses());
  r.evaluate(inputs_at(s, 0), kN, c2.data(), ws);
  EXPECT_EQ(std::memcmp(a.data(), c2.data(), a.size() * sizeof(float)), 0);
  Program t;
  t = p;
  EXPECT_EQ(t.text(), text);
  EXPECT_EQ(t.instruction_count(), p.instruction_count());
}

// ---- errors ------------------------------------------------------------------------------

namespace {

struct Caught {
  bool thrown = false;
  ErrorCode code = ErrorCode::InvalidArgument;
  std::string where, reason, what;
};

// The Error that f() throws, if any.
template <typename F>
Caught caught(F&& f) {
  Caught c;
  try {
    f();
  } catch (const Error& e) {
    c.thrown = true;
    c.code = e.code();
    c.where = e.where();
    c.reason = e.reason();
    c.what = e.what();
  }
  return c;
}

Caught try_compile(std::string_view text, const CompileOptions& o = opts()) {
  return caught([&] { (void)compile(text, o); });
}

Caught try_split(std::string_view text, const CompileOptions& o = opts()) {
  return caught([&] { (void)compile_split_by_curvature(text, o); });
}

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> out;
  std::string line;
  std::istringstream in(s);
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

// The column N of "...column N" in `where`, or -1.
int where_column(const std::string& where) {
  const std::size_t k = where.rfind("column ");
  if (k == std::string::npos) return -1;
  const std::string num = where.substr(k + 7);
  if (num.empty() || num.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::atoi(num.c_str());
}

// 1-based column of the caret under the formula line in the reason, or INT_MIN when the
// reason has no formula line followed by a caret line.
int caret_column(const std::string& reason, std::string_view text) {
  const std::vector<std::string> ls = lines_of(reason);
  for (std::size_t i = ls.size() >= 2 ? ls.size() - 2 : 0; i + 1 < ls.size() && i < ls.size(); --i) {
    const std::string& f = ls[i];
    const std::string& caret = ls[i + 1];
    const std::size_t c = caret.find('^');
    if (c != std::string::npos && caret.find_first_not_of(" ^~") == std::string::npos) {
      std::size_t pos = std::string::npos;
      if (text.empty()) {
        pos = f.size();  // only indentation on the formula line
      } else if (f.size() >= text.size() && f.compare(f.size() - text.size(), text.size(), text) == 0) {
        pos = f.size() - text.size();
      } else {
        pos = f.find(text);
      }
      if (pos != std::string::npos) return int(c) - int(pos) + 1;
    }
    if (i == 0) break;
  }
  return std::numeric_limits<int>::min();
}

struct ErrorCase {
  std::string text;
  int column;                         // expected 1-based column, 0: not asserted
  std::vector<std::string> mentions;  // the first line of the reason names these
};

}  // namespace

TEST(FormulaErrors, ParseErrorsPointAtTheProblem) {
  using namespace std::string_literals;
  const std::vector<ErrorCase> cases = {
      {"1 +", 4, {}},
      {"(1", 3, {")"}},
      {"1)", 2, {")"}},
      {"*2", 1, {"*"}},
      {"2 3", 3, {}},
      {"", 1, {}},
      {"sin()", 0, {"sin"}},
      {"sin(1,2)", 0, {"sin"}},
      {"max(1)", 0, {"max"}},
      {"clamp(x, 1)", 0, {"clamp"}},
      {"foo(1)", 1, {"foo"}},
      {"Hx", 1, {"Hx"}},
      {"1 ? 2", 6, {":"}},
      {"1 ? 2 :", 8, {}},
      {"x + y * (z - foo(1))", 14, {"foo"}},
      {"sqrt(x) + Hx", 11, {"Hx"}},
      {"x $ y", 3, {"$"}},
      {"SIN(x)", 1, {"SIN"}},
      {"Pi", 1, {"Pi"}},
      {"x = 1", 3, {}},
      {"x & y", 3, {}},
      {"x | y", 3, {}},
      {"()", 2, {}},
      {"x +* y", 4, {}},
      {"sin 1", 0, {}},
      {"sin", 0, {}},
      {"pi(2)", 0, {}},
      {"x(1)", 0, {}},
      {"1e+", 0, {}},
      {"x ==", 5, {}},
      {"x\0+1"s, 2, {}},
      {"\xff", 1, {}},
      {"k", 1, {"k"}},
  };
  for (const ErrorCase& c : cases) {
    SCOPED_TRACE("formula '" + c.text + "'");
    const Caught e = try_compile(c.text);
    ASSERT_TRUE(e.thrown) << "compiled without error";
    EXPECT_EQ(e.code, ErrorCode::ParseError) << e.what;
    const int col = where_column(e.where);
    EXPECT_GE(col, 1) << "where = '" << e.where << "'";
    EXPECT_LE(col, int(c.text.size()) + 1) << "where = '" << e.where << "'";
    EXPECT_EQ(e.where.rfind("formula", 0), 0u) << "where = '" << e.where << "'";
    if (c.column > 0) { EXPECT_EQ(col, c.column) << e.what; }
    const std::vector<std::string> ls = lines_of(e.reason);
    ASSERT_GE(ls.size(), 3u) << "message, formula and caret lines expected:\n" << e.reason;
    EXPECT_FALSE(ls[0].empty()) << e.reason;
    for (const std::string& m : c.mentions) EXPECT_NE(ls[0].find(m), std::string::npos) << "'" << m << "' not in: " << ls[0];
    const bool printable = std::all_of(c.text.begin(), c.text.end(), [](char ch) {
      return static_cast<unsigned char>(ch) >= 0x20 && static_cast<unsigned char>(ch) < 0x7f;
    });
    if (printable) {
      const int caret = caret_column(e.reason, c.text);
      EXPECT_EQ(caret, col) << "caret not under column " << col << ":\n" << e.reason;
      if (c.column > 0) { EXPECT_EQ(caret, c.column) << e.reason; }
    } else {
      EXPECT_NE(e.reason.find('^'), std::string::npos) << e.reason;
    }
  }
}

TEST(FormulaErrors, CaretLineExample) {
  const Caught e = try_compile("1 + Hx*2");
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::ParseError);
  EXPECT_EQ(where_column(e.where), 5);
  // The formula line followed by the caret line with the caret under 'H'.
  const std::vector<std::string> ls = lines_of(e.reason);
  bool found = false;
  for (std::size_t i = 0; i + 1 < ls.size(); ++i) {
    const std::size_t f = ls[i].find("1 + Hx*2");
    if (f == std::string::npos) continue;
    const std::size_t c = ls[i + 1].find('^');
    if (c == std::string::npos) continue;
    EXPECT_EQ(c, f + 4) << e.reason;
    EXPECT_EQ(ls[i + 1].substr(0, c).find_first_not_of(' '), std::string::npos) << e.reason;
    found = true;
  }
  EXPECT_TRUE(found) << e.reason;
  EXPECT_NE(e.what.find("1 + Hx*2"), std::string::npos) << e.what;
}

TEST(FormulaErrors, NearNamesAreSuggested) {
  const Caught e = try_compile("1 - kavgg");
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::ParseError);
  EXPECT_EQ(where_column(e.where), 5);
  EXPECT_NE(e.reason.find("kavgg"), std::string::npos) << e.reason;
  // The implementation suggests near names: it must name the right variable.
  const std::size_t dym = e.reason.find("did you mean");
  ASSERT_NE(dym, std::string::npos) << e.reason;
  EXPECT_NE(e.reason.find("'kavg'", dym), std::string::npos) << e.reason;
  const Caught f = try_compile("sqr(x)");
  ASSERT_TRUE(f.thrown);
  EXPECT_EQ(f.code, ErrorCode::ParseError);
  const std::size_t dym2 = f.reason.find("did you mean");
  if (dym2 != std::string::npos) { EXPECT_NE(f.reason.find("sqrt", dym2), std::string::npos) << f.reason; }
}

TEST(FormulaErrors, UnknownConstantNameIsAParseError) {
  // Named constants exist only when given.
  const Caught e = try_compile("1 - eps*H", CompileOptions{});
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::ParseError);
  EXPECT_EQ(where_column(e.where), 5);
  CompileOptions o;
  o.constants = {{"alpha", 0.25}};
  const Program p = compile("alpha*x", o);
  Values v{};
  v[std::size_t(Var::x)] = 2.0;
  EXPECT_DOUBLE_EQ(p.evaluate_scalar(v), 0.5);
  EXPECT_EQ(p.uses(), bit(Var::x));
}

TEST(FormulaErrors, BadConstants) {
  const std::pair<std::string, double> bad[] = {
      {"H", 1.0},
      {"x", 0.0},
      {"kavg", 0.5},
      {"sin", 1.0},
      {"smoothstep", 1.0},
      {"nanconst", std::numeric_limits<double>::quiet_NaN()},
      {"infconst", std::numeric_limits<double>::infinity()},
      {"neginf", -std::numeric_limits<double>::infinity()},
  };
  for (const auto& [name, value] : bad) {
    SCOPED_TRACE(name);
    CompileOptions o = opts();
    o.constants[name] = value;
    const Caught e = try_compile("1 + y", o);
    ASSERT_TRUE(e.thrown) << "constant accepted";
    EXPECT_EQ(e.code, ErrorCode::InvalidArgument) << e.what;
    EXPECT_NE(e.what.find(name), std::string::npos) << e.what;
    const Caught s = try_split("1 + y", o);
    ASSERT_TRUE(s.thrown) << "constant accepted by compile_split_by_curvature";
    EXPECT_EQ(s.code, ErrorCode::InvalidArgument) << s.what;
  }
}

// ---- limits ------------------------------------------------------------------------------

namespace {
std::string repeat(std::string_view s, int n) {
  std::string out;
  out.reserve(s.size() * std::size_t(n));
  for (int i = 0; i < n; ++i) out += s;
  return out;
}
}  // namespace

TEST(FormulaLimits, Length) {
  // 5000 characters of a valid, foldable formula: over max_length (4096).
  std::string text = "1" + repeat("+1", 2499) + " ";
  ASSERT_EQ(text.size(), 5000u);
  Caught e = try_compile(text);
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::LimitExceeded) << e.what.substr(0, 300);
  // The message does not echo the whole 5000 characters... at least it must not crash; and
  // the boundary is exact.
  CompileOptions o = opts();
  o.limits.max_length = 20;
  std::string at = "x+y+z+d+x+y+z+d+x+y";
  at.resize(20, ' ');
  EXPECT_NO_THROW((void)compile(at, o));
  const Caught over = try_compile(at + "1", o);
  ASSERT_TRUE(over.thrown);
  EXPECT_EQ(over.code, ErrorCode::LimitExceeded) << over.what;
  const Caught split = try_split(text);
  ASSERT_TRUE(split.thrown);
  EXPECT_EQ(split.code, ErrorCode::LimitExceeded);
}

TEST(FormulaLimits, Depth) {
  const std::string deep = repeat("(", 200) + "x" + repeat(")", 200);
  Caught e = try_compile(deep);
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::LimitExceeded) << e.what.substr(0, 300);
  e = try_split(deep);
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::LimitExceeded);
  // Unbalanced deep nesting: the depth limit fires before the missing ')' is noticed, or a
  // parse error; never a crash.
  e = try_compile(repeat("(", 1000));
  ASSERT_TRUE(e.thrown);
  EXPECT_TRUE(e.code == ErrorCode::LimitExceeded || e.code == ErrorCode::ParseError) << e.what.substr(0, 300);
  // Calls nest too.
  e = try_compile(repeat("sin(", 200) + "x" + repeat(")", 200));
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::LimitExceeded);
  // Shallow nesting is fine.
  const Program ok = compile(repeat("(", 20) + "x" + repeat(")", 20), opts());
  Values v{};
  v[std::size_t(Var::x)] = 0.75;
  EXPECT_DOUBLE_EQ(ok.evaluate_scalar(v), 0.75);
  const Program ok2 = compile(repeat("abs(", 10) + "x" + repeat(")", 10), opts());
  v[std::size_t(Var::x)] = -0.75;
  EXPECT_DOUBLE_EQ(ok2.evaluate_scalar(v), 0.75);
  // A lower max_depth is honoured.
  CompileOptions o = opts();
  o.limits.max_depth = 4;
  e = try_compile(repeat("(", 10) + "x" + repeat(")", 10), o);
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::LimitExceeded);
}

TEST(FormulaLimits, Instructions) {
  const std::string text = "1" + repeat("+x", 2000);
  ASSERT_LT(text.size(), 4096u);
  Caught e = try_compile(text);
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::LimitExceeded) << e.what.substr(0, 300);
  e = try_split(text);
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::LimitExceeded);
  CompileOptions o = opts();
  o.limits.max_instructions = 4;
  EXPECT_NO_THROW((void)compile("x+y", o));
  e = try_compile("x+y+z+d+H+K+k1+k2", o);
  ASSERT_TRUE(e.thrown);
  EXPECT_EQ(e.code, ErrorCode::LimitExceeded);
  // Many terms that fold to a constant stay within the limit.
  EXPECT_NO_THROW((void)compile(repeat("1+", 1500) + "x", opts()));
}

// Hostile input with the length limit lifted: a limit error or a correct program, never a
// crash (stack overflow from recursion). Each runs in a child process.
TEST(FormulaLimitsDeathTest, HugeInputsDoNotCrash) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  auto survives = [](const std::string& text, double x, double expected) {
    CompileOptions o = opts();
    o.limits.max_length = std::size_t(1) << 23;
    o.limits.max_instructions = 1 << 22;
    try {
      const Program p = compile(text, o);
      Values v{};
      v[std::size_t(Var::x)] = x;
      const double got = p.evaluate_scalar(v);
      if (std::abs(got - expected) > 1e-9 * std::max(1.0, std::abs(expected))) {
        std::cerr << "wrong value " << got << " expected " << expected << "\n";
        return false;
      }
      return true;
    } catch (const Error& e) {
      if (e.code() != ErrorCode::LimitExceeded) std::cerr << "unexpected code " << e.what() << "\n";
      return e.code() == ErrorCode::LimitExceeded;
    }
  };
  const int n = 300000;
  EXPECT_EXIT(std::exit(survives(repeat("(", n) + "x" + repeat(")", n), 1.5, 1.5) ? 0 : 1),
              testing::ExitedWithCode(0), "");
  EXPECT_EXIT(std::exit(survives(repeat("-", 2 * n) + "x", 1.5, 1.5) ? 0 : 1), testing::ExitedWithCode(0), "");
  EXPECT_EXIT(std::exit(survives(repeat("!", 2 * n) + "x", 1.5, 1.0) ? 0 : 1), testing::ExitedWithCode(0), "");
  EXPECT_EXIT(std::exit(survives(repeat("x^", n) + "x", 1.0, 1.0) ? 0 : 1), testing::ExitedWithCode(0), "");
  EXPECT_EXIT(std::exit(survives(repeat("x+", n) + "x", 1.0, double(n + 1)) ? 0 : 1), testing::ExitedWithCode(0),
              "");
  EXPECT_EXIT(std::exit(survives(repeat("x>0?1:", n) + "x", 1.0, 1.0) ? 0 : 1), testing::ExitedWithCode(0), "");
  EXPECT_EXIT(std::exit(survives(repeat("sin(", n) + "x" + repeat(")", n), 0.0, 0.0) ? 0 : 1),
              testing::ExitedWithCode(0), "");
}

TEST(FormulaLimits, NestingWithinLimitsCompiles) {
  // 200 nested unary minuses is operator nesting beyond max_depth 64: a limit error, or (if the
  // implementation handles them without recursion) the right value.
  Values v{};
  v[std::size_t(Var::x)] = 1.25;
  try {
    const Program p = compile(repeat("-", 201) + "x", opts());
    EXPECT_DOUBLE_EQ(p.evaluate_scalar(v), -1.25);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << e.what();
  }
  try {
    const Program p = compile(repeat("x^", 200) + "x", opts());
    v[std::size_t(Var::x)] = 1.0;
    EXPECT_DOUBLE_EQ(p.evaluate_scalar(v), 1.0);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::LimitExceeded) << e.what();
  }
}

// ---- split by curvature --------------------------------------------------------------------

namespace {
constexpr std::uint32_t kCurvatureVars = (1u << int(Var::H)) | (1u << int(Var::K)) | (1u << int(Var::k1)) |
                                         (1u << int(Var::k2)) | (1u << int(Var::kavg));
}  // namespace

TEST(FormulaSplit, ThesisSpeeds) {
  const Samples& s = samples();
  {
    const SplitProgram sp = compile_split_by_curvature("1 - eps*H", opts());
    EXPECT_TRUE(sp.without_curvature.is_constant());
    EXPECT_DOUBLE_EQ(sp.without_curvature.constant_value(), 1.0);
    EXPECT_EQ(sp.with_curvature.uses(), bit(Var::H));
    for (int i = 0; i < kN; ++i) {
      const V v = view(s.dbl[std::size_t(i)]);
      ASSERT_NEAR(sp.with_curvature.evaluate_scalar(s.dbl[std::size_t(i)]), -0.1 * v.H, 1e-12 * std::max(1.0, std::abs(v.H)));
    }
  }
  {
    const SplitProgram sp = compile_split_by_curvature("dn + dist*H", opts());
    EXPECT_EQ(sp.without_curvature.uses(), bit(Var::dn));
    EXPECT_EQ(sp.with_curvature.uses(), bit(Var::dist) | bit(Var::H));
    for (int i = 0; i < kN; ++i) {
      const V v = view(s.dbl[std::size_t(i)]);
      ASSERT_NEAR(sp.without_curvature.evaluate_scalar(s.dbl[std::size_t(i)]), v.dn, 1e-15);
      ASSERT_NEAR(sp.with_curvature.evaluate_scalar(s.dbl[std::size_t(i)]), v.dist * v.H, 1e-14);
    }
  }
  {
    const SplitProgram sp = compile_split_by_curvature("-sign(H)*sqrt(K+abs(K))", opts());
    EXPECT_TRUE(sp.without_curvature.is_constant());
    EXPECT_EQ(sp.without_curvature.constant_value(), 0.0);
    EXPECT_EQ(sp.without_curvature.uses(), 0u);
    EXPECT_EQ(sp.with_curvature.uses(), bit(Var::H) | bit(Var::K));
  }
  {
    const SplitProgram sp = compile_split_by_curvature("x + H*2 - K + 3*y", opts());
    EXPECT_EQ(sp.without_curvature.uses(), bit(Var::x) | bit(Var::y));
    EXPECT_EQ(sp.with_curvature.uses(), bit(Var::H) | bit(Var::K));
    for (int i = 0; i < kN; ++i) {
      const V v = view(s.dbl[std::size_t(i)]);
      ASSERT_NEAR(sp.without_curvature.evaluate_scalar(s.dbl[std::size_t(i)]), v.x + 3 * v.y, 1e-13);
      ASSERT_NEAR(sp.with_curvature.evaluate_scalar(s.dbl[std::size_t(i)]), 2 * v.H - v.K, 1e-13);
    }
  }
  {
    // No curvature at all: everything on the advective side, the curvature side is 0.
    const SplitProgram sp = compile_split_by_curvature("grad*(1 + x)", opts());
    EXPECT_TRUE(sp.with_curvature.is_constant());
    EXPECT_EQ(sp.with_curvature.constant_value(), 0.0);
    EXPECT_EQ(sp.without_curvature.uses(), bit(Var::grad) | bit(Var::x));
  }
  {
    const Caught e = try_split("1 +");
    ASSERT_TRUE(e.thrown);
    EXPECT_EQ(e.code, ErrorCode::ParseError);
    EXPECT_EQ(where_column(e.where), 4);
    const Caught f = try_split("dn + kavgg*H");
    ASSERT_TRUE(f.thrown);
    EXPECT_EQ(f.code, ErrorCode::ParseError);
    EXPECT_EQ(where_column(f.where), 6);
  }
}

TEST(FormulaSplit, PartsAddUpToTheWhole) {
  const Samples& s = samples();
  const char* formulas[] = {
      "1 - eps*H",
      "dn + dist*H",
      "-sign(H)*sqrt(K+abs(K))",
      "-(H-kavg)",
      "x + H*2 - K + 3*y",
      "x - (y - H)",
      "-x + H - (k1 - k2)*grad",
      "-(x + H) - -(y - K)",
      "grad*(1 - eps*H)",
      "x > 0 ? 1 : H",
      "(1 - eps*H) * grad * (1 - step(0.5, edge)) + c*(dgx*nx + dgy*ny + dgz*nz)",
      "smoothstep(0, 1, dist) * (dn + dist*H) + (1 - smoothstep(0, 1, dist)) * (1 - eps*H)",
      "d + x - y + z*2 - kavg/2 + 3 - sin(K) + img/255",
      "2*pi - eps*c",
      "x",
  };
  Workspace ws;
  for (const char* text : formulas) {
    SCOPED_TRACE(text);
    Program whole;
    if (!compile_or_report(text, opts(), whole)) continue;
    SplitProgram sp;
    try {
      sp = compile_split_by_curvature(text, opts());
    } catch (const Error& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    EXPECT_EQ(sp.without_curvature.uses() & kCurvatureVars, 0u) << "advective part reads a curvature";
    EXPECT_EQ((sp.without_curvature.uses() | sp.with_curvature.uses()) & ~whole.uses(), 0u);
    EXPECT_EQ(sp.without_curvature.uses() | sp.with_curvature.uses(), whole.uses());
    if ((whole.uses() & kCurvatureVars) == 0) {
      EXPECT_TRUE(sp.with_curvature.is_constant());
      EXPECT_EQ(sp.with_curvature.constant_value(), 0.0);
    }
    std::vector<double> wv(kN);
    double scale = 1;
    for (int i = 0; i < kN; ++i) {
      wv[std::size_t(i)] = whole.evaluate_scalar(s.dbl[std::size_t(i)]);
      scale = std::max(scale, std::abs(wv[std::size_t(i)]));
    }
    int bad = 0;
    for (int i = 0; i < kN; ++i) {
      const double a = sp.without_curvature.evaluate_scalar(s.dbl[std::size_t(i)]);
      const double c = sp.with_curvature.evaluate_scalar(s.dbl[std::size_t(i)]);
      if (std::abs(a + c - wv[std::size_t(i)]) > 1e-12 * scale && bad++ < 3)
        ADD_FAILURE() << "sample " << i << ": " << a << " + " << c << " != " << wv[std::size_t(i)];
    }
    std::vector<float> fw(kN), fa(kN), fc(kN);
    whole.evaluate(inputs_at(s, 0), kN, fw.data(), ws);
    sp.without_curvature.evaluate(inputs_at(s, 0, sp.without_curvature.uses()), kN, fa.data(), ws);
    sp.with_curvature.evaluate(inputs_at(s, 0, sp.with_curvature.uses()), kN, fc.data(), ws);
    bad = 0;
    for (int i = 0; i < kN; ++i) {
      const double sum = double(fa[std::size_t(i)]) + double(fc[std::size_t(i)]);
      if (!same_value(sum, fw[std::size_t(i)], 1e-5, 2e-6 * scale) && bad++ < 3)
        ADD_FAILURE() << "float sample " << i << ": " << fa[std::size_t(i)] << " + " << fc[std::size_t(i)]
                      << " != " << fw[std::size_t(i)];
    }
  }
}

// ---- threads --------------------------------------------------------------------------------

TEST(FormulaThreads, SameResultsFromFourThreads) {
  const Samples& s = samples();
  const Program p = compile(
      "smoothstep(0, 1, dist) * (dn + dist*H) + (1 - smoothstep(0, 1, dist)) * (1 - eps*H)"
      " + (roi > 0.5 ? max(min(x*y, 1), -1) + abs(d) : -(H - kavg)*grad) * sin(3*atan2(y, x))",
      opts());
  const std::pair<int, int> chunks[] = {{512, 0}, {200, 5}, {1, 100}, {300, 7}, {64, 64}};
  std::vector<std::vector<float>> expected;
  {
    Workspace ws;
    for (const auto& [n, off] : chunks) {
      std::vector<float> out(static_cast<std::size_t>(n));
      p.evaluate(inputs_at(s, off), n, out.data(), ws);
      expected.push_back(std::move(out));
    }
  }
  std::atomic<int> mismatches{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      Workspace ws;
      std::vector<float> out(kN);
      for (int iter = 0; iter < 200; ++iter) {
        const std::size_t k = std::size_t(iter + t) % std::size(chunks);
        const auto [n, off] = chunks[k];
        p.evaluate(inputs_at(s, off), n, out.data(), ws);
        if (std::memcmp(out.data(), expected[k].data(), std::size_t(n) * sizeof(float)) != 0) ++mismatches;
      }
    });
  }
  for (auto& th : threads) th.join();
  EXPECT_EQ(mismatches.load(), 0);
  // And the batch result does not depend on where the batch starts (per-sample operations).
  for (int i = 0; i < 200; ++i) {
    const float a = expected[1][std::size_t(i)];
    const float b0 = expected[0][std::size_t(i + 5)];
    ASSERT_TRUE(same_value(a, b0, 1e-6, 1e-6)) << i;
  }
}

}  // namespace levelset::formula
