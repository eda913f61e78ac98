#include "distance/rim_cone.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "distance/solid_angle.hpp"
#include "grid/coord.hpp"

namespace levelset {

bool segment_meets_box(const Vec3d& a, const Vec3d& b, const Vec3d& lo, const Vec3d& hi) {
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 3; ++k) {
    const double d = b[k] - a[k];
    if (d == 0.0) {
      if (a[k] < lo[k] || a[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - a[k]) / d, tb = (hi[k] - a[k]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

namespace {

// How far the apex lies from the block centre (grid units): far enough that every apex
// segment runs nearly along the chosen direction.
constexpr double kApexDistance = 4096.0;

bool lexicographic_less(const Vec3d& a, const Vec3d& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

// The ends of N's chains: vertices whose incoming and outgoing uses do not cancel.
std::vector<Vec3d> chain_ends(std::span<const OpenSegment> segments) {
  std::vector<std::pair<Vec3d, int>> uses;
  uses.reserve(2 * segments.size());
  for (const OpenSegment& e : segments) {
    uses.push_back({e[0], -1});
    uses.push_back({e[1], +1});
  }
  std::sort(uses.begin(), uses.end(),
            [](const auto& a, const auto& b) { return lexicographic_less(a.first, b.first); });
  std::vector<Vec3d> ends;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    int net = 0;
    for (; j < uses.size() && uses[j].first == uses[i].first; ++j) net += uses[j].second;
    if (net != 0) ends.push_back(uses[i].first);
    i = j;
  }
  return ends;
}

// The segments reordered so that each continues the one before where it can (b of one = a of
// the next): cone_winding_block then computes a shared end's vector once. Greedy, O(N^2) for
// the few tens of segments near a block.
void order_as_chains(std::vector<OpenSegment>& segments) {
  const std::size_t n = segments.size();
  for (std::size_t i = 0; i + 1 < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if (segments[j][0] == segments[i][1]) {
        std::swap(segments[i + 1], segments[j]);
        break;
      }
}

// 26 directions, slightly off the grid's symmetry planes so that no cone triangle lies in a
// grid plane by construction.
std::array<Vec3d, 26> make_directions() {
  std::array<Vec3d, 26> d{};
  int k = 0;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) {
        if (x == 0 && y == 0 && z == 0) continue;
        const Vec3d v{x + 0.0123, y + 0.0371, z + 0.0219};
        d[k++] = v / length(v);
      }
  // Axis directions first: their cones cross the fewest lines of the block.
  std::stable_sort(d.begin(), d.end(), [](const Vec3d& a, const Vec3d& b) {
    auto axisness = [](const Vec3d& v) {
      return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    };
    return axisness(a) > axisness(b);
  });
  return d;
}
const std::array<Vec3d, 26> kDirections = make_directions();

}  // namespace

std::optional<RimCone> make_rim_cone(std::span<const OpenSegment> rims, const Coord& lo, int s,
                                     double reach, double clearance) {
  const Vec3d blo{double(lo.x), double(lo.y), double(lo.z)};
  const Vec3d bhi = blo + Vec3d{double(s - 1), double(s - 1), double(s - 1)};
  const Vec3d grow_reach{reach, reach, reach}, grow_clear{clearance, clearance, clearance};
  RimCone cone;
  for (const OpenSegment& e : rims)
    if (segment_meets_box(e[0], e[1], blo - grow_reach, bhi + grow_reach))
      cone.segments.push_back(e);
  if (cone.segments.empty()) return std::nullopt;
  order_as_chains(cone.segments);
  const std::vector<Vec3d> ends = chain_ends(cone.segments);
  const Vec3d centre = 0.5 * (blo + bhi);
  for (const Vec3d& d : kDirections) {
    const Vec3d apex = centre + kApexDistance * d;
    bool clear = true;
    for (const Vec3d& end : ends)
      if (segment_meets_box(end, apex, blo - grow_clear, bhi + grow_clear)) {
        clear = false;
        break;
      }
    if (clear) {
      cone.apex = apex;
      return cone;
    }
  }
  return std::nullopt;
}

double cone_winding(const RimCone& cone, const Vec3d& p) {
  double omega = 0.0;
  for (const OpenSegment& e : cone.segments)
    omega += triangle_solid_angle(p, e[0], e[1], cone.apex);
  return omega / (4.0 * std::numbers::pi);
}


#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
void cone_winding_block(const RimCone& cone, const Coord& lo, int s, double* out) {
  const int count = s * s * s;
  double px[kBrickVoxels], py[kBrickVoxels], pz[kBrickVoxels], omega[kBrickVoxels];
  for (int k = 0, n = 0; k < s; ++k)
    for (int j = 0; j < s; ++j)
      for (int i = 0; i < s; ++i, ++n) {
        px[n] = double(lo.x + i);
        py[n] = double(lo.y + j);
        pz[n] = double(lo.z + k);
        omega[n] = 0.0;
      }
  // Per voxel: vertex - p and its length, for the apex (once) and for a segment's two ends (the
  // end of one segment is the start of the next along a chain: swapped, not recomputed). The
  // same operations as triangle_solid_angle(p, a, b, apex) term by term.
  struct Ends {
    double x[kBrickVoxels], y[kBrickVoxels], z[kBrickVoxels], l[kBrickVoxels];
    void compute(const Vec3d& v, const double* px, const double* py, const double* pz, int count) {
      for (int n = 0; n < count; ++n) {
        x[n] = v.x - px[n], y[n] = v.y - py[n], z[n] = v.z - pz[n];
        l[n] = std::sqrt(x[n] * x[n] + y[n] * y[n] + z[n] * z[n]);
      }
    }
  };
  Ends apex, first, second;
  apex.compute(cone.apex, px, py, pz, count);
  Ends* a_ends = &first;
  Ends* b_ends = &second;
  const OpenSegment* previous = nullptr;
  for (const OpenSegment& e : cone.segments) {
    if (previous != nullptr && (*previous)[1] == e[0]) std::swap(a_ends, b_ends);
    else a_ends->compute(e[0], px, py, pz, count);
    b_ends->compute(e[1], px, py, pz, count);
    previous = &e;
    const Ends& A = *a_ends;
    const Ends& B = *b_ends;
    for (int n = 0; n < count; ++n) {
      const double xx = A.x[n], xy = A.y[n], xz = A.z[n];
      const double yx = B.x[n], yy = B.y[n], yz = B.z[n];
      const double zx = apex.x[n], zy = apex.y[n], zz = apex.z[n];
      const double det = xx * (yy * zz - yz * zy) + xy * (yz * zx - yx * zz) +
                         xz * (yx * zy - yy * zx);
      const double lx = A.l[n], ly = B.l[n], lz = apex.l[n];
      const double denom = lx * ly * lz + (xx * yx + xy * yy + xz * yz) * lz +
                           (yx * zx + yy * zy + yz * zz) * lx + (zx * xx + zy * xy + zz * xz) * ly;
      omega[n] += 2.0 * polynomial_atan2(det, denom);
    }
  }
  for (int k = 0, n = 0; k < s; ++k)
    for (int j = 0; j < s; ++j)
      for (int i = 0; i < s; ++i, ++n)
        out[local_index(lo.x + i, lo.y + j, lo.z + k)] = omega[n] / (4.0 * std::numbers::pi);
}

std::vector<GridTriangle> reversed_cone_triangles(const RimCone& cone, const Coord& origin) {
  const Vec3d o{double(origin.x), double(origin.y), double(origin.z)};
  std::vector<GridTriangle> out;
  out.reserve(cone.segments.size());
  const Vec3d apex = cone.apex + o;
  for (const OpenSegment& e : cone.segments)
    out.push_back(make_grid_triangle(e[1] + o, e[0] + o, apex));
  return out;
}

}  // namespace levelset
