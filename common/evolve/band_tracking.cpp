#include "evolve/band_tracking.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "distance/redistance_domain.hpp"

namespace levelset::evolve {

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
  auto neighbor = [&](std::size_t b, const Coord& l, int f, std::size_t& nb) -> int {
    const int a = f >> 1;
    Coord q = l;
    q[a] += (f & 1) ? 1 : -1;
    nb = b;
    if (q[a] < 0 || q[a] >= kBrickDim) {
      const std::uint32_t o = w.nbr[b][std::size_t(f)];
      if (o == kNoBrick) return -1;
      nb = o;
      q[a] = (q[a] + kBrickDim) % kBrickDim;
    }
    return local_index(q.x, q.y, q.z);
  };
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
  // Signed value (voxels) of a previously active voxel: the polynomial runs across the zero
  // level, where u is smooth.
  auto signed_at = [&](std::size_t b, int j) {
    const float d = w.values(std::uint32_t(b))[j];
    return w.inside[b].test(j) ? -d : d;
  };
  // Extrapolation to voxel i of brick b from previously active voxels along the 6 axis
  // directions: quadratic through the next three (linear through two), on the direction
  // where u changes fastest; the first one must not be an edge voxel when skip_edge. Returns
  // the distance (voxels) when the result lies on the voxel's own side, else -1.
  auto extrapolate = [&](std::size_t b, int i, bool skip_edge) {
    const Coord l = local_coord(i);
    float best = 0.0f, step = -1.0f;
    for (int f = 0; f < 6; ++f) {
      std::size_t b1, b2, b3;
      const int j1 = neighbor(b, l, f, b1);
      if (j1 < 0 || !old_active[b1].test(j1) || (skip_edge && edge[b1].test(j1))) continue;
      const int j2 = neighbor(b1, local_coord(j1), f, b2);
      if (j2 < 0 || !old_active[b2].test(j2)) continue;
      const float u1 = signed_at(b1, j1), u2 = signed_at(b2, j2);
      if (std::abs(u1 - u2) <= step) continue;
      step = std::abs(u1 - u2);
      best = 2.0f * u1 - u2;
      const int j3 = neighbor(b2, local_coord(j2), f, b3);
      if (j3 >= 0 && old_active[b3].test(j3)) best = 3.0f * u1 - 3.0f * u2 + signed_at(b3, j3);
    }
    if (step < 0.0f || (w.inside[b].test(i) ? best >= 0.0f : best <= 0.0f)) return -1.0f;
    // A distance changes by at most one voxel per voxel: clamp to the range every active
    // 6-neighbour on the same side allows (a polynomial through a kink could leave it, and a
    // value pushed beyond W would leave a hole next to the front).
    float lo = 0.0f, hi = detail::kInf;
    for (int f = 0; f < 6; ++f) {
      std::size_t nb;
      const int j = neighbor(b, l, f, nb);
      if (j < 0 || !old_active[nb].test(j) || w.inside[nb].test(j) != w.inside[b].test(i)) continue;
      const float d = w.values(std::uint32_t(nb))[j];
      lo = std::max(lo, d - 1.0f);
      hi = std::min(hi, d + 1.0f);
    }
    return std::clamp(std::abs(best), lo, std::max(lo, hi));
  };
  std::vector<std::vector<std::pair<int, float>>> edge_values(n);
  if (options.extrapolate_edge)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b)
      edge[b].for_each_set([&](int i) {
        const float d = extrapolate(b, i, true);
        if (d >= 0.0f) edge_values[b].push_back({i, d});
      });
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
      fresh.for_each_set([&](int i) {
        const Coord l = local_coord(i);
        float m[3] = {detail::kInf, detail::kInf, detail::kInf};
        for (int f = 0; f < 6; ++f) {
          std::size_t nb;
          const int j = neighbor(b, l, f, nb);
          if (j < 0 || !old_active[nb].test(j) || w.inside[nb].test(j) != w.inside[b].test(i)) continue;
          m[f >> 1] = std::min(m[f >> 1], w.values(std::uint32_t(nb))[j]);
        }
        // The high-order extrapolation where it agrees with that to half a voxel (smooth
        // field; stencils near the edge read it), the Godunov value where it does not.
        const float first_order = detail::godunov(m[0], m[1], m[2]);
        // Beyond W + 1/2 neither value activates the voxel: skip the extrapolation.
        const float high = first_order <= float(w_half) + 0.5f ? extrapolate(b, i, false) : -1.0f;
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
