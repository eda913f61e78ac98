#include "grid/topology_guard.hpp"

#include <algorithm>
#include <cmath>
#include <array>
#include <cstdlib>
#include <deque>
#include <optional>
#include <string>
#include <unordered_map>

#include "core/error.hpp"
#include "grid/band_accessor.hpp"
#include "grid/for_each_active_parallel.hpp"

namespace levelset {

namespace {

struct Neighbourhood {
  std::array<std::array<int, 26>, 27> adj26{};
  std::array<int, 27> n26{};
  std::array<std::array<int, 6>, 27> adj6{};
  std::array<int, 27> n6{};
  Neighbourhood() {
    for (int a = 0; a < 27; ++a) {
      const int ax = a % 3, ay = (a / 3) % 3, az = a / 9;
      for (int b = 0; b < 27; ++b) {
        if (b == a) continue;
        const int dx = std::abs(b % 3 - ax), dy = std::abs((b / 3) % 3 - ay), dz = std::abs(b / 9 - az);
        if (std::max({dx, dy, dz}) > 1) continue;
        adj26[a][n26[a]++] = b;
        if (dx + dy + dz == 1) adj6[a][n6[a]++] = b;
      }
    }
  }
};

// Components of `set` (bit per neighbourhood index, centre 13 excluded) under 26- or
// 6-adjacency; for 6-adjacency only voxels of the 18-neighbourhood count, and only the
// components holding a face neighbour of the centre.
int neighbourhood_components(std::uint32_t set, bool six) {
  static const Neighbourhood nb;
  set &= ~(1u << 13);
  if (six) {
    for (int a = 0; a < 27; ++a) {
      const int dx = std::abs(a % 3 - 1), dy = std::abs((a / 3) % 3 - 1), dz = std::abs(a / 9 - 1);
      if (dx + dy + dz == 3) set &= ~(1u << a);  // corners: not in the 18-neighbourhood
    }
  }
  int count = 0;
  std::uint32_t seen = 0;
  std::array<int, 27> stack{};
  for (int start = 0; start < 27; ++start) {
    if (!((set >> start) & 1u) || ((seen >> start) & 1u)) continue;
    if (six && !(start == 4 || start == 10 || start == 12 || start == 14 || start == 16 || start == 22)) continue;
    ++count;
    int top = 0;
    stack[std::size_t(top++)] = start;
    seen |= 1u << start;
    while (top > 0) {
      const int a = stack[std::size_t(--top)];
      const int n = six ? nb.n6[std::size_t(a)] : nb.n26[std::size_t(a)];
      for (int k = 0; k < n; ++k) {
        const int b = six ? nb.adj6[std::size_t(a)][std::size_t(k)] : nb.adj26[std::size_t(a)][std::size_t(k)];
        if (((set >> b) & 1u) && !((seen >> b) & 1u)) {
          seen |= 1u << b;
          stack[std::size_t(top++)] = b;
        }
      }
    }
  }
  return count;
}

}  // namespace

bool simple_voxel(std::uint32_t inside) {
  const std::uint32_t outside = ~inside & ((1u << 27) - 1u);
  return neighbourhood_components(inside, false) == 1 && neighbourhood_components(outside, true) == 1 &&
         neighbourhood_components(inside, true) == 1 && neighbourhood_components(outside, false) == 1;
}

bool cutting_voxel(std::uint32_t inside) {
  const std::uint32_t outside = ~inside & ((1u << 27) - 1u);
  return neighbourhood_components(outside, true) == 1 &&
         neighbourhood_components(outside, false) == 1;
}

namespace {

// Whether one of the 12 faces through the centre voxel (sign `centre`, neighbours `inside`)
// has alternating signs: the marching cubes decide those by value (asymptotic decider), so
// a flip that makes or unmakes one is not covered by the fixed-adjacency simple test.
bool ambiguous_face_at_centre(std::uint32_t inside, bool centre) {
  auto in = [&](int dx, int dy, int dz) {
    return (dx | dy | dz) == 0 ? centre : bool((inside >> ((dz + 1) * 9 + (dy + 1) * 3 + dx + 1)) & 1u);
  };
  static constexpr int kPlanes[3][2][3] = {{{1, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {0, 0, 1}}, {{0, 1, 0}, {0, 0, 1}}};
  for (const auto& plane : kPlanes)
    for (int sa = -1; sa <= 1; sa += 2)
      for (int sb = -1; sb <= 1; sb += 2) {
        const int ax = sa * plane[0][0], ay = sa * plane[0][1], az = sa * plane[0][2];
        const int bx = sb * plane[1][0], by = sb * plane[1][1], bz = sb * plane[1][2];
        const bool a = in(ax, ay, az), b = in(bx, by, bz), d = in(ax + bx, ay + by, az + bz);
        if (d == centre && a != centre && b != centre) return true;
      }
  return false;
}

// Keeps the topology of `before`'s inside set: `values` (active-voxel order of `after`, a band
// on the same grid) may flip the sign of a voxel of `before` only where the flip is simple;
// flips are tested one by one from a queue in brick order, and a refused one is tested again
// only after one of its 26 neighbours flipped (nothing else changes its test): O(candidates)
// tests (rounds over all of them were quadratic along a retracting rod). The others keep
// their old sign at +-eps. Serial (the flips are few, all at the front): deterministic.
// Voxels that are not candidates have `after`'s sign in the tests (a voxel inactive in
// `after` keeps that sign whatever is decided). A candidate with a face neighbour inactive in
// `after` on its new side cannot keep its old sign without breaking the band invariant there
// (`after`'s band left it: a component smaller than the band vanished in one step), so its
// flip is taken (counted in forced).
struct KeptTopology {
  std::uint64_t refused = 0, forced = 0;
};
KeptTopology keep_topology(const NarrowBand& before, const NarrowBand& after,
                           std::vector<float>& values, double eps,
                           const std::function<bool(const Coord&)>& free,
                           const std::function<bool(const Coord&)>& pinned,
                           const std::function<bool(const Coord&)>& cuttable,
                           const ProgressHook& progress) {
  struct Candidate {
    Coord c;
    std::size_t slot;
  };
  // Sign changes, found per brick (TBB) and kept in brick order.
  std::vector<std::vector<Candidate>> per_brick(after.brick_count());
  for_each_active_parallel(after, before, 16, [&](BandAccessor& acc, std::uint32_t b, const Coord& c, float, std::size_t i) {
    if ((values[i] < 0.0f) != acc.is_inside(c)) per_brick[b].push_back({c, i});
  });
  std::vector<Candidate> pending;
  for (const auto& list : per_brick) pending.insert(pending.end(), list.begin(), list.end());
  KeptTopology kept;
  if (pending.empty()) return kept;
  BandAccessor old_acc(before), new_acc(after);
  // must_flip[k]: a face neighbour inactive in `after` lies on the candidate's new side.
  std::vector<std::uint8_t> must_flip(pending.size(), 0);
  static constexpr Coord kFaces[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (std::size_t k = 0; k < pending.size(); ++k) {
    const bool to_inside = values[pending[k].slot] < 0.0f;
    for (const Coord& f : kFaces) {
      const Coord n = pending[k].c + f;
      if (!new_acc.probe(n) && new_acc.is_inside(n) == to_inside) must_flip[k] = 1;
    }
  }
  auto key = [](const Coord& c) {
    return (std::uint64_t(std::uint32_t(c.x) & 0x1fffffu) << 42) | (std::uint64_t(std::uint32_t(c.y) & 0x1fffffu) << 21) |
           std::uint64_t(std::uint32_t(c.z) & 0x1fffffu);
  };
  std::unordered_map<std::uint64_t, std::size_t> candidate_at;  // coordinate -> index in pending
  candidate_at.reserve(pending.size());
  for (std::size_t k = 0; k < pending.size(); ++k) candidate_at.emplace(key(pending[k].c), k);
  std::vector<std::uint8_t> flipped(pending.size(), 0), queued(pending.size(), 1);
  auto inside_now = [&](const Coord& c) {
    const auto it = candidate_at.find(key(c));
    if (it != candidate_at.end()) return flipped[it->second] ? values[pending[it->second].slot] < 0.0f : old_acc.is_inside(c);
    return new_acc.is_inside(c);
  };
  std::deque<std::size_t> queue;
  for (std::size_t k = 0; k < pending.size(); ++k) queue.push_back(k);
  std::uint64_t tests = 0;
  while (!queue.empty()) {
    const std::size_t k = queue.front();
    queue.pop_front();
    queued[k] = 0;
    if ((++tests & 0xffff) == 0) progress.check("topology guard");
    const Candidate& cand = pending[k];
    std::uint32_t inside = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if ((dx | dy | dz) != 0 && inside_now(cand.c + Coord{dx, dy, dz}))
            inside |= 1u << ((dz + 1) * 9 + (dy + 1) * 3 + dx + 1);
    const bool to_inside = values[cand.slot] < 0.0f;
    if (!to_inside && pinned && !must_flip[k]) {
      auto in_at = [&](int dx, int dy, int dz) { return bool((inside >> ((dz + 1) * 9 + (dy + 1) * 3 + dx + 1)) & 1u); };
      const bool thin = (!in_at(-1, 0, 0) && !in_at(1, 0, 0)) || (!in_at(0, -1, 0) && !in_at(0, 1, 0)) ||
                        (!in_at(0, 0, -1) && !in_at(0, 0, 1));
      if (thin && pinned(cand.c)) continue;
    }
    const bool keeps = simple_voxel(inside) && !ambiguous_face_at_centre(inside, !to_inside) &&
                       !ambiguous_face_at_centre(inside, to_inside);
    const bool cuts = !keeps && !to_inside && cuttable && cutting_voxel(inside) &&
                      !ambiguous_face_at_centre(inside, true) &&
                      !ambiguous_face_at_centre(inside, false) && cuttable(cand.c);
    if (!keeps && !cuts && !(free && free(cand.c))) {
      if (!must_flip[k]) continue;
      ++kept.forced;
    }
    flipped[k] = 1;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = candidate_at.find(key(cand.c + Coord{dx, dy, dz}));
          if (it == candidate_at.end() || flipped[it->second] || queued[it->second]) continue;
          queued[it->second] = 1;
          queue.push_back(it->second);
        }
  }
  for (std::size_t k = 0; k < pending.size(); ++k)
    if (!flipped[k]) {
      values[pending[k].slot] = float(old_acc.is_inside(pending[k].c) ? -eps : eps);
      ++kept.refused;
    }
  return kept;
}

// The marching cubes join or separate the two inside corners of an ambiguous face (signs
// alternating round it) by the asymptotic decider: joined when v00 v11 > v10 v01 for the
// inside diagonal (00, 11). A change of values without any sign change can therefore add a
// handle or cut a thin part (measured: the snaps grew the bunny's ear handles with every
// sign change simple). So where a face is ambiguous with the same signs before and after,
// its decision must not change: the four corners of a face whose decision changed go back
// to their values in `before` (same signs), repeated until no face changes (each round only
// restores old values, so it ends). Returns the number of voxels restored. Serial over the
// few ambiguous faces: deterministic.
std::uint64_t keep_face_decisions(const NarrowBand& before, const NarrowBand& after, std::vector<float>& values) {
  static constexpr Coord kAxes[3][2] = {{{1, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {0, 0, 1}}, {{0, 1, 0}, {0, 0, 1}}};
  // joined(): +1 inside diagonal joined, -1 separated, 0 not ambiguous.
  auto decision = [](double v00, double v10, double v11, double v01) {
    const bool i00 = v00 < 0, i10 = v10 < 0, i11 = v11 < 0, i01 = v01 < 0;
    if (i00 != i11 || i10 != i01 || i00 == i10) return 0;
    const double inside = i00 ? v00 * v11 : v10 * v01, outside = i00 ? v10 * v01 : v00 * v11;
    return inside > outside ? 1 : -1;
  };
  struct Face {
    std::array<std::size_t, 4> slot;
    std::array<double, 4> old;
    int old_decision;
  };
  // Only faces ambiguous both before and after matter, and a corner of a face ambiguous after
  // has an edge neighbour of the other sign, so it lies within about a voxel of the front:
  // the voxels farther than 1.5 voxels after are skipped. Restoring keeps every sign, so a
  // face whose signs do not alternate now never will. Collected per brick (TBB), kept in
  // brick order.
  const float near = float(1.5 * after.voxel_size());
  std::vector<std::vector<Face>> per_brick(after.brick_count());
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(after.brick_count()), 16),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
    BandAccessor old_acc(before), acc(after);
    auto slot_of = [&](const Coord& c) -> std::size_t {
      const std::uint32_t b = acc.locate(brick_of(c));
      if (b == kNoBrick) return std::size_t(-1);
      const Brick& br = after.bricks()[b];
      const int n = local_index(c);
      return br.active.test(n) ? br.value_offset + br.slot(n) : std::size_t(-1);
    };
    for (std::uint32_t b = r.begin(); b != r.end(); ++b) {
      std::size_t slot = after.bricks()[b].value_offset;
      after.for_each_active_in_brick(b, [&](const Coord& c, float) {
        const std::size_t self = slot++;
        if (std::abs(values[self]) > near) return;
        for (const auto& axes : kAxes) {
          const std::array<Coord, 4> corner{c, c + axes[0], c + axes[0] + axes[1], c + axes[1]};
          Face f;
          f.slot[0] = self;
          f.slot[2] = slot_of(corner[2]);  // the diagonal first: it rules out most faces
          if (f.slot[2] == std::size_t(-1) || (values[self] < 0.0f) != (values[f.slot[2]] < 0.0f)) continue;
          f.slot[1] = slot_of(corner[1]);
          f.slot[3] = slot_of(corner[3]);
          if (f.slot[1] == std::size_t(-1) || f.slot[3] == std::size_t(-1) ||
              decision(values[f.slot[0]], values[f.slot[1]], values[f.slot[2]], values[f.slot[3]]) == 0)
            continue;
          bool ok = true;
          for (int k = 0; k < 4 && ok; ++k) {
            const std::optional<float> v = old_acc.probe(corner[std::size_t(k)]);
            // Only faces whose four signs are unchanged: restoring then keeps every sign (a
            // face whose corners all flipped alternates too, about the other diagonal).
            ok = v.has_value() && ((*v < 0.0f) == (values[f.slot[std::size_t(k)]] < 0.0f));
            if (ok) f.old[std::size_t(k)] = double(*v);
          }
          if (!ok) continue;
          f.old_decision = decision(f.old[0], f.old[1], f.old[2], f.old[3]);
          if (f.old_decision != 0) per_brick[b].push_back(f);
        }
      });
    }
  });
  std::vector<Face> faces;
  for (const auto& list : per_brick) faces.insert(faces.end(), list.begin(), list.end());
  std::uint64_t restored = 0;
  for (bool changed = true; changed;) {
    changed = false;
    for (const Face& f : faces) {
      const std::array<double, 4> v{double(values[f.slot[0]]), double(values[f.slot[1]]), double(values[f.slot[2]]),
                                    double(values[f.slot[3]])};
      const int d = decision(v[0], v[1], v[2], v[3]);
      if (d == 0 || d == f.old_decision) continue;  // signs changed (a simple flip), or same decision
      for (int k = 0; k < 4; ++k) {
        if (values[f.slot[std::size_t(k)]] != float(f.old[std::size_t(k)])) {
          values[f.slot[std::size_t(k)]] = float(f.old[std::size_t(k)]);
          ++restored;
          changed = true;
        }
      }
    }
  }
  return restored;
}

}  // namespace

TopologyGuardResult guard_topology(const NarrowBand& before, const NarrowBand& after, std::vector<float> values,
                                   const TopologyGuardOptions& options) {
  if (values.size() != after.active_voxel_count())
    throw Error(ErrorCode::InvalidArgument, "guard_topology",
                "got " + std::to_string(values.size()) + " values for " + std::to_string(after.active_voxel_count()) +
                    " active voxels");
  if (before.voxel_size() != after.voxel_size() || !(before.origin() == after.origin()))
    throw Error(ErrorCode::InvalidArgument, "guard_topology", "the two bands are not on the same grid");
  TopologyGuardResult r;
  if (!(options.eps > 0.0) || !std::isfinite(options.eps))
    throw Error(ErrorCode::InvalidArgument, "guard_topology", "eps must be a positive number (a refused flip's |value|)");
  const KeptTopology kept = keep_topology(before, after, values, options.eps, options.free,
                                          options.pinned, options.cuttable, options.progress);
  r.refused_flips = kept.refused;
  r.forced_flips = kept.forced;
  r.restored_values = keep_face_decisions(before, after, values);
  r.values = std::move(values);
  return r;
}

}  // namespace levelset
