#include "surface/mesh_measures.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"

namespace levelset {

namespace {

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// The triangles around each vertex (CSR): incident[start[v] .. start[v + 1]).
struct VertexTriangles {
  std::vector<std::uint32_t> start, incident;
  explicit VertexTriangles(const TriangleMesh& mesh) : start(mesh.vertices.size() + 1, 0) {
    for (const auto& t : mesh.triangles)
      for (auto i : t) ++start[i + 1];
    for (std::size_t v = 0; v + 1 < start.size(); ++v) start[v + 1] += start[v];
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    incident.resize(3 * mesh.triangles.size());
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
      for (auto i : mesh.triangles[f]) incident[fill[i]++] = std::uint32_t(f);
  }
};

// Work is split into fixed chunks whose partial results are combined in chunk order, so the
// measures (floating-point sums included) do not depend on the thread count.
constexpr std::size_t kChunk = 16384;

template <typename Part, typename F>
std::vector<Part> chunk_parts(std::size_t items, F&& f) {
  std::vector<Part> parts((items + kChunk - 1) / kChunk);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, parts.size(), 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c != r.end(); ++c) f(c * kChunk, std::min(items, (c + 1) * kChunk), parts[c]);
  });
  return parts;
}

// Area, volume and triangle quality (see the header) of triangles [begin, end).
struct TrianglePart {
  double area = 0.0, volume = 0.0, min_angle = 180.0, sum_min_angle = 0.0, max_aspect = 0.0;
  std::uint64_t degenerate = 0;
};

void measure_triangle_range(const TriangleMesh& mesh, const Vec3d& origin, std::size_t begin, std::size_t end,
                            TrianglePart& p) {
  for (std::size_t f = begin; f < end; ++f) {
    const auto& t = mesh.triangles[f];
    const Vec3d &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const Vec3d n = cross(b - a, c - a);
    const double area2 = length(n);
    p.area += 0.5 * area2;
    p.volume += dot(a - origin, cross(b - origin, c - origin)) / 6.0;
    const double la = length(b - c), lb = length(c - a), lc = length(a - b);
    if (!(area2 > 0.0)) {
      ++p.degenerate;
      p.min_angle = 0.0;
      p.max_aspect = std::numeric_limits<double>::infinity();
      continue;
    }
    auto cosine = [](double opp, double s1, double s2) {
      return std::clamp((s1 * s1 + s2 * s2 - opp * opp) / (2 * s1 * s2), -1.0, 1.0);
    };
    // The smallest angle has the largest cosine (one arc cosine per triangle).
    const double mn = std::acos(std::max({cosine(la, lb, lc), cosine(lb, lc, la), cosine(lc, la, lb)})) * 180.0 /
                      std::numbers::pi;
    p.min_angle = std::min(p.min_angle, mn);
    p.sum_min_angle += mn;
    const double aspect = std::max({la, lb, lc}) * (la + lb + lc) / (4.0 * std::sqrt(3.0) * 0.5 * area2);
    p.max_aspect = std::max(p.max_aspect, aspect);
  }
}

void measure_triangles(const TriangleMesh& mesh, MeshMeasures& m) {
  // The signed tetrahedron volumes are taken about the mesh's centre, not the world origin: far
  // from the origin (a unit cube at 5e6) the products of large coordinates cancel catastrophically.
  const BBox box = mesh.bounds();
  const Vec3d origin = box.empty() ? Vec3d{} : 0.5 * (box.min + box.max);
  double min_angle = 180.0, sum_min_angle = 0.0, max_aspect = 0.0;
  for (const TrianglePart& p : chunk_parts<TrianglePart>(mesh.triangles.size(), [&](std::size_t b, std::size_t e, TrianglePart& p) {
         measure_triangle_range(mesh, origin, b, e, p);
       })) {
    m.area += p.area;
    m.volume += p.volume;
    m.degenerate_triangles += p.degenerate;
    min_angle = std::min(min_angle, p.min_angle);
    sum_min_angle += p.sum_min_angle;
    max_aspect = std::max(max_aspect, p.max_aspect);
  }
  if (m.faces > 0) {
    m.min_angle_deg = min_angle;
    m.mean_min_angle_deg = sum_min_angle / double(m.faces);
    m.max_aspect_ratio = max_aspect;
  }
}

// Edges, counted at their lower vertex from its triangles (no global sort): each undirected
// edge {lo, hi} is seen once per triangle using it, with the direction the triangle gives it.
struct EdgePart {
  std::uint64_t edges = 0, boundary = 0, non_manifold = 0, misoriented = 0;
};

void count_edge_range(const TriangleMesh& mesh, const VertexTriangles& around, std::uint32_t begin, std::uint32_t end,
                      EdgePart& m) {
  std::vector<std::uint64_t> ends;  // (hi << 1) | forward (lo -> hi in the triangle)
  for (std::uint32_t v = begin; v < end; ++v) {
    ends.clear();
    for (std::uint32_t k = around.start[v]; k < around.start[v + 1]; ++k) {
      // A triangle holding v twice is listed twice in a row: its edges are taken once.
      if (k > around.start[v] && around.incident[k] == around.incident[k - 1]) continue;
      const auto& t = mesh.triangles[around.incident[k]];
      for (int at = 0; at < 3; ++at) {
        if (t[at] != v) continue;
        const std::uint32_t next = t[(at + 1) % 3], prev = t[(at + 2) % 3];
        if (next > v) ends.push_back(std::uint64_t(next) << 1 | 1u);  // v -> next: lo -> hi
        if (next == v) ends.push_back(std::uint64_t(v) << 1);         // a degenerate v -> v, once
        if (prev > v) ends.push_back(std::uint64_t(prev) << 1);       // prev -> v: hi -> lo
      }
    }
    std::sort(ends.begin(), ends.end());
    for (std::size_t i = 0; i < ends.size();) {
      std::size_t j = i;
      int fwd = 0;
      while (j < ends.size() && (ends[j] >> 1) == (ends[i] >> 1)) fwd += int(ends[j++] & 1u);
      const std::size_t count = j - i;
      ++m.edges;
      if (count == 1) ++m.boundary;
      else if (count > 2) ++m.non_manifold;
      else if (fwd != 1) ++m.misoriented;
      i = j;
    }
  }
}

void count_edges(const TriangleMesh& mesh, const VertexTriangles& around, MeshMeasures& m) {
  const std::size_t nv = around.start.size() - 1;
  for (const EdgePart& p : chunk_parts<EdgePart>(nv, [&](std::size_t b, std::size_t e, EdgePart& p) {
         count_edge_range(mesh, around, std::uint32_t(b), std::uint32_t(e), p);
       })) {
    m.edges += p.edges;
    m.boundary_edges += p.boundary;
    m.non_manifold_edges += p.non_manifold;
    m.misoriented_edges += p.misoriented;
  }
}

// The link of a vertex (the opposite edges of its triangles) is one cycle. `ends` and `used`
// are scratch.
bool link_is_cycle(const std::vector<std::array<std::uint32_t, 2>>& link, std::vector<std::uint32_t>& ends,
                   std::vector<std::uint8_t>& used) {
  const std::size_t n = link.size();
  if (n < 3) return false;
  ends.clear();
  for (const auto& e : link) {
    ends.push_back(e[0]);
    ends.push_back(e[1]);
  }
  std::sort(ends.begin(), ends.end());
  for (std::size_t i = 0; i < ends.size(); i += 2)
    if (ends[i] != ends[i + 1] || (i + 2 < ends.size() && ends[i + 2] == ends[i])) return false;
  // Every link vertex has degree 2: the link is a union of cycles; walk one.
  used.assign(n, 0);
  std::uint32_t start = link[0][0], cur = link[0][1];
  used[0] = 1;
  std::size_t walked = 1;
  while (cur != start) {
    bool found = false;
    for (std::size_t i = 0; i < n; ++i) {
      if (used[i] || (link[i][0] != cur && link[i][1] != cur)) continue;
      used[i] = 1;
      cur = link[i][0] == cur ? link[i][1] : link[i][0];
      ++walked;
      found = true;
      break;
    }
    if (!found) return false;
  }
  return walked == n;
}

std::uint64_t non_manifold_vertex_range(const TriangleMesh& mesh, const VertexTriangles& around,
                                        std::uint32_t begin, std::uint32_t end) {
  std::uint64_t count = 0;
  std::vector<std::array<std::uint32_t, 2>> link;
  std::vector<std::uint32_t> ends;
  std::vector<std::uint8_t> used;
  for (std::uint32_t v = begin; v < end; ++v) {
    if (around.start[v] == around.start[v + 1]) continue;  // not referenced
    link.clear();
    for (std::uint32_t k = around.start[v]; k < around.start[v + 1]; ++k) {
      const auto& t = mesh.triangles[around.incident[k]];
      const int at = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
      link.push_back({t[(at + 1) % 3], t[(at + 2) % 3]});
    }
    if (!link_is_cycle(link, ends, used)) ++count;
  }
  return count;
}

std::uint64_t non_manifold_vertices(const TriangleMesh& mesh, const VertexTriangles& around) {
  std::uint64_t count = 0;
  for (const std::uint64_t c : chunk_parts<std::uint64_t>(around.start.size() - 1, [&](std::size_t b, std::size_t e, std::uint64_t& c) {
         c = non_manifold_vertex_range(mesh, around, std::uint32_t(b), std::uint32_t(e));
       }))
    count += c;
  return count;
}

}  // namespace

MeshMeasures measure_mesh(const TriangleMesh& mesh) {
  MeshMeasures m;
  const std::size_t nv = mesh.vertices.size();
  for (const auto& t : mesh.triangles)
    for (auto i : t)
      if (i >= nv) throw Error(ErrorCode::InvalidArgument, "measure_mesh", "vertex index out of range");
  m.faces = mesh.triangles.size();
  measure_triangles(mesh, m);
  const VertexTriangles around(mesh);
  count_edges(mesh, around, m);
  // Components through shared vertices.
  std::vector<std::uint32_t> parent(nv);
  std::iota(parent.begin(), parent.end(), 0u);
  for (const auto& t : mesh.triangles)
    for (int k = 1; k < 3; ++k) {
      const std::uint32_t ra = find_root(parent, t[0]), rb = find_root(parent, t[k]);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  for (std::size_t v = 0; v < nv; ++v) {
    if (around.start[v] == around.start[v + 1]) continue;  // not referenced
    ++m.vertices;
    m.bounds.extend(mesh.vertices[v]);
    if (find_root(parent, std::uint32_t(v)) == v) ++m.components;
  }
  m.euler_characteristic = std::int64_t(m.vertices) - std::int64_t(m.edges) + std::int64_t(m.faces);
  m.genus = (2.0 * double(m.components) - double(m.euler_characteristic)) / 2.0;
  m.non_manifold_vertices = non_manifold_vertices(mesh, around);
  m.watertight = m.boundary_edges == 0 && m.non_manifold_edges == 0;
  m.manifold = m.non_manifold_edges == 0 && m.non_manifold_vertices == 0;
  m.oriented = m.watertight && m.misoriented_edges == 0;
  return m;
}

double area_weighted_mean_curvature(const TriangleMesh& mesh) {
  const std::size_t nv = mesh.vertices.size();
  const std::size_t nf = mesh.triangles.size();
  std::vector<Vec3d> normals(nf);
  double area = 0.0;
  struct FaceEdge {
    std::uint32_t lo, hi, face;
    bool forward;  // lo -> hi in the face
  };
  std::vector<FaceEdge> edges;
  edges.reserve(3 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& t = mesh.triangles[f];
    for (auto i : t)
      if (i >= nv)
        throw Error(ErrorCode::InvalidArgument, "area_weighted_mean_curvature", "vertex index out of range");
    const Vec3d n = cross(mesh.vertices[t[1]] - mesh.vertices[t[0]], mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    const double len = length(n);
    area += 0.5 * len;
    normals[f] = len > 0.0 ? n / len : Vec3d{};
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = t[k], v = t[(k + 1) % 3];
      edges.push_back({std::min(u, v), std::max(u, v), std::uint32_t(f), u < v});
    }
  }
  if (!(area > 0.0)) return 0.0;
  std::sort(edges.begin(), edges.end(), [](const FaceEdge& a, const FaceEdge& b) {
    return a.lo != b.lo ? a.lo < b.lo : (a.hi != b.hi ? a.hi < b.hi : a.face < b.face);
  });
  double integral = 0.0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
    if (j - i == 2 && edges[i].forward != edges[i + 1].forward) {
      // Direct the edge as face 1 traverses it; theta > 0 where convex.
      const FaceEdge& e1 = edges[i].forward ? edges[i] : edges[i + 1];
      const FaceEdge& e2 = edges[i].forward ? edges[i + 1] : edges[i];
      const Vec3d ev = mesh.vertices[e1.hi] - mesh.vertices[e1.lo];
      const double elen = length(ev);
      const Vec3d &n1 = normals[e1.face], &n2 = normals[e2.face];
      if (elen > 0.0 && dot(n1, n1) > 0.0 && dot(n2, n2) > 0.0) {
        const double theta = std::atan2(dot(cross(n1, n2), ev) / elen, dot(n1, n2));
        integral += elen * theta;
      }
    }
    i = j;
  }
  return integral / area;
}

}  // namespace levelset
