// guard_topology: new values for a band that move its zero level without changing the
// topology of its inside set (digital topology: simple points, after Bertrand; the idea of
// Han, Xu and Prince's topology-preserving level sets).
//
// Inputs: `before`, a band; `after`, a band on the same grid (the same band, or the result of
//   an evolve step: its active set may differ); `values`, proposed values in `after`'s
//   active-voxel order; TopologyGuardOptions.
// Rules:
//   1. A voxel's sign may change only where it is a simple point: the flip changes neither the
//      number of components of the inside and outside sets nor their handles (3x3x3 test: one
//      component of the inside and one of the outside in the neighbourhood, each touching the
//      voxel). The marching cubes decide ambiguous faces by value (asymptotic decider), which
//      follows neither fixed adjacency pair, so a flip must be simple for both (26, 6) and
//      (6, 26) and may neither make nor unmake an ambiguous face at the voxel. Flips are taken
//      one by one in brick order, a refused one again after a neighbour flipped; the others keep
//      their old sign at +-eps. options.free(c), when given and true, allows any flip at voxel c
//      (where the caller wants topology to change, e.g. far from data). A flip whose voxel has a
//      face neighbour inactive in `after` on its new side is taken whatever its test says: keeping
//      the old sign there would break the band invariant (two face neighbours of opposite sign,
//      one inactive), which `after`'s band upkeep leaves when a component smaller than the band
//      vanishes in one step. Counted in forced_flips. Voxels inactive in `after` keep `after`'s
//      sign (they hold no value to restore), and the tests see it.
//   2. An ambiguous face (signs alternating round it) with the same four signs before and
//      after keeps its decision (values are taken to be distances: faces are looked for
//      among the voxels within 1.5 voxels of the zero level): where a change of values alone would
//      join or separate its inside corners, its four corners go back to their values in `before`
//      (same signs), repeated until no face changes. Why: a thin part otherwise gains a handle or
//      breaks with every sign change simple (measured on the bunny's ears in the reconstruction's
//      snaps).
//   1b. options.cuttable(c), when given and true, also allows a flip to outside at c that only
//      cuts the inside: the outside stays one component in the neighbourhood (both adjacency
//      pairs), the inside may split there or vanish (a handle cut, a part split from another,
//      a lone voxel dropped), neither making nor unmaking an ambiguous face at the voxel;
//      never a tunnel or a cavity.
//   3. options.pinned(c), when given and true, keeps an inside voxel inside where it is thin
//      (both face neighbours along some axis outside), unless rule 1 forces its flip: a sheet
//      one voxel thick loses its voxels from the rim inward by simple flips alone, so topology
//      alone does not keep it (the caller pins the voxels that hold data).
// Output: TopologyGuardResult (the values, how many flips were refused, how many values were
//   restored for face decisions).
// Errors: Error{InvalidArgument} when values.size() is not after's active voxel count, the
//   bands' voxel sizes or origins differ, or eps is not a positive number; Error{Cancelled}
//   through options.progress.
// Cost: O(active voxels) scans (TBB) plus serial work on the sign changes (each tested again
//   only when a neighbour flipped: O(changes)) and the ambiguous faces near the front.
//   Deterministic for any thread count.
// Why it exists: a part thinner than the voxel (the bunny's ears at a reconstruction's coarse
//   level, a thin sheet under noisy fits) otherwise breaks into pieces or grows handles when
//   the front crosses voxel centres on both of its sides.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/progress.hpp"
#include "grid/coord.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

struct TopologyGuardOptions {
  double eps = 0.0;                        // world, > 0: |value| given to a refused flip's voxel
  std::function<bool(const Coord&)> free;  // optional: flips allowed at any topology cost here
  std::function<bool(const Coord&)> pinned;  // optional: a thin inside voxel here stays inside (rule 3)
  std::function<bool(const Coord&)>
      cuttable;  // optional: flips to outside that only cut the inside allowed here (rule 1b)
  ProgressHook progress;                   // checked every 2^16 flip tests
};

struct TopologyGuardResult {
  std::vector<float> values;
  std::uint64_t refused_flips = 0;
  std::uint64_t forced_flips = 0;  // not simple, taken anyway: `after` has no room for the old sign (rule 1)
  std::uint64_t restored_values = 0;
};

TopologyGuardResult guard_topology(const NarrowBand& before, const NarrowBand& after, std::vector<float> values,
                                   const TopologyGuardOptions& options);

// Whether flipping the centre of a 3x3x3 neighbourhood (bit (dz + 1) 9 + (dy + 1) 3 + dx + 1
// set where inside; the centre's bit is ignored) keeps the topology for both adjacency pairs.
bool simple_voxel(std::uint32_t inside);
// Whether turning the centre outside leaves the outside one component around it for both
// adjacency pairs (rule 1b: the flip may cut or drop the inside, never join the outside).
bool cutting_voxel(std::uint32_t inside);

}  // namespace levelset
