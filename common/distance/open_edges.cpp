#include "distance/open_edges.hpp"

#include <numeric>

#include <tbb/parallel_sort.h>

namespace levelset {

std::vector<std::uint32_t> weld_exact(std::span<const Vec3d> positions) {
  const std::size_t n = positions.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  auto less = [&](std::uint32_t a, std::uint32_t b) {
    const Vec3d& p = positions[a];
    const Vec3d& q = positions[b];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    if (p.z != q.z) return p.z < q.z;
    return a < b;
  };
  tbb::parallel_sort(order.begin(), order.end(), less);
  std::vector<std::uint32_t> id(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i + 1;
    while (j < n && positions[order[j]] == positions[order[i]]) ++j;
    for (std::size_t k = i; k < j; ++k) id[order[k]] = order[i];  // lowest index: sorted by index
    i = j;
  }
  return id;
}

std::vector<std::array<std::uint32_t, 2>> open_edges(const TriangleMesh& mesh,
                                                     std::span<const std::uint32_t> welded,
                                                     const std::vector<bool>& counts) {
  struct Use {
    std::uint64_t key;
    int direction;
    bool operator<(const Use& o) const {
      return key != o.key ? key < o.key : direction < o.direction;
    }
  };
  std::vector<Use> uses;
  uses.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!counts[t]) continue;
    const auto& f = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = welded[f[k]], b = welded[f[(k + 1) % 3]];
      if (a == b) continue;
      uses.push_back({a < b ? (a << 32) | b : (b << 32) | a, a < b ? 1 : -1});
    }
  }
  tbb::parallel_sort(uses.begin(), uses.end());
  std::vector<std::array<std::uint32_t, 2>> open;
  for (std::size_t i = 0; i < uses.size();) {
    int net = 0;
    std::size_t j = i;
    for (; j < uses.size() && uses[j].key == uses[i].key; ++j) net += uses[j].direction;
    if (net != 0) open.push_back({std::uint32_t(uses[i].key >> 32), std::uint32_t(uses[i].key)});
    i = j;
  }
  return open;
}

}  // namespace levelset
