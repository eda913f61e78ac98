// levelsetd offset IN.lsg --distance D -o OUT.lsg: move the surface by D along its normals
// (common/apps/offset.hpp).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "apps/offset.hpp"
#include "apps/shape_measures.hpp"
#include "commands/output_check.hpp"
#include "commands/command.hpp"
#include "commands/report.hpp"
#include "commands/shape_report.hpp"
#include "grid/lsg_file.hpp"

namespace levelset::cli {

namespace {

struct OffsetArgs {
  std::string input, output, stats;
  double distance = 0;
  std::string scheme = "weno5";
  int rk = 3;
  bool measure = false;
};

evolve::Scheme offset_scheme(const std::string& s) {
  if (s == "eno2") return evolve::Scheme::Eno2;
  if (s == "godunov") return evolve::Scheme::Upwind1;
  return evolve::Scheme::Weno5;
}

int run_offset(const OffsetArgs& args) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const LsgReadResult in = load_lsg(args.input);
  const auto t1 = Clock::now();
  apps::OffsetOptions o;
  o.distance = args.distance;
  o.scheme = offset_scheme(args.scheme);
  o.rk_order = args.rk;
  const apps::OffsetResult r = apps::offset_surface(in.band, o);
  const auto t2 = Clock::now();
  const LsgWriteResult written = save_lsg(r.band, args.output);
  const auto t3 = Clock::now();
  std::FILE* out = summary_stream(args.stats);
  std::fprintf(out, "%s: offset by %g in %d steps, %zu -> %zu active voxels, %.3f s -> %s (%s)\n", args.input.c_str(),
               args.distance, r.steps, in.band.active_voxel_count(), r.band.active_voxel_count(), secs(t1, t2),
               args.output.c_str(), human_bytes(written.file_bytes).c_str());
  Stats stats("offset", r.band);
  stats.seconds["read"] = secs(t0, t1);
  stats.seconds["offset"] = secs(t1, t2);
  stats.seconds["write"] = secs(t2, t3);
  stats.extra["distance"] = args.distance;
  stats.extra["scheme"] = args.scheme;
  stats.extra["rk"] = args.rk;
  stats.extra["steps"] = r.steps;
  stats.extra["redistance_count"] = r.redistance_count;
  stats.extra["landmine_count"] = r.landmine_count;
  stats.extra["output"] = args.output;
  if (args.measure || !args.stats.empty()) {
    const apps::ShapeMeasures before = apps::measure_shape(in.band), after = apps::measure_shape(r.band);
    print_shape(out, "before", before);
    print_shape(out, "after", after);
    stats.extra["before"] = shape_json(before);
    stats.extra["after"] = shape_json(after);
  }
  stats.seconds["total"] = secs(t0, Clock::now());
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace

Command add_offset_command(CLI::App& app, int& threads) {
  auto args = std::make_shared<OffsetArgs>();
  CLI::App* sub = app.add_subcommand("offset", "Offset surface: move the surface by a signed distance D along its normals");
  sub->add_option("input", args->input, "Input .lsg")->required();
  sub->add_option("-o,--output", args->output, "Output .lsg file")->required()->check(lsg_output());
  sub->add_option("--distance", args->distance, "Signed distance D in world units (> 0 grows, < 0 shrinks)")->required();
  sub->add_option("--scheme", args->scheme, "Spatial scheme: weno5 (default), eno2, godunov")
      ->check(CLI::IsMember({"weno5", "eno2", "godunov"}));
  sub->add_option("--rk", args->rk, "Time integration: 3 (TVD-RK3, default) or 1 (forward Euler)")->check(CLI::IsMember({1, 3}));
  sub->add_flag("--measure", args->measure, "Print area, volume, genus and roughness before and after");
  add_common_options(sub, threads, args->stats);
  return {sub, [args]() { return run_offset(*args); }};
}

}  // namespace levelset::cli
