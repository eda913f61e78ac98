#include "apps/fairing.hpp"

#include <chrono>
#include <cmath>

#include "core/error.hpp"

namespace levelset::apps {

FairingFlow fairing_flow_from_name(std::string_view name) {
  if (name == "mean-curvature") return FairingFlow::MeanCurvature;
  if (name == "mean-gaussian") return FairingFlow::MeanGaussian;
  if (name == "volume-preserving") return FairingFlow::VolumePreserving;
  throw Error(ErrorCode::InvalidArgument, std::string(name),
              "unknown fairing flow; known: mean-curvature, mean-gaussian, volume-preserving");
}

std::string_view fairing_flow_name(FairingFlow flow) {
  switch (flow) {
    case FairingFlow::MeanCurvature: return "mean-curvature";
    case FairingFlow::MeanGaussian: return "mean-gaussian";
    case FairingFlow::VolumePreserving: return "volume-preserving";
  }
  return "?";
}

FairingResult fair_surface(const NarrowBand& band, const FairingOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const bool by_time = options.time != 0, by_steps = options.steps != 0;
  if (by_time == by_steps)
    throw Error(ErrorCode::InvalidArgument, "fairing", "give exactly one of time and steps");
  if (by_time && !(std::isfinite(options.time) && options.time > 0))
    throw Error(ErrorCode::InvalidArgument, "fairing time", "must be finite and > 0");
  if (by_steps && (options.steps < 0 || options.steps > options.max_steps))
    throw Error(ErrorCode::InvalidArgument, "fairing steps", "must be in [1, max_steps]");
  if (options.redistance_every < 0)
    throw Error(ErrorCode::InvalidArgument, "fairing redistance_every", "must be >= 0");

  FairingResult result;
  if (options.measure) result.before = measure_shape(band);
  evolve::EvolutionOptions eo;
  eo.speed = evolve::builtin_speed(fairing_flow_name(options.flow));
  eo.time = options.time;
  eo.steps = options.steps;
  eo.max_steps = options.max_steps;
  eo.scheme = options.scheme;
  eo.rk_order = options.rk_order;
  eo.cfl = options.cfl;
  eo.redistance_every = options.redistance_every;
  eo.progress = options.progress;
  evolve::EvolutionResult er = evolve::evolve(band, eo);
  evolve::throw_if_stopped(er, "fairing");
  result.band = std::move(er.band);
  result.steps = er.steps;
  result.time = er.time;
  result.redistance_count = er.redistance_count;
  if (options.measure) result.after = measure_shape(result.band);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace levelset::apps
