#include "distance/unique_faces.hpp"

#include <algorithm>
#include <numeric>
#include <tuple>

namespace levelset {

UniqueFacesResult unique_faces(const TriangleMesh& mesh) {
  // Weld: vertices sorted by coordinates; equal runs map to the first of the run.
  const std::size_t nv = mesh.vertices.size();
  std::vector<std::uint32_t> order(nv);
  std::iota(order.begin(), order.end(), 0u);
  auto coords = [&](std::uint32_t i) {
    const Vec3d& v = mesh.vertices[i];
    return std::make_tuple(v.x, v.y, v.z);
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return coords(a) != coords(b) ? coords(a) < coords(b) : a < b;
  });
  std::vector<std::uint32_t> weld(nv);
  for (std::size_t k = 0; k < nv; ++k)
    weld[order[k]] = (k > 0 && coords(order[k]) == coords(order[k - 1])) ? weld[order[k - 1]] : order[k];

  UniqueFacesResult result;
  result.mesh.vertices = mesh.vertices;
  struct Key {
    std::array<std::uint32_t, 3> sorted;
    std::uint32_t face;
  };
  std::vector<Key> keys;
  keys.reserve(mesh.triangles.size());
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    std::array<std::uint32_t, 3> t = {weld[mesh.triangles[f][0]], weld[mesh.triangles[f][1]],
                                      weld[mesh.triangles[f][2]]};
    const Vec3d n = cross(mesh.vertices[t[1]] - mesh.vertices[t[0]], mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || (n.x == 0 && n.y == 0 && n.z == 0)) {
      ++result.degenerate_removed;
      continue;
    }
    std::sort(t.begin(), t.end());
    keys.push_back({t, static_cast<std::uint32_t>(f)});
  }
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return a.sorted != b.sorted ? a.sorted < b.sorted : a.face < b.face;
  });
  std::vector<std::uint32_t> kept;
  kept.reserve(keys.size());
  for (std::size_t k = 0; k < keys.size(); ++k) {
    if (k > 0 && keys[k].sorted == keys[k - 1].sorted) {
      ++result.duplicates_removed;
      continue;
    }
    kept.push_back(keys[k].face);
  }
  // Same face count and order as the input (face indices stay valid); a dropped face becomes
  // the point triangle (a, a, a), which has no area, no solid angle and no crossings.
  result.mesh.triangles.resize(mesh.triangles.size());
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const std::uint32_t a = weld[mesh.triangles[f][0]];
    result.mesh.triangles[f] = {a, a, a};
  }
  for (std::uint32_t f : kept)
    result.mesh.triangles[f] = {weld[mesh.triangles[f][0]], weld[mesh.triangles[f][1]],
                                weld[mesh.triangles[f][2]]};
  return result;
}

}  // namespace levelset
