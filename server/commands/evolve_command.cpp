// levelsetd evolve IN.lsg -o OUT.lsg --speed NAME (--steps N | --time T) [...]: move the
// surface with the level set equation (common/evolve/evolution.hpp).
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <map>
#include <cstdio>

#include "commands/commands.hpp"
#include "commands/report.hpp"
#include "core/error.hpp"
#include "evolve/evolution.hpp"
#include "grid/lsg_file.hpp"

namespace levelset::cli {

int run_evolve(const EvolveArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const LsgReadResult in = load_lsg(args.input);
  const auto t1 = std::chrono::steady_clock::now();
  evolve::EvolutionOptions options;
  if (!args.speed.empty()) {
    std::map<std::string, double, std::less<>> constants;
    for (const std::string& kv : args.constants) {
      const std::size_t eq = kv.find('=');
      char* end = nullptr;
      const std::string value = eq == std::string::npos ? "" : kv.substr(eq + 1);
      const double v = std::strtod(value.c_str(), &end);
      if (eq == std::string::npos || eq == 0 || value.empty() || end != value.c_str() + value.size())
        throw Error(ErrorCode::InvalidArgument, "--const", "expected NAME=VALUE, got '" + kv + "'");
      constants[kv.substr(0, eq)] = v;
    }
    options.speed = evolve::speed_from_text(args.speed, args.c, args.eps, constants);
  }
  if (!args.velocity.empty()) {
    options.velocity.kind = evolve::Velocity::Kind::Constant;
    options.velocity.constant = {args.velocity[0], args.velocity[1], args.velocity[2]};
  }
  options.scheme = evolve::scheme_from_name(args.scheme);
  options.hamiltonian = args.hamiltonian == "llf" ? evolve::Hamiltonian::LaxFriedrichs : evolve::Hamiltonian::Godunov;
  options.rk_order = args.rk;
  options.cfl = args.cfl;
  options.steps = args.steps;
  options.time = args.time;
  options.redistance_every = args.redistance_every;
  options.drift_tolerance = args.drift_tolerance;
  options.band_growth_limit = args.band_growth_limit;
  options.extension = args.extension;
  std::FILE* out = summary_stream(args.stats);
  if (args.report_every > 0)
    options.on_step = [&](const evolve::StepInfo& s) {
      if (s.step % args.report_every != 0) return;
      std::fprintf(out, "step %d t %.6g dt %.3g active %llu max|speed| %.3g redistances %d drift %.4f %.2f s\n", s.step,
                   s.time, s.dt, (unsigned long long)s.active_voxels, s.max_speed, s.redistance_count,
                   s.grad_drift, s.elapsed_seconds);
      std::fflush(out);
    };
  const evolve::EvolutionResult result = evolve::evolve(in.band, options);
  const auto t2 = std::chrono::steady_clock::now();
  const LsgWriteResult written = save_lsg(result.band, args.output);
  const auto t3 = std::chrono::steady_clock::now();

  std::fprintf(out, "%s: %d steps to t = %.6g (%s), %zu -> %zu active voxels, %d redistances, %.3f s -> %s (%s)\n",
               args.input.c_str(), result.steps, result.time, evolve::to_string(result.stop).data(), in.band.active_voxel_count(),
               result.band.active_voxel_count(), result.redistance_count, secs(t1, t2), args.output.c_str(),
               human_bytes(written.file_bytes).c_str());
  if (result.stop == evolve::StopReason::Vanished) std::fprintf(out, "%s\n", result.message.c_str());
  Stats stats("evolve", result.band);
  stats.seconds["read"] = secs(t0, t1);
  stats.seconds["evolve"] = secs(t1, t2);
  stats.seconds["operator"] = result.seconds.operator_eval;
  stats.seconds["gradient_cpu"] = result.seconds.gradient_cpu;
  stats.seconds["curvature_cpu"] = result.seconds.curvature_cpu;
  stats.seconds["speed_cpu"] = result.seconds.speed_cpu;
  stats.seconds["rates_cpu"] = result.seconds.rates_cpu;
  stats.seconds["update"] = result.seconds.update;
  stats.seconds["tracking"] = result.seconds.tracking;
  stats.seconds["redistance"] = result.seconds.redistance;
  stats.seconds["write"] = secs(t2, t3);
  stats.seconds["total"] = secs(t0, t3);
  stats.extra["speed"] = args.speed;
  stats.extra["scheme"] = args.scheme;
  stats.extra["rk"] = args.rk;
  stats.extra["cfl"] = args.cfl;
  stats.extra["steps"] = result.steps;
  stats.extra["time"] = result.time;
  stats.extra["stop"] = evolve::to_string(result.stop).data();
  stats.extra["redistance_count"] = result.redistance_count;
  stats.extra["growth_redistance_count"] = result.growth_redistance_count;
  stats.extra["landmine_count"] = result.landmine_count;
  stats.extra["activated"] = result.activated;
  stats.extra["retired"] = result.retired;
  stats.extra["grad_drift"] = result.grad_drift;
  stats.extra["extension"] = args.extension;
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  if (result.stop == evolve::StopReason::NonFinite)
    throw Error(ErrorCode::NonFinite, "evolve", result.message + " (written: " + args.output + ")");
  return 0;
}

}  // namespace levelset::cli
