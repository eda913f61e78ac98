#include "apps/segmentation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/text.hpp"
#include "grid/build_from_sdf.hpp"
#include "grid/interpolate.hpp"
#include "surface/marching_cubes.hpp"

namespace levelset::apps {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void require(bool ok, const std::string& reason) {
  if (!ok) throw Error(ErrorCode::InvalidArgument, "segment_image", reason);
}

// (1 - eps H) g: g advective, -eps g H parabolic (|beta_p| <= eps |H| since g <= 1).
evolve::SpeedFunction segmentation_speed(double eps) {
  evolve::SpeedFunction s;
  s.name = "segmentation";
  s.needs = evolve::kNeedsEdge | (eps > 0 ? evolve::kNeedsMean : 0u);
  s.has_parabolic = eps > 0;
  s.diffusion = eps;
  s.eval = [eps](const evolve::SpeedBatch& b, const evolve::SpeedOutput& out) {
    for (int i = 0; i < b.count; ++i) {
      out.advective[i] = b.edge[i];
      if (out.parabolic) out.parabolic[i] = eps > 0 ? float(-eps * double(b.edge[i]) * double(b.mean[i])) : 0.0f;
    }
  };
  return s;
}

// Enclosed volume and area of the zero level (marching cubes, divergence theorem).
struct VolumeArea {
  double volume = 0, area = 0;
};
VolumeArea measure_front(const NarrowBand& band) {
  const SurfaceResult s = marching_cubes(band);
  VolumeArea m;
  // About the mesh's centre, as measure_mesh does (precision far from the world origin).
  const BBox box = s.mesh.bounds();
  const Vec3d o = box.empty() ? Vec3d{} : 0.5 * (box.min + box.max);
  for (const auto& t : s.mesh.triangles) {
    const Vec3d a = s.mesh.vertices[t[0]] - o;
    const Vec3d b = s.mesh.vertices[t[1]] - o;
    const Vec3d c = s.mesh.vertices[t[2]] - o;
    m.volume += dot(a, cross(b, c)) / 6.0;
    m.area += 0.5 * length(cross(b - a, c - a));
  }
  return m;
}

}  // namespace

std::uint64_t segmentation_memory_bytes(const ImageVolume& image, const SegmentationOptions& o) {
  const double voxels = double(image.voxel_count());
  double bytes = 5.0 * sizeof(float) * voxels;  // edge indicator: normal/smoothed/g + grad g (3)
  if (o.label_mask) bytes += voxels;
  // The front: at most about the image box's surface, 2 W voxels thick, ~16 bytes per active
  // voxel with the evolution's copies of the band.
  const double h = o.voxel_size > 0 ? o.voxel_size : std::min({image.spacing.x, image.spacing.y, image.spacing.z});
  if (std::isfinite(h) && h > 0) {
    const double ax = double(image.nx) * image.spacing.x / h + 1, ay = double(image.ny) * image.spacing.y / h + 1,
                 az = double(image.nz) * image.spacing.z / h + 1;
    bytes += 2.0 * (ax * ay + ay * az + az * ax) * 2.0 * std::max(2.0, o.half_width) * 16.0;
  }
  return bytes >= 1.8e19 ? ~std::uint64_t{0} : std::uint64_t(bytes);
}

void require_segmentation_budget(const ImageVolume& image, std::uint64_t file_bytes, const SegmentationOptions& o,
                                 const std::string& where) {
  const std::uint64_t samples = image.voxel_count() * sizeof(float);
  const std::uint64_t work = segmentation_memory_bytes(image, o);
  const std::uint64_t need = std::max(file_bytes + samples, samples + work);
  require_within_budget(need, o.memory_budget, where,
                        "segmenting a " + std::to_string(image.nx) + " x " + std::to_string(image.ny) + " x " +
                            std::to_string(image.nz) + " image");
}

std::vector<std::uint8_t> inside_mask(const NarrowBand& band, const ImageVolume& image) {
  std::vector<std::uint8_t> mask(image.voxel_count(), 0);
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, image.nz), [&](const tbb::blocked_range<std::int64_t>& r) {
    BandAccessor accessor(band);
    for (std::int64_t k = r.begin(); k != r.end(); ++k)
      for (std::int64_t j = 0; j < image.ny; ++j)
        for (std::int64_t i = 0; i < image.nx; ++i)
          mask[image.index(i, j, k)] = sample_trilinear(accessor, band, image.world(i, j, k)) < 0.0f ? 1 : 0;
  });
  return mask;
}

SegmentationResult segment_image(const ImageVolume& image, const SegmentationOptions& o) {
  const auto t0 = Clock::now();
  require(image.voxel_count() > 0 && image.samples.size() == image.voxel_count(), "empty image");
  require(isfinite(image.spacing) && image.spacing.x > 0 && image.spacing.y > 0 && image.spacing.z > 0 &&
              isfinite(image.origin), "image spacing must be positive and finite");
  require(!o.seeds.empty(), "no seeds");
  const double h = o.voxel_size > 0 ? o.voxel_size : std::min({image.spacing.x, image.spacing.y, image.spacing.z});
  require(std::isfinite(o.voxel_size) && o.voxel_size >= 0 && std::isfinite(h), "voxel_size must be >= 0 and finite");
  require(std::isfinite(o.half_width) && o.half_width >= 2 && o.half_width <= 64, "half_width must be in [2, 64]");
  require(std::isfinite(o.eps), "eps must be finite");
  require(std::isfinite(o.attraction) && o.attraction >= 0, "attraction must be >= 0");
  require(o.steps >= 0 && std::isfinite(o.time) && o.time >= 0 && !(o.steps > 0 && o.time > 0),
          "give steps or time (or neither, to run until steady), not both, and not negative");
  require(std::isfinite(o.max_time) && o.max_time >= 0 && o.max_steps > 0, "max_time >= 0 and max_steps > 0");
  require(std::isfinite(o.check_time) && o.check_time >= 0, "check_time must be >= 0");
  require(std::isfinite(o.motion_tolerance) && o.motion_tolerance >= 0, "motion_tolerance must be >= 0");
  require(std::isfinite(o.seed_radius) && o.seed_radius >= 0, "seed_radius must be >= 0");
  const BBox box = image.bounds();
  const Vec3d extent = box.extent();
  const double cells = (extent.x / h + 1) * (extent.y / h + 1) * (extent.z / h + 1);
  if (!(cells <= double(o.max_grid_voxels)))
    throw Error(ErrorCode::LimitExceeded, "segment_image",
                "the image box holds " + format_number(cells) + " grid voxels of size " + format_number(h) +
                    ", above the limit of " + std::to_string(o.max_grid_voxels));
  require_segmentation_budget(image, 0, o, "segment_image");
  const double default_radius = o.seed_radius > 0 ? o.seed_radius : 3 * h;
  std::vector<SegmentationSeed> seeds = o.seeds;
  BBox seed_bounds;
  for (SegmentationSeed& s : seeds) {
    require(isfinite(s.center) && std::isfinite(s.radius) && s.radius >= 0, "seed centres and radii must be finite");
    if (s.radius == 0) s.radius = default_radius;
    require(s.radius >= h, "a seed radius must be at least one grid voxel (" + format_number(h) + ")");
    require(s.center.x >= box.min.x && s.center.y >= box.min.y && s.center.z >= box.min.z &&
                s.center.x <= box.max.x && s.center.y <= box.max.y && s.center.z <= box.max.z,
            "a seed centre lies outside the image");
    seed_bounds.extend(s.center - Vec3d{s.radius, s.radius, s.radius});
    seed_bounds.extend(s.center + Vec3d{s.radius, s.radius, s.radius});
  }
  SegmentationResult result;

  // 1. The edge indicator.
  EdgeIndicatorOptions edge_options = o.edge;
  edge_options.progress.cancel = o.progress.cancel;
  edge_options.progress.on_progress = nullptr;
  const EdgeIndicator edges = edge_indicator(image, edge_options);
  result.intensity_low = edges.intensity_low;
  result.intensity_high = edges.intensity_high;
  result.seconds_edges = since(t0);

  // 2. The seeds' band on the image's grid.
  SdfBuildOptions build;
  build.frame = GridFrame{h, image.origin, o.half_width};
  build.progress.cancel = o.progress.cancel;
  const auto sdf = [&seeds](const Vec3d& p) {
    double d = std::numeric_limits<double>::infinity();
    for (const SegmentationSeed& s : seeds) d = std::min(d, length(p - s.center) - s.radius);
    return d;
  };
  NarrowBand band = build_from_sdf(sdf, seed_bounds, build).band;

  // 3. Evolve.
  const auto t1 = Clock::now();
  const double eps = o.eps < 0 ? h : o.eps;
  const double s_ref = std::min({image.spacing.x, image.spacing.y, image.spacing.z});
  evolve::EvolutionOptions e;
  e.speed = segmentation_speed(eps);
  e.fields.edge = [&edges](const Vec3d& p) { return edges.sample(p); };
  if (o.attraction > 0) {
    e.velocity.kind = evolve::Velocity::Kind::Field;
    const double w = o.attraction * s_ref;
    e.velocity.field = [&edges, w](const Vec3d& p, double) { return edges.sample_gradient(p) * -w; };
  }
  e.extension = o.extension;
  e.redistance_every = o.redistance_every;
  e.drift_tolerance = o.drift_tolerance;
  e.scheme = o.scheme;
  e.rk_order = o.rk_order;
  e.progress.cancel = o.progress.cancel;
  const bool steady = o.steps == 0 && o.time == 0;
  const double max_time = o.max_time > 0 ? o.max_time : 2 * length(extent + Vec3d{h, h, h});
  const double check_time = o.check_time > 0 ? o.check_time : 4 * h;
  double volume = steady ? measure_front(band).volume : 0.0;
  while (true) {
    if (o.steps > 0) {
      e.steps = std::min(o.steps, o.max_steps);
    } else {
      const double goal = steady ? max_time : o.time;
      e.time = steady ? std::min(check_time, goal - result.time) : goal;
      e.max_steps = o.max_steps - result.steps;
    }
    evolve::EvolutionResult r = evolve::evolve(band, e);
    band = std::move(r.band);
    result.steps += r.steps;
    result.time += r.time;
    result.stop = r.stop;
    result.message = r.message;
    if (r.stop != evolve::StopReason::Completed || !steady) break;
    const VolumeArea m = measure_front(band);
    // Mean normal motion of the front over the interval, in grid voxels, scaled to a full
    // interval (the last one may be cut short by max_time).
    result.last_motion = std::abs(m.volume - volume) / (std::max(m.area, h * h) * h) *
                         (r.time > 0 ? check_time / r.time : 1.0);
    volume = m.volume;
    ++result.checks;
    if (o.on_check) o.on_check({result.steps, result.time, m.volume, m.area, result.last_motion, band.active_voxel_count()});
    o.progress.step(std::min(1.0, result.time / max_time), "segment");
    if (result.last_motion <= o.motion_tolerance) {
      result.converged = true;
      break;
    }
    if (result.time >= max_time * (1 - 1e-12) || result.steps >= o.max_steps) break;
  }
  if (result.stop == evolve::StopReason::Cancelled) throw Error(ErrorCode::Cancelled, "segment_image", "cancelled");
  result.seconds_evolve = since(t1);

  // 4. Surface, measures, mask.
  const auto t2 = Clock::now();
  result.surface = marching_cubes(band);
  result.measures = measure_mesh(result.surface.mesh);
  if (o.label_mask) {
    result.label_mask = inside_mask(band, image);
    for (const std::uint8_t m : result.label_mask) result.inside_voxels += m;
  }
  result.band = std::move(band);
  result.seconds_surface = since(t2);
  result.seconds_total = since(t0);
  return result;
}

}  // namespace levelset::apps
