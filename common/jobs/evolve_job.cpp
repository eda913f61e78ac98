// job = evolve: the input surface moved by a speed (a built-in name or a typed formula, the
// thesis's PDE set) for a number of steps or a time. Its set:
//   evolve { speed = -sign(H)*sqrt(K+abs(K))   c = 1  eps = 0.1   constants { a = 2 }
//            steps = 20 | time = 0.5   scheme = godunov|eno2|weno5   rk = 1|3   cfl = 0.5
//            redistance_every = 0   drift_tolerance = 0.05   band_growth_limit = 1.5
//            extension = no   report_every = 10
//            points = FILE (dist dgx dgy dgz dn: the distance to a point cloud)
//            roi = FILE.lsg (roi: a stored level set, the thesis's region of influence) }
// drift_tolerance and band_growth_limit keep long runs bounded (evolve/evolution.hpp); 0 turns
// either off. Without points / roi the caller's (a daemon session's) are used.
#include <algorithm>
#include <cstdio>
#include <map>

#include "core/error.hpp"
#include "evolve/evolution.hpp"
#include "grid/lsg_file.hpp"
#include "io/point_cloud_reader.hpp"
#include "jobs/applications.hpp"
#include "jobs/speed_fields.hpp"

namespace levelset::jobs {

// Shared by the jobs that run the evolution engine with a speed from their set.
evolve::EvolutionOptions evolution_options_from(JobContext& ctx, const config::Set& s) {
  evolve::EvolutionOptions o;
  const std::string speed = ctx.text(s, "speed", "");
  if (speed.empty()) throw Error(ErrorCode::InvalidArgument, ctx.options().name, "the evolve set needs 'speed = ...'");
  std::map<std::string, double, std::less<>> constants;
  if (const config::Entry* c = s.find("constants"); c != nullptr && c->is_set)
    for (const config::Entry& e : c->set.entries) constants[e.key] = ctx.number(c->set, e.key, 0, -1e300, 1e300);
  try {
    o.speed = evolve::speed_from_text(speed, ctx.number(s, "c", 1.0, -1e6, 1e6), ctx.number(s, "eps", 0.1, 0, 1e6),
                                      constants);
  } catch (const Error& e) {
    throw Error(e.code(), ctx.place(s, "speed") + " (" + e.where() + ")", e.reason());
  }
  const bool has_steps = ctx.has(s, "steps"), has_time = ctx.has(s, "time");
  if (has_steps == has_time)
    throw Error(ErrorCode::InvalidArgument, ctx.options().name, "give exactly one of 'steps' and 'time'");
  o.steps = ctx.integer(s, "steps", 0, 1, 100000000);
  o.time = ctx.number(s, "time", 0, 1e-300, 1e300);
  const std::string scheme = ctx.word(s, "scheme", "godunov", {"godunov", "eno2", "weno5"});
  o.scheme = evolve::scheme_from_name(scheme);
  o.rk_order = ctx.integer(s, "rk", 1, 1, 3);
  if (o.rk_order == 2) throw Error(ErrorCode::InvalidArgument, ctx.place(s, "rk"), "rk must be 1 or 3");
  o.cfl = ctx.number(s, "cfl", 0.0, 0.0, 1.0);
  o.redistance_every = ctx.integer(s, "redistance_every", 0, 0, 1000000);
  o.drift_tolerance = ctx.number(s, "drift_tolerance", evolve::kDefaultDriftTolerance, 0.0, 10.0);
  o.band_growth_limit = ctx.number(s, "band_growth_limit", evolve::kDefaultBandGrowthLimit, 0.0, 1e6);
  if (o.band_growth_limit > 0 && o.band_growth_limit < 1)
    throw Error(ErrorCode::InvalidArgument, ctx.place(s, "band_growth_limit"), "must be 0 (off) or at least 1");
  o.extension = ctx.flag(s, "extension", false);
  o.progress = ctx.options().progress;
  const int every = ctx.integer(s, "report_every", 10, 0, 1000000);
  if (every > 0 || ctx.options().on_step)
    o.on_step = [&ctx, every](const evolve::StepInfo& info) {
      if (ctx.options().on_step) ctx.options().on_step(info);
      if (every <= 0 || info.step % every != 0) return;
      char line[200];
      std::snprintf(line, sizeof line, "step %d t %.6g dt %.3g active %llu max|speed| %.3g redistances %d", info.step,
                    info.time, info.dt, static_cast<unsigned long long>(info.active_voxels), info.max_speed,
                    info.redistance_count);
      ctx.log(line);
    };
  return o;
}

nlohmann::json evolution_json(const evolve::EvolutionResult& r) {
  return {{"steps", r.steps},
          {"time", r.time},
          {"stop", std::string(evolve::to_string(r.stop))},
          {"redistance_count", r.redistance_count},
          {"growth_redistance_count", r.growth_redistance_count},
          {"landmine_count", r.landmine_count},
          {"band_updates", r.band_updates},
          {"grad_drift", r.grad_drift},
          {"seconds", r.seconds.total}};
}

void run_evolve_job(JobContext& ctx) {
  const config::Set& input = ctx.section("input", JobContext::input_keys());
  const config::Set& s = ctx.section("evolve", {"speed", "c", "eps", "constants", "steps", "time", "scheme", "rk", "cfl",
                                                "redistance_every", "drift_tolerance", "band_growth_limit", "extension",
                                                "report_every", "points", "roi"});
  const NarrowBand band = ctx.input_band(input);
  const MeshMeasures before = ctx.measure_band(band);
  ctx.stats()["mesh_before"] = measures_json(before);
  evolve::EvolutionOptions options = evolution_options_from(ctx, s);
  // Fields: files named here, else what the caller holds (a daemon session's cloud and ROI).
  std::shared_ptr<const PointCloud> points = ctx.options().points;
  std::shared_ptr<const NarrowBand> roi = ctx.options().roi;
  if (ctx.has(s, "points")) points = std::make_shared<const PointCloud>(read_point_cloud(ctx.input_path(s, "points")).cloud);
  if (ctx.has(s, "roi")) roi = std::make_shared<const NarrowBand>(load_lsg(ctx.input_path(s, "roi")).band);
  options.fields = speed_fields(points, roi);
  const evolve::EvolutionResult result = evolve::evolve(band, options);
  ctx.stats()["evolution"] = evolution_json(result);
  ctx.log("evolved " + std::to_string(result.steps) + " steps to t = " + std::to_string(result.time) + " (" +
          std::string(evolve::to_string(result.stop)) + ")");
  ctx.write_band(result.band);
  ctx.write_surface(result.band);
  evolve::throw_if_stopped(result, "evolve");  // cancelled or non-finite: no result
}

}  // namespace levelset::jobs
