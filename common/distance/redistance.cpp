// redistance(): validation and the phases in order; each phase lives in its own file:
// redistance_domain (domain and output band), interface_init (step 1), eikonal_sweep and
// eikonal_march (step 2).
#include "distance/redistance.hpp"

#include <chrono>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "distance/eikonal_march.hpp"
#include "distance/eikonal_sweep.hpp"
#include "distance/interface_init.hpp"
#include "distance/redistance_domain.hpp"

namespace levelset {

namespace {

void validate(const RedistanceOptions& o) {
  if (!(o.half_width == 0.0 || (std::isfinite(o.half_width) && o.half_width >= 1.0)))
    throw Error(ErrorCode::InvalidArgument, "half_width",
                "must be 0 (keep the input's) or a finite width >= 1 voxel, got " +
                    std::to_string(o.half_width));
  if (o.max_sweep_iterations < 1)
    throw Error(ErrorCode::InvalidArgument, "max_sweep_iterations",
                "must be >= 1, got " + std::to_string(o.max_sweep_iterations));
  if (o.order != 1 && o.order != 2)
    throw Error(ErrorCode::InvalidArgument, "order", "must be 1 or 2, got " + std::to_string(o.order));
  if (!(std::isfinite(o.tolerance) && o.tolerance >= 0.0))
    throw Error(ErrorCode::InvalidArgument, "tolerance", "must be finite and >= 0");
}

}  // namespace

RedistanceResult redistance(const NarrowBand& in, const RedistanceOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  validate(options);
  GridFrame frame = in.frame();
  if (options.half_width != 0.0) frame.half_width = options.half_width;
  RedistanceResult result{NarrowBand(frame), 0, 0, 0, 0.0};  // validates the new frame
  result.band.set_far_inside(in.far_inside());
  options.progress.step(0.0, "redistance");
  if (in.brick_count() > 0) {
    const double grow = frame.half_width - in.half_width();
    const int grow_voxels = grow > 0.0 ? int(std::ceil(grow)) : 0;
    detail::RedistanceDomain w = detail::build_domain(in, grow_voxels, options.progress);
    result.interface_voxels = detail::init_interface(in, w);
    options.progress.step(0.1, "redistance interface");
    if (options.method == RedistanceMethod::Sweep) {
      result.sweep_iterations = detail::sweep(w, options.order, options.max_sweep_iterations,
                                              float(options.tolerance), options.progress);
    } else {
      result.march_rounds = detail::march(w, options.order, frame.half_width, float(options.tolerance), options.progress);
    }
    options.progress.step(0.9, "redistance assemble");
    result.band = detail::assemble_band(in, w, frame);
  }
  options.progress.step(1.0, "redistance");
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace levelset
