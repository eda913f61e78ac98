// reconstruct_surface's carving of buried gaps (reconstruction_parts.hpp): the start shell
// closes gaps and tunnels narrower than its offset, and the topology guard keeps them closed;
// the points sampling their walls then lie inside the surface. This finds those points and
// turns the empty space beside them (inside the surface, away from every point) to outside.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <numeric>
#include <optional>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "apps/reconstruction_parts.hpp"
#include "distance/redistance.hpp"
#include "grid/band_accessor.hpp"
#include "grid/band_builder.hpp"
#include "grid/interpolate.hpp"
#include "grid/topology_guard.hpp"

namespace levelset::apps::detail {

namespace {

// Buried points per candidate-gathering chunk (each gathers up to ~(4/3) pi reach^3 keys).
constexpr std::size_t kCarveChunk = 2048;

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// How far (voxels) point_values searches the band for a depth beyond it.
constexpr double kMaxDepthSearchVoxels = 24.0;

// Offsets within `radius` voxels, nearest first.
std::vector<Coord> ball_by_distance(int radius) {
  std::vector<Coord> ball;
  for (int z = -radius; z <= radius; ++z)
    for (int y = -radius; y <= radius; ++y)
      for (int x = -radius; x <= radius; ++x)
        if (x * x + y * y + z * z <= radius * radius) ball.push_back({x, y, z});
  std::stable_sort(ball.begin(), ball.end(), [](const Coord& a, const Coord& b) {
    return a.x * a.x + a.y * a.y + a.z * a.z < b.x * b.x + b.y * b.y + b.z * b.z;
  });
  return ball;
}

// How deep point p lies inside the surface when the band's value there is its limit (p beyond
// the band's inner edge): the shortest way to the surface through the band, min over active
// voxels v near p of |p - v| + max(0, -u(v)) (u(v) is v's distance to the surface; an upper
// bound, within a small fraction of a voxel of the depth for a distance band), at most `cap`.
// The ball is searched nearest first and left once no farther voxel can improve the minimum.
double depth_beyond_band(BandAccessor& acc, const NarrowBand& band, const Vec3d& p, const std::vector<Coord>& ball,
                         double cap) {
  const double h = band.voxel_size();
  const Vec3d q = (p - band.origin()) / h;
  const Coord c{int(std::lround(q.x)), int(std::lround(q.y)), int(std::lround(q.z))};
  const Vec3d off = q - Vec3d{double(c.x), double(c.y), double(c.z)};  // |off| <= sqrt(3) / 2
  double best = cap / h;
  for (const Coord& d : ball) {
    const Vec3d dv{double(d.x), double(d.y), double(d.z)};
    if (length(dv) - 0.8660254 >= best) break;
    const std::optional<float> u = acc.probe(c + d);
    if (!u) continue;
    best = std::min(best, length(dv - off) + std::max(0.0, -double(*u) / h));
  }
  return best * h;
}

// The band's value (trilinear) at every point: how deep each lies inside the surface (negative
// inside). The band's values stop at -background(), so where a depth threshold the caller
// tests (`deepest`, world) lies near or beyond that, the points at the band's inner edge
// get their depth through the band (depth_beyond_band) instead, up to deepest + h: with a
// noise sigma of 0.75 voxels or more the burial depth (4 sigma) exceeds a 3-voxel band, and
// no point could ever read as buried.
std::vector<float> point_values(const NarrowBand& band, const PointIndex& index, double deepest) {
  const double h = band.voxel_size();
  const double limit = double(band.background()) - h;  // values beyond may be the band's limit
  const bool refine = deepest > limit;
  // The search ball is bounded (kMaxDepthSearchVoxels: ~60k offsets), whatever the noise says:
  // deeper thresholds then read no point as buried, as before.
  const double cap = std::min(deepest + h, kMaxDepthSearchVoxels * h);
  const std::vector<Coord> ball = refine ? ball_by_distance(int(std::ceil(cap / h)) + 1) : std::vector<Coord>{};
  std::vector<float> value(index.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, index.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    BandAccessor acc(band);
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Vec3d& p = index.points()[i];
      value[i] = sample_trilinear(acc, band, p);
      if (refine && double(value[i]) < -limit)
        value[i] = -float(std::max(-double(value[i]), depth_beyond_band(acc, band, p, ball, cap)));
    }
  });
  return value;
}

// The points lying deeper than `depth` inside the surface.
std::vector<std::uint32_t> deeper_than(const std::vector<float>& value, double depth) {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < value.size(); ++i)
    if (double(value[i]) < -depth) out.push_back(std::uint32_t(i));
  return out;
}

// The band with the voxels `carved` (sorted keys) and their inside face neighbours active
// (-h/2 where they were inactive; signs unchanged): bricks rebuilt through BandBuilder, the
// untouched ones copied.
NarrowBand with_active(const NarrowBand& band, const std::vector<std::uint64_t>& carved) {
  const float half = float(0.5 * band.voxel_size());
  struct Edit {
    std::uint64_t brick;
    Coord brick_coord;
    int voxel;
    bool carve;
    bool operator<(const Edit& o) const { return brick < o.brick || (brick == o.brick && voxel < o.voxel); }
  };
  const Coord steps[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<Edit> edits;
  BandAccessor acc(band);
  for (const std::uint64_t k : carved) {
    const Coord c = coord_of(k);
    edits.push_back({brick_key(brick_of(c)), brick_of(c), local_index(c), true});
    for (const Coord& step : steps) {
      const Coord q = c + step;
      if (!std::binary_search(carved.begin(), carved.end(), key_of(q)) && acc.is_inside(q))
        edits.push_back({brick_key(brick_of(q)), brick_of(q), local_index(q), false});
    }
  }
  std::sort(edits.begin(), edits.end());
  std::vector<Coord> bricks;  // every brick of the result: the band's and the edited ones
  for (std::uint32_t b = 0; b < band.brick_count(); ++b) bricks.push_back(band.bricks()[b].coord);
  for (std::size_t e = 0; e < edits.size(); ++e) {
    if (e > 0 && edits[e].brick == edits[e - 1].brick) continue;
    const Coord c = edits[e].brick_coord;
    if (acc.locate(c) == kNoBrick) bricks.push_back(c);
  }
  BandBuilder builder(band.frame());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bricks.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
    BandAccessor local(band);
    std::vector<float> values(kBrickVoxels);
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Coord bc = bricks[i];
      const std::uint32_t b = local.locate(bc);
      BrickMask active{}, inside{};
      if (b != kNoBrick) {
        active = band.bricks()[b].active;
        inside = band.inside_mask(b);
        std::size_t slot = band.bricks()[b].value_offset;
        active.for_each_set([&](int n) { values[std::size_t(n)] = band.values()[slot++]; });
      } else {
        const Coord o = brick_origin(bc);
        for (int n = 0; n < kBrickVoxels; ++n) inside.assign(n, local.is_inside(o + local_coord(n)));
      }
      const std::uint64_t key = brick_key(bc);
      auto e = std::lower_bound(edits.begin(), edits.end(), Edit{key, bc, -1, false});
      for (; e != edits.end() && e->brick == key; ++e) {
        const int n = e->voxel;
        if (!active.test(n)) values[std::size_t(n)] = -half;  // carved voxels are inside too
        active.set(n);
      }
      builder.add_brick(bc, active, inside, values.data());
    }
  });
  return builder.finish(band.far_inside());
}

// Empty space farther than this from every point may be carved.
// The noise the clearance allows for is that of the points it is measured from.
// A lining point deeper than this (world) inside the front is buried.
double lining_depth_of(const CarveSettings& s, double h) {
  return std::max(kCarveDepthVoxels * h, kLiningNoiseDepth * s.noise);
}

// `more` brick keys merged into the sorted `into`.
void merge_bricks(std::vector<std::uint64_t>& into, const std::vector<std::uint64_t>& more) {
  into.insert(into.end(), more.begin(), more.end());
  std::sort(into.begin(), into.end());
  into.erase(std::unique(into.begin(), into.end()), into.end());
}

double clearance_of(const CarveSettings& s, double h) {
  const double noise = s.clearance_points ? s.clearance_noise : s.noise;
  return std::max({h, kCarveNoiseDepth * noise, s.gap});
}

// 1. Candidate voxels: within `reach` voxels of a buried point, inside the surface, farther
// than `clearance` (and no farther than `outer`) from every point of `clearance_points` (the
// empty space beside the buried walls, and the parts' own interiors beyond their walls: told
// apart by carve_regions). Sorted keys. In chunks of buried points, each chunk's keys
// deduplicated and merged: the transient memory is a chunk's balls, not every buried point's.
std::vector<std::uint64_t> air_candidates(const NarrowBand& band, const PointIndex& index,
                                          const PointIndex& clearance_points, const std::vector<std::uint32_t>& buried,
                                          int reach, double clearance, double outer, const ProgressHook& progress) {
  const double h = band.voxel_size();
  std::vector<std::uint64_t> keys;
  for (std::size_t first = 0; first < buried.size(); first += kCarveChunk) {
    progress.check("reconstruct carve");
    const std::size_t last = std::min(buried.size(), first + kCarveChunk);
    std::vector<std::vector<std::uint64_t>> gathered(last - first);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(first, last, 64), [&](const tbb::blocked_range<std::size_t>& r) {
      BandAccessor acc(band);
      for (std::size_t b = r.begin(); b != r.end(); ++b) {
        const Vec3d q = (index.points()[buried[b]] - band.origin()) / h;
        const Coord c{int(std::lround(q.x)), int(std::lround(q.y)), int(std::lround(q.z))};
        for (int dz = -reach; dz <= reach; ++dz)
          for (int dy = -reach; dy <= reach; ++dy)
            for (int dx = -reach; dx <= reach; ++dx) {
              if (dx * dx + dy * dy + dz * dz > reach * reach) continue;
              const Coord v{c.x + dx, c.y + dy, c.z + dz};
              if (acc.is_inside(v)) gathered[b - first].push_back(key_of(v));
            }
      }
    });
    std::vector<std::uint64_t> chunk;
    for (auto& g : gathered) chunk.insert(chunk.end(), g.begin(), g.end());
    std::vector<std::vector<std::uint64_t>>().swap(gathered);
    tbb::parallel_sort(chunk.begin(), chunk.end());
    chunk.erase(std::unique(chunk.begin(), chunk.end()), chunk.end());
    std::vector<std::uint64_t> merged;
    merged.reserve(keys.size() + chunk.size());
    std::set_union(keys.begin(), keys.end(), chunk.begin(), chunk.end(), std::back_inserter(merged));
    keys.swap(merged);
  }
  std::vector<std::uint8_t> clear(keys.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    progress.check("reconstruct carve");
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const double d = clearance_points.nearest(band.world(coord_of(keys[i]))).distance;
      clear[i] = d > clearance && d <= outer;
    }
  });
  std::vector<std::uint64_t> air;
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (clear[i]) air.push_back(keys[i]);
  return air;
}

}  // namespace

std::vector<std::uint32_t> label_regions(const std::vector<std::uint64_t>& air) {
  auto find = [&](const Coord& c) -> std::int64_t {
    const auto it = std::lower_bound(air.begin(), air.end(), key_of(c));
    return it != air.end() && *it == key_of(c) ? std::int64_t(it - air.begin()) : -1;
  };
  const Coord plus[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // each neighbour pair once
  std::vector<std::uint32_t> parent(air.size());
  std::iota(parent.begin(), parent.end(), 0u);
  for (std::size_t i = 0; i < air.size(); ++i) {
    const Coord c = coord_of(air[i]);
    for (const Coord& step : plus) {
      const std::int64_t j = find(c + step);
      if (j < 0) continue;
      const std::uint32_t a = find_root(parent, std::uint32_t(i)), b = find_root(parent, std::uint32_t(j));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<std::uint32_t> root(air.size());
  for (std::size_t i = 0; i < air.size(); ++i) root[i] = find_root(parent, std::uint32_t(i));
  return root;
}

std::int64_t euler_lost(BandAccessor& acc, const std::vector<std::uint64_t>& region) {
  std::vector<std::uint64_t> anchors;
  for (const std::uint64_t k : region) {
    const Coord c = coord_of(k);
    for (int d = 0; d < 8; ++d) anchors.push_back(key_of(c - Coord{d & 1, (d >> 1) & 1, (d >> 2) & 1}));
  }
  std::sort(anchors.begin(), anchors.end());
  anchors.erase(std::unique(anchors.begin(), anchors.end()), anchors.end());
  std::int64_t lost = 0;
  for (const std::uint64_t a : anchors) {
    const Coord o = coord_of(a);
    std::uint8_t in = 0, mine = 0;  // bit d: corner o + (d & 1, d >> 1 & 1, d >> 2 & 1)
    for (int d = 0; d < 8; ++d) {
      const Coord c = o + Coord{d & 1, (d >> 1) & 1, (d >> 2) & 1};
      if (std::binary_search(region.begin(), region.end(), key_of(c))) mine |= std::uint8_t(1u << d);
      if ((mine >> d & 1u) || acc.is_inside(c)) in |= std::uint8_t(1u << d);
    }
    // The cells anchored at o: a subset of the axes spans each; its corners are the sub-masks.
    for (int axes = 0; axes < 8; ++axes) {
      bool all = true, touches = false;
      for (int d = 0; d < 8; ++d) {
        if ((d & ~axes) != 0) continue;
        all = all && (in >> d & 1u);
        touches = touches || (mine >> d & 1u);
      }
      if (all && touches) lost += (__builtin_popcount(unsigned(axes)) & 1) ? -1 : 1;
    }
  }
  return lost;
}

namespace {

// Steps 2-3: per region (indexed by its root in label_regions), its size, its faces on the
// outside (mouth), its voxels with such a face (exposed), and its lining: the points within
// clearance + 1.5 h of its boundary voxels, and of them those deeper than lining_depth.
struct RegionStats {
  std::vector<std::uint32_t> size, mouth, exposed, lining, lining_buried;
};
RegionStats region_stats(const NarrowBand& band, const PointIndex& index, const std::vector<std::uint64_t>& air,
                         const std::vector<std::uint32_t>& root, const std::vector<float>& value, double lining_depth,
                         double clearance) {
  const double h = band.voxel_size();
  auto find = [&](const Coord& c) { return std::binary_search(air.begin(), air.end(), key_of(c)); };
  const Coord steps[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  RegionStats st;
  for (auto* v : {&st.size, &st.mouth, &st.exposed, &st.lining, &st.lining_buried}) v->assign(air.size(), 0);
  std::vector<std::uint8_t> is_buried(index.size(), 0);
  // The lining counts the points below the front (deeper than max(1.5 h, 2 noise), not the
  // burial depth): under noise the walls of a closed gap near its mouth lie shallower than
  // 4 noise, and counting them as front points rejected the gap (CGAL's anchor at 0.5 %).
  for (const std::uint32_t p : deeper_than(value, lining_depth))
    is_buried[p] = 1;
  std::vector<std::uint32_t> seen_by(index.size(), std::uint32_t(-1));
  std::vector<std::pair<std::uint32_t, double>> near;
  BandAccessor acc(band);
  for (std::size_t i = 0; i < air.size(); ++i) {
    const Coord c = coord_of(air[i]);
    const std::uint32_t r = root[i];
    ++st.size[r];
    bool boundary = false, open = false;
    for (const Coord& step : steps) {
      const Coord q = c + step;
      if (find(q)) continue;
      boundary = true;
      if (!acc.is_inside(q)) {
        ++st.mouth[r];
        open = true;
      }
    }
    st.exposed[r] += open;
    if (!boundary) continue;
    index.within(band.world(c), clearance + 1.5 * h, near);
    for (const auto& [p, d2] : near) {
      if (seen_by[p] == r) continue;
      seen_by[p] = r;
      ++st.lining[r];
      st.lining_buried[r] += is_buried[p];
    }
  }
  return st;
}

}  // namespace

RegionGroups group_by_region(const std::vector<std::uint32_t>& root) {
  RegionGroups g;
  g.order.resize(root.size());
  std::iota(g.order.begin(), g.order.end(), 0u);
  std::stable_sort(g.order.begin(), g.order.end(), [&](std::uint32_t a, std::uint32_t b) { return root[a] < root[b]; });
  g.start.assign(root.size() + 1, 0);
  for (std::size_t j = g.order.size(); j-- > 0;) g.start[root[g.order[j]]] = std::uint32_t(j);
  return g;
}

namespace {

RegionChoice carve_regions(const NarrowBand& band, const PointIndex& index,
                           const std::vector<std::uint64_t>& air, const std::vector<float>& value,
                           double lining_depth, double clearance, bool allow_pierce, bool cut_webs,
                           bool cut_sheets) {
  RegionChoice out;
  // 2. Regions: 6-connected components of the candidates.
  const std::vector<std::uint32_t> root = label_regions(air);
  // 3. A region is a closed gap when it meets the outside through a mouth (the shell spans
  // it: at least kMinMouthShare size^(2/3) faces, the gap's width across) and the points
  // lining it are mostly buried (a gap's walls); a part's own interior meets the outside only
  // through a hole in the sampling or a dent of the front, a face or a few, and its lining is
  // the part's surface, mostly on the front.
  const RegionStats st = region_stats(band, index, air, root, value, lining_depth, clearance);
  // 4. Carved regions; those large and lined almost only by buried points may also open
  // tunnels (a hole through a plate: the air meets the outside at both mouths). A region
  // lined almost only by buried points is a gap the shell sealed even where its mouth is a
  // face or two (a cavity behind a narrow opening: homer's mouth at 200k points); a part's
  // interior reached through a pinhole is lined by the part's surface (handle.off's: 74 %
  // buried, beside its slot).
  // Webs (cut_webs): a region with at least kWebExposure of its voxels touching the outside is
  // a sheet of the inside that no point supports (the shell spanning a gap: homer's legs and
  // arms, man's at 200k points); it is cut (turned outside whole) where that removes a handle
  // or splits a part (euler_lost < 0), never where it would open a tunnel (a web only partly
  // clear of the points: cow and camel at 200k points gained handles).
  std::vector<std::uint8_t> carve(air.size(), 0), pierce(air.size(), 0), cut(air.size(), 0);
  const RegionGroups groups = cut_webs ? group_by_region(root) : RegionGroups{};
  BandAccessor acc(band);
  std::vector<std::uint64_t> members;
  for (std::size_t i = 0; i < air.size(); ++i) {
    const std::uint32_t r = root[i];
    const double size = st.size[r], lining = st.lining[r], buried = st.lining_buried[r];
    if (r != i || size < kMinCarveVoxels) continue;
    const bool sealed = st.mouth[r] > 0 && buried >= kSealedGapLining * lining;
    const bool has_mouth = sealed || double(st.mouth[r]) >= kMinMouthShare * std::cbrt(size * size);
    bool web = false, sheet = false;
    if (cut_webs && double(st.exposed[r]) >= kWebExposure * size) {
      members.clear();
      for (std::uint32_t j = groups.start[r]; j < groups.start[r] + st.size[r]; ++j) members.push_back(air[groups.order[j]]);
      web = euler_lost(acc, members) < 0;
      sheet = !web && cut_sheets;
    }
    const bool gap = has_mouth && buried >= kMinBuriedLining * lining;
    if (!web && !gap && !sheet) continue;
    carve[r] = 1;
    ++out.regions;
    if (sheet) {
      cut[r] = 1;
      ++out.cut_sheets;
    }
    if (web || (allow_pierce && size >= kMinPierceVoxels && buried >= kMinPierceLining * lining)) {
      pierce[r] = 1;
      ++out.pierced_regions;
      out.webs += web;
    }
  }
  for (std::size_t i = 0; i < air.size(); ++i) {
    if (carve[root[i]]) out.carved.push_back(air[i]);
    if (pierce[root[i]]) out.pierced.push_back(air[i]);
    if (cut[root[i]]) out.cuttable.push_back(air[i]);
  }
  return out;
}

}  // namespace

// 5. (See the header; the steps below.)
Dug dig_regions(const NarrowBand& band, const RegionChoice& choice, const ProgressHook& progress) {
  Dug out;
  const double h = band.voxel_size();
  const std::vector<std::uint64_t>& carved = choice.carved;
  const std::vector<std::uint64_t>& pierced = choice.pierced;
  // The carved voxels and their inside face neighbours join the band (-h/2 where they were
  // inactive: every sign change stays between active voxels, the band's invariant); the
  // carved ones turn outside (+h/2) as far as the topology guard lets them: simple flips
  // only, taken again as their neighbours flip, so the region is dug out from the shell
  // inward without making handles. Where only part of a gap could be cleared (a slot
  // narrower than the clearance in places), removing what is left of the shell across it
  // would open tunnels, and opening the rest would leave bridges: both change the genus.
  // A pierced region turns outside whole (the guard's free voxels): it is empty space
  // farther than the clearance from every point, so no sampled wall lies across it, and
  // where it meets the outside at two mouths the tunnel it opens is the data's
  // (kMinPierceLining: CGAL's anchor and couplingdown at 20k points reopen their holes; a
  // looser share gave the fist of hand.off tunnels between its fingers).
  // The band is then redistanced out to its half-width (the snaps that follow move the new
  // walls onto the points).
  NarrowBand active = with_active(band, carved);
  std::vector<float> proposed(active.values().begin(), active.values().end());
  {
    BandAccessor at(active);
    const float half = float(0.5 * h);
    for (const std::uint64_t k : carved) {
      const Coord c = coord_of(k);
      const std::uint32_t b = at.locate(brick_of(c));
      const Brick& br = active.bricks()[b];
      proposed[br.value_offset + br.slot(local_index(c))] = half;
    }
  }
  TopologyGuardOptions guard;
  guard.eps = 1e-3 * h;
  guard.progress = progress;
  if (!pierced.empty())
    guard.free = [&](const Coord& c) { return std::binary_search(pierced.begin(), pierced.end(), key_of(c)); };
  if (!choice.cuttable.empty())
    guard.cuttable = [&](const Coord& c) {
      return std::binary_search(choice.cuttable.begin(), choice.cuttable.end(), key_of(c));
    };
  TopologyGuardResult kept = guard_topology(active, active, std::move(proposed), guard);
  out.carved_voxels = carved.size() - std::min<std::uint64_t>(carved.size(), kept.refused_flips);
  active.swap_values(kept.values);
  if (choice.webs > 0) drop_web_scraps(active, pierced);
  for (const std::uint64_t k : carved) {
    const Coord b = brick_of(coord_of(k));
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) out.bricks.push_back(brick_key(b + Coord{dx, dy, dz}));
  }
  std::sort(out.bricks.begin(), out.bricks.end());
  out.bricks.erase(std::unique(out.bricks.begin(), out.bricks.end()), out.bricks.end());
  for (const std::uint64_t k : choice.cuttable) {
    const Coord c = coord_of(k);
    for (int dz = -kCutZoneVoxels; dz <= kCutZoneVoxels; ++dz)
      for (int dy = -kCutZoneVoxels; dy <= kCutZoneVoxels; ++dy)
        for (int dx = -kCutZoneVoxels; dx <= kCutZoneVoxels; ++dx)
          out.cut_zone.push_back(key_of(c + Coord{dx, dy, dz}));
  }
  std::sort(out.cut_zone.begin(), out.cut_zone.end());
  out.cut_zone.erase(std::unique(out.cut_zone.begin(), out.cut_zone.end()), out.cut_zone.end());
  RedistanceOptions redo;
  redo.half_width = band.half_width();
  redo.progress = progress;
  out.band = redistance(reframed(active, {}, 1.0), redo).band;
  return out;
}

namespace {

// One carving (see reconstruction_parts.hpp) with the given settings; its candidates lie no
// farther than `outer` from every point (the narrow carving leaves the space beyond the first
// one's clearance, which that carving has judged, alone).
CarveOutput carve_once(NarrowBand band, const PointIndex& index, const CarveSettings& s, double outer,
                       const ProgressHook& progress) {
  CarveOutput out;
  const double h = band.voxel_size();
  const double depth = std::max(kCarveDepthVoxels * h, kCarveNoiseDepth * s.noise);
  const double clearance = clearance_of(s, h);
  const double lining_depth = lining_depth_of(s, h);
  const std::vector<float> value = point_values(band, index, std::max(depth, lining_depth));
  const std::vector<std::uint32_t> buried = deeper_than(value, depth);
  out.buried = buried.size();
  out.band = std::move(band);
  if (buried.size() < std::max<std::size_t>(kMinBuried, std::size_t(kMinBuriedShare * double(index.size()))) ||
      double(buried.size()) > kMaxBuriedShare * double(index.size()))
    return out;
  progress.check("reconstruct carve");
  const std::vector<std::uint64_t> air =
      air_candidates(out.band, index, s.clearance_points ? *s.clearance_points : index, buried,
                     int(std::ceil(s.reach_voxels)), clearance, outer, progress);
  if (air.empty()) return out;
  const RegionChoice choice = carve_regions(out.band, index, air, value, lining_depth, clearance,
                                            s.pierce, s.cut_webs, s.cut_sheets);
  out.regions = choice.regions;
  out.pierced_regions = choice.pierced_regions;
  out.webs = choice.webs;
  if (choice.carved.empty()) return out;
  Dug dug = dig_regions(out.band, choice, progress);
  out.band = std::move(dug.band);
  out.carved_voxels = dug.carved_voxels;
  out.bricks = std::move(dug.bricks);
  out.cut_zone = std::move(dug.cut_zone);
  out.cut_sheets = choice.cut_sheets;
  return out;
}

}  // namespace

CarveOutput carve_buried_gaps(NarrowBand band, const PointIndex& index, const CarveSettings& s,
                              const ProgressHook& progress) {
  const double h = band.voxel_size();
  CarveOutput out = carve_once(std::move(band), index, s, std::numeric_limits<double>::infinity(), progress);
  if (s.web_tunnels) {
    WebTunnelSettings ws;
    ws.clearance = clearance_of(s, h);
    ws.lining_depth = lining_depth_of(s, h);
    ws.clearance_points = s.clearance_points;
    ws.fine_clearance = s.fine_tunnels ? kFineTunnelClearance * ws.clearance : 0.0;
    ws.shallow_depth = std::max(kShallowLiningVoxels * h, kLiningNoiseDepth * s.noise);
    WebTunnels webs = open_web_tunnels(std::move(out.band), index, ws, progress);
    out.band = std::move(webs.band);
    out.web_tunnels = webs.tunnels;
    out.carved_voxels += webs.voxels;
    merge_bricks(out.bricks, webs.bricks);
  }
  if (!s.narrow) return out;
  // The narrow gaps (see kNarrowGapClearance), after the wide ones are open: simple flips only.
  CarveSettings narrow = s;
  narrow.gap *= kNarrowGapClearance;
  narrow.pierce = false;
  narrow.cut_webs = false;
  // Nothing to look at where the noise or the voxel, not the gap, sets the clearance.
  if (!(clearance_of(narrow, h) < clearance_of(s, h))) return out;
  CarveOutput more = carve_once(std::move(out.band), index, narrow, clearance_of(s, h), progress);
  out.band = std::move(more.band);
  out.regions += more.regions;
  out.carved_voxels += more.carved_voxels;
  merge_bricks(out.bricks, more.bricks);
  return out;
}

}  // namespace levelset::apps::detail
