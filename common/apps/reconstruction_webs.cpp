// reconstruct_surface's tunnels through webs (reconstruction_parts.hpp): where the start shell
// spans the hole of a handle (the elephant's trunk loop), the sheet it leaves lies on no
// point, and the snaps cannot move it (no fit reaches it); the surface has one handle fewer
// than the data. This finds such sheets and turns them outside where that opens one tunnel.
#include <algorithm>
#include <cstdint>
#include <optional>
#include <unordered_set>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "apps/reconstruction_parts.hpp"
#include "grid/band_accessor.hpp"
#include "grid/interpolate.hpp"
#include "surface/marching_cubes.hpp"
#include "surface/mesh_measures.hpp"

namespace levelset::apps::detail {

namespace {

const Coord kFaceSteps[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

bool beside_outside(BandAccessor& acc, const Coord& c) {
  for (const Coord& step : kFaceSteps)
    if (!acc.is_inside(c + step)) return true;
  return false;
}

// The band's active inside voxels farther than `clearance` from every point that are
// connected (6-neighbours, through such voxels) to one beside the outside (sorted keys): the
// components of those voxels that could be a sheet (the others are exposed nowhere). The
// voxels beside the outside are tested in parallel, the rest only as the flood reaches them.
std::vector<std::uint64_t> unsupported_inside(const NarrowBand& band, const PointIndex& points, double clearance,
                                              const ProgressHook& progress) {
  // No point nearer than the clearance (a radius query that stops at the first point found).
  auto clear = [&](const Coord& c, std::vector<std::pair<std::uint32_t, double>>& scratch) {
    return points.within(band.world(c), clearance, 0, scratch);
  };
  std::vector<std::vector<std::uint64_t>> per_brick(band.brick_count());
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), 16),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
                      progress.check("reconstruct webs");
                      BandAccessor acc(band);
                      std::vector<std::pair<std::uint32_t, double>> scratch;
                      for (std::uint32_t b = r.begin(); b != r.end(); ++b)
                        band.for_each_active_in_brick(b, [&](const Coord& c, float v) {
                          if (v < 0.0f && beside_outside(acc, c) && clear(c, scratch))
                            per_brick[b].push_back(key_of(c));
                        });
                    });
  std::vector<std::uint64_t> keys;
  for (const auto& k : per_brick) keys.insert(keys.end(), k.begin(), k.end());
  std::unordered_set<std::uint64_t> seen(keys.begin(), keys.end());
  BandAccessor acc(band);
  std::vector<std::pair<std::uint32_t, double>> scratch;
  for (std::size_t at = 0; at < keys.size(); ++at)
    for (const Coord& step : kFaceSteps) {
      const Coord q = coord_of(keys[at]) + step;
      if (!seen.insert(key_of(q)).second) continue;
      const std::optional<float> u = acc.probe(q);
      if (u && *u < 0.0f && clear(q, scratch)) keys.push_back(key_of(q));
    }
  std::sort(keys.begin(), keys.end());
  return keys;
}

// The shares of a region's lining (the points within `reach` of its voxels) deeper than
// `buried` and than `shallow` inside the surface (the band's values), from one gathering.
struct LiningShares {
  double buried = 0.0, shallow = 0.0;
};
LiningShares lining_shares(BandAccessor& acc, const NarrowBand& band, const PointIndex& points,
                           const std::vector<std::uint64_t>& region, double reach, double buried, double shallow) {
  std::unordered_set<std::uint32_t> lining;
  std::vector<std::pair<std::uint32_t, double>> near;
  for (const std::uint64_t k : region) {
    points.within(band.world(coord_of(k)), reach, near);
    for (const auto& [i, d2] : near) lining.insert(i);
  }
  LiningShares out;
  if (lining.empty()) return out;
  std::size_t deep = 0, below = 0;
  for (const std::uint32_t i : lining) {
    const double u = double(sample_trilinear(acc, band, points.points()[i]));
    deep += u < -buried;
    below += u < -shallow;
  }
  out.buried = double(deep) / double(lining.size());
  out.shallow = double(below) / double(lining.size());
  return out;
}

// The region (sorted keys) with its inside face neighbours.
std::vector<std::uint64_t> grown_inside(BandAccessor& acc, const std::vector<std::uint64_t>& region) {
  std::vector<std::uint64_t> grown = region;
  for (const std::uint64_t k : region)
    for (const Coord& step : kFaceSteps)
      if (acc.is_inside(coord_of(k) + step)) grown.push_back(key_of(coord_of(k) + step));
  std::sort(grown.begin(), grown.end());
  grown.erase(std::unique(grown.begin(), grown.end()), grown.end());
  return grown;
}

// The zero level's genus and components (its marching cubes mesh, as the result's).
MeshMeasures surface_topology(const NarrowBand& band, const ProgressHook& progress) {
  MarchingCubesOptions mc;
  mc.progress = progress;
  return measure_mesh(marching_cubes(band, mc).mesh);
}

// What makes a region of clear voxels a web: its clearance (world), its smallest size, and
// for the fine pass its share of lining points below the surface.
struct WebRule {
  double clearance = 0.0;
  std::uint32_t min_voxels = kMinTunnelWebVoxels;
  double shallow_depth = 0.0;  // world; with min_shallow > 0
  double min_shallow = 0.0;
};

// The regions of clear inside voxels (sorted keys each) that are webs under `rule` (see
// reconstruction_parts.hpp).
std::vector<std::vector<std::uint64_t>> find_webs(const NarrowBand& band, const PointIndex& points,
                                                  const PointIndex& clear_of, double lining_depth, const WebRule& rule,
                                                  const ProgressHook& progress) {
  std::vector<std::vector<std::uint64_t>> webs;
  const double h = band.voxel_size();
  const std::vector<std::uint64_t> air = unsupported_inside(band, clear_of, rule.clearance, progress);
  if (air.empty()) return webs;
  // The band's values stop at its half-width: no point reads deeper than that.
  const double depth = std::min(lining_depth, double(band.background()) - h);
  const double reach = rule.clearance + 1.5 * h;
  const std::vector<std::uint32_t> root = label_regions(air);
  const RegionGroups groups = group_by_region(root);
  BandAccessor acc(band);
  std::vector<std::uint32_t> size(air.size(), 0), exposed(air.size(), 0);
  for (std::size_t i = 0; i < air.size(); ++i) {
    ++size[root[i]];
    exposed[root[i]] += beside_outside(acc, coord_of(air[i]));
  }
  std::vector<std::uint64_t> members;
  for (std::size_t r = 0; r < air.size(); ++r) {
    if (root[r] != r || size[r] < rule.min_voxels || double(exposed[r]) < kTunnelWebExposure * double(size[r]))
      continue;
    members.assign(size[r], 0);
    for (std::uint32_t j = 0; j < size[r]; ++j) members[j] = air[groups.order[groups.start[r] + j]];
    if (euler_lost(acc, members) != 1) continue;
    const LiningShares lining = lining_shares(acc, band, points, members, reach, depth, rule.shallow_depth);
    if (lining.buried >= kMinBuriedLining || (rule.min_shallow > 0.0 && lining.shallow < rule.min_shallow)) continue;
    webs.push_back(members);
  }
  return webs;
}

// Each cut is kept only where the surface's own topology (the mesh's) gains exactly one
// handle: the voxels' Euler count is the inside's 6-connected complex, and where the cut
// leaves the web's rim touching itself across a voxel's diagonal, the marching cubes join
// what the count separates (CGAL's elephant at 20k points, one sample set: genus 2 -> 4).
// There the web grown by one voxel (its rim too, which the snaps after the carving put
// back on the points) is tried instead.
void cut_webs(std::vector<std::vector<std::uint64_t>>& webs, const ProgressHook& progress, WebTunnels& out) {
  if (webs.empty()) return;
  MeshMeasures before = surface_topology(out.band, progress);
  for (std::vector<std::uint64_t>& web : webs) {
    for (int attempt = 0; attempt < 2; ++attempt) {
      if (attempt == 1) {
        BandAccessor acc(out.band);
        web = grown_inside(acc, web);
        if (euler_lost(acc, web) != 1) break;
      }
      RegionChoice choice;
      choice.carved = choice.pierced = web;
      choice.regions = choice.pierced_regions = 1;
      Dug dug = dig_regions(out.band, choice, progress);
      const MeshMeasures after = surface_topology(dug.band, progress);
      if (after.components != before.components || after.genus != before.genus + 1.0 || !after.watertight) continue;
      out.band = std::move(dug.band);
      before = after;
      ++out.tunnels;
      out.voxels += dug.carved_voxels;
      out.bricks.insert(out.bricks.end(), dug.bricks.begin(), dug.bricks.end());
      break;
    }
  }
}

}  // namespace

WebTunnels open_web_tunnels(NarrowBand band, const PointIndex& points, const WebTunnelSettings& s,
                            const ProgressHook& progress) {
  WebTunnels out;
  out.band = std::move(band);
  const PointIndex& clear_of = s.clearance_points ? *s.clearance_points : points;
  WebRule wide;
  wide.clearance = s.clearance;
  std::vector<std::vector<std::uint64_t>> webs = find_webs(out.band, points, clear_of, s.lining_depth, wide, progress);
  cut_webs(webs, progress, out);
  if (s.fine_clearance > 0.0 && s.fine_clearance < s.clearance) {
    // Holes too narrow for the clearance (turbine's bolt holes, ~5 voxels across): their
    // walls' points lie inside the plug the shell left, below the surface (see the header).
    WebRule fine;
    fine.clearance = s.fine_clearance;
    fine.min_voxels = kMinFineTunnelVoxels;
    fine.shallow_depth = s.shallow_depth;
    fine.min_shallow = kMinShallowLining;
    webs = find_webs(out.band, points, clear_of, s.lining_depth, fine, progress);
    cut_webs(webs, progress, out);
  }
  std::sort(out.bricks.begin(), out.bricks.end());
  out.bricks.erase(std::unique(out.bricks.begin(), out.bricks.end()), out.bricks.end());
  return out;
}

}  // namespace levelset::apps::detail
