#include "surface/cell_loops.hpp"

#include <array>
#include <vector>

namespace levelset::cell {

std::array<int, 4> face_corners(int f) {
  const int a = f >> 1, side = f & 1;
  const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
  const int base = side << a;
  return {base, base | (1 << u), base | (1 << u) | (1 << v), base | (1 << v)};
}

namespace {

// Offset of edge e's lower corner along axis a (0 when a is the edge's own axis).
int edge_offset(int e, int a) { return (edge_lower_corner(e) >> a) & 1; }

}  // namespace

int common_face(int e0, int e1) {
  if (e0 == e1) return -1;
  // A face normal to a holds every edge along the other two axes with its offset along a.
  for (int a = 0; a < 3; ++a) {
    if (a == (e0 >> 2) || a == (e1 >> 2)) continue;
    if (edge_offset(e0, a) == edge_offset(e1, a)) return 2 * a + edge_offset(e0, a);
  }
  return -1;
}

int edge_from_lower_neighbor(int e, int a) {
  const int lower = edge_lower_corner(e) | (1 << a);
  for (int k = 0; k < 12; ++k)
    if (edge_lower_corner(k) == lower && (k >> 2) == (e >> 2)) return k;
  return -1;
}

namespace {

int edge_between(int c0, int c1) {
  for (int e = 0; e < 12; ++e) {
    const int lo = edge_lower_corner(e), hi = edge_upper_corner(e);
    if ((lo == c0 && hi == c1) || (lo == c1 && hi == c0)) return e;
  }
  return -1;
}

LoopSet trace(int m, int decisions) {
  LoopSet s;
  s.loop_of_edge.fill(0xff);
  std::array<int, 12> next;
  next.fill(-1);
  // Which face holds both segments of a 4-crossing face: pairs of entry edges per face.
  std::array<std::array<int, 3>, 6> doubled;  // entry edges and face, per 4-crossing face
  int doubled_count = 0;
  for (int f = 0; f < 6; ++f) {
    std::array<int, 4> c = face_corners(f);
    // Counter-clockwise seen from outside the cell. The canonical order turns about +axis for
    // x and z (y x z = +x, x x y = +z) and about -axis for y (x x z = -y).
    const bool about_plus = (f >> 1) != 1;
    const bool outward_plus = (f & 1) == 1;
    if (about_plus != outward_plus) c = {c[0], c[3], c[2], c[1]};
    int edges[4];
    bool in[4];
    for (int i = 0; i < 4; ++i) {
      edges[i] = edge_between(c[i], c[(i + 1) & 3]);
      in[i] = (m >> c[i]) & 1;
    }
    int crossings = 0;
    for (int i = 0; i < 4; ++i) crossings += in[i] != in[(i + 1) & 3];
    if (crossings == 0) continue;
    // Edge i is an entry when it goes outside -> inside; segments run entry -> exit.
    if (crossings == 2) {
      int entry = -1, exit = -1;
      for (int i = 0; i < 4; ++i) {
        if (!in[i] && in[(i + 1) & 3]) entry = edges[i];
        if (in[i] && !in[(i + 1) & 3]) exit = edges[i];
      }
      next[entry] = exit;
      continue;
    }
    const bool connected = (decisions >> f) & 1;
    std::array<int, 3> pair{0, 0, f};
    int k = 0;
    for (int i = 0; i < 4; ++i) {
      if (in[i] || !in[(i + 1) & 3]) continue;
      next[edges[i]] = connected ? edges[(i + 3) & 3] : edges[(i + 1) & 3];
      pair[k++] = edges[i];
    }
    doubled[std::size_t(doubled_count++)] = pair;
  }
  int pos = 0;
  for (int e0 = 0; e0 < 12; ++e0) {
    if (next[e0] < 0 || s.loop_of_edge[e0] != 0xff) continue;
    const int l = s.loop_count++;
    s.begin[l] = std::uint8_t(pos);
    int e = e0;
    do {
      s.loop_of_edge[e] = std::uint8_t(l);
      s.edges[pos++] = std::uint8_t(e);
      e = next[e];
    } while (e != e0);
    s.length[l] = std::uint8_t(pos - s.begin[l]);
  }
  for (int k = 0; k < doubled_count; ++k) {
    const std::array<int, 3>& p = doubled[std::size_t(k)];
    if (s.loop_of_edge[p[0]] == s.loop_of_edge[p[1]]) {
      s.doubled_face_loops |= std::uint8_t(1u << s.loop_of_edge[p[0]]);
      s.doubled_faces[s.loop_of_edge[p[0]]] |= std::uint8_t(1u << p[2]);
    }
  }
  for (int l = 0; l < s.loop_count; ++l) {
    const int n = s.length[l];
    const bool centre = n > 3 && ((s.doubled_face_loops >> l) & 1);
    s.fan_triangles = std::uint8_t(s.fan_triangles + (n == 3 ? 1 : centre ? n : n - 2));
    s.centre_vertices = std::uint8_t(s.centre_vertices + (centre ? 1 : 0));
  }
  return s;
}

}  // namespace

int ambiguous_faces(int m) {
  int faces = 0;
  for (int f = 0; f < 6; ++f) {
    const std::array<int, 4> c = face_corners(f);
    const int in0 = (m >> c[0]) & 1, in1 = (m >> c[1]) & 1, in2 = (m >> c[2]) & 1, in3 = (m >> c[3]) & 1;
    if (in0 == in2 && in1 == in3 && in0 != in1) faces |= 1 << f;
  }
  return faces;
}

namespace {

// Built on first use: traced once per distinct decision pattern (the decisions on faces that
// are not ambiguous do not matter), about 1/10 of the 16384 (mask, decisions) pairs, which
// index the distinct sets (32 KiB of indices and ~60 KiB of sets instead of 640 KiB of copies:
// a cold process's first extraction faults in a few pages, and the hot loop's lookups stay
// in cache).
struct Table {
  std::vector<LoopSet> sets;
  std::array<std::uint16_t, 256 * 64> index{};
  std::array<std::uint8_t, 256> ambiguous{};
  LoopLookup lookup;
  Table() {
    for (int m = 0; m < 256; ++m) {
      const int amb = ambiguous_faces(m);
      ambiguous[std::size_t(m)] = std::uint8_t(amb);
      for (int d = 0; d < 64; ++d)
        if ((d & amb) == d) {
          index[std::size_t(m * 64 + d)] = std::uint16_t(sets.size());
          sets.push_back(trace(m, d));
        }
      for (int d = 0; d < 64; ++d)
        if ((d & amb) != d) index[std::size_t(m * 64 + d)] = index[std::size_t(m * 64 + (d & amb))];
    }
    lookup = LoopLookup{sets.data(), index.data(), ambiguous.data()};
  }
};

const Table& table() {
  static const Table t;
  return t;
}

}  // namespace

const LoopSet& loops_for(int inside_mask, int face_decisions) { return table().lookup.at(inside_mask, face_decisions); }

const LoopLookup& loop_lookup() { return table().lookup; }

}  // namespace levelset::cell
