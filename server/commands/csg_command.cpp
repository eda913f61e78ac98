// levelsetd csg union|intersection|difference A.lsg B.lsg -o OUT.lsg [--voxel-size h]
// [--fair-seams TIME --seam-radius R]: Boolean operations on two bands (common/apps/csg.hpp).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "apps/csg.hpp"
#include "apps/shape_measures.hpp"
#include "commands/number_checks.hpp"
#include "commands/output_check.hpp"
#include "commands/command.hpp"
#include "commands/report.hpp"
#include "commands/shape_report.hpp"
#include "grid/lsg_file.hpp"

namespace levelset::cli {

namespace {

struct CsgArgs {
  std::string op, a, b, output, stats;
  double voxel_size = 0, half_width = 0, seam_time = 0, seam_radius = 0;
};

int run_csg(const CsgArgs& args) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const LsgReadResult a = load_lsg(args.a), b = load_lsg(args.b);
  const auto t1 = Clock::now();
  apps::CsgOptions o;
  o.op = apps::csg_op_from_name(args.op);
  o.voxel_size = args.voxel_size;
  o.half_width = args.half_width;
  o.seam_time = args.seam_time;
  o.seam_radius = args.seam_radius;
  const apps::CsgResult r = apps::csg(a.band, b.band, o);
  const auto t2 = Clock::now();
  const LsgWriteResult written = save_lsg(r.band, args.output);
  const auto t3 = Clock::now();
  std::FILE* out = summary_stream(args.stats);
  std::fprintf(out, "%s %s %s: h %g, %zu active voxels, %d seam fairing steps, %.3f s -> %s (%s)\n", args.op.c_str(),
               args.a.c_str(), args.b.c_str(), r.band.voxel_size(), r.band.active_voxel_count(), r.seam_steps,
               secs(t1, t2), args.output.c_str(), human_bytes(written.file_bytes).c_str());
  const apps::ShapeMeasures m = apps::measure_shape(r.band);
  print_shape(out, "result", m);
  Stats stats("csg", r.band);
  stats.set_phases("csg", t0, t1, t2, t3);
  stats.extra["operation"] = args.op;
  stats.extra["voxel_size"] = r.band.voxel_size();
  stats.extra["half_width"] = r.band.half_width();
  stats.extra["candidate_bricks"] = r.candidate_bricks;
  stats.extra["seam_time"] = r.seam_time;
  stats.extra["seam_steps"] = r.seam_steps;
  stats.extra["seam_radius"] = args.seam_radius;
  stats.extra["result"] = shape_json(m);
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace

Command add_csg_command(CLI::App& app, int& threads) {
  auto args = std::make_shared<CsgArgs>();
  CLI::App* sub = app.add_subcommand("csg", "Boolean operations on two bands: union, intersection, difference (A minus B)");
  sub->add_option("operation", args->op, "union, intersection or difference")
      ->required()
      ->check(CLI::IsMember({"union", "intersection", "difference"}));
  sub->add_option("a", args->a, "First .lsg (A)")->required();
  sub->add_option("b", args->b, "Second .lsg (B)")->required();
  sub->add_option("-o,--output", args->output, "Output .lsg file")->required()->check(lsg_output());
  sub->add_option("--voxel-size", args->voxel_size, "Result voxel size (default: the finer input's)")->transform(levelset::cli::positive());
  sub->add_option("--band", args->half_width, "Result half-width in voxels (default: the larger input's)")
      ->transform(levelset::cli::in_range(2.0, 1024.0));
  auto* fair = sub->add_option("--fair-seams", args->seam_time, "Fair the seam with mean curvature flow for TIME (world units^2)")
                   ->transform(levelset::cli::positive());
  auto* radius = sub->add_option("--seam-radius", args->seam_radius,
                                 "Region of influence R (world units): full speed where |a|, |b| <= R, none beyond 2R")
                     ->transform(levelset::cli::positive());
  fair->needs(radius);
  add_common_options(sub, threads, args->stats);
  return {sub, [args]() { return run_csg(*args); }};
}

}  // namespace levelset::cli
