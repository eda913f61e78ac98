// levelsetd fair IN.lsg --flow NAME (--time T | --steps N) -o OUT.lsg: smooth the surface with a
// curvature flow and report the roughness before and after (common/apps/fairing.hpp).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "apps/fairing.hpp"
#include "commands/number_checks.hpp"
#include "commands/output_check.hpp"
#include "commands/command.hpp"
#include "commands/report.hpp"
#include "commands/shape_report.hpp"
#include "core/error.hpp"
#include "grid/lsg_file.hpp"

namespace levelset::cli {

namespace {

struct FairArgs {
  std::string input, output, stats;
  std::string flow = "mean-curvature";
  double time = 0;
  int steps = 0;
  int redistance_every = 10;
};

int run_fair(const FairArgs& args) {
  using Clock = std::chrono::steady_clock;
  if ((args.time > 0) == (args.steps > 0))
    throw Error(ErrorCode::InvalidArgument, "fair", "give exactly one of --time and --steps");
  const auto t0 = Clock::now();
  const LsgReadResult in = load_lsg(args.input);
  const auto t1 = Clock::now();
  apps::FairingOptions o;
  o.flow = apps::fairing_flow_from_name(args.flow);
  o.time = args.time;
  o.steps = args.steps;
  o.redistance_every = args.redistance_every;
  const apps::FairingResult r = apps::fair_surface(in.band, o);
  const auto t2 = Clock::now();
  const LsgWriteResult written = save_lsg(r.band, args.output);
  const auto t3 = Clock::now();
  std::FILE* out = summary_stream(args.stats);
  std::fprintf(out, "%s: %s flow, %d steps to t = %.6g, %.3f s -> %s (%s)\n", args.input.c_str(), args.flow.c_str(),
               r.steps, r.time, secs(t1, t2), args.output.c_str(), human_bytes(written.file_bytes).c_str());
  print_shape(out, "before", r.before);
  print_shape(out, "after", r.after);
  Stats stats("fair", r.band);
  stats.set_phases("fair", t0, t1, t2, t3);
  stats.extra["flow"] = args.flow;
  stats.extra["steps"] = r.steps;
  stats.extra["time"] = r.time;
  stats.extra["redistance_count"] = r.redistance_count;
  stats.extra["before"] = shape_json(r.before);
  stats.extra["after"] = shape_json(r.after);
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace

Command add_fair_command(CLI::App& app, int& threads) {
  auto args = std::make_shared<FairArgs>();
  CLI::App* sub = app.add_subcommand("fair", "Fairing: smooth the surface with a curvature flow, report roughness");
  sub->add_option("input", args->input, "Input .lsg")->required();
  sub->add_option("-o,--output", args->output, "Output .lsg file")->required()->check(lsg_output());
  sub->add_option("--flow", args->flow, "mean-curvature (default), mean-gaussian, volume-preserving")
      ->check(CLI::IsMember({"mean-curvature", "mean-gaussian", "volume-preserving"}));
  auto* time_opt = sub->add_option("--time", args->time, "Evolve until this time (world units^2)")->transform(levelset::cli::positive());
  auto* steps_opt = sub->add_option("--steps", args->steps, "Number of time steps")->transform(levelset::cli::positive_int());
  time_opt->excludes(steps_opt);
  sub->add_option("--redistance-every", args->redistance_every, "Redistance every K steps (0: never)")
      ->transform(levelset::cli::non_negative_int());
  add_common_options(sub, threads, args->stats);
  return {sub, [args]() { return run_fair(*args); }};
}

}  // namespace levelset::cli
