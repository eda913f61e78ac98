#include "distance/unique_faces.hpp"

#include <algorithm>

#include <tbb/parallel_sort.h>

#include "distance/open_edges.hpp"

namespace levelset {

UniqueFacesResult unique_faces(const TriangleMesh& mesh) {
  // Weld: equal positions map to the lowest index among them.
  const std::vector<std::uint32_t> weld = weld_exact(mesh.vertices);

  UniqueFacesResult result;
  result.mesh.vertices = mesh.vertices;
  struct Key {
    std::array<std::uint32_t, 3> sorted;
    std::uint32_t face;
    int orientation;  // +1 / -1: the parity of the face's vertex order against the sorted one
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
    // A cyclic rotation keeps the orientation; the sorted order is even or odd against it.
    const int rot = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
    const std::array<std::uint32_t, 3> r = {t[rot], t[(rot + 1) % 3], t[(rot + 2) % 3]};
    const int orientation = r[1] < r[2] ? 1 : -1;
    std::sort(t.begin(), t.end());
    keys.push_back({t, static_cast<std::uint32_t>(f), orientation});
  }
  tbb::parallel_sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return a.sorted != b.sorted ? a.sorted < b.sorted : a.face < b.face;
  });
  // Copies of a face: their orientations add up. Opposite copies cancel (a double-sided sheet
  // encloses nothing), so a group keeps one copy of the net orientation, or none when it is 0.
  std::vector<std::uint32_t> kept;
  kept.reserve(keys.size());
  for (std::size_t k = 0; k < keys.size();) {
    std::size_t end = k;
    int net = 0;
    while (end < keys.size() && keys[end].sorted == keys[k].sorted) net += keys[end++].orientation;
    std::size_t keep = end;
    for (std::size_t j = k; j < end && net != 0; ++j)
      if (keys[j].orientation == (net > 0 ? 1 : -1)) { keep = j; break; }
    if (keep != end) kept.push_back(keys[keep].face);
    result.duplicates_removed += (end - k) - (keep != end ? 1 : 0);
    k = end;
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
