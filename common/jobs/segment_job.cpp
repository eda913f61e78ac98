// job = segment: shape detection in a 3D image (apps/segmentation, thesis 3.4).
//   input   { image = FILE (.inr .inr.gz .nrrd .nhdr)  downsample = 1 }
//   segment { seeds = (x1, y1, z1, ...)  |  seed_above = T (lattice seeds whose 7^3 box is above T)
//             seed_stride = 6  seed_radius = 0  sigma = 1  contrast = 0.02  power = 2  eps = -1
//             attraction = 2  tolerance = 0.1  steps = N | time = T  max_time = 0  voxel_size = 0
//             reference_threshold = T (Dice against the component of {I > T} holding the seeds) }
// Outputs: STEM.lsg, STEM.ply, the stats (image, steps, convergence, measures, Dice).
#include <algorithm>

#include "apps/image_regions.hpp"
#include "apps/segmentation.hpp"
#include "core/error.hpp"
#include "core/memory_budget.hpp"
#include "io/image_reader.hpp"
#include "jobs/applications.hpp"

namespace levelset::jobs {

void run_segment_job(JobContext& ctx) {
  const config::Set& in = ctx.section("input", {"image", "downsample"});
  const config::Set& s =
      ctx.section("segment", {"seeds", "seed_above", "seed_stride", "seed_radius", "sigma", "contrast", "power", "eps",
                              "attraction", "tolerance", "steps", "time", "max_time", "voxel_size", "reference_threshold"});
  // Every option is read (and checked) before the image is read and the work starts, so a
  // bad value fails at once.
  const std::string path = ctx.input_path(in, "image");
  const int factor = ctx.integer(in, "downsample", 1, 1, 64);
  apps::SegmentationOptions o;
  if (ctx.has(s, "seeds") == ctx.has(s, "seed_above"))
    throw Error(ErrorCode::InvalidArgument, ctx.options().name, "the segment set needs exactly one of 'seeds' and 'seed_above'");
  o.seed_radius = ctx.number(s, "seed_radius", 0.0, 0.0, 1e30);
  const std::vector<Vec3d> seed_points = ctx.has(s, "seeds") ? ctx.points(s, "seeds") : std::vector<Vec3d>{};
  const float seed_above = static_cast<float>(ctx.number(s, "seed_above", 0.0, -1e30, 1e30));
  const int seed_stride = ctx.integer(s, "seed_stride", 6, 1, 1000);
  o.edge.sigma = ctx.number(s, "sigma", o.edge.sigma, 0.0, 100.0);
  o.edge.contrast = ctx.number(s, "contrast", o.edge.contrast, 1e-9, 1e9);
  o.edge.power = ctx.integer(s, "power", o.edge.power, 1, 2);
  o.eps = ctx.number(s, "eps", o.eps, -1.0, 1e30);
  o.attraction = ctx.number(s, "attraction", o.attraction, 0.0, 1e6);
  o.motion_tolerance = ctx.number(s, "tolerance", o.motion_tolerance, 1e-9, 1e6);
  o.steps = ctx.integer(s, "steps", 0, 0, 100000000);
  o.time = ctx.number(s, "time", 0.0, 0.0, 1e30);
  o.max_time = ctx.number(s, "max_time", 0.0, 0.0, 1e30);
  o.voxel_size = ctx.number(s, "voxel_size", 0.0, 0.0, 1e30);
  o.label_mask = ctx.has(s, "reference_threshold");
  const float reference_threshold = static_cast<float>(ctx.number(s, "reference_threshold", 0.0, -1e30, 1e30));
  o.progress = ctx.options().progress;
  o.on_check = [&ctx](const apps::SegmentationCheck& c) {
    char line[160];
    std::snprintf(line, sizeof line, "check: step %d t %.4g volume %.6g front motion %.3g voxel", c.steps, c.time,
                  c.volume, c.motion);
    ctx.log(line);
  };

  // The header first: reading, downsampling and segmenting are checked against the memory
  // budget before a single sample is inflated.
  {
    ImageReadOptions header_only;
    header_only.samples = ImageSamples::Skip;
    const ImageReadResult header = read_image(path, header_only);
    const ImageVolume& full = header.image;
    ImageVolume work = full;  // the image segment_image sees (dimensions only)
    if (factor > 1 && factor <= full.nx && factor <= full.ny && factor <= full.nz) {
      work.nx = full.nx / factor;
      work.ny = full.ny / factor;
      work.nz = full.nz / factor;
      work.spacing = full.spacing * double(factor);
    }
    const std::uint64_t full_bytes = full.voxel_count() * sizeof(float);
    const std::uint64_t work_bytes = work.voxel_count() * sizeof(float);
    // Reading (the file and the samples), downsampling (both images), then the segmentation.
    const std::uint64_t read = header.file_bytes + full_bytes;
    const std::uint64_t down = factor > 1 ? full_bytes + work_bytes : 0;
    const std::uint64_t segment = work_bytes + apps::segmentation_memory_bytes(work, o);
    require_within_budget(std::max({read, down, segment}), o.memory_budget, path,
                          "segmenting a " + std::to_string(full.nx) + " x " + std::to_string(full.ny) + " x " +
                              std::to_string(full.nz) + " image" +
                              (factor > 1 ? " downsampled " + std::to_string(factor) + "x" : std::string()));
  }
  ImageReadOptions load;  // cancellable: a daemon's cancelled job stops inflating (per chunk of samples)
  load.progress = ctx.options().progress;
  load.memory_budget = o.memory_budget;
  ImageVolume image = read_image(path, load).image;
  if (factor > 1) image = apps::downsample_image(image, factor, ctx.options().progress);
  ctx.log("input: " + path + " " + std::to_string(image.nx) + "x" + std::to_string(image.ny) + "x" +
          std::to_string(image.nz) + (factor > 1 ? " (downsampled " + std::to_string(factor) + "x)" : ""));

  std::vector<std::size_t> seed_voxels;
  if (!seed_points.empty()) {
    for (const Vec3d& p : seed_points) {
      o.seeds.push_back({p, 0.0});
      const Vec3d q = image.to_index(p);
      const auto clamp = [](double v, std::int64_t n) { return std::clamp<std::int64_t>(std::llround(v), 0, n - 1); };
      seed_voxels.push_back(image.index(clamp(q.x, image.nx), clamp(q.y, image.ny), clamp(q.z, image.nz)));
    }
  } else {
    seed_voxels = apps::seed_voxels_above(image, seed_above, seed_stride, 3, ctx.options().progress);
    if (seed_voxels.empty())
      throw Error(ErrorCode::InvalidArgument, ctx.place(s, "seed_above"), "no voxel's 7^3 box lies above the threshold");
    for (const std::size_t v : seed_voxels) {
      const std::int64_t i = std::int64_t(v) % image.nx, j = (std::int64_t(v) / image.nx) % image.ny,
                         k = std::int64_t(v) / (image.nx * image.ny);
      o.seeds.push_back({image.world(i, j, k), o.seed_radius > 0 ? o.seed_radius : 2.5 * image.spacing.x});
    }
  }
  const apps::SegmentationResult r = apps::segment_image(image, o);
  ctx.log("segmentation: " + std::to_string(r.steps) + " steps, " + (r.converged ? "steady" : "not steady"));
  ctx.stats()["segment"] = {{"seeds", o.seeds.size()},
                            {"steps", r.steps},
                            {"time", r.time},
                            {"converged", r.converged},
                            {"last_motion_voxels", r.last_motion},
                            {"image", {image.nx, image.ny, image.nz}},
                            {"spacing", {image.spacing.x, image.spacing.y, image.spacing.z}},
                            {"seconds", {{"edges", r.seconds_edges}, {"evolve", r.seconds_evolve}, {"total", r.seconds_total}}}};
  if (o.label_mask) {
    const std::vector<std::uint8_t> reference =
        apps::threshold_component(image, reference_threshold, seed_voxels, ctx.options().progress);
    const double d = apps::dice(reference, r.label_mask);
    ctx.stats()["segment"]["dice_vs_threshold"] = d;
    ctx.log("Dice against the threshold component: " + std::to_string(d));
  }
  ctx.write_band(r.band);
  ctx.write_surface(r.band);
  if (r.stop == evolve::StopReason::NonFinite) throw Error(ErrorCode::NonFinite, "segment", r.message);
}

}  // namespace levelset::jobs
