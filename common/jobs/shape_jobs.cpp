// The shape operations as jobs (apps/offset, fairing, minmax_flow, csg): their sets map
// one to one onto the Options structs; stats hold the shape measures before and after.
//   offset { distance = 0.35  back = no  scheme = weno5  rk = 3  drift_tolerance = 0.1 }
//   fair   { flow = mean-curvature|mean-gaussian|volume-preserving  time = T | steps = N
//            redistance_every = 10 }
//   minmax { radius = 6  tolerance = 1e-4  patience = 3  update_every = 1  max_steps = 2000
//            redistance_every = 10 }
//   csg    { op = union|intersection|difference  operand { shape|mesh|lsg ... }
//            voxel_size = 0  band = 0  seam_time = 0  seam_radius = 0 }
#include "apps/csg.hpp"
#include "apps/fairing.hpp"
#include "apps/minmax_flow.hpp"
#include "apps/offset.hpp"
#include "apps/shape_measures.hpp"
#include "core/error.hpp"
#include "jobs/applications.hpp"

namespace levelset::jobs {

namespace {

evolve::Scheme scheme_of(JobContext& ctx, const config::Set& s, const char* fallback) {
  return evolve::scheme_from_name(ctx.word(s, "scheme", fallback, {"godunov", "eno2", "weno5"}));
}

}  // namespace

void run_offset_job(JobContext& ctx) {
  const config::Set& s = ctx.section("offset", {"distance", "back", "scheme", "rk", "cfl", "drift_tolerance"});
  const NarrowBand band = ctx.input_band(ctx.section("input", JobContext::input_keys()));
  apps::OffsetOptions o;
  o.distance = ctx.number(s, "distance", 0.0, -1e30, 1e30);
  if (o.distance == 0) throw Error(ErrorCode::InvalidArgument, ctx.place(s, "distance"), "the offset needs 'distance' != 0");
  o.scheme = scheme_of(ctx, s, "weno5");
  o.rk_order = ctx.integer(s, "rk", 3, 1, 3);
  o.cfl = ctx.number(s, "cfl", 0.0, 0.0, 1.0);
  o.drift_tolerance = ctx.number(s, "drift_tolerance", 0.1, 0.0, 10.0);
  o.progress = ctx.options().progress;
  const bool back = ctx.flag(s, "back", false);
  ctx.stats()["before"] = shape_json(apps::measure_shape(band));
  const apps::OffsetResult out = apps::offset_surface(band, o);
  ctx.log("offset by " + std::to_string(o.distance) + ": " + std::to_string(out.steps) + " steps");
  ctx.stats()["offset"] = {{"steps", out.steps}, {"time", out.time}, {"seconds", out.seconds}};
  if (!back) {
    ctx.stats()["after"] = shape_json(apps::measure_shape(out.band));
    ctx.write_band(out.band);
    ctx.write_surface(out.band);
    return;
  }
  // +D then -D: a morphological closing (thesis fig. 5.1); the intermediate surface too.
  ctx.stats()["outward"] = shape_json(apps::measure_shape(out.band));
  ctx.write_surface(out.band, "_outward");
  o.distance = -o.distance;
  const apps::OffsetResult in = apps::offset_surface(out.band, o);
  ctx.log("offset back by " + std::to_string(o.distance) + ": " + std::to_string(in.steps) + " steps");
  ctx.stats()["offset_back"] = {{"steps", in.steps}, {"time", in.time}, {"seconds", in.seconds}};
  ctx.stats()["after"] = shape_json(apps::measure_shape(in.band));
  ctx.write_band(in.band);
  ctx.write_surface(in.band);
}

void run_fair_job(JobContext& ctx) {
  const config::Set& s = ctx.section("fair", {"flow", "time", "steps", "scheme", "rk", "cfl", "redistance_every"});
  const NarrowBand band = ctx.input_band(ctx.section("input", JobContext::input_keys()));
  apps::FairingOptions o;
  o.flow = apps::fairing_flow_from_name(ctx.word(s, "flow", "mean-curvature",
                                                 {"mean-curvature", "mean-gaussian", "volume-preserving"}));
  if (ctx.has(s, "time") == ctx.has(s, "steps"))
    throw Error(ErrorCode::InvalidArgument, ctx.options().name, "the fair set needs exactly one of 'time' and 'steps'");
  o.time = ctx.number(s, "time", 0.0, 1e-300, 1e30);
  o.steps = ctx.integer(s, "steps", 0, 1, 10000000);
  o.scheme = scheme_of(ctx, s, "godunov");
  o.rk_order = ctx.integer(s, "rk", 1, 1, 3);
  o.cfl = ctx.number(s, "cfl", 0.0, 0.0, 1.0);
  o.redistance_every = ctx.integer(s, "redistance_every", 10, 0, 1000000);
  o.progress = ctx.options().progress;
  const apps::FairingResult r = apps::fair_surface(band, o);
  ctx.log("fairing: " + std::to_string(r.steps) + " steps to t = " + std::to_string(r.time));
  ctx.stats()["fair"] = {{"flow", std::string(apps::fairing_flow_name(o.flow))}, {"steps", r.steps}, {"time", r.time},
                         {"redistance_count", r.redistance_count}, {"seconds", r.seconds}};
  ctx.stats()["before"] = shape_json(r.before);
  ctx.stats()["after"] = shape_json(r.after);
  ctx.write_band(r.band);
  ctx.write_surface(r.band);
}

void run_minmax_job(JobContext& ctx) {
  const config::Set& s =
      ctx.section("minmax", {"radius", "tolerance", "patience", "update_every", "max_steps", "cfl", "redistance_every"});
  const NarrowBand band = ctx.input_band(ctx.section("input", JobContext::input_keys()));
  apps::MinMaxOptions o;
  o.radius = ctx.integer(s, "radius", o.radius, 1, 16);
  o.tolerance = ctx.number(s, "tolerance", o.tolerance, 1e-12, 10.0);
  o.patience = ctx.integer(s, "patience", o.patience, 1, 1000);
  o.update_every = ctx.integer(s, "update_every", o.update_every, 1, 1000);
  o.max_steps = ctx.integer(s, "max_steps", o.max_steps, 1, 10000000);
  o.cfl = ctx.number(s, "cfl", 0.0, 0.0, 1.0);
  o.redistance_every = ctx.integer(s, "redistance_every", o.redistance_every, 0, 1000000);
  o.progress = ctx.options().progress;
  const apps::MinMaxResult r = apps::minmax_flow(band, o);
  ctx.log("min/max flow: " + std::to_string(r.steps) + " steps, " + (r.steady ? "steady" : "not steady"));
  nlohmann::json history = nlohmann::json::array();
  for (const apps::MinMaxChunk& c : r.history) history.push_back({c.step, c.time, c.mean_change, c.max_change});
  ctx.stats()["minmax"] = {{"steps", r.steps}, {"time", r.time}, {"steady", r.steady}, {"steady_step", r.steady_step},
                           {"seconds", r.seconds}, {"history_columns", {"step", "time", "mean_change", "max_change"}},
                           {"history", history}};
  ctx.stats()["before"] = shape_json(r.before);
  ctx.stats()["after"] = shape_json(r.after);
  ctx.write_band(r.band);
  ctx.write_surface(r.band);
}

void run_csg_job(JobContext& ctx) {
  const config::Set& s = ctx.section("csg", {"op", "operand", "voxel_size", "band", "seam_time", "seam_radius"});
  const config::Entry* operand = s.find("operand");
  if (operand == nullptr || !operand->is_set)
    throw Error(ErrorCode::InvalidArgument, ctx.options().name, "the csg set needs 'operand { shape|mesh|lsg = ... }'");
  config::check_keys(operand->set, JobContext::input_keys(), ctx.options().name);
  const NarrowBand a = ctx.input_band(ctx.section("input", JobContext::input_keys()));
  const NarrowBand b = ctx.input_band(operand->set);
  apps::CsgOptions o;
  o.op = apps::csg_op_from_name(ctx.word(s, "op", "union", {"union", "intersection", "difference"}));
  o.voxel_size = ctx.number(s, "voxel_size", 0.0, 0.0, 1e30);
  o.half_width = ctx.number(s, "band", 0.0, 0.0, 64.0);
  o.seam_time = ctx.number(s, "seam_time", 0.0, 0.0, 1e30);
  o.seam_radius = ctx.number(s, "seam_radius", 0.0, 0.0, 1e30);
  o.progress = ctx.options().progress;
  ctx.stats()["a"] = shape_json(apps::measure_shape(a));
  ctx.stats()["b"] = shape_json(apps::measure_shape(b));
  const apps::CsgResult r = apps::csg(a, b, o);
  ctx.log(std::string(apps::csg_op_name(o.op)) + " of the input and the operand");
  ctx.stats()["csg"] = {{"op", std::string(apps::csg_op_name(o.op))}, {"seam_steps", r.seam_steps},
                        {"seconds", r.seconds}};
  ctx.stats()["after"] = shape_json(apps::measure_shape(r.band));
  ctx.write_band(r.band);
  ctx.write_surface(r.band);
}

}  // namespace levelset::jobs
