#include "distance/orient_faces.hpp"

#include <algorithm>
#include <array>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/huge_pages.hpp"
#include "io/validate_mesh.hpp"
#include "distance/edge_uses.hpp"
#include "distance/open_edges.hpp"

namespace levelset {

namespace {

struct Link {
  std::uint32_t face;
  bool same_direction;  // both faces traverse the edge the same way: relative flip needed
};

bool degenerate(const TriangleMesh& mesh, const std::array<std::uint32_t, 3>& f) {
  if (f[0] == f[1] || f[1] == f[2] || f[2] == f[0]) return true;
  const Vec3d& a = mesh.vertices[f[0]];
  const Vec3d n = cross(mesh.vertices[f[1]] - a, mesh.vertices[f[2]] - a);
  return n.x == 0.0 && n.y == 0.0 && n.z == 0.0;
}

}  // namespace

OrientResult orient_faces(TriangleMesh input, const OrientOptions& options) {
  const std::size_t nf = input.triangles.size();
  if (nf >= 0xffffffffu) throw Error(ErrorCode::LimitExceeded, "mesh", "2^32 or more faces");
  validate_mesh(input);
  OrientResult result;
  result.mesh = std::move(input);
  const TriangleMesh& mesh = result.mesh;  // read as given; the flips are applied at the end
  // Edges join faces through vertices at exactly equal positions (split seam vertices too).
  std::vector<std::uint32_t> id;
  if (options.welded) {
    id.resize(mesh.vertices.size());
    std::iota(id.begin(), id.end(), 0u);
  } else {
    id = weld_exact(mesh.vertices);
  }

  // Edge uses of non-degenerate faces, grouped by undirected edge.
  std::vector<bool> counted(nf);
  for (std::size_t t = 0; t < nf; ++t) {
    const auto& f = mesh.triangles[t];
    counted[t] =
        !(degenerate(mesh, f) || id[f[0]] == id[f[1]] || id[f[1]] == id[f[2]] || id[f[2]] == id[f[0]]);
    result.degenerate_faces += !counted[t];
  }
  std::vector<EdgeUse> uses = sorted_edge_uses(mesh, id, counted);
  options.progress.step(0.4, "orient");

  // Manifold edges become links between their two faces (CSR, neighbours sorted by index).
  std::vector<std::uint32_t> offsets(nf + 1, 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;  // index into uses of each pair
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].same_edge(uses[i])) ++j;
    if (j - i == 2) {
      pairs.push_back({std::uint32_t(i), std::uint32_t(i + 1)});
      ++offsets[uses[i].face + 1];
      ++offsets[uses[i + 1].face + 1];
    } else if (j - i > 2) {
      ++result.nonmanifold_edges;
    }
    i = j;
  }
  for (std::size_t t = 0; t < nf; ++t) offsets[t + 1] += offsets[t];
  std::vector<Link> links;
  resize_with_huge_pages(links, offsets[nf]);
  {
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (const auto& [i, j] : pairs) {
      const EdgeUse& u = uses[i];
      const EdgeUse& v = uses[j];
      const bool same = u.forward == v.forward;
      links[fill[u.face]++] = {v.face, same};
      links[fill[v.face]++] = {u.face, same};
    }
  }
  for (std::size_t t = 0; t < nf; ++t)
    std::sort(links.begin() + offsets[t], links.begin() + offsets[t + 1],
              [](const Link& a, const Link& b) { return a.face < b.face; });
  uses.clear();
  uses.shrink_to_fit();
  options.progress.step(0.6, "orient");

  // Breadth-first propagation per component, then whole-component flips by signed volume.
  std::vector<bool> flip(nf, false), reached(nf, false);
  std::vector<std::uint32_t> queue;
  queue.reserve(nf);
  for (std::size_t seed = 0; seed < nf; ++seed) {
    if (!counted[seed] || reached[seed]) continue;
    ++result.components;
    const std::size_t begin = queue.size();
    queue.push_back(std::uint32_t(seed));
    reached[seed] = true;
    for (std::size_t q = begin; q < queue.size(); ++q) {
      const std::uint32_t f = queue[q];
      for (std::uint32_t k = offsets[f]; k < offsets[f + 1]; ++k) {
        const Link& l = links[k];
        if (reached[l.face]) {
          if (flip[l.face] != (flip[f] != l.same_direction)) ++result.inconsistent_edges;
          continue;
        }
        reached[l.face] = true;
        flip[l.face] = flip[f] != l.same_direction;
        queue.push_back(l.face);
      }
    }
    // Signed volume about the component's area-weighted centroid.
    double total = 0.0;
    Vec3d weighted{}, plain{};
    for (std::size_t q = begin; q < queue.size(); ++q) {
      const auto& t = mesh.triangles[queue[q]];
      const Vec3d& a = mesh.vertices[t[0]];
      const Vec3d& b = mesh.vertices[t[1]];
      const Vec3d& c = mesh.vertices[t[2]];
      const double area = length(cross(b - a, c - a));
      const Vec3d g = (a + b + c) / 3.0;
      total += area;
      weighted += g * area;
      plain += g;
    }
    const Vec3d center = total > 0.0 ? weighted / total : plain / double(queue.size() - begin);
    double volume = 0.0;
    for (std::size_t q = begin; q < queue.size(); ++q) {
      const auto& t = mesh.triangles[queue[q]];
      const Vec3d a = mesh.vertices[t[0]] - center;
      Vec3d b = mesh.vertices[t[1]] - center;
      Vec3d c = mesh.vertices[t[2]] - center;
      if (flip[queue[q]]) std::swap(b, c);
      volume += dot(a, cross(b, c));
    }
    if (volume < 0.0)
      for (std::size_t q = begin; q < queue.size(); ++q) flip[queue[q]] = !flip[queue[q]];
  }
  // Each inconsistent manifold edge was seen from both of its faces.
  result.inconsistent_edges /= 2;
  options.progress.step(0.9, "orient");

  for (std::size_t t = 0; t < nf; ++t) {
    if (!flip[t]) continue;
    std::swap(result.mesh.triangles[t][1], result.mesh.triangles[t][2]);
    ++result.faces_flipped;
  }
  return result;
}

}  // namespace levelset
