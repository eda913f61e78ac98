#include "apps/offset.hpp"

#include <chrono>
#include <cmath>

#include "core/error.hpp"
#include "core/text.hpp"
#include "distance/redistance.hpp"

namespace levelset::apps {

OffsetResult offset_surface(const NarrowBand& band, const OffsetOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const double D = options.distance;
  if (!std::isfinite(D) || D == 0.0)
    throw Error(ErrorCode::InvalidArgument, "offset distance", "must be finite and non-zero");
  if (!(options.max_distance_voxels > 0) || std::abs(D) / band.voxel_size() > options.max_distance_voxels)
    throw Error(ErrorCode::InvalidArgument, "offset distance",
                "|D| / h exceeds max_distance_voxels (" + format_number(options.max_distance_voxels) + ")");
  evolve::EvolutionOptions eo;
  eo.speed = evolve::constant_speed(D > 0 ? 1.0 : -1.0);
  eo.scheme = options.scheme;
  eo.rk_order = options.rk_order;
  eo.cfl = options.cfl;
  eo.time = std::abs(D);
  eo.redistance_every = options.redistance_every;
  eo.drift_tolerance = options.drift_tolerance;
  eo.progress = options.progress;
  evolve::EvolutionResult er = evolve::evolve(band, eo);
  evolve::throw_if_stopped(er, "offset");
  OffsetResult result;
  result.steps = er.steps;
  result.time = er.time;
  result.redistance_count = er.redistance_count;
  result.landmine_count = er.landmine_count;
  if (options.redistance_result) {
    RedistanceOptions ro;
    ro.progress = options.progress;
    result.band = redistance(er.band, ro).band;
  } else {
    result.band = std::move(er.band);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace levelset::apps
