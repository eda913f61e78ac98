#include "evolve/band_tracking.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/uninitialized_vector.hpp"
#include "distance/redistance_domain.hpp"

namespace levelset::evolve {

namespace {

// A brick of the tracking domain and the voxels up to three steps across each of its faces
// (what a voxel of the brick reaches along an axis), as a dense tile: the previously active
// voxels' signed distances (voxels; -0 for an inside voxel at distance 0), NaN elsewhere, so
// one load answers "active?", "which side?" and "how far?". Samples off the cross (more than
// one coordinate outside the brick) are never read and not filled.
struct StarTile {
  static constexpr int kReach = 3, kDim = kBrickDim + 2 * kReach;
  static constexpr std::ptrdiff_t kStride[3] = {1, kDim, kDim * kDim};
  std::array<float, std::size_t(kDim) * kDim * kDim> v;

  static constexpr std::size_t index(int x, int y, int z) {
    return std::size_t((x + kReach) + kDim * ((y + kReach) + kDim * (z + kReach)));
  }
  const float* at(const Coord& l) const { return v.data() + index(l.x, l.y, l.z); }
  // The step to the neighbour across face f = 2 a + (1 if +a).
  static constexpr std::ptrdiff_t face_step(int f) { return (f & 1) ? kStride[f >> 1] : -kStride[f >> 1]; }
  // From the signed values of the brick (slot 0) and its face neighbours (1 + f, face f =
  // 2 a + (1 if +a); null: no brick).
  void fill(const std::array<const float*, 7>& value) {
    constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
    // Rows of the brick (x in [0, 8)) and the y and z neighbours' slabs.
    auto rows = [&](const float* src, int y0, int y1, int z0, int z1, int dy, int dz) {
      for (int z = z0; z < z1; ++z)
        for (int y = y0; y < y1; ++y) {
          float* out = v.data() + index(0, y, z);
          const float* in = src ? src + local_index(0, y - dy, z - dz) : nullptr;
          for (int x = 0; x < kBrickDim; ++x) out[x] = in ? in[x] : kNaN;
        }
    };
    rows(value[0], 0, kBrickDim, 0, kBrickDim, 0, 0);
    rows(value[3], -kReach, 0, 0, kBrickDim, -kBrickDim, 0);  // -y
    rows(value[4], kBrickDim, kBrickDim + kReach, 0, kBrickDim, kBrickDim, 0);  // +y
    rows(value[5], 0, kBrickDim, -kReach, 0, 0, -kBrickDim);  // -z
    rows(value[6], 0, kBrickDim, kBrickDim, kBrickDim + kReach, 0, kBrickDim);  // +z
    // The x neighbours' three columns per row.
    for (int z = 0; z < kBrickDim; ++z)
      for (int y = 0; y < kBrickDim; ++y)
        for (int k = 0; k < kReach; ++k) {
          v[index(-1 - k, y, z)] = value[1] ? value[1][local_index(kBrickDim - 1 - k, y, z)] : kNaN;
          v[index(kBrickDim + k, y, z)] = value[2] ? value[2][local_index(k, y, z)] : kNaN;
        }
  }
};

// Extrapolation to the voxel at tile sample c (signed values, StarTile) from previously active
// voxels along the 6 axis directions: quadratic through the next three (linear through two),
// on the direction where u changes fastest; skip bit f: the direction f may not be used (its
// first voxel is an edge voxel). Signed values: the polynomial runs across the zero level,
// where u is smooth. Returns the distance (voxels) when the result lies on the voxel's own
// side (in_self: inside), else -1.
float extrapolate(const float* c, bool in_self, unsigned skip) {
  float best = 0.0f, step = -1.0f;
  for (int f = 0; f < 6; ++f) {
    const std::ptrdiff_t s = StarTile::face_step(f);
    const float u1 = c[s];
    if (std::isnan(u1) || ((skip >> f) & 1u)) continue;
    const float u2 = c[2 * s];
    if (std::isnan(u2)) continue;
    if (std::abs(u1 - u2) <= step) continue;
    step = std::abs(u1 - u2);
    best = 2.0f * u1 - u2;
    if (const float u3 = c[3 * s]; !std::isnan(u3)) best = 3.0f * u1 - 3.0f * u2 + u3;
  }
  if (step < 0.0f || (in_self ? best >= 0.0f : best <= 0.0f)) return -1.0f;
  // A distance changes by at most one voxel per voxel: clamp to the range every active
  // 6-neighbour on the same side allows (a polynomial through a kink could leave it, and a
  // value pushed beyond W would leave a hole next to the front).
  float lo = 0.0f, hi = detail::kInf;
  for (int f = 0; f < 6; ++f) {
    const float u = c[StarTile::face_step(f)];
    if (std::isnan(u) || std::signbit(u) != in_self) continue;
    const float d = std::abs(u);
    lo = std::max(lo, d - 1.0f);
    hi = std::min(hi, d + 1.0f);
  }
  return std::clamp(std::abs(best), lo, std::max(lo, hi));
}

// Bit f: the face neighbour of brick-local voxel l across face f is set in its mask (star[0]:
// the brick's, star[1 + f]: the neighbour across f; null: none).
unsigned face_neighbour_bits(const std::array<const BrickMask*, 7>& star, const Coord& l) {
  unsigned bits = 0;
  for (int f = 0; f < 6; ++f) {
    const int a = f >> 1;
    Coord q = l;
    q[a] += (f & 1) ? 1 : -1;
    std::size_t slot = 0;
    if (q[a] < 0 || q[a] >= kBrickDim) {
      slot = std::size_t(1 + f);
      q[a] -= (f & 1) ? kBrickDim : -kBrickDim;
    }
    if (star[slot] && star[slot]->test(local_index(q.x, q.y, q.z))) bits |= 1u << f;
  }
  return bits;
}

}  // namespace

TrackResult track_band(const NarrowBand& moved, const TrackOptions& options) {
  const double w_half = options.half_width;
  if (!std::isfinite(w_half) || w_half < 1.0 || w_half > 1024.0)
    throw Error(ErrorCode::InvalidArgument, "track_band", "half_width must be in [1, 1024] voxels");
  const double h = moved.voxel_size();
  detail::RedistanceDomain w = detail::build_domain(moved, 1, options.progress);
  const std::size_t n = w.size();

  // Previously active voxels: |u| / h, exactly as stored, and signed (StarTile's values).
  std::vector<BrickMask> old_active(n);
  UninitializedVector<float> signed_values(n * kBrickVoxels);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      float* sv = signed_values.data() + b * kBrickVoxels;
      std::fill_n(sv, kBrickVoxels, std::numeric_limits<float>::quiet_NaN());
      const std::uint32_t src = w.source[b];
      if (src == kNoBrick) continue;
      const Brick& br = moved.bricks()[src];
      old_active[b] = br.active;
      float* d = w.values(std::uint32_t(b));
      const float* v = moved.values().data() + br.value_offset;
      const BrickMask& inside = w.inside[b];
      br.active.for_each_set([&](int i) {
        d[i] = float(std::abs(double(*v++)) / h);
        sv[i] = inside.test(i) ? -d[i] : d[i];
      });
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
  // The signed values and edge masks of brick b and its face neighbours (StarTile's slots).
  auto star_values = [&](std::size_t b) {
    std::array<const float*, 7> value{};
    value[0] = signed_values.data() + b * kBrickVoxels;
    for (std::size_t f = 0; f < 6; ++f)
      if (const std::uint32_t o = w.nbr[b][f]; o != kNoBrick) value[1 + f] = signed_values.data() + std::size_t(o) * kBrickVoxels;
    return value;
  };
  auto star_edges = [&](std::size_t b) {
    std::array<const BrickMask*, 7> masks{};
    masks[0] = &edge[b];
    for (std::size_t f = 0; f < 6; ++f)
      if (const std::uint32_t o = w.nbr[b][f]; o != kNoBrick) masks[1 + f] = &edge[o];
    return masks;
  };
  tbb::enumerable_thread_specific<StarTile> tile;
  std::vector<std::vector<std::pair<int, float>>> edge_values(n);
  if (options.extrapolate_edge)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b) {
      if (edge[b].none()) continue;
      tile.local().fill(star_values(b));
      const std::array<const BrickMask*, 7> edges = star_edges(b);
      edge[b].for_each_set([&](int i) {
        const Coord l = local_coord(i);
        const float d = extrapolate(tile.local().at(l), w.inside[b].test(i), face_neighbour_bits(edges, l));
        if (d >= 0.0f) edge_values[b].push_back({i, d});
      });
    }
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t b = r.begin(); b != r.end(); ++b)
      for (const auto& [i, d] : edge_values[b]) {
        w.values(std::uint32_t(b))[i] = d;
        signed_values[b * kBrickVoxels + std::size_t(i)] = w.inside[b].test(i) ? -d : d;
      }
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
      StarTile& t = tile.local();
      t.fill(star_values(b));
      const BrickMask& inside = w.inside[b];
      fresh.for_each_set([&](int i) {
        const float* c = t.at(local_coord(i));
        const bool in_self = inside.test(i);
        // The nearest previously active face neighbour on the same side, per axis.
        float m[3] = {detail::kInf, detail::kInf, detail::kInf};
        for (int f = 0; f < 6; ++f) {
          const float u = c[StarTile::face_step(f)];
          if (!std::isnan(u) && std::signbit(u) == in_self) m[f >> 1] = std::min(m[f >> 1], std::abs(u));
        }
        // The high-order extrapolation where it agrees with that to half a voxel (smooth
        // field; stencils near the edge read it), the Godunov value where it does not.
        const float first_order = detail::godunov(m[0], m[1], m[2]);
        // Beyond W + 1/2 neither value activates the voxel: skip the extrapolation.
        const float high = first_order <= float(w_half) + 0.5f ? extrapolate(c, in_self, 0u) : -1.0f;
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
