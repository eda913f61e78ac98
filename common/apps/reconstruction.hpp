// reconstruct_surface: a watertight surface through unorganised points, no normals needed
// (thesis 5.1.3, after Zhao, Osher and Fedkiw: the zero level of a narrow band moved by the
// gradient flow of the distance to the data, with a curvature term, coarse to fine).
//
// Inputs: points (world units, finite, at least 4 distinct, not all equal); ReconstructionOptions.
// Method:
//   Duplicates (copies, and points within 1e-9 of the box's longest side: apps/unique_points.hpp)
//   count once, counted in duplicate_points.
//   Grid. Isolated points (a scan's far outliers: apps/point_extent.hpp) do not count
//   towards the box; they stay in the point set, outside every grid. Points are shifted to
//   their bounding-box centre (all work in float positions stays
//   exact to ~1e-4 voxel), the final voxel size is h = L / (resolution - 2 (W + 2)) (L the
//   longest side of the points' box: `resolution` voxels span the box padded by W + 2 on each
//   side) or voxel_size; level l of `levels` uses h * 2^(levels - 1 - l). With neither given,
//   the resolution follows from the data (apps/point_sampling.hpp: spacing s, noise n): h =
//   max(s / 4, 2 n): clean points resolve detail finer than their spacing (the fits
//   interpolate), noisy ones get voxels no finer than twice the noise, whose fits would chase
//   it; within [64, 512] voxels.
//   Start (coarsest level): the offset surface {d = offset * h_c} of the unsigned
//   distance d to the points, outer component only (flood fill from the grid's boundary over
//   d > offset on a dense grid of the coarsest level; the cavity inside a closed shell is
//   filled). Why this and not the bounding box the thesis starts from: the offset already
//   follows concavities up to the offset radius, so the flow only has to travel ~offset
//   voxels instead of carving deep concavities, and closing gaps up to 2 * offset * h_c
//   between samples at the coarse level keeps the flood fill from leaking into the inside.
//   offset = max(shell_offset, 1.5 g / h_c), g the 90th percentile of the distance from a
//   sample to its 8th nearest (apps/point_distance.hpp sample_gap): with fewer levels or
//   sparser points a fixed offset leaked (the bunny at 20k-35k points, levels = 2: the flow
//   then pulled the shell onto the points from both sides and collapsed it). Levels (unless
//   given): 1 + floor(log2(1.5 g / h)) within [2, 3], the coarsest voxel no wider than the gap
//   the shell must close, and shell_offset 1: a coarser start closed tunnels and gaps between
//   nearby parts that the points resolve, which the topology guard then kept (CGAL's
//   elephant at 50k points came out genus 1 instead of 3; bench_reconstruct --sweep).
//   Coarsest level, a flow: u_t + beta |grad u| = 0 with (beta > 0 outward, H = k1 + k2)
//     beta = -clamp(g (s - u) / h, -1, 1) - w * min(d, h) * H,   g = 3,
//   s = the signed distance of the voxel to the surface the k nearest points sample along the
//   level set normal (apps/point_distance.hpp LocalFit::signed_offset: the point centroid's
//   offset along n, without the curvature correction here: fed by the front's own curvature
//   it is a backward heat term that grew wrinkles and spurious handles), so s - u is the
//   offset of the front from the data, constant along normals near the data: the flow keeps u a
//   distance (no redistance per step) and moves the front by a fixed fraction of its offset
//   per step: the gradient flow of E_2 = integral of s^2 (thesis eq. 5.4 with p = 2),
//   converging geometrically to the zero of s, which is linear across a voxel (sub-voxel
//   accurate where p = 1's unit speed grad d . n would chatter across the data); far from it
//   the clamp gives unit speed, as p = 1. The second term is Zhao's d * H (p = 1
//   normalisation, weight w): it smooths where the surface is away from the data and
//   vanishes on it; it carries the coarse level's topology regularisation. Fits are cached
//   on the voxels within W + 2 of the start front, computed on the fly elsewhere. One
//   evolve call (evolve/evolution.hpp, first-order upwind, forward Euler) stopped by
//   stop_when once the mean front motion (|beta| dt over the voxels within one voxel of the
//   front) is below tolerance voxels per step, or after max_steps.
//   Finer levels, a snap: the band is resampled (trilinear) at half the voxel size; gaps the
//   start shell closed are dug out where the points sampling their walls lie buried inside
//   the front (carve_gaps; reconstruction_parts.hpp carve_buried_gaps: the empty space beside
//   them, farther than the sampling gap from every point and reaching the outside, turned
//   outside by simple flips only, so no handle is made, except a gap lined almost only by
//   buried points, which reopens whole, tunnels included: pierce_tunnels, CGAL's anchor and
//   couplingdown; a sheet of the inside spanning a gap (cut_webs) whose removal would open a
//   tunnel as it cuts a handle is cut through the bridge's rim instead, by flips that cut the
//   inside and never join the outside, in the carving and the snaps after it: cut_sheets,
//   homer's ankles at 200k points; then, narrow_gaps, a second carving at 0.7 of that clearance,
//   simple flips only: camel, hand, man at 20k points; under noise wider than half a final voxel,
//   the clearance is measured from the points projected onto their neighbourhoods' planes,
//   denoised_clearance, apps/point_denoise.hpp, and a point's burial depth beyond the band's
//   inner edge is read through the band; then at least 3 snap passes: homer's
//   legs at 50k points, bench_reconstruct --sweep); then snap_passes times: every voxel within 1
//   voxel of the front computes its front offset e = clamp(s - u, -h, h) from fits of the points
//   near the voxel (the others within 1.5 voxels, which also move, take their neighbours' mean e;
//   the voxels of a column along the normal share one fit, made at their centroid and evaluated at
//   each, where its quadric patch is at least 4 voxels wide: SheetModel) (point_distance.hpp
//   sheet_fit: the nearest points less those off the near sheet along the normal, so a part
//   thinner than the neighbourhood is not flattened onto its middle plane), two of them:
//   the plane (centroid) fit of the k nearest, with the curvature correction from the coarse
//   level's H (interpolated, bounded by 0.5 h), and a second-order fit, the weighted least
//   squares quadric height function over the level set's tangent plane of max(k, 16) points
//   (unbiased by curvature; used where well-conditioned and within h of the plane fit's).
//   sigma, the fits' mean noise estimate, decides between them: clean data (sigma < 0.4
//   final voxels) take the second-order offsets, each voxel moving by the mean e of itself
//   and its 6 face neighbours (later passes refit only the voxels within 1 voxel of the front);
//   noisy data take the plane offsets (lower variance), smoothed by round(4 sigma^2) (at most
//   3) 3x3x3 box passes (sigma in this level's voxels), and each voxel moves by the mean e of
//   its 3x3x3 neighbourhood (tangential averaging of the fits' noise); once a level found the
//   data noisy, the following levels take height fits over 48 (density / 0.15)^(3/4) points
//   (clean data: over 48 (density / 0.15)^(3/4) sqrt(n / 0.7) points, at least 16, n the
//   previous level's height-fit residual beyond 0.1 voxel in final voxels: mild noise that the
//   plane fits' spread, which carries the sagitta, still calls clean)
//   (density: points per final voxel^2 of front) with at most one smoothing pass instead. A
//   voxel may change sign only next to the front and only where the flip keeps the topology
//   (grid/topology_guard.hpp, also in the coarse flow except where no point lies within
//   free_distance coarse voxels and the voxel is not in a gap between a sampled patch's points,
//   apps/patch_coverage.hpp; a thin inside voxel holding a point within 0.75 coarse voxels, in
//   such a patch, stays inside there (the guard's pinned rule: sheets do not erode); components the
//   data do not support are dropped after the flow: sign_components), and the band is redistanced
//   (fast sweeping, W) on its domain grown by one voxel (the front moved by up to one voxel;
//   without the growth the band lacked voxels near the front where it moved outward, and the next
//   upsampling or the marching cubes left holes). This is the p = 2 flow's fixed point reached in
//   one step (the flow with the gain g = 2 / dt is the snap), valid because the upsampled coarse
//   front lies within about a voxel of the data. Passes (snap_passes per level; on the final level
//   at least clean_final_passes when the first pass found the data clean: the second pass refits
//   along the corrected normals; mildly noisy data there (height-fit residual at most 0.7 final
//   voxels), refit_moved: one more pass on the bricks whose voxels the last pass moved more than
//   0.25 voxel on average, where one pass of neighbourhood-averaged offsets stops short;
//   widen_smooth: a later pass on a level gives 5/3 the points to the soft-scale height fits of the
//   bricks where the pass before kept their largest patch with a mean weight of at least 0.4;
//   facing_points: every pass first gives each point within max(0.5 voxel, 3 sigma) of the front
//   the band's unit gradient there, and a voxel's fits leave out its nearest points that face away
//   from its normal: the far side of a part thinner than the fits' band and the other wall of a
//   narrow gap, which under noise sank the fits toward the part's middle) stop early when the mean
//   |change| of the snapped voxels is below tolerance. A level's first pass may run before any
//   level has read the noise; where its reading asks for 4 times the height fits' points or more,
//   the final level, and a level whose fits read more noise than 0.7 final voxels, start again from
//   the band before it (the few-point fits' noise would otherwise stay in the band: a pass moves
//   each voxel by its neighbourhood's mean offset, which keeps the band's own high-frequency part).
//   Output mesh: marching cubes of the final band (watertight by construction).
// Output: ReconstructionResult (band in the input's world frame, mesh, measures, stages).
// Cost: coarsest level O(steps * band) plus its fits; finer levels O(snap_passes * (voxels
//   within 1.5 h of the front * (max(k, 16) log N + a 6x6 solve) + band)) (fits and
//   redistance); the coarsest level's dense start grid has (L / h_c + 2 pad)^3 voxels.
//   bench_reconstruct --sweep, resolution 256, one core: 2-4 s for 20k points (bunny, 0.1 %
//   noise: 2.6 s, of it the coarsest level's flow 0.95 s, the final level's fits 0.8 s).
// Threading: TBB throughout; the result is identical for any thread count.
// Errors (thrown): Error{InvalidArgument} when no surface is left (the parts are about a voxel
//   thin or smaller at the resolution: two objects 1000 units apart at the automatic 512
//   voxels), for fewer than 4 (distinct) points, all points equal, bad
//   options (resolution < 2 (W + 2) + 8, both resolution and voxel_size,
//   half_width not in [2, 8], levels not in [1, 6], neighbors not in [1, 256], negative
//   curvature weight, tolerance <= 0, max_steps < 1, snap_passes or clean_final_passes not in
//   [0, 16],
//   shell_offset not in [1, 16], negative free_distance; the start shell's offset raised to close
//   the samples' gaps is capped at 16 coarse voxels); Error{NonFinite} for a non-finite point
//   (naming it) or option; Error{LimitExceeded} when the final grid would exceed max_resolution
//   voxels along a side or the coarsest level's dense grid 2^27 voxels; Error{Cancelled} through
//   progress (checked between steps and inside each phase).
// Log: options.log (may be empty) gets one line per level (steps, voxels, phase seconds) and
//   one for the mesh, from the calling thread; a warning when under 70 % of the points lie
//   near the surface (ReconstructionResult::coverage: a sampled open sheet collapses, parts
//   thinner than a voxel vanish) and when the automatic resolution is capped.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "apps/point_sampling.hpp"
#include "core/progress.hpp"
#include "core/vec3.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::apps {

struct ReconstructionOptions {
  int resolution = 0;           // voxels along the longest side of the padded box, or ...
  double voxel_size = 0.0;      // ... the final voxel size (world); at most one of the two > 0;
                                // neither: the resolution follows from the data (see above)
  double half_width = 3.0;      // band half-width W, voxels
  int levels = 0;               // coarse-to-fine levels (voxel size halves per level); 0: from the data
  double shell_offset = 1.0;    // start shell: offset of the points in coarsest-level voxels (at least)
  int neighbors = 8;            // k points per local surface fit (more: smoother under noise)
  double curvature_weight = 0.3;  // w of the coarsest level's flow
  int max_steps = 120;          // coarsest level's flow
  int snap_passes = 1;          // per finer level (noisy data: more drift, 1 measured best)
  int clean_final_passes = 2;   // final level, clean data (second-order snaps): at least this many
  bool refit_moved = true;      // final level, noisy data: one more pass on the bricks the last one moved far
  bool widen_smooth = true;     // later passes: wider soft-scale height fits where the pass before kept the largest patch
  bool facing_points = true;    // snaps: fits leave out the points facing away from the front (a thin part's far side)
  double tolerance = 0.01;      // voxels: flow: mean front motion per step; snap: mean change
  bool guard_flow = true;        // coarsest flow: refuse sign changes that change the topology (slower)
  bool guard_snaps = true;      // snaps: the same
  double free_distance = 1.0;   // flow guard: topology may change where the nearest point is farther (coarse voxels)
  bool carve_gaps = true;       // finer levels: reopen gaps the start shell closed over buried points
  bool pierce_tunnels = true;   // carve_gaps: a gap lined almost only by buried points may reopen as a tunnel
  bool narrow_gaps = true;      // carve_gaps: a second carving reopens gaps narrower than the sampling gap's clearance
  bool cut_webs = true;         // carve_gaps: sheets of the inside exposed to the outside and clear of every point are cut where that removes a handle
  bool web_tunnels = true;      // carve_gaps: such sheets spanning a handle's hole (wherever they lie) are cut where that opens one tunnel (noise up to half a final voxel)
  bool cut_sheets =
      true;  // carve_gaps: sheets whose removal whole would not remove a handle are cut by cutting
             // flips only, the snaps after may cut the bridge they span (no tunnels)
  bool denoised_clearance = true;  // carve_gaps under noise (sigma > 0.5 final voxels): clearance from points projected onto their planes
  int max_resolution = 4096;    // cap on the final grid's longest side (voxels)
  ProgressHook progress;
  std::function<void(const std::string&)> log;  // progress lines; empty: none
  bool log_topology = false;    // with log: also each level's genus and components (a marching cubes per level)
};

struct ReconstructionStage {
  int level = 0;                // 0 = coarsest (flow), then snaps
  double voxel_size = 0.0;
  int steps = 0;                // flow steps, or snap passes
  double shell_offset = 0.0;    // coarsest level: the start shell's offset (voxels; raised to close the samples' gaps)
  bool converged = false;       // tolerance reached
  double last_change = 0.0;     // voxels: flow: mean front motion per step; snap: mean change
  double noise = 0.0;           // snap: the fits' mean robust spread (noise estimate), voxels
  double height_noise = 0.0;    // snap: the height fits' mean residual (noise without the sagitta), voxels
  int smoothing = 0;            // snap: extra smoothing passes of the offsets it chose
  bool second_order = false;    // snap: clean data: the height fits' offsets, unaveraged (last pass)
  std::uint64_t height_fits = 0;  // snap: fits whose height fit was usable (all passes)
  int height_neighbors = 0;     // snap: points per height fit (last pass)
  std::uint64_t refused_flips = 0;  // sign changes refused as not simple (topology kept), all steps / passes
  // coarsest level: components without data, and specks, turned to the other sign
  std::uint64_t dropped_components = 0;
  std::uint64_t buried_points = 0;  // finer levels: points buried inside the upsampled front
  int carved_regions = 0;           // finer levels: closed gaps reopened (turned outside)
  int pierced_regions = 0;          // of them reopened whole, tunnels allowed (pierce_tunnels), or webs cut
  int webs_cut = 0;                 // of those, webs (cut_webs)
  int sheets_cut = 0;               // carved regions dug by cutting flips (cut_sheets)
  int web_tunnels = 0;              // finer levels: webs spanning a handle's hole cut, one tunnel each (web_tunnels)
  std::uint64_t refit_bricks = 0;   // final level, noisy data: bricks that took one more snap pass (refit_moved)
  std::uint64_t widened_bricks = 0;  // bricks whose height fits a later pass widened (widen_smooth), summed over passes
  std::uint64_t carved_voxels = 0;
  std::uint64_t active_voxels = 0;
  std::uint64_t fit_voxels = 0; // local fits computed (cache, or snapped voxels of all passes)
  std::uint64_t fit_models = 0; // snap: sheet fits made for them (voxels of a column or block share one)
  std::uint64_t facing_fits = 0;  // snap: fits that left out points facing away (facing_points), all passes
  double seconds = 0.0;         // whole level
  double seconds_start = 0.0;   // start shell, or upsampling
  double seconds_fit = 0.0;     // fits (the snap passes' fits and updates)
  double seconds_flow = 0.0;    // evolve (includes its redistances)
  double seconds_redistance = 0.0;
};

struct ReconstructionResult {
  NarrowBand band;              // final level, world frame of the input
  TriangleMesh mesh;            // its zero level (marching cubes)
  MeshMeasures measures;
  std::vector<ReconstructionStage> stages;
  int steps = 0;                // all levels (flow steps + snap passes)
  double voxel_size = 0.0;      // final
  int resolution = 0;           // the final grid's (given, or chosen from the data); 0 with voxel_size
  SamplingEstimate sampling;    // the points' spacing and noise (world), measured first
  double denoised_noise = 0.0;  // the noise of the points the carving's clearance was measured from
                                // (denoised_clearance: projected onto their planes; 0: the raw points)
  std::uint64_t isolated_points = 0;  // isolated points outside the box the grids span (apps/point_extent.hpp)
  std::uint64_t duplicate_points = 0;  // copies merged before anything else (apps/unique_points.hpp)
  double coverage = 1.0;        // share of the points within max(2 h, 3 noise) of the surface (apps/surface_coverage.hpp)
  double seconds_mesh = 0.0;
  double seconds = 0.0;         // total
};

ReconstructionResult reconstruct_surface(const std::vector<Vec3d>& points, const ReconstructionOptions& options);

}  // namespace levelset::apps
