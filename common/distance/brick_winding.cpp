#include "distance/brick_winding.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "distance/voxel_winding.hpp"
#include "geometry/point_triangle.hpp"

namespace levelset {

namespace {

// Interior voxels (local 1..6 on every axis, so all six edges lie in the brick), nearest the
// brick centre first, ties by voxel number.
std::array<std::uint16_t, 216> make_candidates() {
  std::array<std::uint16_t, 216> c{};
  int k = 0;
  for (int n = 0; n < kBrickVoxels; ++n) {
    const Coord l = local_coord(n);
    if (l.x >= 1 && l.x <= 6 && l.y >= 1 && l.y <= 6 && l.z >= 1 && l.z <= 6)
      c[k++] = std::uint16_t(n);
  }
  auto dist2 = [](int n) {
    const Coord l = local_coord(n);
    return (2 * l.x - 7) * (2 * l.x - 7) + (2 * l.y - 7) * (2 * l.y - 7) +
           (2 * l.z - 7) * (2 * l.z - 7);
  };
  std::stable_sort(c.begin(), c.end(), [&](int a, int b) { return dist2(a) < dist2(b); });
  return c;
}
const std::array<std::uint16_t, 216> kCandidates = make_candidates();

// 6-neighbourhood dilation of a brick mask (word = z slice, bit = x + 8 y).
BrickMask dilate(const BrickMask& m) {
  constexpr std::uint64_t kNotX0 = 0xfefefefefefefefeull;  // bits with x > 0
  constexpr std::uint64_t kNotX7 = 0x7f7f7f7f7f7f7f7full;  // bits with x < 7
  BrickMask d;
  for (int z = 0; z < 8; ++z) {
    const std::uint64_t w = m.words[z];
    std::uint64_t r = w | ((w << 1) & kNotX0) | ((w >> 1) & kNotX7) | (w << 8) | (w >> 8);
    if (z > 0) r |= m.words[z - 1];
    if (z < 7) r |= m.words[z + 1];
    d.words[z] = r;
  }
  return d;
}

// `rejected`: candidates found too close to the surface (avoided on every tier).
int pick_reference(const BrickMask& near, const BrickMask& rejected) {
  const BrickMask d1 = dilate(near);
  const BrickMask d2 = dilate(d1);
  for (const BrickMask* avoid : {&d2, &d1, &near})
    for (std::uint16_t n : kCandidates)
      if (!avoid->test(n) && !rejected.test(n)) return n;
  return -1;
}

// The reference's winding number comes from the tree, evaluated at the world-space voxel
// centre, while the jumps use the grid-space copy of the mesh with the symbolic perturbation.
// A centre (nearly) on the surface -- e.g. on a box edge or corner that is off every grid line
// through it by a rounding error of (v - origin) / h, so that no crossed edge marks it `near` --
// gets an unreliable value there (the solid angle jumps across the surface; world and grid
// space may disagree on the side). The reference must therefore keep this distance (in voxels)
// from every triangle; listed triangles are all those within the brick's margin of it.
constexpr double kReferenceClearance = 0.05;

double distance_squared_to_surface(std::span<const GridTriangle> triangles,
                                   std::span<const std::uint32_t> ids, const Vec3d& p,
                                   double stop_below) {
  double best = std::numeric_limits<double>::infinity();
  for (std::uint32_t id : ids) {
    const GridTriangle& t = triangles[id];
    // Cheap bounding-box rejection first.
    double box = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double lo = std::min({t.corner[0][a], t.corner[1][a], t.corner[2][a]});
      const double hi = std::max({t.corner[0][a], t.corner[1][a], t.corner[2][a]});
      const double d = p[a] < lo ? lo - p[a] : (p[a] > hi ? p[a] - hi : 0.0);
      box += d * d;
    }
    if (box >= best) continue;
    best = std::min(best, closest_point_on_triangle(p, t.corner[0], t.corner[1],
                                                            t.corner[2])
                              .distance_squared);
    if (best < stop_below) break;
  }
  return best;
}

// rel[n] for the voxels n of the block [lo, lo + s)^3: the sum of jumps along the path
// r -> along x -> along y -> along z (r inside the block; the path stays in it).
void propagate(const BrickCrossings& x, const Coord& r, const Coord& lo, int s, int* rel) {
  // delta[w][line][e], line = l_u + 8 l_v with u = (w+1)%3, v = (w+2)%3.
  const auto& dx = x.delta[0][r.y + 8 * r.z];  // the reference row
  const int hx = lo.x + s, hy = lo.y + s, hz = lo.z + s;
  int row[8];
  row[r.x] = 0;
  for (int i = r.x + 1; i < hx; ++i) row[i] = row[i - 1] + dx[i - 1];
  for (int i = r.x - 1; i >= lo.x; --i) row[i] = row[i + 1] - dx[i];
  int slice[8][8];  // [y][x] at z = r.z
  for (int i = lo.x; i < hx; ++i) {
    const auto& col = x.delta[1][r.z + 8 * i];
    slice[r.y][i] = row[i];
    for (int j = r.y + 1; j < hy; ++j) slice[j][i] = slice[j - 1][i] + col[j - 1];
    for (int j = r.y - 1; j >= lo.y; --j) slice[j][i] = slice[j + 1][i] - col[j];
  }
  for (int j = lo.y; j < hy; ++j)
    for (int i = lo.x; i < hx; ++i) {
      const auto& col = x.delta[2][i + 8 * j];
      int w = slice[j][i];
      rel[local_index(i, j, r.z)] = w;
      for (int k = r.z + 1; k < hz; ++k) rel[local_index(i, j, k)] = (w += col[k - 1]);
      w = slice[j][i];
      for (int k = r.z - 1; k >= lo.z; --k) rel[local_index(i, j, k)] = (w -= col[k]);
    }
}

// Winding number jump from local voxel m to its neighbour m + step e_a.
int jump(const BrickCrossings& x, const Coord& m, int a, int step) {
  const int u = (a + 1) % 3, v = (a + 2) % 3;
  const auto& line = x.delta[a][m[u] + 8 * m[v]];
  return step > 0 ? line[m[a]] : -line[m[a] - 1];
}

double query(const BrickWindingContext& c, const Coord& brick, int n, std::uint64_t& queries) {
  const Coord g = brick_origin(brick) + local_coord(n);
  ++queries;
  const Vec3d p =
      c.frame.origin + Vec3d{double(g.x), double(g.y), double(g.z)} * c.frame.voxel_size;
  return winding_number(c.tree.get(), p, c.beta);
}

// Cone-modelled voxels whose value lies this close to 1/2 get a direct query: the model's
// error (trilinear, plus the tree's at the corners) could flip them. Measured on CGAL's
// b9_mesh and elephant-with-holes, subdivided, R = 128: fewer voxels disagree with the exact
// winding number than with a direct query per voxel near the rims.
constexpr double kAmbiguousBand = 0.02;

struct Adaptive {
  const BrickCrossings& x;
  const Coord& brick;
  std::span<const OpenSegment> rims;
  const BrickWindingContext& context;
  std::uint64_t& queries;
  std::array<double, kBrickVoxels> value{};
  BrickMask known;
  BrickMask inside;
  int rel[kBrickVoxels];

  double direct(int n) {
    if (!known.test(n)) {
      value[n] = query(context, brick, n, queries);
      known.set(n);
    }
    return value[n];
  }

  // Direct values of the listed voxels not yet known, in one tree traversal (winding_numbers:
  // the same values as one query each). Voxels on the surface are left to surface_value.
  void prefetch(std::span<const int> voxels) {
    std::array<int, kBrickVoxels> wanted;
    std::size_t count = 0;
    for (const int n : voxels) {
      if (known.test(n) || x.on_surface.test(n)) continue;
      known.set(n);  // each once, even if listed twice
      wanted[count++] = n;
    }
    if (count == 0) return;
    std::array<double, kBrickVoxels> values;
    voxel_winding_numbers(context.tree.get(), context.frame, brick_origin(brick), std::span(wanted.data(), count),
                          context.beta, values);
    for (std::size_t i = 0; i < count; ++i) value[std::size_t(wanted[i])] = values[i];
    queries += count;
  }

  // A voxel exactly on the surface: a neighbour off the surface plus the exact jump.
  double surface_value(int n) {
    const Coord c = local_coord(n);
    for (int a = 0; a < 3; ++a)
      for (int step : {-1, 1}) {
        Coord m = c;
        m[a] += step;
        if (m[a] < 0 || m[a] >= kBrickDim) continue;
        const int k = local_index(m.x, m.y, m.z);
        if (!x.on_surface.test(k)) return direct(k) + jump(x, m, a, -step);
      }
    return direct(n);
  }
  double value_of(int n) { return x.on_surface.test(n) ? surface_value(n) : direct(n); }

  // An open edge within s/2 voxels of the block: the continuous part is not smooth there.
  bool rim_near(const Coord& lo, int s) const {
    const double r = 0.5 * double(s);
    const Vec3d blo{lo.x - r, lo.y - r, lo.z - r};
    const Vec3d bhi{lo.x + s - 1 + r, lo.y + s - 1 + r, lo.z + s - 1 + r};
    for (const OpenSegment& e : rims)
      if (segment_meets_box(e[0], e[1], blo, bhi)) return true;
    return false;
  }

  // The inside bits of the block from its modelled values. Voxels exactly on the surface get a
  // direct off-surface neighbour's value plus the exact jump, as on the direct path (a flat
  // sheet's model sits at 1/2 there, and a modelled neighbour may itself lie on the surface
  // unflagged, where the model follows no side). `checked`: voxels modelled within
  // kAmbiguousBand of 1/2 are queried directly.
  void write_inside(const Coord& lo, int s, const double* modelled, bool checked) {
    if (checked) {
      std::array<int, kBrickVoxels> ambiguous;
      std::size_t count = 0;
      for (int k = lo.z; k < lo.z + s; ++k)
        for (int j = lo.y; j < lo.y + s; ++j)
          for (int i = lo.x; i < lo.x + s; ++i) {
            const int n = local_index(i, j, k);
            if (std::abs(modelled[n] - 0.5) < kAmbiguousBand) ambiguous[count++] = n;
          }
      prefetch(std::span(ambiguous.data(), count));
    }
    for (int k = lo.z; k < lo.z + s; ++k)
      for (int j = lo.y; j < lo.y + s; ++j)
        for (int i = lo.x; i < lo.x + s; ++i) {
          const int n = local_index(i, j, k);
          double w = modelled[n];
          if (x.on_surface.test(n))
            w = surface_value(n);
          else if (checked && std::abs(w - 0.5) < kAmbiguousBand)
            w = direct(n);
          inside.assign(n, w > 0.5);
        }
  }

  // Models w over the block [lo, lo + s)^3 as known_part[n] (exact, per voxel; none: 0) + the
  // rest at ref + the integer jumps `jumps` along the path from ref + the trilinear
  // interpolation of the corners' residuals. Accepted (inside bits written) when a direct query
  // at the block centre agrees within kAdaptiveTolerance.
  bool model_block(const Coord& lo, int s, int ref, const BrickCrossings& jumps,
                   const double* known_part) {
    auto corner = [&](int bits) {
      return local_index(lo.x + ((bits & 1) ? s - 1 : 0), lo.y + ((bits & 2) ? s - 1 : 0),
                         lo.z + ((bits & 4) ? s - 1 : 0));
    };
    auto known_at = [&](int n) { return known_part ? known_part[n] : 0.0; };
    auto in_block = [&](const Coord& m) {
      return m.x >= lo.x && m.x < lo.x + s && m.y >= lo.y && m.y < lo.y + s && m.z >= lo.z &&
             m.z < lo.z + s;
    };
    // w - known at voxel n. On the surface, with a known part: an off-surface neighbour in the
    // block plus the exact jump of w - known, which has no singularity there (w itself may
    // change by much more than its jump over one voxel near a rim).
    auto remainder = [&](int n) {
      if (known_part && x.on_surface.test(n)) {
        const Coord c = local_coord(n);
        for (int a = 0; a < 3; ++a)
          for (int step : {-1, 1}) {
            Coord m = c;
            m[a] += step;
            const int k = local_index(m.x, m.y, m.z);
            if (in_block(m) && !x.on_surface.test(k))
              return direct(k) - known_part[k] + jump(jumps, m, a, -step);
          }
      }
      return value_of(n) - known_at(n);
    };
    if (ref < 0 || jumps.on_surface.test(ref)) ref = corner(0);
    const int c = s / 2;
    const int centre = local_index(lo.x + c, lo.y + c, lo.z + c);
    {
      const int needed[10] = {ref,       centre,    corner(0), corner(1), corner(2),
                              corner(3), corner(4), corner(5), corner(6), corner(7)};
      prefetch(needed);
    }
    propagate(jumps, local_coord(ref), lo, s, rel);
    const double wr = remainder(ref);
    double smooth[8];
    for (int b = 0; b < 8; ++b) smooth[b] = remainder(corner(b)) - (wr + rel[corner(b)]);
    auto model = [&](int i, int j, int k) {
      const double tx = double(i - lo.x) / (s - 1), ty = double(j - lo.y) / (s - 1),
                   tz = double(k - lo.z) / (s - 1);
      double m = 0.0;
      for (int b = 0; b < 8; ++b)
        m += smooth[b] * ((b & 1) ? tx : 1 - tx) * ((b & 2) ? ty : 1 - ty) *
             ((b & 4) ? tz : 1 - tz);
      const int n = local_index(i, j, k);
      return wr + rel[n] + m + known_at(n);
    };
    if (std::abs(remainder(centre) + known_at(centre) - model(lo.x + c, lo.y + c, lo.z + c)) >
        kAdaptiveTolerance)
      return false;
    double modelled[kBrickVoxels];
    for (int k = lo.z; k < lo.z + s; ++k)
      for (int j = lo.y; j < lo.y + s; ++j)
        for (int i = lo.x; i < lo.x + s; ++i) modelled[local_index(i, j, k)] = model(i, j, k);
    write_inside(lo, s, modelled, known_part != nullptr);
    return true;
  }

  // Open edges near the block: subtract their cone's winding number, exact per voxel
  // (rim_cone.hpp), so that what remains is smooth there apart from integer jumps -- those of
  // the surface and of the reversed cone. False when no cone applies (no apex keeps its
  // segments clear, or a voxel lies exactly on a cone triangle) or the model fails.
  bool model_with_cone(const Coord& lo, int s, int ref) {
    const double half = 0.5 * double(s);
    const std::optional<RimCone> cone = make_rim_cone(rims, lo, s, half, half);
    if (!cone) return false;
    const Coord origin = brick_origin(brick);
    const std::vector<GridTriangle> reversed = reversed_cone_triangles(*cone, origin);
    std::vector<std::uint32_t> ids(reversed.size());
    for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = std::uint32_t(i);
    LineSet lines{0, 0, 0};
    for (int w = 0; w < 3; ++w) {
      const int u = (w + 1) % 3, v = (w + 2) % 3;
      for (int jv = lo[v]; jv < lo[v] + s; ++jv)
        for (int ju = lo[u]; ju < lo[u] + s; ++ju) lines[w] |= std::uint64_t{1} << (ju + 8 * jv);
    }
    BrickCrossings jumps = x;
    jumps.on_surface = BrickMask{};
    brick_crossings(reversed, ids, brick, lines, jumps);
    for (int k = lo.z; k < lo.z + s; ++k)
      for (int j = lo.y; j < lo.y + s; ++j)
        for (int i = lo.x; i < lo.x + s; ++i)
          if (jumps.on_surface.test(local_index(i, j, k))) return false;  // on a cone triangle
    double known_part[kBrickVoxels];
    cone_winding_block(*cone, lo, s, known_part);
    jumps.on_surface = x.on_surface;
    return model_block(lo, s, ref, jumps, known_part);
  }

  void solve(const Coord& lo, int s, int ref) {
    if (s == 1) {
      const int n = local_index(lo.x, lo.y, lo.z);
      inside.assign(n, value_of(n) > 0.5);
      return;
    }
    auto corner = [&](int bits) {
      return local_index(lo.x + ((bits & 1) ? s - 1 : 0), lo.y + ((bits & 2) ? s - 1 : 0),
                         lo.z + ((bits & 4) ? s - 1 : 0));
    };
    if (s == 2) {  // every voxel is a corner
      for (int b = 0; b < 8; ++b) inside.assign(corner(b), value_of(corner(b)) > 0.5);
      return;
    }
    // No open edge within half the block's size: the jumps are path independent in the block
    // and the rest of w is smooth there. Otherwise the same after subtracting the cone.
    if (rim_near(lo, s) ? model_with_cone(lo, s, ref) : model_block(lo, s, ref, x, nullptr))
      return;
    const int half = s / 2;
    for (int b = 0; b < 8; ++b) {
      const Coord child{lo.x + ((b & 1) ? half : 0), lo.y + ((b & 2) ? half : 0),
                        lo.z + ((b & 4) ? half : 0)};
      solve(child, half, corner(b));
    }
  }
};

}  // namespace

BrickMask inside_from_reference(std::span<const GridTriangle> triangles,
                                std::span<const std::uint32_t> ids, const Coord& brick,
                                const BrickWindingContext& context, BrickCrossings& x,
                                std::uint64_t& queries) {
  // Lines along z everywhere; along x and y only those of the path from the reference (its
  // x-row, the y-lines of its z-slice). A reference found next to a crossing on them is
  // replaced (those crossings now count in `near`), up to kMaxReferenceTries times.
  // A reference too close to the surface (kReferenceClearance) is rejected and replaced, up to
  // kMaxClearanceTries times; failing that, the clearest candidate tried is used.
  constexpr int kMaxReferenceTries = 4;
  constexpr int kMaxClearanceTries = 64;
  x = BrickCrossings{};
  LineSet done{0, 0, ~0ull};
  brick_crossings(triangles, ids, brick, done, x);
  const Coord o = brick_origin(brick);
  constexpr double kClear2 = kReferenceClearance * kReferenceClearance;
  BrickMask rejected;
  int r = kCandidates[0];
  int best = -1;
  double best_d2 = -1.0;
  // The lines of the path from reference r (computed once each).
  auto add_path_lines = [&](int r) {
    const Coord c = local_coord(r);
    LineSet add{0, 0, 0};
    add[0] = (std::uint64_t{1} << (c.y + 8 * c.z)) & ~done[0];
    for (int i = 0; i < kBrickDim; ++i) add[1] |= std::uint64_t{1} << (c.z + 8 * i);
    add[1] &= ~done[1];
    if (add[0] | add[1]) {
      brick_crossings(triangles, ids, brick, add, x);
      done[0] |= add[0];
      done[1] |= add[1];
    }
  };
  for (int attempt = 0, clearance_tries = 0; attempt < kMaxReferenceTries;) {
    const int pick = pick_reference(x.near, rejected);
    if (pick < 0) {  // every candidate rejected: the clearest one tried
      if (best >= 0) r = best;
      break;
    }
    r = pick;
    const Coord c = local_coord(r);
    const Vec3d p{double(o.x + c.x), double(o.y + c.y), double(o.z + c.z)};
    const double d2 = distance_squared_to_surface(triangles, ids, p, kClear2);
    if (d2 < kClear2) {
      if (d2 > best_d2) {
        best_d2 = d2;
        best = r;
      }
      rejected.set(r);
      if (++clearance_tries < kMaxClearanceTries) continue;
      r = best;
    }
    ++attempt;
    add_path_lines(r);
    if (!x.near.test(r)) break;
  }
  add_path_lines(r);
  const double w_ref = query(context, brick, r, queries);
  int rel[kBrickVoxels];
  propagate(x, local_coord(r), Coord{0, 0, 0}, kBrickDim, rel);
  BrickMask inside;
  for (int n = 0; n < kBrickVoxels; ++n)
    if (w_ref + rel[n] > 0.5) inside.set(n);
  return inside;
}

std::array<int, kBrickVoxels> relative_winding(std::span<const GridTriangle> triangles,
                                               std::span<const std::uint32_t> ids,
                                               const Coord& brick, BrickCrossings& x) {
  x = BrickCrossings{};
  LineSet lines{1, 0, ~0ull};  // x: the line (y, z) = (0, 0); y: the lines (z, x) = (0, i)
  for (int i = 0; i < kBrickDim; ++i) lines[1] |= std::uint64_t{1} << (8 * i);
  brick_crossings(triangles, ids, brick, lines, x);
  std::array<int, kBrickVoxels> rel;
  propagate(x, Coord{0, 0, 0}, Coord{0, 0, 0}, kBrickDim, rel.data());
  return rel;
}

BrickMask inside_adaptive(const BrickCrossings& crossings, const Coord& brick,
                          std::span<const OpenSegment> rims, const BrickWindingContext& context,
                          std::uint64_t& queries) {
  Adaptive a{crossings, brick, rims, context, queries, {}, {}, {}, {}};
  a.solve(Coord{0, 0, 0}, kBrickDim, -1);
  return a.inside;
}

}  // namespace levelset
