// levelsetd minmax IN.lsg --radius R [--tolerance TOL] [--max-steps N] -o OUT.lsg: feature-
// preserving smoothing to a steady state (common/apps/minmax_flow.hpp).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "apps/minmax_flow.hpp"
#include "commands/number_checks.hpp"
#include "commands/output_check.hpp"
#include "commands/command.hpp"
#include "commands/report.hpp"
#include "commands/shape_report.hpp"
#include "grid/lsg_file.hpp"

namespace levelset::cli {

namespace {

struct MinMaxArgs {
  std::string input, output, stats;
  int radius = 3;
  double tolerance = 1e-4;
  int max_steps = 2000;
  int update_every = 1;
};

int run_minmax(const MinMaxArgs& args) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const LsgReadResult in = load_lsg(args.input);
  const auto t1 = Clock::now();
  apps::MinMaxOptions o;
  o.radius = args.radius;
  o.tolerance = args.tolerance;
  o.max_steps = args.max_steps;
  o.update_every = args.update_every;
  const apps::MinMaxResult r = apps::minmax_flow(in.band, o);
  const auto t2 = Clock::now();
  const LsgWriteResult written = save_lsg(r.band, args.output);
  const auto t3 = Clock::now();
  std::FILE* out = summary_stream(args.stats);
  std::fprintf(out, "%s: min/max flow R = %d voxels, %d steps to t = %.6g, %s, %.3f s -> %s (%s)\n", args.input.c_str(),
               args.radius, r.steps, r.time, r.steady ? "steady" : "NOT steady (max steps reached)", secs(t1, t2),
               args.output.c_str(), human_bytes(written.file_bytes).c_str());
  print_shape(out, "before", r.before);
  print_shape(out, "after", r.after);
  Stats stats("minmax", r.band);
  stats.set_phases("minmax", t0, t1, t2, t3);
  stats.extra["radius"] = args.radius;
  stats.extra["tolerance"] = args.tolerance;
  stats.extra["steps"] = r.steps;
  stats.extra["time"] = r.time;
  stats.extra["steady"] = r.steady;
  stats.extra["steady_step"] = r.steady_step;
  nlohmann::json history = nlohmann::json::array();
  for (const apps::MinMaxChunk& c : r.history)
    history.push_back({{"step", c.step}, {"time", c.time}, {"mean_change", c.mean_change}, {"max_change", c.max_change}});
  stats.extra["history"] = history;
  stats.extra["before"] = shape_json(r.before);
  stats.extra["after"] = shape_json(r.after);
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace

Command add_minmax_command(CLI::App& app, int& threads) {
  auto args = std::make_shared<MinMaxArgs>();
  CLI::App* sub = app.add_subcommand("minmax", "Min/max flow: remove oscillations below a scale, keep features, stop at steady state");
  sub->add_option("input", args->input, "Input .lsg")->required();
  sub->add_option("-o,--output", args->output, "Output .lsg file")->required()->check(lsg_output());
  sub->add_option("--radius", args->radius, "Scale R in voxels (the average's cube has 2R+1 voxels a side)")
      ->required()
      ->transform(levelset::cli::in_range(1, 16));
  sub->add_option("--tolerance", args->tolerance, "Steady when the mean change near the surface < TOL voxels per step")
      ->transform(levelset::cli::positive());
  sub->add_option("--max-steps", args->max_steps, "Give up after N steps")->transform(levelset::cli::positive_int());
  sub->add_option("--update-every", args->update_every, "Recompute the average every K steps")->transform(levelset::cli::positive_int());
  add_common_options(sub, threads, args->stats);
  return {sub, [args]() { return run_minmax(*args); }};
}

}  // namespace levelset::cli
