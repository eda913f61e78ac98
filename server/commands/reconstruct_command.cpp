// levelsetd reconstruct POINTS [--resolution R | --voxel-size H] -o OUT.(ply|obj|off|stl)
//   [--lsg OUT.lsg] [--curvature-weight w] [...]: a watertight surface through a point cloud
//   (apps/reconstruction.hpp). POINTS is a point cloud file (.xyz .xyzn .pwn .ply .off) or
//   builtin:knot[:N] (N points, default 20000, sampled by area on the built-in torus knot).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "apps/reconstruction.hpp"
#include "apps/sample_points.hpp"
#include "commands/number_checks.hpp"
#include "commands/output_check.hpp"
#include "commands/command.hpp"
#include "commands/report.hpp"
#include "core/error.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/lsg_file.hpp"
#include "io/mesh_writer.hpp"
#include "io/point_cloud_reader.hpp"
#include "jobs/measures_json.hpp"

namespace levelset::cli {

namespace {

struct ReconstructArgs {
  std::string input, output, lsg, stats;
  int resolution = 0;
  double voxel_size = 0.0;
  apps::ReconstructionOptions options;
  double noise = 0.0;  // builtin only, fraction of the bounding-box diagonal
  std::uint64_t seed = 1;
};

std::vector<Vec3d> load_points(const ReconstructArgs& a) {
  const std::string prefix = "builtin:knot";
  if (a.input.rfind(prefix, 0) != 0) return read_point_cloud(a.input).cloud.points;
  std::size_t count = 20000;
  const std::string rest = a.input.substr(prefix.size());
  if (!rest.empty()) {
    char* end = nullptr;
    const unsigned long long n = rest[0] == ':' ? std::strtoull(rest.c_str() + 1, &end, 10) : 0;
    if (rest[0] != ':' || rest.size() < 2 || end != rest.c_str() + rest.size() || n == 0 || n > (1ull << 26))
      throw Error(ErrorCode::InvalidArgument, "reconstruct", "expected builtin:knot or builtin:knot:N, got '" + a.input + "'");
    count = std::size_t(n);
  }
  const auto knot = make_builtin_shape("knot");
  apps::SurfaceSampleOptions s;
  s.count = count;
  s.seed = a.seed;
  s.noise = a.noise * length(knot->bounds().extent());
  return apps::sample_shape_surface(*knot, s);
}

int run(const ReconstructArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Vec3d> points = load_points(a);
  const auto t1 = std::chrono::steady_clock::now();
  apps::ReconstructionOptions o = a.options;
  o.resolution = a.voxel_size > 0.0 ? 0 : a.resolution;  // neither: chosen from the data
  o.voxel_size = a.voxel_size;
  std::FILE* out = summary_stream(a.stats);
  o.log = [out](const std::string& line) {
    std::fprintf(out, "%s\n", line.c_str());
    std::fflush(out);
  };
  const apps::ReconstructionResult r = apps::reconstruct_surface(points, o);
  const auto t2 = std::chrono::steady_clock::now();
  write_mesh(r.mesh, a.output);
  if (!a.lsg.empty()) save_lsg(r.band, a.lsg);
  const auto t3 = std::chrono::steady_clock::now();

  std::fprintf(out, "%s: %zu points -> %llu triangles, genus %g, %s, area %.6g, volume %.6g, %.3f s -> %s\n",
               a.input.c_str(), points.size(), (unsigned long long)r.measures.faces, r.measures.genus,
               r.measures.watertight ? "watertight" : "NOT watertight", r.measures.area, r.measures.volume, secs(t1, t2),
               a.output.c_str());
  Stats stats("reconstruct", r.band);
  stats.set_phases("reconstruct", t0, t1, t2, t3);
  stats.seconds["mesh"] = r.seconds_mesh;
  stats.extra["levels"] = jobs::stages_json(r.stages);
  stats.extra["points"] = points.size();
  stats.extra["voxel_size"] = r.voxel_size;
  stats.extra["resolution"] = r.resolution;
  stats.extra["resolution_from_data"] = a.resolution == 0 && a.voxel_size <= 0.0;
  stats.extra["sampling"] = {{"spacing", r.sampling.spacing}, {"noise", r.sampling.noise}, {"denoised_noise", r.denoised_noise}};
  stats.extra["isolated_points"] = r.isolated_points;
  stats.extra["duplicate_points"] = r.duplicate_points;
  stats.extra["coverage"] = r.coverage;
  stats.extra["steps"] = r.steps;
  stats.extra["triangles"] = r.measures.faces;
  stats.extra["genus"] = r.measures.genus;
  stats.extra["components"] = r.measures.components;
  stats.extra["watertight"] = r.measures.watertight;
  stats.extra["area"] = r.measures.area;
  stats.extra["volume"] = r.measures.volume;
  stats.extra["output"] = a.output;
  write_stats(stats, a.stats);
  return 0;
}

}  // namespace

Command add_reconstruct_command(CLI::App& app, int& threads) {
  auto args = std::make_shared<ReconstructArgs>();
  CLI::App* sub = app.add_subcommand("reconstruct", "Surface from an unorganised point cloud (no normals needed)");
  sub->add_option("points", args->input, "Point cloud (.xyz .xyzn .pwn .ply .off) or builtin:knot[:N]")->required();
  auto* res = sub->add_option("--resolution", args->resolution, "Voxels along the longest side of the padded box (default: from the points' spacing and noise)")
                  ->transform(levelset::cli::in_range(16, 1 << 14));
  auto* vs = sub->add_option("--voxel-size", args->voxel_size, "Final voxel size (world units)")->transform(levelset::cli::positive());
  res->excludes(vs);
  sub->add_option("-o,--output", args->output, "Output mesh (.ply .obj .off .stl)")->required()->check(mesh_output());
  sub->add_option("--lsg", args->lsg, "Also write the final narrow band (.lsg)")->check(lsg_output());
  auto& o = args->options;
  sub->add_option("--curvature-weight", o.curvature_weight, "Curvature weight of the coarsest level's flow")->capture_default_str();
  sub->add_option("--snap-passes", o.snap_passes, "Snap passes per finer level")->capture_default_str();
  sub->add_option("--clean-final-passes", o.clean_final_passes, "Snap passes at the final level on clean data (second-order fits)")->capture_default_str();
  sub->add_option("--neighbors", o.neighbors, "Points per local surface fit")->capture_default_str();
  sub->add_option("--levels", o.levels, "Coarse-to-fine levels")->capture_default_str();
  sub->add_option("--band", o.half_width, "Band half-width (voxels)")->capture_default_str();
  sub->add_option("--shell-offset", o.shell_offset, "Start shell offset (coarsest voxels)")->capture_default_str();
  sub->add_option("--max-steps", o.max_steps, "Flow steps (coarsest level) at most")->capture_default_str();
  sub->add_option("--tolerance", o.tolerance, "Convergence: mean front motion per step / snap change (voxels)")->capture_default_str();
  sub->add_option("--noise", args->noise, "builtin:knot only: Gaussian noise, fraction of the bbox diagonal")->capture_default_str();
  sub->add_option("--seed", args->seed, "builtin:knot only: sampling seed")->capture_default_str();
  add_common_options(sub, threads, args->stats);
  return {sub, [args] { return run(*args); }};
}

}  // namespace levelset::cli
