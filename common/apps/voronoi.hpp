// Voronoi regions of labelled seeds (thesis 3.5): every node takes the label of the seed
// whose front reaches it first, by one multi-source fast march (apps/fast_marching.hpp).
// With unit cost the regions are the Euclidean Voronoi cells (up to about one voxel at the
// bisectors, where the discrete fronts meet); with a cost field or obstacles they are the
// geodesic Voronoi regions (distance = travel time around obstacles).
//
// Inputs: FastMarchingOptions (grid, seeds with labels >= 0 (several seeds may share a
//   label: the region is then the union of their cells), cost, obstacles, order).
// Output: VoronoiResult: the march's field (time = distance to the nearest seed in travel
//   time, label per node, -1 where unreached or blocked), the node count per label, and
//   the number of nodes that have a 6-neighbour with another label (the discrete region
//   boundaries).
// Cost, memory, threading, errors: those of fast_marching; the counts add one O(nodes)
//   pass. Results are identical for any thread count.
#pragma once

#include <cstdint>
#include <map>

#include "apps/fast_marching.hpp"

namespace levelset::apps {

using VoronoiOptions = FastMarchingOptions;

struct VoronoiResult {
  FastMarchingResult field;
  std::map<std::int32_t, std::uint64_t> region_voxels;  // label -> nodes
  std::uint64_t unreached = 0;        // free nodes no front reached
  std::uint64_t boundary_voxels = 0;  // labelled nodes with a differently labelled 6-neighbour
};

VoronoiResult voronoi_regions(const VoronoiOptions& options);

}  // namespace levelset::apps
