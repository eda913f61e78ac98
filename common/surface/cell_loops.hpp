// Cell loops: the iso-contour of one grid cell as closed loops through its edge crossings,
// shared by marching_cubes and surface_nets (thesis 4.6; loop-tracing formulation of
// marching cubes with the asymptotic decider on faces, Nielson & Hamann 1991).
//
// Cell: the unit cube between 8 voxel centres. Corner i sits at offset (i&1, i>>1&1, i>>2&1).
// Edge e = 4*axis + (ob + 2*oc): axis a, offsets ob, oc along the other two axes in increasing
//   axis order; its endpoints are corner lower = offset bits, upper = lower + (1 << axis).
// Face f = 2*axis + side (side 0 at coordinate 0, 1 at 1).
// Inside: value < iso (ties count as outside, everywhere).
// Method: on each face the crossings are joined by segments (1, or 2 on an ambiguous face,
//   paired by comparing the bilinear interpolant's saddle value with iso: decide_face gives the
//   same answer for both cells sharing the face); segments are linked into closed loops, each
//   loop oriented so that its polygon normal (right-hand rule) points to the outside.
//   The loops for every (inside mask, face decision bits) pair are generated once, at first
//   use, by that tracing code (no hand-written tables).
// Inputs/outputs: plain values; no allocation after the first call. Thread-safe.
#pragma once

#include <array>
#include <cstdint>

namespace levelset::cell {

inline constexpr int kEdgeAxis[12] = {0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2};

// Lower endpoint corner of edge e.
constexpr int edge_lower_corner(int e) {
  const int a = e >> 2, ob = e & 1, oc = (e >> 1) & 1;
  const int b = a == 0 ? 1 : 0, c = a == 2 ? 1 : 2;
  return (ob << b) | (oc << c);
}
constexpr int edge_upper_corner(int e) { return edge_lower_corner(e) | (1 << (e >> 2)); }

struct LoopSet {
  std::uint8_t loop_count = 0;
  std::array<std::uint8_t, 4> begin{};   // first position of loop l in edges
  std::array<std::uint8_t, 4> length{};
  std::array<std::uint8_t, 12> edges{};  // loop after loop, outward orientation
  std::array<std::uint8_t, 12> loop_of_edge{};  // 0xff where the edge has no crossing
  // Bit l: loop l holds both segments of a face with 4 crossings (two of its vertices lie on
  // one face without a segment between them; a diagonal there could be shared by neighbours).
  std::uint8_t doubled_face_loops = 0;
  // Per loop: bit f set when the loop holds both segments of face f.
  std::array<std::uint8_t, 4> doubled_faces{};
  // What marching cubes emits for this set (its counting pass reads these): a triangle per
  // 3-loop, a fan of n - 2 per other loop, and a centre vertex with n triangles per doubled one.
  std::uint8_t fan_triangles = 0;
  std::uint8_t centre_vertices = 0;
};

// The face (2 * axis + side) holding both edges e0 and e1 of one cell, -1 if none.
int common_face(int e0, int e1);

// The grid edge e of a cell, seen from the neighbouring cell at -1 along axis a (e lies on the
// cell's face 2a, i.e. its offset along a is 0): that cell's index for the same edge.
int edge_from_lower_neighbor(int e, int a);

// Loops for the inside mask (bit i: corner i inside) and face decisions (bit f: on face f,
// when it has 4 crossings, the inside corners are connected across the face).
const LoopSet& loops_for(int inside_mask, int face_decisions);

// Faces of inside mask m with 4 crossings (bit f), whose decision bits select its loops.
int ambiguous_faces(int inside_mask);

// The lookup behind loops_for for a hot loop: fetched once, then a table read per cell (no
// first-use guard, no call). ambiguous[m] is ambiguous_faces(m).
struct LoopLookup {
  const LoopSet* sets = nullptr;
  const std::uint16_t* index = nullptr;  // 64 entries per mask
  const std::uint8_t* ambiguous = nullptr;
  const LoopSet& at(int inside_mask, int face_decisions) const {
    return sets[index[std::size_t(inside_mask) * 64 + std::size_t(face_decisions)]];
  }
};
const LoopLookup& loop_lookup();

// Face corners of face f in the canonical order (0,0),(1,0),(1,1),(0,1) over the face's two
// axes in increasing order.
std::array<int, 4> face_corners(int f);

// Asymptotic decider: true when the inside corners (a < 0) of an ambiguous face are connected
// through the face. a[] are value - iso at the canonical corners (a0, a2 on one side, a1, a3
// on the other). Symmetric under the face's rotations and reflections, so both cells agree.
inline bool inside_connected(double a0, double a1, double a2, double a3) {
  const double num = a0 * a2 - a1 * a3;
  const double den = a0 + a2 - a1 - a3;
  return den > 0.0 ? num < 0.0 : num > 0.0;  // saddle value num/den < 0 (inside)
}

// The corners of face f in the order the decider reads them (around the face).
inline constexpr int kDeciderCorners[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                               {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};

// The face decision bits of a cell for its ambiguous faces (bits of ambiguous_faces(mask)),
// from its 8 corner values minus iso.
inline int face_decisions(const double a[8], int ambiguous) {
  int d = 0;
  for (int f = 0; f < 6; ++f) {
    const int* c = kDeciderCorners[f];
    if (((ambiguous >> f) & 1) && inside_connected(a[c[0]], a[c[1]], a[c[2]], a[c[3]])) d |= 1 << f;
  }
  return d;
}

// Inside mask and face decision bits of a cell from its 8 corner values minus iso.
inline void classify(const double a[8], int& inside_mask, int& face_decisions) {
  int m = 0;
  for (int i = 0; i < 8; ++i) m |= (a[i] < 0.0 ? 1 : 0) << i;
  inside_mask = m;
  int d = 0;
  if (m != 0 && m != 255) {
    for (int f = 0; f < 6; ++f) {
      const int* c = kDeciderCorners[f];
      const int s0 = (m >> c[0]) & 1, s1 = (m >> c[1]) & 1, s2 = (m >> c[2]) & 1,
                s3 = (m >> c[3]) & 1;
      if (s0 == s2 && s1 == s3 && s0 != s1 && inside_connected(a[c[0]], a[c[1]], a[c[2]], a[c[3]]))
        d |= 1 << f;
    }
  }
  face_decisions = d;
}

}  // namespace levelset::cell
