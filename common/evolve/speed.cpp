#include "evolve/speed.hpp"

#include <cmath>

#include "core/error.hpp"

namespace levelset::evolve {

namespace {

void require_finite(double v, std::string_view what) {
  if (!std::isfinite(v))
    throw Error(ErrorCode::InvalidArgument, "speed", std::string(what) + " must be finite");
}

}  // namespace

SpeedFunction constant_speed(double c) {
  require_finite(c, "the constant speed");
  SpeedFunction s;
  s.name = "constant";
  s.eval = [c](const SpeedBatch& b, const SpeedOutput& out) {
    for (int i = 0; i < b.count; ++i) out.advective[i] = float(c);
  };
  return s;
}

SpeedFunction mean_curvature_flow() {
  SpeedFunction s;
  s.name = "mean-curvature";
  s.needs = kNeedsMean;
  s.has_advective = false;
  s.has_parabolic = true;
  s.diffusion = 1.0;
  s.eval = [](const SpeedBatch& b, const SpeedOutput& out) {
    for (int i = 0; i < b.count; ++i) out.parabolic[i] = -b.mean[i];
  };
  return s;
}

SpeedFunction mean_gaussian_flow() {
  SpeedFunction s;
  s.name = "mean-gaussian";
  s.needs = kNeedsPrincipal;
  s.has_advective = false;
  s.has_parabolic = true;
  s.diffusion = 0.5;  // sqrt(K) <= |H| / 2
  s.eval = [](const SpeedBatch& b, const SpeedOutput& out) {
    for (int i = 0; i < b.count; ++i) {
      const float k = b.gauss[i] > 0.0f ? std::sqrt(b.gauss[i]) : 0.0f;
      out.parabolic[i] = b.mean[i] > 0.0f ? -k : (b.mean[i] < 0.0f ? k : 0.0f);
    }
  };
  return s;
}

SpeedFunction volume_preserving_flow() {
  SpeedFunction s;
  s.name = "volume-preserving";
  s.needs = kNeedsMean | kNeedsMeanAverage;
  s.has_advective = false;
  s.has_parabolic = true;
  s.diffusion = 1.0;
  s.eval = [](const SpeedBatch& b, const SpeedOutput& out) {
    for (int i = 0; i < b.count; ++i) out.parabolic[i] = -(b.mean[i] - float(b.kavg));
  };
  return s;
}

SpeedFunction curvature_regularized(double c, double eps) {
  require_finite(c, "c");
  require_finite(eps, "eps");
  SpeedFunction s;
  s.name = "one-minus-eps-kappa";
  s.needs = kNeedsMean;
  s.has_parabolic = true;
  s.diffusion = std::abs(c * eps);
  s.eval = [c, eps](const SpeedBatch& b, const SpeedOutput& out) {
    for (int i = 0; i < b.count; ++i) {
      out.advective[i] = float(c);
      out.parabolic[i] = float(-c * eps * double(b.mean[i]));
    }
  };
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

}  // namespace levelset::evolve
