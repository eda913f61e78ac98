// The parts of reconstruct_surface (apps/reconstruction.hpp), one file each:
//   reconstruction_grid.cpp   the grids: the start shell, reframing, upsampling a level;
//   reconstruction_flow.cpp   the coarsest level: the flow from the start shell toward the
//                             fitted points, one guarded step at a time, strays dropped;
//   reconstruction_snap.cpp   every finer level (and a single one): the snap of the front onto
//                             the local fits, pass after pass;
//   reconstruction_snap_pass.cpp  one snap pass (its settings and readings:
//                             reconstruction_snap_pass.hpp);
//   reconstruction_fits.cpp   a snap pass's local fits of one brick's voxels, shared along
//                             columns and blocks of voxels that see the same points;
//   reconstruction_carve.cpp  gaps the start shell closed reopened where the points sampling
//                             their walls lie buried inside the surface;
//   reconstruction_webs.cpp   webs the start shell left across a handle's hole, on no point,
//                             cut where that opens one tunnel;
//   reconstruction.cpp        validation, resolution and levels from the data, the levels in
//                             order, the mesh.
// Internal to levelset_core (namespace apps::detail). Units: world (the points centred on
// their box). Threading: TBB inside each part; results do not depend on the thread count.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <vector>

#include "apps/point_distance.hpp"
#include "apps/reconstruction.hpp"
#include "core/progress.hpp"
#include "grid/band_accessor.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::apps::detail {

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// ---- reconstruction_grid.cpp
// The band with its frame moved by `offset` and its half-width set to `half_width` voxels
// (values, active voxels and signs unchanged).
NarrowBand reframed(const NarrowBand& band, const Vec3d& offset, double half_width);
// Start band on the coarsest level: the outer component of {d < offset} (see the header).
NarrowBand start_shell(const PointIndex& index, const BBox& box, const Vec3d& origin, double h, double offset,
                       double half_width, const ProgressHook& progress);
// A per-voxel field of `coarse` (band value order) at voxel c of the grid with half its voxel
// size and the same origin: the mean of the 1, 2, 4 or 8 coarse voxels around c / 2; NaN when
// one of them is not active.
double coarse_field_at(BandAccessor& acc, const NarrowBand& coarse, const std::vector<float>& field, const Coord& c);
// The field at voxel c of `band` itself (NaN when c is not active).
double field_at(BandAccessor& acc, const NarrowBand& band, const std::vector<float>& field, const Coord& c);
// The next level's band: `coarse` at half the voxel size, half-width `half_width` voxels.
NarrowBand upsample(const NarrowBand& coarse, double half_width, const ProgressHook& progress);

// ---- reconstruction_fits.cpp
// The local sheet fits of one brick's voxels for a snap pass (point_distance.hpp SheetModel),
// shared where they see the same points. Thread-safe per NearbyPoints object.
// A voxel that takes a fit: its slot, position, unit normal, the coarse curvature, its value
// and its column within the brick (kColumns: the axis nearest its normal and the two other
// coordinates).
constexpr int kColumns = 3 * 64;
struct FitVoxel {
  std::size_t i;
  Vec3d x, n;
  double H, u;
  int column;
};

struct FitSettings {
  int neighbors, height_neighbors;
  double min_band;      // world
  double share_radius;  // world: columns share a fit whose quadric patch is at least this wide
  double block_radius;  // world: 2x2 blocks of columns share one where it is at least this wide (0: never)
  bool wide_blocks;     // the blocks are 4x4 columns (strong noise), each split into 2x2 where needed
  HeightNoise noise;    // the points' noise, which the height fits correct for (sheet_fit)
  std::span<const Vec3f> facing;  // per point, or empty: fits leave out the points facing away (sheet_fit)
};

// The pass's fit settings at voxel size h (world): neighbors / height_neighbors points, the
// sheet band min_band, the noise model, 4x4 blocks or 2x2; the sharing radii from the
// constants in the .cpp.
FitSettings snap_fit_settings(int neighbors, int height_neighbors, double min_band, double h, HeightNoise noise,
                              bool wide_blocks);
// Which way each point faces (sheet_fit's facing): the unit gradient of the band's level set at
// the point (central differences of trilinear samples a voxel apart), zero where it has none
// (beyond the band, all samples at its limit) or where the point lies farther than max_depth
// (world) from the front. A point of a thin part's far side, or of a narrow gap's other wall,
// lies nearer to that side of the front than to the near one, so it faces away from the near
// side's normal; a point far from the front (the wall of a hole the front spans) says nothing
// about the side it samples. Cost: 7 trilinear samples per point; TBB.
std::vector<Vec3f> point_facing(const NarrowBand& band, const PointIndex& index, double max_depth);
// The k nearest points of every voxel of brick b with |u| < window (world) from one radius
// query (apps/nearby_points.hpp; identical results): around the box of those voxels; the
// tree answers where the brick has fewer than a few such voxels.
void prepare_brick_neighbours(const NarrowBand& band, std::uint32_t b, double window, int k, NearbyPoints& near);
// The sheet fit of every voxel (fits[v] for voxels[v], one brick's), shared along columns and
// across blocks of columns where the patches allow (see the .cpp); returns how many fits were made.
int fit_voxels(const NearbyPoints& near, const std::vector<FitVoxel>& voxels, const FitSettings& fs,
               std::vector<SheetFit>& fits);

// ---- reconstruction_flow.cpp
// The coarsest level's flow from the start shell `band` (voxel size h) toward the points'
// fits: the stage's flow fields (steps, change, refused flips, dropped components, seconds)
// filled in; progress reported as a share of `levels` levels.
struct LevelOutput {
  NarrowBand band;
  ReconstructionStage stage;
};
LevelOutput flow_level(NarrowBand band, const PointIndex& index, const ReconstructionOptions& o, int levels,
                       ReconstructionStage stage);

// Components the data do not support: a component of the inside or outside voxel set
// (not the exterior, not the inside component with the largest front) whose front voxels have a
// point within `support` for less than kMinSupport of them. They arise on the coarse level where
// the front crossed a gap between parts far from the data (the free_distance rule lets the
// topology change there), and the guard keeps them once they reach the data (measured: the
// knot at R = 128 with 0.2% noise kept a blob 2 coarse voxels off the surface, 5% of its
// front near a point). Each is turned to the other sign; the caller redistances. Components
// with voxels off the band are kept (too large to be strays). Specks are turned as well,
// near data or not: a component of a few voxels that lie within a tenth of a voxel of the
// zero level. The guard keeps a 6-connected set 6-connected, so only its forced and free flips
// (grid/topology_guard.hpp) leave one: a voxel held at the refused flips' +-eps while its
// face neighbours moved to the other side. The marching cubes make each a closed speck of a
// voxel's size that every later level keeps (bench_reconstruct --sweep: 200k points at 0.5 %
// noise, 6 of 8 meshes with 1-2 one-voxel components beside the surface; elk at 20k / 0.5 %,
// dino at 50k / 0.1 %). Returns how many were turned.
std::uint64_t drop_unsupported_components(NarrowBand& band, const PointIndex& index, double support,
                                          const ProgressHook& progress);

// ---- reconstruction_carve.cpp
// Points deeper than max(kCarveDepthVoxels h, kCarveNoiseDepth noise) inside the front are
// buried (a gap or tunnel the start shell closed: the points sampling its walls; a point
// beyond the band's inner edge reads its depth through the band, as the band's values stop at
// its half-width). The voxels inside the front within reach_voxels of a buried point and
// farther than clearance = max(h, kCarveNoiseDepth noise, gap) from every point (of
// settings.clearance_points, with their noise, where given) form 6-connected regions;
// a region that meets the outside through a mouth (the shell spans it: at least
// kMinMouthShare size^(2/3) faces, not a pinhole) and whose lining (points
// within clearance + 1.5 h of its boundary) is at least kMinBuriedLining below the front
// (deeper than max(kCarveDepthVoxels h, kLiningNoiseDepth noise)) is turned outside, by
// simple flips only (grid/topology_guard.hpp: no handle is made or removed): a part's own
// interior beside buried points is lined by its surface's points, which lie on the front.
// With settings.pierce, a region of at least kMinPierceVoxels whose lining is at least
// kMinPierceLining below the front turns outside whole, tunnels included (a hole through a
// plate that the shell spanned: its air meets the outside at both mouths). A region lined at
// least kSealedGapLining below the front needs a mouth of one face only (a sealed cavity).
// With settings.cut_webs, a region of which at least kWebExposure of the voxels touch the
// outside (a sheet of the inside clear of every point: the shell spanning a gap, partly
// closed where the gap narrows) turns outside whole where that raises the inside's Euler
// characteristic (it cuts a handle or splits a part), never where it would open a tunnel or
// a cavity; inside pieces of fewer than kMinPierceVoxels voxels a cut leaves beside it turn
// outside too. With settings.cut_sheets, such a sheet whose removal whole would not raise it
// (its clear core is a hole in a bridge whose rim lies within the clearance of the walls'
// points: removed whole it opens a tunnel as it cuts) is dug by simple and cutting flips
// (guard rule 1b: the inside may be cut, the outside never joined), and the level's snaps
// that follow may cut the inside where the fits put it outside and it connects to the sheet
// (CarveOutput::cut_zone, cutting_reach): the bridge is cut through its rim, no tunnel is
// opened (bench_reconstruct --sweep, 200k points, 0.1 % noise: homer's bridges between its
// ankles, across a gap 2.2-2.7 final voxels wide, and from its right hand to its belly, genus
// 2 -> 0, the truth's). Nothing happens
// with fewer than max(kMinBuried, kMinBuriedShare N) buried points, or more than
// kMaxBuriedShare N (then the front is not near the data at all, and the candidates would be
// ~reach^3 voxels per point: work and memory stay bounded). With settings.narrow, a second carving
// of the result with the clearance's gap at kNarrowGapClearance of the sampling's and no piercing
// (simple flips only): gaps whose middle lies nearer to the walls' points than the sampling's
// gap (narrower than about twice it) reopen as well, once the wide ones are open. The band
// is rebuilt (the carved voxels and their face neighbours active) and redistanced when a
// region was carved; the caller snaps the new walls onto their points.
// Cost (per carving): O(N) band samples, O(buried * reach^3) candidate voxels and as many
// nearest-point queries, the guard's work on the carved voxels; nothing more without buried
// points.
inline constexpr double kCarveDepthVoxels = 1.5;
inline constexpr double kCarveNoiseDepth = 4.0;
inline constexpr std::size_t kMinBuried = 16;
inline constexpr double kMinBuriedShare = 5e-4;
inline constexpr double kMaxBuriedShare = 0.1;
inline constexpr std::uint32_t kMinCarveVoxels = 8;
// A region's mouth: at least this share of size^(2/3) faces on the outside. bench_reconstruct
// --sweep, 20k points, 0.5 % noise: closed gaps and holes met the outside through 0.44-11
// size^(2/3) faces (couplingdown, anchor, elephant, handle's slot); parts' interiors reached
// through a dent of the front or a hole in the sampling through 0.004-0.09 of it (handle.off:
// 2236 voxels through one face, lined 74 % below the front: pockets dug into its slot's walls).
inline constexpr double kMinMouthShare = 0.2;
inline constexpr double kMinBuriedLining = 0.5;
// A region lined at least this much below the front is a sealed gap whatever its mouth (one
// face is enough): bench_reconstruct --sweep, 200k points, 0.1 % noise: homer's mouth, a
// cavity behind its lips, 98 % (truth up to 0.034 from ours, Chamfer 1.47 -> 1.08 of
// Poisson's); handle.off's interior behind a pinhole, the highest such share measured, 74 %.
inline constexpr double kSealedGapLining = 0.9;
// Webs: regions with at least this share of their voxels face-adjacent to the outside.
// bench_reconstruct --sweep, 200k points, 0.1 % noise: the sheets the start shell spans
// between homer's legs and between man's arms and body 0.49-0.93; parts' interiors 0-0.01.
inline constexpr double kWebExposure = 0.25;
// A point at the front lies within ~noise of it (P(u < -2 noise) ~ 2 %); a closed gap's
// walls near its mouth lie deeper than that but shallower than the burial depth.
inline constexpr double kLiningNoiseDepth = 2.0;
// Pierced regions (tunnels allowed): bench_reconstruct --sweep at 20k points: CGAL's anchor
// (the ring's hole) and couplingdown (genus 2 -> 6 of 9) reopened at 0.1 % noise; regions
// of the fist of hand.off lined 50-62 % below the front opened tunnels between its fingers.
inline constexpr std::uint32_t kMinPierceVoxels = 64;
inline constexpr double kMinPierceLining = 0.75;
// The second carving's gap (a fraction of the sampling's); its candidates lie no farther from
// the points than the first carving's clearance (the space beyond was judged there: taking it
// again, handle.off's own interior met the outside and was carved, 0.90 -> 1.36).
// bench_reconstruct --sweep, 20k points, 0.1 % noise, of Poisson's Chamfer: camel 1.28 -> 1.16,
// hand 1.03 -> 0.97, man 1.05 -> 0.98, homer 1.045 -> 1.009, handle 0.90 -> 0.83, dino 0.87 ->
// 0.81, no case worse (wins 26 -> 28 of 33). 0.5 (tried before that bound) merged regions
// across holes in the sampling (hand 1.01, camel 1.29); the same clearance in one carving,
// before the wide gaps were open: anchor 0.75 -> 1.25, couplingdown genus 6 -> 3.
inline constexpr double kNarrowGapClearance = 0.7;
struct CarveSettings {
  double noise = 0.0;         // the points' noise estimate (world)
  double gap = 0.0;           // the sampling's gap (world): clearance so a region does not leak between samples
  double reach_voxels = 8.0;  // how far from a buried point regions are sought
  bool pierce = true;         // regions lined almost only by buried points may open tunnels
  bool cut_webs = true;       // regions that are sheets exposed to the outside are cut where that removes handles
  bool cut_sheets = true;     // ... and the others dug by cutting flips (guard rule 1b), the snaps
                              // after cutting their bridges
  bool narrow = true;         // a second carving at kNarrowGapClearance of the gap, simple flips only
  bool web_tunnels = true;    // open_web_tunnels after the first carving (see below)
  bool fine_tunnels = false;  // ... with its fine pass (holes narrower than the clearance)
  // The points the clearance is measured from (the index's own when null): under noise, the
  // points projected onto their neighbourhoods' planes (apps/point_denoise.hpp), so that the
  // noise's scatter into a gap does not fill its clearance.
  const PointIndex* clearance_points = nullptr;
  double clearance_noise = 0.0;  // their noise estimate (world), with clearance_points
};
struct CarveOutput {
  NarrowBand band;
  std::uint64_t buried = 0;         // points buried before carving
  std::uint64_t carved_voxels = 0;  // turned outside (the topology guard left the others inside)
  int regions = 0;                  // regions carved
  int pierced_regions = 0;          // of them turned outside whole (tunnels allowed)
  int webs = 0;                     // of those, webs cut (cut_webs)
  int web_tunnels = 0;              // webs spanning a handle's hole cut (web_tunnels: open_web_tunnels)
  std::vector<std::uint64_t> bricks;  // brick_key of the bricks with carved voxels and their 26 neighbours, sorted
  // Voxel keys (sorted) within kCutZoneVoxels of a sheet cut by guard rule 1b: the snaps that
  // follow may cut the inside there too (the sheet's rim lies within the clearance of the
  // walls' points, where no region reaches).
  std::vector<std::uint64_t> cut_zone;
  int cut_sheets = 0;  // sheets dug with cutting flips
};
inline constexpr int kCutZoneVoxels = 2;
// A voxel key: 21 bits per axis after an offset (voxel indices of the level's grid).
inline constexpr std::int64_t kKeyBias = 1 << 20;
inline std::uint64_t key_of(const Coord& c) {
  return (std::uint64_t(c.x + kKeyBias) << 42) | (std::uint64_t(c.y + kKeyBias) << 21) | std::uint64_t(c.z + kKeyBias);
}
inline Coord coord_of(std::uint64_t k) {
  const std::int64_t mask = (std::int64_t{1} << 21) - 1;
  return Coord{int(std::int64_t(k >> 42) - kKeyBias), int(std::int64_t((k >> 21) & std::uint64_t(mask)) - kKeyBias),
               int(std::int64_t(k & std::uint64_t(mask)) - kKeyBias)};
}

// The Euler characteristic the inside loses when the voxels `region` (sorted keys, all inside)
// turn outside: the alternating count of the cells of the inside's cubical complex (voxels as
// vertices, 6-adjacent pairs as edges, 2x2 squares, 2x2x2 cubes, all voxels inside) that hold
// a voxel of the region. chi = components - tunnels + cavities, so a removal that cuts a
// handle or splits a part returns <= -1, one that opens a tunnel or a cavity to the outside
// >= 1, a dent 0. Cost: O(|region|) accessor probes (27 per voxel).
std::int64_t euler_lost(BandAccessor& acc, const std::vector<std::uint64_t>& region);
// The 6-connected components of the voxels `air` (sorted keys): each one's root index.
std::vector<std::uint32_t> label_regions(const std::vector<std::uint64_t>& air);
// The voxels' indices grouped by region (a region's keys stay sorted) and where each
// region's group starts (indexed by its root).
struct RegionGroups {
  std::vector<std::uint32_t> order, start;
};
RegionGroups group_by_region(const std::vector<std::uint32_t>& root);
// Which voxels are carved (sorted keys, all inside) and which of them pierced (turned outside
// whole, tunnels allowed), with the counts of regions; webs > 0 drops the scraps beside the
// pierced voxels.
struct RegionChoice {
  std::vector<std::uint64_t> carved, pierced, cuttable;  // sorted keys; cuttable: guard rule 1b
  int regions = 0, pierced_regions = 0, webs = 0, cut_sheets = 0;
};
// The band with the chosen voxels dug out: carved ones by simple flips only, pierced ones
// whole; then redistanced out to the band's half-width. How many voxels turned outside and
// the bricks touched (with their 26 neighbours, sorted keys).
struct Dug {
  NarrowBand band;
  std::uint64_t carved_voxels = 0;
  std::vector<std::uint64_t> bricks;
  std::vector<std::uint64_t> cut_zone;  // see CarveOutput
};
Dug dig_regions(const NarrowBand& band, const RegionChoice& choice, const ProgressHook& progress);
CarveOutput carve_buried_gaps(NarrowBand band, const PointIndex& index, const CarveSettings& settings,
                              const ProgressHook& progress);

// ---- reconstruction_cuts.cpp
// The voxels a snap may cut (guard rule 1b): those inside in `band` and outside in `next`
// (its proposed values, active-voxel order) that are 26-connected through such voxels to one
// in `zone` (sorted keys: a cut sheet's neighbourhood, CarveOutput::cut_zone). A bridge the
// start shell threw across a gap narrower than the carving's clearance is empty only in its
// core; its rim lies within the clearance of the walls' points, where the fits put it outside.
// Sorted keys. Cost: O(active voxels) plus 27 searches per reached voxel.
std::vector<std::uint64_t> cutting_reach(const NarrowBand& band, const std::vector<float>& next,
                                         const std::vector<std::uint64_t>& zone);
// The inside pieces of fewer than kMinPierceVoxels voxels (6-connected, every voxel active)
// within one voxel of a voxel of `cut` (sorted keys) turned outside: the scraps a cut leaves.
void drop_web_scraps(NarrowBand& band, const std::vector<std::uint64_t>& cut);

// ---- reconstruction_webs.cpp
// Tunnels through webs: where the start shell spans a handle's hole (CGAL's elephant: the
// loop of its trunk), it leaves a sheet of the inside that lies on no point; no point is
// buried beside it (the hole's walls are on the front), so carving never looks there, and
// the snaps cannot move it (no fit reaches it): the surface has one handle fewer than the
// data. The band's inside voxels farther than `clearance` from every point form 6-connected
// regions; one of at least kMinTunnelWebVoxels voxels, at least kTunnelWebExposure of them
// face-adjacent to the outside (a sheet: a part's interior beside a hole in the sampling
// is a slab the band's width deep, exposed 1/3 at most), whose removal opens exactly one
// tunnel (euler_lost == 1: not a dent, not a split) and whose lining (the points within
// clearance + 1.5 h of it) lies less than kMinBuriedLining deeper than settings.lining_depth
// (the hole's walls are on the front; a region lined by buried points is a closed gap,
// carve_buried_gaps' to judge: between homer's legs at 50k points, 57 % buried, where the
// legs nearly touch below it and cutting it opened a handle the truth does not have) turns
// outside whole (dig_regions), where the mesh's genus then rises by one (see the .cpp).
// bench_reconstruct --sweep, 20k points: the one-tunnel regions over the elephant's trunk
// loop, anchor_dense's holes (0.5 % noise) and cheese's were exposed 0.55-1.0, the parts'
// interiors along the band's inner edge 0.0-0.26. On the middle level the trunk loop's
// region (11 voxels) opened two tunnels where the truth has one (genus 2 -> 4: a cut that
// small does not survive the next level's upsampling as it was); on the final level its 55
// voxels open one (2 -> 3, the truth's).
// Fine pass (settings.fine_clearance > 0: on the final level, on points with noise of at
// most 0.15 final voxels, reconstruction.cpp): a hole narrower than about twice the
// clearance through a thin plate (CGAL's turbine: bolt holes ~5 final voxels across in a
// plate ~3 thick) leaves no voxel that far from its wall's points, and its plug holds too
// few buried points for the carving (24 at 50k points, below kMinBuriedShare N). The same
// search runs again after the first with kFineTunnelClearance of the clearance and regions
// of kMinFineTunnelVoxels, and a region is cut only where at least kMinShallowLining of its
// lining lies deeper than settings.shallow_depth (max(kShallowLiningVoxels h, 2 noise))
// below the surface: the hole's wall inside the plug (turbine 0.47-0.65 on the final level
// at 0.5 h), where a hole in the sampling of a thin part is lined by its faces' points, on
// the surface (bones.off, clean 20k points: 0-0.08, which cuts raised its genus 13 -> 16
// against the truth's 0).
// Cost: one radius query per inside band voxel beside the outside and per region voxel, the
// regions' Euler counts; a dig, its redistance and two marching cubes only per region that
// qualifies; the fine pass as much again.
inline constexpr std::uint32_t kMinTunnelWebVoxels = 32;
inline constexpr double kTunnelWebExposure = 0.5;
inline constexpr double kFineTunnelClearance = 0.5;
inline constexpr std::uint32_t kMinFineTunnelVoxels = 4;
inline constexpr double kMinShallowLining = 0.2;
inline constexpr double kShallowLiningVoxels = 0.5;
struct WebTunnels {
  NarrowBand band;
  int tunnels = 0;                    // regions turned outside
  std::uint64_t voxels = 0;           // voxels turned outside
  std::vector<std::uint64_t> bricks;  // as CarveOutput::bricks
};
struct WebTunnelSettings {
  double clearance = 0.0;     // world: candidates lie farther than this from every point of clearance_points
  double lining_depth = 0.0;  // world: a lining point deeper than this inside the surface is buried
  const PointIndex* clearance_points = nullptr;  // the points the clearance is measured from (null: points)
  double fine_clearance = 0.0;  // world: the fine pass's clearance (0: no fine pass)
  double shallow_depth = 0.0;   // world: the fine pass's lining depth (kMinShallowLining)
};
WebTunnels open_web_tunnels(NarrowBand band, const PointIndex& points, const WebTunnelSettings& settings,
                            const ProgressHook& progress);

// ---- reconstruction_snap.cpp
// The last snap pass's noise estimates, in final voxels (they choose the next level's fits).
struct SnapNoise {
  double noise = 0.0;         // the fits' spread
  double height_noise = 0.0;  // the height fits' residual (no sagitta)
};
struct SnapLevel {
  int level = 0, levels = 1;
  double h_final = 0.0;
  CarveSettings carve;  // level > 0 with ReconstructionOptions::carve_gaps: buried gaps reopened first
};
struct SnapOutput {
  NarrowBand band;
  ReconstructionStage stage;
  SnapNoise noise;
};
// Level `where.level` (voxel size stage.voxel_size): `coarse` upsampled (level > 0; on a
// single level the flow's band as it is), then snapped onto the fits pass after pass.
SnapOutput snap_level(NarrowBand coarse, const PointIndex& index, const ReconstructionOptions& o,
                      const SnapLevel& where, ReconstructionStage stage, SnapNoise previous);
// The band redistanced (fast sweeping, half-width W, on its domain less `shrink` voxels) after
// a snap pass that moved only the voxels of the bricks `moved` (brick_key, sorted): only the
// bricks within one brick of them are recomputed (the front moved by at most a voxel there,
// and a distance within W + 1 < 8 voxels of it is all that can change), from a copy of the
// band holding every brick within two more (those not allocated with their signs and no
// active voxel, so that no sign is guessed along a row near them); the other bricks are kept.
// The same values as a redistance of the whole band up to the sweep's tolerance, at a cost in
// the bricks moved, not in the band: the passes on carved and moved bricks (snap_level) redo
// a few percent of the band.
NarrowBand redistanced_near(const NarrowBand& band, const std::vector<std::uint64_t>& moved,
                            double W, double shrink, const ProgressHook& progress);

}  // namespace levelset::apps::detail
