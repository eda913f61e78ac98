// levelsetd segment IMAGE --seed x,y,z [--seed ...] -o OUT.lsg [...]: shape detection in a 3D
// image (INR / NRRD) by a level set grown from seeds (common/apps/segmentation.hpp).
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "apps/segmentation.hpp"
#include "commands/number_checks.hpp"
#include "commands/output_check.hpp"
#include "commands/command.hpp"
#include "commands/report.hpp"
#include "core/error.hpp"
#include "core/file_io.hpp"
#include "grid/lsg_file.hpp"
#include "io/image_reader.hpp"
#include "io/mesh_writer.hpp"

namespace levelset::cli {

namespace {

struct SegmentArgs {
  std::string image;
  std::vector<std::string> seeds;  // "x,y,z" or "x,y,z,r"
  double seed_radius = 0, sigma = 1.0, contrast = 0.02, eps = -1.0, attraction = 2.0;
  double voxel_size = 0, band = 3.0, time = 0, max_time = 0, tolerance = 0.1;
  int power = 2, steps = 0;
  bool report = false;
  std::string output, mesh, mask, stats;
};

const char* stop_name(const apps::SegmentationResult& r) {
  if (r.stop == evolve::StopReason::NonFinite) return "non-finite";
  return r.converged ? "steady" : "limit";
}

int run_segment(const SegmentArgs& a) {
  const auto t0 = std::chrono::steady_clock::now();
  apps::SegmentationOptions o;
  for (const std::string& text : a.seeds) {
    std::vector<double> s;
    std::size_t pos = 0;
    while (pos <= text.size() && s.size() < 5) {
      const std::size_t comma = std::min(text.find(',', pos), text.size());
      const std::string part = text.substr(pos, comma - pos);
      char* end = nullptr;
      const double v = std::strtod(part.c_str(), &end);
      if (part.empty() || end != part.c_str() + part.size())
        throw Error(ErrorCode::InvalidArgument, "--seed", "expected x,y,z or x,y,z,r, got '" + text + "'");
      s.push_back(v);
      pos = comma + 1;
    }
    if (s.size() != 3 && s.size() != 4)
      throw Error(ErrorCode::InvalidArgument, "--seed", "expected x,y,z or x,y,z,r, got '" + text + "'");
    o.seeds.push_back({{s[0], s[1], s[2]}, s.size() == 4 ? s[3] : 0.0});
  }
  o.seed_radius = a.seed_radius;
  o.edge.sigma = a.sigma;
  o.edge.contrast = a.contrast;
  o.edge.power = a.power;
  o.eps = a.eps;
  o.attraction = a.attraction;
  o.voxel_size = a.voxel_size;
  o.half_width = a.band;
  o.steps = a.steps;
  o.time = a.time;
  o.max_time = a.max_time;
  o.motion_tolerance = a.tolerance;
  o.label_mask = !a.mask.empty();
  std::FILE* out = summary_stream(a.stats);
  if (a.report)
    o.on_check = [out](const apps::SegmentationCheck& c) {
      std::fprintf(out, "step %d t %.5g volume %.6g area %.6g motion %.3g voxels, active %llu\n", c.steps, c.time,
                   c.volume, c.area, c.motion, (unsigned long long)c.active_voxels);
      std::fflush(out);
    };
  // The header first: what the segmentation will allocate is checked against the memory
  // budget before a single sample is inflated.
  ImageReadOptions header_only;
  header_only.samples = ImageSamples::Skip;
  const ImageReadResult header = read_image(a.image, header_only);
  apps::require_segmentation_budget(header.image, header.file_bytes, o, a.image);
  ImageReadOptions load;  // the samples under the same budget as the segmentation (--memory-budget)
  load.memory_budget = o.memory_budget;
  load.progress = o.progress;
  const ImageReadResult in = read_image(a.image, load);
  const auto t1 = std::chrono::steady_clock::now();
  const apps::SegmentationResult r = apps::segment_image(in.image, o);
  const auto t2 = std::chrono::steady_clock::now();
  const LsgWriteResult written = save_lsg(r.band, a.output);
  if (!a.mesh.empty()) write_mesh(r.surface.mesh, a.mesh);
  if (!a.mask.empty()) {
    // The mask as an 8-bit NRRD on the image's grid (0 outside, 1 inside).
    const ImageVolume& im = in.image;
    char header[512];
    std::snprintf(header, sizeof header,
                  "NRRD0004\ntype: uint8\ndimension: 3\nsizes: %lld %lld %lld\nencoding: raw\n"
                  "space dimension: 3\nspace directions: (%.17g,0,0) (0,%.17g,0) (0,0,%.17g)\n"
                  "space origin: (%.17g,%.17g,%.17g)\n\n",
                  (long long)im.nx, (long long)im.ny, (long long)im.nz, im.spacing.x, im.spacing.y, im.spacing.z,
                  im.origin.x, im.origin.y, im.origin.z);
    std::string bytes(header);
    bytes.append(reinterpret_cast<const char*>(r.label_mask.data()), r.label_mask.size());
    write_file_atomically(a.mask, bytes);
  }
  const auto t3 = std::chrono::steady_clock::now();
  std::fprintf(out,
               "%s: %lld x %lld x %lld %s image; %d steps to t = %.5g (%s, last motion %.3g voxels); volume %.6g, "
               "area %.6g, %llu components, genus %g, %s; %.3f s -> %s (%s)\n",
               a.image.c_str(), (long long)in.image.nx, (long long)in.image.ny, (long long)in.image.nz,
               in.sample_type.c_str(), r.steps, r.time, stop_name(r), r.last_motion, r.measures.volume,
               r.measures.area, (unsigned long long)r.measures.components, r.measures.genus,
               r.measures.watertight ? "watertight" : "not watertight", secs(t1, t2), a.output.c_str(),
               human_bytes(written.file_bytes).c_str());
  Stats stats("segment", r.band);
  stats.seconds["read"] = secs(t0, t1);
  stats.seconds["edges"] = r.seconds_edges;
  stats.seconds["evolve"] = r.seconds_evolve;
  stats.seconds["surface"] = r.seconds_surface;
  stats.seconds["write"] = secs(t2, t3);
  stats.seconds["total"] = secs(t0, t3);
  stats.extra["image"] = {{"nx", in.image.nx}, {"ny", in.image.ny}, {"nz", in.image.nz},
                          {"spacing", {in.image.spacing.x, in.image.spacing.y, in.image.spacing.z}},
                          {"type", in.sample_type}, {"format", std::string(to_string(in.format))}};
  stats.extra["intensity_range"] = {r.intensity_low, r.intensity_high};
  stats.extra["steps"] = r.steps;
  stats.extra["time"] = r.time;
  stats.extra["stop"] = stop_name(r);
  stats.extra["converged"] = r.converged;
  stats.extra["checks"] = r.checks;
  stats.extra["last_motion_voxels"] = r.last_motion;
  stats.extra["volume"] = r.measures.volume;
  stats.extra["area"] = r.measures.area;
  stats.extra["components"] = r.measures.components;
  stats.extra["genus"] = r.measures.genus;
  stats.extra["watertight"] = r.measures.watertight;
  stats.extra["triangles"] = r.surface.mesh.triangles.size();
  if (o.label_mask) stats.extra["inside_voxels"] = r.inside_voxels;
  stats.extra["output"] = a.output;
  write_stats(stats, a.stats);
  if (r.stop == evolve::StopReason::NonFinite)
    throw Error(ErrorCode::NonFinite, "segment", r.message + " (written: " + a.output + ")");
  return 0;
}

}  // namespace

Command add_segment_command(CLI::App& app, int& threads) {
  auto args = std::make_shared<SegmentArgs>();
  CLI::App* sub = app.add_subcommand("segment", "Shape detection in a 3D image (INR, NRRD): grow a level set from seeds until it locks on edges");
  sub->add_option("image", args->image, "Input image (.inr, .inr.gz, .nrrd, .nhdr)")->required();
  sub->add_option("--seed", args->seeds, "Seed x,y,z[,r] in world coordinates of the image (repeatable)")
      ->required();
  sub->add_option("--seed-radius", args->seed_radius, "Radius of seeds without one (default 3 grid voxels; keep it above 2 eps or the seed shrinks)")->transform(levelset::cli::non_negative());
  sub->add_option("--sigma", args->sigma, "Gaussian smoothing of the image, in image voxels")->transform(levelset::cli::in_range(0.0, 64.0));
  sub->add_option("--contrast", args->contrast, "Intensity change per voxel (of the [0,1]-normalised image) where g = 1/2")->transform(levelset::cli::positive());
  sub->add_option("--power", args->power, "p in g = 1/(1+(|grad|/contrast)^p): 1 or 2")->check(CLI::IsMember({1, 2}));
  sub->add_option("--eps", args->eps, "Curvature weight eps in (1 - eps H) g, world units (default: one grid voxel)")->transform(levelset::cli::non_negative());
  sub->add_option("--attraction", args->attraction, "Weight of the edge attraction -grad g (0: the thesis's plain model)")->transform(levelset::cli::non_negative());
  sub->add_option("--voxel-size", args->voxel_size, "Grid spacing (default: the image's smallest spacing)")->transform(levelset::cli::non_negative());
  sub->add_option("--band", args->band, "Band half-width in voxels")->transform(levelset::cli::in_range(2.0, 64.0));
  auto* steps = sub->add_option("--steps", args->steps, "Run exactly N steps")->transform(levelset::cli::positive_int());
  auto* time = sub->add_option("--time", args->time, "Run until time T (the front moves at speed g <= 1 world unit per time)")->transform(levelset::cli::positive());
  steps->excludes(time);
  sub->add_option("--max-time", args->max_time, "Cap for the run until steady (default: twice the image diagonal)")->transform(levelset::cli::non_negative());
  sub->add_option("--tolerance", args->tolerance, "Steady when the front moved less than this many voxels (mean) since the last check")->transform(levelset::cli::non_negative());
  sub->add_option("-o,--output", args->output, "Output .lsg")->required()->check(lsg_output());
  sub->add_option("--mesh", args->mesh, "Also write the surface (.ply .off .obj .stl)")->check(mesh_output());
  sub->add_option("--mask", args->mask, "Also write the inside voxels of the image as a uint8 .nrrd")->check(nrrd_output());
  sub->add_flag("--report", args->report, "Print one line per steady-state check");
  add_common_options(sub, threads, args->stats);
  return {sub, [args] { return run_segment(*args); }};
}

}  // namespace levelset::cli
