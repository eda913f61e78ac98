#include "distance/unique_faces.hpp"

#include <algorithm>

#include "core/huge_pages.hpp"
#include "core/index_hash_table.hpp"
#include "distance/open_edges.hpp"

namespace levelset {

UniqueFacesResult unique_faces(const TriangleMesh& mesh) {
  // Weld: equal positions map to the lowest index among them.
  const std::vector<std::uint32_t> weld = weld_exact(mesh.vertices);

  UniqueFacesResult result;
  reserve_with_huge_pages(result.mesh.vertices, mesh.vertices.size());
  result.mesh.vertices.assign(mesh.vertices.begin(), mesh.vertices.end());
  struct Key {
    std::array<std::uint32_t, 3> sorted;
    std::uint32_t face;
    int orientation;  // +1 / -1: the parity of the face's vertex order against the sorted one
  };
  // Faces grouped by their welded vertex set in one pass (the first face of each set is its
  // representative); only the sets met more than once are sorted below.
  std::vector<Key> keys;
  reserve_with_huge_pages(keys, mesh.triangles.size());
  IndexHashTable table(mesh.triangles.size());
  std::vector<std::uint32_t> copies;  // per representative face
  resize_with_huge_pages(copies, mesh.triangles.size());
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
    const std::uint64_t hash = (std::uint64_t{t[0]} << 32 | t[1]) ^ IndexHashTable::mix(t[2]);
    const std::uint32_t first = table.find_or_insert(hash, std::uint32_t(keys.size() - 1), [&](std::uint32_t k) {
      const std::array<std::uint32_t, 3>& o = keys[k].sorted;  // not operator== (a memcmp call)
      return o[0] == t[0] && o[1] == t[1] && o[2] == t[2];
    });
    ++copies[keys[first].face];
  }
  // Sets met once keep their face; every face of a repeated set goes through the sort.
  std::vector<std::uint32_t> kept;
  kept.reserve(keys.size());
  std::vector<Key> repeated;
  for (const Key& k : keys) {
    if (copies[k.face] == 1)
      kept.push_back(k.face);
    else  // a representative with copies, or a copy (0: counted on its representative)
      repeated.push_back(k);
  }
  std::sort(repeated.begin(), repeated.end(), [](const Key& x, const Key& y) {
    return x.sorted != y.sorted ? x.sorted < y.sorted : x.face < y.face;
  });
  // Copies of a face: their orientations add up. Opposite copies cancel (a double-sided sheet
  // encloses nothing), so a group keeps one copy of the net orientation, or none when it is 0.
  for (std::size_t k = 0; k < repeated.size();) {
    std::size_t end = k;
    int net = 0;
    while (end < repeated.size() && repeated[end].sorted == repeated[k].sorted) net += repeated[end++].orientation;
    std::size_t keep = end;
    for (std::size_t j = k; j < end && net != 0; ++j)
      if (repeated[j].orientation == (net > 0 ? 1 : -1)) { keep = j; break; }
    if (keep != end) kept.push_back(repeated[keep].face);
    result.duplicates_removed += (end - k) - (keep != end ? 1 : 0);
    k = end;
  }
  // Same face count and order as the input (face indices stay valid); a dropped face becomes
  // the point triangle (a, a, a), which has no area, no solid angle and no crossings.
  resize_with_huge_pages(result.mesh.triangles, mesh.triangles.size());
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
