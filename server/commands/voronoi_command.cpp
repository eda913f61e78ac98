// levelsetd voronoi --seed x,y,z:label ... [grid / cost / obstacle options] -o LABELS.nrrd
// [--distance DIST.nrrd]: (geodesic) Voronoi regions by multi-source fast marching
// (common/apps/voronoi.hpp). LABELS.nrrd: int32 per node, the label of the nearest seed,
// -1 where blocked or unreached; DIST.nrrd: float32 travel time to it (+inf there).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "apps/voronoi.hpp"
#include "commands/output_check.hpp"
#include "commands/command.hpp"
#include "commands/medium_options.hpp"
#include "commands/report.hpp"
#include "core/error.hpp"
#include "io/nrrd_file.hpp"

namespace levelset::cli {

namespace {

struct VoronoiArgs {
  MediumArgs medium;
  std::vector<std::string> seeds;
  std::string output, distance, stats;
};

apps::Seed parse_seed(const std::string& text, std::size_t index) {
  const std::string what = "--seed " + std::to_string(index + 1);
  const std::size_t colon = text.rfind(':');
  apps::Seed s;
  s.label = std::int32_t(index);
  if (colon == std::string::npos) {
    s.position = parse_point(text, what);
    return s;
  }
  s.position = parse_point(std::string_view(text).substr(0, colon), what);
  const std::string label = text.substr(colon + 1);
  char* end = nullptr;
  const long v = std::strtol(label.c_str(), &end, 10);
  if (label.empty() || *end != '\0' || v < 0 || v > 2147483647L)
    throw Error(ErrorCode::InvalidArgument, what, "label must be an integer in [0, 2^31), got '" + label + "'");
  s.label = std::int32_t(v);
  return s;
}

int run_voronoi(const VoronoiArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  apps::VoronoiOptions o;
  std::vector<Vec3d> points;
  std::size_t labelled = 0;
  for (std::size_t i = 0; i < args.seeds.size(); ++i) {
    o.seeds.push_back(parse_seed(args.seeds[i], i));
    points.push_back(o.seeds.back().position);
    labelled += args.seeds[i].find(':') != std::string::npos;
  }
  if (labelled != 0 && labelled != args.seeds.size())
    throw Error(ErrorCode::InvalidArgument, "--seed", "give every seed a label (x,y,z:label) or none (labels 0, 1, ...)");
  const Medium medium = load_medium(args.medium, points);
  o.grid = medium.grid;
  o.cost = medium.cost;
  o.obstacles = medium.obstacles;
  o.order = args.medium.order;
  const apps::VoronoiResult r = apps::voronoi_regions(o);
  const auto t1 = std::chrono::steady_clock::now();
  const apps::DenseGrid& g = r.field.grid;
  const NrrdFrame frame{{g.nx, g.ny, g.nz}, g.voxel_size, g.origin};
  save_nrrd(args.output, frame, std::span<const std::int32_t>(r.field.label));
  if (!args.distance.empty()) {
    const std::vector<float> d(r.field.time.begin(), r.field.time.end());
    save_nrrd(args.distance, frame, std::span<const float>(d));
  }
  const auto t2 = std::chrono::steady_clock::now();

  std::fprintf(summary_stream(args.stats),
               "voronoi: %zu seeds, %zu regions, grid %dx%dx%d h %.4g, %llu blocked, %llu unreached; %.3f s -> %s\n",
               o.seeds.size(), r.region_voxels.size(), g.nx, g.ny, g.nz, g.voxel_size,
               (unsigned long long)r.field.blocked_count, (unsigned long long)r.unreached, secs(t0, t2),
               args.output.c_str());
  Stats stats("voronoi", medium.band ? *medium.band : NarrowBand{});
  stats.seconds["read"] = medium.seconds_read;
  stats.seconds["cost"] = r.field.seconds_cost;
  stats.seconds["march"] = r.field.seconds_march;
  stats.seconds["write"] = secs(t1, t2);
  stats.seconds["total"] = secs(t0, t2);
  nlohmann::json regions = nlohmann::json::object();
  for (const auto& [label, count] : r.region_voxels) regions[std::to_string(label)] = count;
  stats.extra["regions"] = regions;
  stats.extra["seeds"] = o.seeds.size();
  stats.extra["grid"] = {g.nx, g.ny, g.nz};
  stats.extra["voxel_size"] = g.voxel_size;
  stats.extra["grid_voxels"] = g.voxel_count();
  stats.extra["blocked"] = r.field.blocked_count;
  stats.extra["unreached"] = r.unreached;
  stats.extra["boundary_voxels"] = r.boundary_voxels;
  stats.extra["order"] = args.medium.order;
  stats.extra["output"] = args.output;
  write_stats(stats, args.stats);
  return 0;
}

}  // namespace

Command add_voronoi_command(CLI::App& app, int& threads) {
  auto args = std::make_shared<VoronoiArgs>();
  CLI::App* sub = app.add_subcommand("voronoi", "Voronoi regions of labelled seeds (geodesic with obstacles or a cost)");
  sub->add_option("--seed", args->seeds, "Seed x,y,z[:label] (repeatable; all labelled, or none: labels 0, 1, ... in order)")
      ->required()
      ->take_all();
  add_medium_options(sub, args->medium);
  sub->add_option("-o,--output", args->output, "Output labels (.nrrd, int32, -1 = blocked/unreached)")->required()->check(nrrd_output());
  sub->add_option("--distance", args->distance, "Also write the travel time to the nearest seed (.nrrd, float32)")->check(nrrd_output());
  add_common_options(sub, threads, args->stats);
  return {sub, [args] { return run_voronoi(*args); }};
}

}  // namespace levelset::cli
