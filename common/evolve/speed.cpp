#include "evolve/speed.hpp"

#include <algorithm>

#include <array>
#include <cmath>
#include <memory>

#include "core/error.hpp"
#include "formula/formula.hpp"

namespace levelset::evolve {

namespace {

void require_finite(double v, std::string_view what) {
  if (!std::isfinite(v))
    throw Error(ErrorCode::InvalidArgument, "speed", std::string(what) + " must be finite");
}

}  // namespace

namespace {

using formula::Var;

std::uint32_t needs_of(const formula::Program& p) {
  std::uint32_t needs = kNeedsNothing;
  if (p.uses_var(Var::x) || p.uses_var(Var::y) || p.uses_var(Var::z)) needs |= kNeedsPosition;
  if (p.uses_var(Var::nx) || p.uses_var(Var::ny) || p.uses_var(Var::nz)) needs |= kNeedsNormal;
  if (p.uses_var(Var::H)) needs |= kNeedsMean;
  if (p.uses_var(Var::k1) || p.uses_var(Var::k2)) needs |= kNeedsPrincipal;
  else if (p.uses_var(Var::K)) needs |= kNeedsGauss;
  if (p.uses_var(Var::kavg)) needs |= kNeedsMeanAverage | kNeedsMean;
  if (p.uses_var(Var::grad)) needs |= kNeedsGradNorm;
  if (p.uses_var(Var::dist)) needs |= kNeedsDist;
  if (p.uses_var(Var::dgx) || p.uses_var(Var::dgy) || p.uses_var(Var::dgz)) needs |= kNeedsDistGradient;
  if (p.uses_var(Var::dn)) needs |= kNeedsDistGradient | kNeedsNormal;
  if (p.uses_var(Var::img)) needs |= kNeedsImage;
  if (p.uses_var(Var::edge)) needs |= kNeedsEdge;
  if (p.uses_var(Var::roi)) needs |= kNeedsRoi;
  return needs;
}

// The batch's arrays by formula variable.
std::array<const float*, formula::kVarCount> inputs_of(const SpeedBatch& b, std::vector<float>& scalars) {
  std::array<const float*, formula::kVarCount> in{};
  in[int(Var::d)] = b.d;
  in[int(Var::x)] = b.x;
  in[int(Var::y)] = b.y;
  in[int(Var::z)] = b.z;
  in[int(Var::nx)] = b.nx;
  in[int(Var::ny)] = b.ny;
  in[int(Var::nz)] = b.nz;
  in[int(Var::H)] = b.mean;
  in[int(Var::K)] = b.gauss;
  in[int(Var::k1)] = b.k1;
  in[int(Var::k2)] = b.k2;
  in[int(Var::grad)] = b.grad;
  in[int(Var::dist)] = b.dist;
  in[int(Var::dgx)] = b.dgx;
  in[int(Var::dgy)] = b.dgy;
  in[int(Var::dgz)] = b.dgz;
  in[int(Var::dn)] = b.dn;
  in[int(Var::img)] = b.img;
  in[int(Var::edge)] = b.edge;
  in[int(Var::roi)] = b.roi;
  // Per-batch scalars broadcast: t, h, kavg.
  scalars.assign(std::size_t(3) * std::size_t(b.count), 0.0f);
  std::fill_n(scalars.begin(), b.count, float(b.time));
  std::fill_n(scalars.begin() + b.count, b.count, float(b.h));
  std::fill_n(scalars.begin() + 2 * b.count, b.count, float(b.kavg));
  in[int(Var::t)] = scalars.data();
  in[int(Var::h)] = scalars.data() + b.count;
  in[int(Var::kavg)] = scalars.data() + 2 * b.count;
  return in;
}

// Largest |f| over curvature probes of size <= 1 (the other inputs at neutral values).
double probe_diffusion(const formula::Program& p) {
  double worst = 0.0;
  for (double H : {-1.0, 0.0, 1.0})
    for (double K : {-1.0, 0.0, 0.25, 1.0}) {
      std::array<double, formula::kVarCount> v{};
      v[int(Var::grad)] = 1.0;
      v[int(Var::nz)] = 1.0;
      v[int(Var::h)] = 1.0;
      v[int(Var::H)] = H;
      v[int(Var::K)] = K;
      v[int(Var::k1)] = 0.5 * H;
      v[int(Var::k2)] = 0.5 * H;
      const double f = p.evaluate_scalar(v);
      if (std::isfinite(f)) worst = std::max(worst, std::abs(f));
    }
  return std::max(worst, 0.05);
}

}  // namespace

SpeedFunction formula_speed(std::string_view text, const std::map<std::string, double, std::less<>>& constants) {
  formula::CompileOptions options;
  options.constants = constants;
  formula::SplitProgram split = formula::compile_split_by_curvature(text, options);
  SpeedFunction s;
  s.name = std::string(text);
  s.needs = needs_of(split.without_curvature) | needs_of(split.with_curvature);
  const formula::Program& adv = split.without_curvature;
  const formula::Program& par = split.with_curvature;
  s.has_advective = !(adv.is_constant() && adv.constant_value() == 0.0);
  s.has_parabolic = !(par.is_constant() && par.constant_value() == 0.0);
  s.diffusion = s.has_parabolic ? probe_diffusion(par) : 0.0;
  auto programs = std::make_shared<formula::SplitProgram>(std::move(split));
  s.eval = [programs](const SpeedBatch& b, const SpeedOutput& out) {
    thread_local formula::Workspace ws;
    thread_local std::vector<float> scalars;
    const auto in = inputs_of(b, scalars);
    programs->without_curvature.evaluate(in, b.count, out.advective, ws);
    programs->with_curvature.evaluate(in, b.count, out.parabolic, ws);
  };
  return s;
}

SpeedFunction constant_speed(double c) {
  require_finite(c, "the constant speed");
  SpeedFunction s = formula_speed("c", {{"c", c}});
  s.name = "constant";
  return s;
}

SpeedFunction mean_curvature_flow() {
  SpeedFunction s = formula_speed("-H");
  s.name = "mean-curvature";
  return s;
}

SpeedFunction mean_gaussian_flow() {
  SpeedFunction s = formula_speed("-sign(H)*sqrt(max(K,0))");
  s.name = "mean-gaussian";
  s.diffusion = 0.5;  // sqrt(K) <= |H| / 2 for real surfaces (the probe is more cautious)
  return s;
}

SpeedFunction volume_preserving_flow() {
  SpeedFunction s = formula_speed("-(H-kavg)");
  s.name = "volume-preserving";
  s.diffusion = 1.0;
  return s;
}

SpeedFunction curvature_regularized(double c, double eps) {
  require_finite(c, "c");
  require_finite(eps, "eps");
  SpeedFunction s = formula_speed("c - c*eps*H", {{"c", c}, {"eps", eps}});  // c advective, the rest parabolic
  s.name = "one-minus-eps-kappa";
  return s;
}

std::vector<std::string> builtin_speed_names() {
  return {"constant", "mean-curvature", "mean-gaussian", "volume-preserving", "one-minus-eps-kappa"};
}

SpeedFunction builtin_speed(std::string_view name, double c, double eps) {
  if (name == "constant") return constant_speed(c);
  if (name == "mean-curvature") return mean_curvature_flow();
  if (name == "mean-gaussian") return mean_gaussian_flow();
  if (name == "volume-preserving") return volume_preserving_flow();
  if (name == "one-minus-eps-kappa") return curvature_regularized(c, eps);
  std::string known;
  for (const std::string& n : builtin_speed_names()) known += (known.empty() ? "" : ", ") + n;
  throw Error(ErrorCode::InvalidArgument, "speed", "unknown speed '" + std::string(name) + "' (known: " + known + ")");
}

SpeedFunction speed_from_text(std::string_view name_or_formula, double c, double eps,
                              const std::map<std::string, double, std::less<>>& constants) {
  const auto names = builtin_speed_names();
  if (std::find(names.begin(), names.end(), name_or_formula) != names.end()) return builtin_speed(name_or_formula, c, eps);
  return formula_speed(name_or_formula, constants);
}

}  // namespace levelset::evolve
