// build_adjacency: the welded adjacency the characteristic scan reads: per triangle edge the one
// other triangle across it (manifold edges only), per welded vertex its lowest-index triangle and
// its distinct neighbouring vertices.
//
// Inputs: a triangle mesh (indices valid). Vertices are welded by exact position (weld_exact).
// Output: WeldedAdjacency (below); an edge used by two triangles is manifold, by an odd number a border.
// Cost: O(F + V) beyond sorted_edge_uses' fans; 12 bytes per triangle, ~16 per vertex.
// Threading: none. Errors: none.
#pragma once

#include <cstdint>
#include <vector>

#include "io/triangle_mesh.hpp"

namespace levelset {

inline constexpr std::uint32_t kNoAdjacent = 0xffffffffu;  // no triangle there

struct WeldedAdjacency {
  std::vector<std::uint32_t> welded;          // per input vertex
  std::vector<std::uint32_t> across;          // 3 per triangle: edge k = (v_k, v_k+1)
  std::vector<std::uint32_t> first_triangle;  // per welded id (kNoAdjacent: unused)
  std::vector<std::uint32_t> ring_offsets;    // per welded id, CSR into ring_vertices
  std::vector<std::uint32_t> ring_vertices;   // input vertex indices of distinct neighbours
  std::uint64_t odd_edges = 0;                // edges used by an odd number of triangles
};

WeldedAdjacency build_adjacency(const TriangleMesh& mesh);

}  // namespace levelset
