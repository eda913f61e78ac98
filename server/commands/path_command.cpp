// levelsetd path (--obstacles OBST.lsg | --cost FORMULA | --cost-grid COST.nrrd) --from x,y,z
// --to x,y,z [grid options] -o PATH.txt: the cheapest path by fast marching and back-tracing
// (common/apps/path_planning.hpp). PATH.txt: '#' header lines (length, time, points, grid),
// then one "x y z" per line from start to goal.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "apps/path_planning.hpp"
#include "commands/number_checks.hpp"
#include "commands/command.hpp"
#include "commands/medium_options.hpp"
#include "commands/report.hpp"
#include "core/file_io.hpp"

namespace levelset::cli {

namespace {

struct PathArgs {
  MediumArgs medium;
  std::string from, to;
  double step = 0.5;
  int rk = 2;
  std::string output, stats;
};

std::string path_text(const apps::PathResult& r, const apps::DenseGrid& g, const Vec3d& a, const Vec3d& b) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "# levelsetd path from %.17g,%.17g,%.17g to %.17g,%.17g,%.17g\n", a.x, a.y, a.z,
                b.x, b.y, b.z);
  out += line;
  std::snprintf(line, sizeof line, "# length %.9g time %.9g points %zu\n", r.length, r.arrival_time, r.points.size());
  out += line;
  std::snprintf(line, sizeof line, "# grid %d %d %d voxel_size %.9g origin %.9g %.9g %.9g\n", g.nx, g.ny, g.nz,
                g.voxel_size, g.origin.x, g.origin.y, g.origin.z);
  out += line;
  for (const Vec3d& p : r.points) {
    std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", p.x, p.y, p.z);
    out += line;
  }
  return out;
}

int run_path(const PathArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const Vec3d from = parse_point(args.from, "--from"), to = parse_point(args.to, "--to");
  const Medium medium = load_medium(args.medium, {from, to});
  apps::PathOptions o;
  o.grid = medium.grid;
  o.start = from;
  o.goal = to;
  o.cost = medium.cost;
  o.obstacles = medium.obstacles;
  o.order = args.medium.order;
  o.trace.step = args.step;
  o.trace.rk_order = args.rk;
  const apps::PathResult r = apps::plan_path(o);
  const auto t1 = std::chrono::steady_clock::now();
  write_file_atomically(args.output, path_text(r, medium.grid, from, to));
  const auto t2 = std::chrono::steady_clock::now();

  const apps::DenseGrid& g = medium.grid;
  std::fprintf(summary_stream(args.stats),
               "path: length %.6g, time %.6g, %zu points; grid %dx%dx%d h %.4g, %llu blocked; %.3f s -> %s\n", r.length,
               r.arrival_time, r.points.size(), g.nx, g.ny, g.nz, g.voxel_size, (unsigned long long)r.blocked,
               secs(t0, t2), args.output.c_str());
  Stats stats("path", medium.band ? *medium.band : NarrowBand{});
  stats.seconds["read"] = medium.seconds_read;
  stats.seconds["cost"] = r.seconds_cost;
  stats.seconds["march"] = r.seconds_march;
  stats.seconds["trace"] = r.seconds_trace;
  stats.seconds["write"] = secs(t1, t2);
  stats.seconds["total"] = secs(t0, t2);
  stats.extra["length"] = r.length;
  stats.extra["time"] = r.arrival_time;
  stats.extra["points"] = r.points.size();
  stats.extra["trace_steps"] = r.steps;
  stats.extra["grid"] = {g.nx, g.ny, g.nz};
  stats.extra["voxel_size"] = g.voxel_size;
  stats.extra["grid_voxels"] = g.voxel_count();
  stats.extra["accepted"] = r.accepted;
  stats.extra["blocked"] = r.blocked;
  stats.extra["first_order_fallbacks"] = r.first_order_fallbacks;
  stats.extra["order"] = args.medium.order;
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace

Command add_path_command(CLI::App& app, int& threads) {
  auto args = std::make_shared<PathArgs>();
  CLI::App* sub = app.add_subcommand("path", "Cheapest path between two points around obstacles / through a cost field");
  sub->add_option("--from", args->from, "Start point x,y,z")->required();
  sub->add_option("--to", args->to, "Goal point x,y,z")->required();
  add_medium_options(sub, args->medium);
  sub->add_option("--step", args->step, "Trace step in voxels (default 0.5)")->transform(levelset::cli::in_range(0.01, 1.0));
  sub->add_option("--rk", args->rk, "Trace integrator: 2 (Heun, default) or 4")->check(CLI::IsMember({2, 4}));
  sub->add_option("-o,--output", args->output, "Output polyline (text: one 'x y z' per line)")->required();
  add_common_options(sub, threads, args->stats);
  return {sub, [args] { return run_path(*args); }};
}

}  // namespace levelset::cli
