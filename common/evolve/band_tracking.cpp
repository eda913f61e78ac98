#include "evolve/band_tracking.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "distance/redistance_domain.hpp"

namespace levelset::evolve {

namespace {

// A brick of the tracking domain and its six face neighbours (slot 0: the brick, 1 + f: the
// neighbour across face f = 2 a + (1 if +a)), resolved once per brick: the voxels up to
// three steps along an axis from the brick lie in these.
struct BrickStar {
  std::array<const float*, 7> value{};  // unsigned distances (voxels); null: no brick
  std::array<const BrickMask*, 7> active{}, inside{}, edge{};

  struct At {
    int slot = -1, index = 0;  // slot -1: outside the domain
  };
  // The voxel `steps` (1-3) from brick-local l across face direction f.
  static At step(const Coord& l, int f, int steps, const BrickStar& star) {
    const int a = f >> 1;
    Coord q = l;
    q[a] += (f & 1) ? steps : -steps;
    int slot = 0;
    if (q[a] < 0 || q[a] >= kBrickDim) {
      slot = 1 + f;
      q[a] -= (f & 1) ? kBrickDim : -kBrickDim;
    }
    if (!star.value[std::size_t(slot)]) return {};
    return {slot, local_index(q.x, q.y, q.z)};
  }
  bool is_active(At p) const { return p.slot >= 0 && active[std::size_t(p.slot)]->test(p.index); }
  bool is_inside(At p) const { return inside[std::size_t(p.slot)]->test(p.index); }
  float distance(At p) const { return value[std::size_t(p.slot)][p.index]; }
  // Signed value (voxels) of a previously active voxel.
  float signed_at(At p) const { return is_inside(p) ? -distance(p) : distance(p); }
};

// Bit i of the result: the neighbour of voxel i across face f is set in the mask (star[0]: the
// brick's, star[1 + f]: its face neighbours'; null: an empty mask). Layout (brick_mask.hpp):
// word = z-slice, byte = y-row, bit = x.
BrickMask neighbour_bits(const std::array<BrickMask, 7>& star, int f) {
  constexpr std::uint64_t kCol0 = 0x0101010101010101ull, kCol7 = 0x8080808080808080ull;
  const BrickMask& m = star[0];
  const BrickMask& o = star[std::size_t(1 + f)];
  BrickMask r;
  for (int z = 0; z < 8; ++z) {
    const std::uint64_t a = m.words[std::size_t(z)];
    std::uint64_t v = 0;
    switch (f) {
      case 0: v = (a << 1 & ~kCol0) | (o.words[std::size_t(z)] & kCol7) >> 7; break;
      case 1: v = (a >> 1 & ~kCol7) | (o.words[std::size_t(z)] & kCol0) << 7; break;
      case 2: v = a << 8 | o.words[std::size_t(z)] >> 56; break;
      case 3: v = a >> 8 | o.words[std::size_t(z)] << 56; break;
      case 4: v = z > 0 ? m.words[std::size_t(z - 1)] : o.words[7]; break;
      default: v = z < 7 ? m.words[std::size_t(z + 1)] : o.words[0]; break;
    }
    r.words[std::size_t(z)] = v;
  }
  return r;
}

}  // namespace

TrackResult track_band(const NarrowBand& moved, const TrackOptions& options) {
  const double w_half = options.half_width;
  if (!std::isfinite(w_half) || w_half < 1.0 || w_half > 1024.0)
    throw Error(ErrorCode::InvalidArgument, "track_band", "half_width must be in [1, 1024] voxels");
  const double h = moved.voxel_size();
  detail::RedistanceDomain w = detail::build_domain(moved, 1, options.progress);
  const std::size_t n = w.size();

  // Previously active voxels: |u| / h, exactly as stored.
  std::vector<BrickMask> old_active(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const std::uint32_t src = w.source[b];
      if (src == kNoBrick) continue;
      const Brick& br = moved.bricks()[src];
      old_active[b] = br.active;
      float* d = w.values(std::uint32_t(b));
      const float* v = moved.values().data() + br.value_offset;
      br.active.for_each_set([&](int i) { d[i] = float(std::abs(double(*v++)) / h); });
    }
  });
  // The band's edge layer (previously active voxels with an inactive 6-neighbour): their
  // stencils read +-W h beyond the band, so their PDE values lag (on the upwind side of an
  // expanding front they would never grow past W h and never retire). They are extrapolated
  // from the interior instead: linearly, 2 u1 - u2, from the two next voxels inward along
  // the axis and direction where u changes fastest (the one nearest the normal); exact for
  // linear u, second order for smooth u.
  // Edge voxels by mask arithmetic: active voxels with an inactive 6-neighbour (a missing
  // brick counts as inactive). Layout (brick_mask.hpp): word = z-slice, byte = y-row, bit = x.
  std::vector<BrickMask> edge(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    constexpr std::uint64_t kCol0 = 0x0101010101010101ull, kCol7 = 0x8080808080808080ull;
    const BrickMask none{};
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      const BrickMask& m = old_active[b];
      auto face = [&](int f) -> const BrickMask& {
        const std::uint32_t o = w.nbr[b][std::size_t(f)];
        return o == kNoBrick ? none : old_active[o];
      };
      const BrickMask &xm = face(0), &xp = face(1), &ym = face(2), &yp = face(3), &zm = face(4), &zp = face(5);
      for (int z = 0; z < 8; ++z) {
        const std::uint64_t a = m.words[std::size_t(z)];
        // Active neighbour in each direction, per voxel.
        const std::uint64_t left = (a << 1 & ~kCol0) | (xm.words[std::size_t(z)] & kCol7) >> 7;
        const std::uint64_t right = (a >> 1 & ~kCol7) | (xp.words[std::size_t(z)] & kCol0) << 7;
        const std::uint64_t down = a << 8 | ym.words[std::size_t(z)] >> 56;
        const std::uint64_t up = a >> 8 | yp.words[std::size_t(z)] << 56;
        const std::uint64_t below = z > 0 ? m.words[std::size_t(z - 1)] : zm.words[7];
        const std::uint64_t above = z < 7 ? m.words[std::size_t(z + 1)] : zp.words[0];
        edge[b].words[std::size_t(z)] = a & ~(left & right & down & up & below & above);
      }
    }
  });
  auto star_of = [&](std::size_t b) {
    BrickStar st;
    auto set = [&](std::size_t slot, std::uint32_t o) {
      if (o == kNoBrick) return;
      st.value[slot] = w.values(o);
      st.active[slot] = &old_active[o];
      st.inside[slot] = &w.inside[o];
      st.edge[slot] = &edge[o];
    };
    set(0, std::uint32_t(b));
    for (std::size_t f = 0; f < 6; ++f) set(1 + f, w.nbr[b][f]);
    return st;
  };
  // Extrapolation to voxel i of the star's brick from previously active voxels along the 6
  // axis directions: quadratic through the next three (linear through two), on the direction
  // where u changes fastest; the first one must not be an edge voxel when skip_edge. Signed
  // values: the polynomial runs across the zero level, where u is smooth. Returns the
  // distance (voxels) when the result lies on the voxel's own side, else -1.
  auto extrapolate = [&](const BrickStar& st, int i, bool skip_edge) {
    using At = BrickStar::At;
    const Coord l = local_coord(i);
    const bool in_self = st.inside[0]->test(i);
    float best = 0.0f, step = -1.0f;
    for (int f = 0; f < 6; ++f) {
      const At p1 = BrickStar::step(l, f, 1, st);
      if (!st.is_active(p1) || (skip_edge && st.edge[std::size_t(p1.slot)]->test(p1.index))) continue;
      const At p2 = BrickStar::step(l, f, 2, st);
      if (!st.is_active(p2)) continue;
      const float u1 = st.signed_at(p1), u2 = st.signed_at(p2);
      if (std::abs(u1 - u2) <= step) continue;
      step = std::abs(u1 - u2);
      best = 2.0f * u1 - u2;
      const At p3 = BrickStar::step(l, f, 3, st);
      if (st.is_active(p3)) best = 3.0f * u1 - 3.0f * u2 + st.signed_at(p3);
    }
    if (step < 0.0f || (in_self ? best >= 0.0f : best <= 0.0f)) return -1.0f;
    // A distance changes by at most one voxel per voxel: clamp to the range every active
    // 6-neighbour on the same side allows (a polynomial through a kink could leave it, and a
    // value pushed beyond W would leave a hole next to the front).
    float lo = 0.0f, hi = detail::kInf;
    for (int f = 0; f < 6; ++f) {
      const At p = BrickStar::step(l, f, 1, st);
      if (!st.is_active(p) || st.is_inside(p) != in_self) continue;
      const float d = st.distance(p);
      lo = std::max(lo, d - 1.0f);
      hi = std::min(hi, d + 1.0f);
    }
    return std::clamp(std::abs(best), lo, std::max(lo, hi));
  };
  std::vector<std::vector<std::pair<int, float>>> edge_values(n);
  if (options.extrapolate_edge)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      if (edge[b].none()) continue;
      const BrickStar st = star_of(b);
      edge[b].for_each_set([&](int i) {
        const float d = extrapolate(st, i, true);
        if (d >= 0.0f) edge_values[b].push_back({i, d});
      });
    }
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b)
      for (const auto& [i, d] : edge_values[b]) w.values(std::uint32_t(b))[i] = d;
  });

  // Newly reached voxels: the first-order Godunov distance update from their previously
  // active 6-neighbours on the same side (exact for a plane; never below the nearest
  // neighbour's distance, so a new voxel cannot look nearer the front than it is), replaced
  // by the high-order extrapolation where the two agree.
  std::atomic<std::uint64_t> activated{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      float* d = w.values(std::uint32_t(b));
      std::uint64_t count = 0;
      BrickMask fresh;
      for (int z = 0; z < 8; ++z) fresh.words[std::size_t(z)] = w.domain[b].words[std::size_t(z)] & ~old_active[b].words[std::size_t(z)];
      if (fresh.none()) continue;
      const BrickStar st = star_of(b);
      // Per face: the fresh voxels whose neighbour across it is previously active and on the
      // same side, by mask arithmetic.
      std::array<BrickMask, 7> in_star{}, out_star{};
      for (std::size_t k = 0; k < 7; ++k)
        if (st.value[k])
          for (std::size_t z = 0; z < 8; ++z) {
            in_star[k].words[z] = st.active[k]->words[z] & st.inside[k]->words[z];
            out_star[k].words[z] = st.active[k]->words[z] & ~st.inside[k]->words[z];
          }
      std::array<BrickMask, 6> same_side;
      for (int f = 0; f < 6; ++f) {
        const BrickMask in_n = neighbour_bits(in_star, f), out_n = neighbour_bits(out_star, f);
        for (std::size_t z = 0; z < 8; ++z)
          same_side[std::size_t(f)].words[z] = fresh.words[z] & ((st.inside[0]->words[z] & in_n.words[z]) |
                                                                  (~st.inside[0]->words[z] & out_n.words[z]));
      }
      fresh.for_each_set([&](int i) {
        const Coord l = local_coord(i);
        float m[3] = {detail::kInf, detail::kInf, detail::kInf};
        for (int f = 0; f < 6; ++f)
          if (same_side[std::size_t(f)].test(i))
            m[f >> 1] = std::min(m[f >> 1], st.distance(BrickStar::step(l, f, 1, st)));
        // The high-order extrapolation where it agrees with that to half a voxel (smooth
        // field; stencils near the edge read it), the Godunov value where it does not.
        const float first_order = detail::godunov(m[0], m[1], m[2]);
        // Beyond W + 1/2 neither value activates the voxel: skip the extrapolation.
        const float high = first_order <= float(w_half) + 0.5f ? extrapolate(st, i, false) : -1.0f;
        const float best = high >= 0.0f && std::abs(high - first_order) <= 0.5f ? high : first_order;
        d[i] = best;
        count += best <= float(w_half);
      });
      activated += count;
    }
  });
  TrackResult result;
  result.activated = activated.load();
  GridFrame frame{h, moved.origin(), w_half};
  result.band = detail::assemble_band(moved, w, frame);
  const std::uint64_t before = moved.active_voxel_count(), after = result.band.active_voxel_count();
  result.retired = before + result.activated - after;
  return result;
}

}  // namespace levelset::evolve
