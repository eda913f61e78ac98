// reconstruct_surface: validation, the resolution and the levels from the data, the levels in
// order (reconstruction_parts.hpp: the flow, the snaps, the grids), the mesh.
#include "apps/reconstruction.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "apps/point_extent.hpp"
#include "apps/point_denoise.hpp"
#include "apps/point_sampling.hpp"
#include "apps/reconstruction_parts.hpp"
#include "apps/surface_coverage.hpp"
#include "apps/unique_points.hpp"
#include "core/error.hpp"
#include "surface/marching_cubes.hpp"

namespace levelset::apps {

namespace {

using detail::Clock;
using detail::reframed;
using detail::seconds_since;
using detail::start_shell;

constexpr double kGapClosing = 1.5;
constexpr double kDenoiseClearanceNoise = 0.5;
// Webs are cut to open tunnels (ReconstructionOptions::web_tunnels) only under noise of at
// most this many final voxels: beyond it a web's clear core cannot tell a handle's hole from
// a narrow gap the noise blurs shut below it (bench_reconstruct --sweep, 0.5 % noise, ~1.8
// final voxels: diplodocus' tail by its leg genus 0 -> 2 at 20k points and 0 -> 1 at 50k,
// camel 0 -> 2 at 50k, where anchor_dense at 20k came right, 1 -> 4); at 0.1 % (~0.4) the
// cuts were the truth's (the elephants' trunk loops at 20k points, 2 -> 3).
constexpr double kMaxWebTunnelNoise = 0.5;
// The web tunnels' fine pass (reconstruction_parts.hpp) only on the final level and on points
// this clean (final voxels): measured on the clean sweep rows only (their noise reads
// 0.03-0.1 voxel; 0.1 % of a diagonal is at least 0.256 final voxels at R = 256). On the
// middle level a hole in the sampling of rotor_small's thin blades (50k points) read 0.26 of
// its lining below the surface, among turbine's bolt holes' 0.24-0.32, and its cut made a
// handle the truth does not have.
constexpr double kMaxFineTunnelNoise = 0.15;
constexpr double kDenoiseMaxMove = 2.0;
// Points this close (relative to the longest side of their box) are one point: float noise
// of a copy, far below any grid (max_resolution 4096 is 2.4e-4).
constexpr double kDuplicateTolerance = 1e-9;
// Below this share of the points near the surface the log warns (0.5 % noise at R = 256, 2
// voxels sigma, still has ~80 % within the 3 voxels tested).
constexpr double kLowCoverage = 0.7;

// The resolution when the caller gives none (see the header): voxels kSpacingVoxels sample
// spacings wide, widened to kNoiseVoxels times the noise estimate, within [kAutoMin, kAutoMax].
// Measured on the built-in knot (20k points, resolutions 128-512): clean points gain from
// every finer grid (512: 3x better Chamfer than 256), noisy ones (0.2%) are best near 2 sigma
// per voxel (finer grids fit the noise).
constexpr double kSpacingVoxels = 0.25, kNoiseVoxels = 2.0;
constexpr int kAutoMin = 64, kAutoMax = 512;
// Levels from the data (see reconstruct_surface): a single level runs the flow on the final
// grid (slow: 15-30 s at 256); more than three coarsen beyond what 20k points need.
constexpr int kMinAutoLevels = 2, kMaxAutoLevels = 3;

int auto_resolution(const SamplingEstimate& s, double longest, double half_width) {
  const double h = std::max(kSpacingVoxels * s.spacing, kNoiseVoxels * s.noise);
  const double pad = 2.0 * (half_width + 2.0);
  if (!(h > 0.0)) return kAutoMax;
  return int(std::clamp(std::ceil(longest / h + pad), double(kAutoMin), double(kAutoMax)));
}

void require(bool ok, const std::string& reason) {
  if (!ok) throw Error(ErrorCode::InvalidArgument, "reconstruct", reason);
}

void validate(const std::vector<Vec3d>& points, const ReconstructionOptions& o) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y) || !std::isfinite(points[i].z))
      throw Error(ErrorCode::NonFinite, "reconstruct", "point " + std::to_string(i) + " is not finite");
  require(points.size() >= 4, "need at least 4 points, got " + std::to_string(points.size()));
  if (!std::isfinite(o.voxel_size) || !std::isfinite(o.half_width) || !std::isfinite(o.shell_offset) ||
      !std::isfinite(o.curvature_weight) || !std::isfinite(o.tolerance))
    throw Error(ErrorCode::NonFinite, "reconstruct", "non-finite option");
  require(!(o.resolution > 0 && o.voxel_size > 0.0), "give at most one of resolution and voxel_size");
  require(o.resolution >= 0 && o.voxel_size >= 0.0, "resolution and voxel_size must not be negative");
  require(o.half_width >= 2.0 && o.half_width <= 8.0, "half_width must be in [2, 8] voxels");
  require(o.resolution == 0 || o.resolution >= int(2 * (o.half_width + 2)) + 8,
          "resolution " + std::to_string(o.resolution) + " is too small for the band");
  require(o.levels >= 0 && o.levels <= 6, "levels must be in [1, 6] (0: from the data)");
  require(o.shell_offset >= 1.0 && o.shell_offset <= 16.0, "shell_offset must be in [1, 16] voxels");
  require(o.neighbors >= 1 && o.neighbors <= 256, "neighbors must be in [1, 256]");
  require(o.curvature_weight >= 0.0, "curvature_weight must be >= 0");
  require(o.max_steps >= 1, "max_steps must be >= 1");
  require(o.snap_passes >= 0 && o.snap_passes <= 16, "snap_passes must be in [0, 16]");
  require(o.clean_final_passes >= 0 && o.clean_final_passes <= 16, "clean_final_passes must be in [0, 16]");
  require(o.tolerance > 0.0, "tolerance must be > 0");
  require(o.max_resolution >= 16, "max_resolution must be >= 16");
  if (!std::isfinite(o.free_distance)) throw Error(ErrorCode::NonFinite, "reconstruct", "non-finite free_distance");
  require(o.free_distance >= 0.0, "free_distance must be >= 0 coarse voxels");
}

// The log line of a finished level.
std::string stage_line(const ReconstructionStage& stage) {
  char line[640];
  std::snprintf(line, sizeof line,
                "level %d: h %.4g, shell offset %.2f voxel, %s %d, change %.4f voxel, noise %.3f "
                "voxel (height fits %.3f), "
                "%s (%d points), smoothing %d, %llu buried points, %d regions carved (%d pierced, "
                "%d webs cut, %d sheets cut, %llu voxels), %d web tunnels, %llu voxels, "
                "%llu fits (%llu height, %llu models); start %.3f s, "
                "fits %.3f s, flow %.3f s, redistance %.3f s, total %.3f s",
                stage.level, stage.voxel_size, stage.shell_offset,
                stage.level == 0 ? "flow steps" : "snap passes", stage.steps, stage.last_change,
                stage.noise, stage.height_noise, stage.second_order ? "second order" : "plane fits",
                stage.height_neighbors, stage.smoothing,
                static_cast<unsigned long long>(stage.buried_points), stage.carved_regions,
                stage.pierced_regions, stage.webs_cut, stage.sheets_cut,
                static_cast<unsigned long long>(stage.carved_voxels), stage.web_tunnels,
                static_cast<unsigned long long>(stage.active_voxels),
                static_cast<unsigned long long>(stage.fit_voxels),
                static_cast<unsigned long long>(stage.height_fits),
                static_cast<unsigned long long>(stage.fit_models), stage.seconds_start,
                stage.seconds_fit, stage.seconds_flow, stage.seconds_redistance, stage.seconds);
  return line;
}

// The topology of a level's zero level (ReconstructionOptions::log_topology).
std::string topology_line(const NarrowBand& band, const ReconstructionStage& stage, const ProgressHook& progress) {
  MarchingCubesOptions mc;
  mc.progress = progress;
  const MeshMeasures m = measure_mesh(marching_cubes(band, mc).mesh);
  char line[256];
  std::snprintf(line, sizeof line,
                "level %d: genus %g, components %llu, watertight %s, %llu sign changes refused, %llu stray components "
                "dropped",
                stage.level, m.genus, static_cast<unsigned long long>(m.components), m.watertight ? "yes" : "no",
                static_cast<unsigned long long>(stage.refused_flips),
                static_cast<unsigned long long>(stage.dropped_components));
  return line;
}

}  // namespace

ReconstructionResult reconstruct_surface(const std::vector<Vec3d>& input, const ReconstructionOptions& o) {
  const auto t_start = Clock::now();
  validate(input, o);
  BBox box;
  for (const Vec3d& p : input) box.extend(p);
  Vec3d centre = box.center();
  {
    const Vec3d raw = box.extent();
    const double longest_raw = std::max({raw.x, raw.y, raw.z});
    require(longest_raw > 0.0 && std::isfinite(longest_raw), "all points are equal (or the extent is not finite)");
  }
  const double W = o.half_width;
  // Copies of a point (and coordinates equal to 1e-9 of the extent) count once: the k-nearest
  // statistics and fits below assume distinct samples.
  UniquePointsOptions unique;
  unique.tolerance = kDuplicateTolerance * std::max({box.extent().x, box.extent().y, box.extent().z});
  UniquePointsResult distinct = unique_points(input, unique);
  require(distinct.points.size() >= 4,
          "need at least 4 distinct points, got " + std::to_string(distinct.points.size()));
  const std::vector<Vec3d>& cloud = distinct.points;
  std::vector<Vec3d> points(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) points[i] = cloud[i] - centre;
  auto index = std::make_unique<PointIndex>(points);
  // The grid spans the cloud without its isolated points (far outliers of a scan), which
  // stay in the index but lie outside every grid; re-centred on that box.
  const PointExtentResult extent = point_extent(*index);
  std::uint64_t isolated = 0;
  if (extent.isolated > 0) {
    isolated = extent.isolated;
    box.min = extent.box.min + centre;
    box.max = extent.box.max + centre;
    centre = box.center();
    for (std::size_t i = 0; i < cloud.size(); ++i) points[i] = cloud[i] - centre;
    index = std::make_unique<PointIndex>(points);
  }
  const Vec3d ext = box.extent();
  const double longest = std::max({ext.x, ext.y, ext.z});
  require(longest > 0.0 && std::isfinite(longest), "all points but isolated ones are equal");
  ReconstructionResult result;
  result.isolated_points = isolated;
  result.duplicate_points = distinct.merged;
  result.sampling = estimate_sampling(*index, {16, 2000, o.progress});
  result.resolution = o.resolution > 0 ? o.resolution : 0;
  if (o.resolution == 0 && o.voxel_size <= 0.0) result.resolution = auto_resolution(result.sampling, longest, W);
  const double h_final = o.voxel_size > 0.0 ? o.voxel_size : longest / (double(result.resolution) - 2.0 * (W + 2.0));
  const double side = longest / h_final + 2.0 * (W + 2.0);
  if (!(side <= double(o.max_resolution)))
    throw Error(ErrorCode::LimitExceeded, "reconstruct",
                "the final grid would have " + std::to_string(side) + " voxels along its longest side (max_resolution " +
                    std::to_string(o.max_resolution) + ")");
  auto log = [&](const std::string& line) {
    if (o.log) o.log(line);
  };

  if (distinct.merged > 0) log(std::to_string(distinct.merged) + " duplicate points merged");
  if (isolated > 0) log(std::to_string(isolated) + " isolated points outside the box the grids span");
  if (o.resolution == 0 && o.voxel_size <= 0.0) {
    char chosen[200];
    std::snprintf(chosen, sizeof chosen, "resolution %d from the data: spacing %.4g, noise %.4g (world; %.2f and %.2f voxels)",
                  result.resolution, result.sampling.spacing, result.sampling.noise, result.sampling.spacing / h_final,
                  result.sampling.noise / h_final);
    log(chosen);
    const double asked = std::max(kSpacingVoxels * result.sampling.spacing, kNoiseVoxels * result.sampling.noise);
    if (result.resolution == kAutoMax && asked < 0.5 * h_final)
      log("the resolution is capped at " + std::to_string(kAutoMax) +
          ": the spacing asks for finer voxels (parts far apart? give --resolution or --voxel-size)");
  }
  BBox local;
  local.min = box.min - centre;
  local.max = box.max - centre;

  // The start shell closes holes between samples up to its offset: at least kGapClosing times
  // the 90th percentile of the distance to the 8th nearest sample, or its flood fill leaks
  // into the inside and the flow collapses onto the points from both sides.
  const double gap = extent.gap;  // sample_gap(index, 8, 0.9, 4000), measured by point_extent
  // Levels from the data unless given: the coarsest voxel no wider than the gap the shell
  // must close (coarser levels only close more: tunnels and gaps between nearby parts that
  // the points resolve), within [kMinAutoLevels, kMaxAutoLevels]; fewer when the coarsest
  // would have under 24 voxels along the longest side.
  int levels = o.levels;
  if (levels == 0) {
    const double ratio = kGapClosing * gap / h_final;
    levels = ratio >= 1.0 ? 1 + int(std::floor(std::log2(ratio))) : 1;
    levels = std::clamp(levels, kMinAutoLevels, kMaxAutoLevels);
  }
  while (levels > 1 && longest / (h_final * std::ldexp(1.0, levels - 1)) < 24.0) --levels;
  const double h_coarse = h_final * std::ldexp(1.0, levels - 1);
  const double shell_offset = std::min(16.0, std::max(o.shell_offset, kGapClosing * gap / h_coarse));
  const double pad = (shell_offset + W + 3.0) * h_coarse;
  const Vec3d origin = local.min - Vec3d{pad, pad, pad};

  // Under noise (sigma above kDenoiseClearanceNoise final voxels) the carving's clearance is
  // measured from the points projected onto their local planes: the raw points' scatter
  // into a closed gap or hole (~2.5 sigma at its extremes) left no clear core in holes a few
  // sigma wider than the gap (CGAL's couplingdown and anchor at 20k points, 0.5 %).
  std::unique_ptr<PointIndex> projected;
  double projected_noise = 0.0;
  if (o.carve_gaps && o.denoised_clearance && result.sampling.noise > kDenoiseClearanceNoise * h_final) {
    ProjectToPlanesOptions project;
    project.progress = o.progress;
    project.max_move = kDenoiseMaxMove * result.sampling.noise;
    projected = std::make_unique<PointIndex>(project_to_planes(*index, project).points);
    projected_noise = estimate_sampling(*projected, {16, 2000, o.progress}).noise;
    result.denoised_noise = projected_noise;
    char line[256];
    std::snprintf(line, sizeof line, "carving clearance from the points projected onto their planes: noise %.3g -> %.3g (%.2f -> %.2f final voxels)",
                  result.sampling.noise, projected_noise, result.sampling.noise / h_final, projected_noise / h_final);
    log(line);
  }
  NarrowBand band;
  detail::SnapNoise noise;  // the last snap pass's estimates, final voxels
  for (int level = 0; level < levels; ++level) {
    const auto t_level = Clock::now();
    const double h = h_final * std::ldexp(1.0, levels - 1 - level);
    ReconstructionStage stage;
    stage.level = level;
    stage.voxel_size = h;
    if (level == 0) {
      // The flow from the start shell.
      band = start_shell(*index, local, origin, h, shell_offset, W, o.progress);
      stage.shell_offset = shell_offset;
      stage.seconds_start = seconds_since(t_level);
      detail::LevelOutput flowed = detail::flow_level(std::move(band), *index, o, levels, std::move(stage));
      band = std::move(flowed.band);
      stage = std::move(flowed.stage);
    }
    if (level > 0 || levels == 1) {
      // The snap (on a single level: after the flow, with its own curvature).
      detail::SnapLevel where{level, levels, h_final, {}};
      where.carve.noise = result.sampling.noise;
      where.carve.gap = gap;
      where.carve.pierce = o.pierce_tunnels;
      where.carve.narrow = o.narrow_gaps;
      where.carve.cut_webs = o.cut_webs;
      where.carve.cut_sheets = o.cut_sheets;
      where.carve.web_tunnels = o.web_tunnels && result.sampling.noise <= kMaxWebTunnelNoise * h_final;
      where.carve.fine_tunnels = where.carve.web_tunnels && level == levels - 1 &&
                                 result.sampling.noise <= kMaxFineTunnelNoise * h_final;
      where.carve.clearance_points = projected.get();
      where.carve.clearance_noise = projected_noise;
      detail::SnapOutput snapped = detail::snap_level(std::move(band), *index, o, where, std::move(stage), noise);
      band = std::move(snapped.band);
      stage = std::move(snapped.stage);
      noise = snapped.noise;
    }
    stage.active_voxels = band.active_voxel_count();
    stage.seconds = seconds_since(t_level);
    log(stage_line(stage));
    if (o.log && o.log_topology) log(topology_line(band, stage, o.progress));  // debug aid
    result.steps += stage.steps;
    result.stages.push_back(stage);
  }

  const auto t_mesh = Clock::now();
  result.band = reframed(band, centre, band.half_width());
  MarchingCubesOptions mc;
  mc.progress = o.progress;
  result.mesh = marching_cubes(result.band, mc).mesh;
  // No surface at all is never the answer for points: say why instead of writing an empty mesh.
  if (result.mesh.triangles.empty()) {
    char reason[320];
    std::snprintf(reason, sizeof reason,
                  "no surface left at voxel size %.4g (the points' spacing is %.4g): their parts are about a voxel "
                  "thin or smaller at this resolution; give a finer resolution or voxel size, or reconstruct the "
                  "parts separately",
                  h_final, result.sampling.spacing);
    throw Error(ErrorCode::InvalidArgument, "reconstruct", reason);
  }
  result.measures = measure_mesh(result.mesh);
  {
    // The result against its data (apps/surface_coverage.hpp): points within 2 voxels, or 3
    // noise sigmas, of the surface; isolated points do not count.
    SurfaceCoverageOptions cover;
    cover.distance = std::max(2.0 * h_final, 3.0 * result.sampling.noise);
    cover.within = box;
    result.coverage = surface_coverage(result.band, cloud, cover).fraction;
    if (result.coverage < kLowCoverage) {
      char line[256];
      std::snprintf(line, sizeof line,
                    "only %.0f %% of the points lie near the surface: parts thinner than a voxel or open sheets "
                    "were lost (a finer resolution keeps thin parts)",
                    100.0 * result.coverage);
      log(line);
    }
  }
  result.seconds_mesh = seconds_since(t_mesh);
  result.voxel_size = h_final;
  result.seconds = seconds_since(t_start);
  char line[128];
  std::snprintf(line, sizeof line, "mesh: %zu triangles, %.3f s; total %.3f s", result.mesh.triangles.size(),
                result.seconds_mesh, result.seconds);
  log(line);
  return result;
}

}  // namespace levelset::apps

