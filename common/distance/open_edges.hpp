// Vertex welding by exact position, and the open edges of a triangle soup: where its winding
// number is not piecewise constant.
//
// weld_exact
//   Input: positions. Output: per position the lowest index holding exactly the same
//   coordinates (so split vertices along texture or normal seams share edges).
//   Cost: O(V) expected (one pass over a hash table of 2-4 slots per position). Threading:
//   none. Errors: Error{LimitExceeded} for 2^32 - 1 or more positions.
// open_edges
//   Inputs: the mesh's triangles (indices), welded vertex ids (weld_exact of the positions the
//   caller uses), and per triangle whether it counts (exactly degenerate triangles carry no
//   area and are left out). Output: the undirected edges (welded ids, lower first, sorted)
//   whose uses do not cancel: the number of counted triangles traversing a -> b differs from
//   the number traversing b -> a. These are the boundary of the oriented surface as a chain:
//   holes and open borders, edges of inconsistent or non-orientable regions, unmatched
//   non-manifold fins. Away from them the winding number jumps by exact integers across the
//   surface and is constant elsewhere; near them it also varies continuously.
//   Cost: O(F + V) (sorted_edge_uses, edge_uses.hpp). Threading: none.
//   Errors: none (indices must be valid).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset {

std::vector<std::uint32_t> weld_exact(std::span<const Vec3d> positions);

std::vector<std::array<std::uint32_t, 2>> open_edges(const TriangleMesh& mesh,
                                                     std::span<const std::uint32_t> welded,
                                                     const std::vector<bool>& counts);

}  // namespace levelset
