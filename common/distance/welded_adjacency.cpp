#include "distance/welded_adjacency.hpp"

#include <algorithm>

#include "distance/edge_uses.hpp"
#include "distance/open_edges.hpp"

namespace levelset {

WeldedAdjacency build_adjacency(const TriangleMesh& mesh) {
  WeldedAdjacency adj;
  adj.welded = weld_exact(mesh.vertices);
  const std::size_t nt = mesh.triangles.size(), nv = mesh.vertices.size();
  const std::vector<EdgeUse> uses = sorted_edge_uses(mesh, adj.welded);
  adj.across.assign(3 * nt, kNoAdjacent);
  adj.first_triangle.assign(nv, kNoAdjacent);
  // Distinct edges (first use of each run); the rings in CSR form, each vertex's neighbours in
  // the order of the sorted edges (ascending).
  std::vector<std::size_t> edge_starts;
  adj.ring_offsets.assign(nv + 1, 0);
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].same_edge(uses[i])) ++j;
    if (j - i == 2 && uses[i].lo != uses[i].hi) {
      adj.across[3 * uses[i].face + uses[i].slot] = uses[i + 1].face;
      adj.across[3 * uses[i + 1].face + uses[i + 1].slot] = uses[i].face;
    }
    if (uses[i].lo != uses[i].hi && (j - i) % 2 == 1) ++adj.odd_edges;
    if (uses[i].lo != uses[i].hi) {
      edge_starts.push_back(i);
      ++adj.ring_offsets[uses[i].lo + 1];
      ++adj.ring_offsets[uses[i].hi + 1];
    }
    i = j;
  }
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& first = adj.first_triangle[adj.welded[mesh.triangles[t][k]]];
      first = std::min(first, std::uint32_t(t));
    }
  for (std::size_t v = 0; v < nv; ++v) adj.ring_offsets[v + 1] += adj.ring_offsets[v];
  adj.ring_vertices.resize(adj.ring_offsets[nv]);
  std::vector<std::uint32_t> fill(adj.ring_offsets.begin(), adj.ring_offsets.end() - 1);
  for (std::size_t i : edge_starts) {
    adj.ring_vertices[fill[uses[i].lo]++] = uses[i].hi;
    adj.ring_vertices[fill[uses[i].hi]++] = uses[i].lo;
  }
  return adj;
}

}  // namespace levelset
