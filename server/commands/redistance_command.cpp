// levelsetd redistance IN.lsg --method sweep|march [--band W] -o OUT.lsg: restore |grad u| = 1.
#include <chrono>
#include <cstdio>

#include "commands/commands.hpp"
#include "commands/report.hpp"
#include "distance/redistance.hpp"
#include "grid/lsg_file.hpp"

namespace levelset::cli {

int run_redistance(const RedistanceArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const LsgReadResult in = load_lsg(args.input);
  const auto t1 = std::chrono::steady_clock::now();
  RedistanceOptions options;
  options.method = args.method == "march" ? RedistanceMethod::March : RedistanceMethod::Sweep;
  options.half_width = args.band;
  options.order = args.order;
  const RedistanceResult result = redistance(in.band, options);
  const auto t2 = std::chrono::steady_clock::now();
  const LsgWriteResult written = save_lsg(result.band, args.output);
  const auto t3 = std::chrono::steady_clock::now();

  std::fprintf(summary_stream(args.stats), "%s: %zu -> %zu active voxels (%s), %.3f s -> %s (%s)\n", args.input.c_str(),
              in.band.active_voxel_count(), result.band.active_voxel_count(), args.method.c_str(),
              secs(t1, t2), args.output.c_str(), human_bytes(written.file_bytes).c_str());
  Stats stats("redistance", result.band);
  stats.set_phases("redistance", t0, t1, t2, t3);
  stats.extra["method"] = args.method;
  stats.extra["order"] = args.order;
  stats.extra["input_active_voxels"] = in.band.active_voxel_count();
  stats.extra["band_half_width"] = result.band.half_width();
  stats.extra["interface_voxels"] = result.interface_voxels;
  stats.extra["sweep_iterations"] = result.sweep_iterations;
  stats.extra["march_rounds"] = result.march_rounds;
  stats.extra["voxels_per_second"] = double(result.band.active_voxel_count()) / std::max(1e-12, secs(t1, t2));
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace levelset::cli
