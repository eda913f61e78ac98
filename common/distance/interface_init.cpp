#include "distance/interface_init.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "distance/redistance_tile.hpp"
#include "grid/tile.hpp"

namespace levelset::detail {

namespace {

// Activeness of the input's voxels on a halo-1 tile around brick src (1 = active).
void gather_active(const NarrowBand& in, std::uint32_t src, std::uint8_t* act) {
  const Coord self = in.bricks()[src].coord;
  const BrickMask* masks[27];
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const std::uint32_t nb = (dx | dy | dz) == 0 ? src : in.find_brick(self + Coord{dx, dy, dz});
        masks[(dx + 1) + 3 * (dy + 1) + 9 * (dz + 1)] = nb == kNoBrick ? nullptr : &in.bricks()[nb].active;
      }
  for (int z = -1; z <= kBrickDim; ++z)
    for (int y = -1; y <= kBrickDim; ++y)
      for (int x = -1; x <= kBrickDim; ++x) {
        auto part = [](int c) { return c < 0 ? 0 : (c < kBrickDim ? 1 : 2); };
        const BrickMask* m = masks[part(x) + 3 * part(y) + 9 * part(z)];
        act[TileGeom<1>::index(x, y, z)] = m != nullptr && m->test(local_index(x & 7, y & 7, z & 7));
      }
}

// Unsigned subcell distance (voxels) of an interface voxel at tile index t; see redistance.hpp.
// d_C: distance to the plane through the edge crossings (inverse crossing distances on
// crossing axes, |du/dx_a|/|u| elsewhere) - robust, exact for linear u, first order in the
// surface's curvature. d_T: second-order Taylor along the normal, u = g d - (u_nn/2) d^2,
// from central first and second differences - exact for distance fields and for u whose
// gradient varies along the normal, but it needs a full 3x3x3 stencil of active values on
// one side of every crossing. d_T is used where it exists and agrees with d_C to 0.1 voxel;
// the result never exceeds the nearest crossing.
double subcell_distance(const float* tile, const std::uint8_t* act, int t) {
  constexpr int S[3] = {TileGeom<1>::kStride[0], TileGeom<1>::kStride[1], TileGeom<1>::kStride[2]};
  const double u = tile[t];
  if (u == 0.0) return 0.0;
  const bool in_u = tile[t] < 0.0f;
  double gsum = 0.0, gmax = 0.0;
  bool full = true;  // every face neighbour active, no axis crossed on both sides
  for (int a = 0; a < 3; ++a) {
    const double um = tile[t - S[a]], up = tile[t + S[a]];
    const bool cm = (tile[t - S[a]] < 0.0f) != in_u, cp = (tile[t + S[a]] < 0.0f) != in_u;
    const bool am = act[t - S[a]] != 0, ap = act[t + S[a]] != 0;
    full &= am && ap && !(cm && cp);
    double g = 0.0;
    if (cm || cp) {
      // Inverse crossing distance 1/theta = (u - u_j)/u >= 1; the nearer crossing wins.
      if (cm) g = std::max(g, (u - um) / u);
      if (cp) g = std::max(g, (u - up) / u);
      gmax = std::max(gmax, g);
    } else if (am && ap) {
      g = std::abs(up - um) / (2.0 * std::abs(u));
    } else if (am) {
      g = std::abs(u - um) / std::abs(u);
    } else if (ap) {
      g = std::abs(up - u) / std::abs(u);
    }
    gsum += g * g;
  }
  const double d_plane = 1.0 / std::sqrt(gsum);  // gsum >= 1: at most 1 voxel
  const double nearest = 1.0 / gmax;             // distance to the nearest crossing
  if (!full) return d_plane;
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b)
      for (int s = -1; s <= 1; s += 2)
        for (int r = -1; r <= 1; r += 2)
          if (!act[t + s * S[a] + r * S[b]]) return d_plane;
  double g[3], H[3][3];
  for (int a = 0; a < 3; ++a) {
    g[a] = 0.5 * (double(tile[t + S[a]]) - double(tile[t - S[a]]));
    H[a][a] = double(tile[t + S[a]]) - 2.0 * u + double(tile[t - S[a]]);
    for (int b = a + 1; b < 3; ++b) {
      H[a][b] = H[b][a] = 0.25 * (double(tile[t + S[a] + S[b]]) - double(tile[t + S[a] - S[b]]) -
                                  double(tile[t - S[a] + S[b]]) + double(tile[t - S[a] - S[b]]));
    }
  }
  const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
  if (!(g2 > 0.0)) return d_plane;
  double unn = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) unn += g[a] * H[a][b] * g[b];
  unn /= g2;
  const double gn = std::sqrt(g2);
  const double disc = g2 - 2.0 * unn * u;  // g^2 - 4 (u_nn/2) u
  if (!(disc > 0.0)) return d_plane;
  const double d_taylor = std::abs(2.0 * u / (gn + std::sqrt(disc)));
  if (!(std::abs(d_taylor - d_plane) <= 0.1)) return d_plane;
  return std::min(d_taylor, nearest);
}

}  // namespace

std::uint64_t init_interface(const NarrowBand& in, RedistanceDomain& w) {
  std::vector<std::uint32_t> work_of_input;  // input bricks that hold active voxels
  for (std::uint32_t b = 0; b < w.size(); ++b)
    if (w.source[b] != kNoBrick && !in.bricks()[w.source[b]].active.none()) work_of_input.push_back(b);
  std::vector<std::uint32_t> counts(work_of_input.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, work_of_input.size(), 8), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<float> tile(TileGeom<1>::kVoxels);
    std::vector<std::uint8_t> act(TileGeom<1>::kVoxels);
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const std::uint32_t b = work_of_input[i];
      const std::uint32_t src = w.source[b];
      gather_tile(in, src, 1, tile);
      gather_active(in, src, act.data());
      float* dist = w.values(b);
      BrickMask& fixed = w.fixed[b];
      std::uint32_t count = 0;
      in.bricks()[src].active.for_each_set([&](int n) {
        const int t = kGeom1.tile_of[n];
        const bool in_u = tile[t] < 0.0f;
        bool crossing = false;
        for (int a = 0; a < 3; ++a) {
          const int st = TileGeom<1>::kStride[a];
          crossing |= int((tile[t - st] < 0.0f) != in_u) | int((tile[t + st] < 0.0f) != in_u);
        }
        if (!crossing) return;
        dist[n] = static_cast<float>(subcell_distance(tile.data(), act.data(), t));
        fixed.set(n);
        ++count;
      });
      counts[i] = count;
    }
  });
  std::uint64_t total = 0;
  for (std::uint32_t c : counts) total += c;
  return total;
}

}  // namespace levelset::detail
