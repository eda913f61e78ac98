#include "distance/edge_uses.hpp"

#include <algorithm>

#include "core/huge_pages.hpp"

namespace levelset {

std::vector<EdgeUse> sorted_edge_uses(const TriangleMesh& mesh, std::span<const std::uint32_t> ids,
                                      const std::vector<bool>& counted) {
  const std::size_t nf = mesh.triangles.size();
  auto taken = [&](std::size_t t) { return counted.empty() || counted[t]; };
  std::vector<std::uint32_t> bucket(ids.size() + 1, 0);
  for (std::size_t t = 0; t < nf; ++t) {
    if (!taken(t)) continue;
    const auto& f = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) ++bucket[std::min(ids[f[k]], ids[f[(k + 1) % 3]]) + 1];
  }
  for (std::size_t v = 0; v + 1 < bucket.size(); ++v) bucket[v + 1] += bucket[v];
  std::vector<EdgeUse> uses;
  resize_with_huge_pages(uses, bucket.back());
  {
    std::vector<std::uint32_t> fill(bucket.begin(), bucket.end() - 1);
    for (std::size_t t = 0; t < nf; ++t) {
      if (!taken(t)) continue;
      const auto& f = mesh.triangles[t];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = ids[f[k]], b = ids[f[(k + 1) % 3]];
        const std::uint32_t lo = std::min(a, b);
        uses[fill[lo]++] = {lo, std::max(a, b), std::uint32_t(t), std::uint8_t(k), a < b};
      }
    }
  }
  for (std::size_t v = 0; v + 1 < bucket.size(); ++v) {
    const std::uint32_t begin = bucket[v], end = bucket[v + 1];
    if (end - begin > 32) {  // a fan's apex: sorted like any (the order is total)
      std::sort(uses.begin() + begin, uses.begin() + end);
      continue;
    }
    for (std::uint32_t i = begin + 1; i < end; ++i)
      for (std::uint32_t j = i; j > begin && uses[j] < uses[j - 1]; --j) std::swap(uses[j], uses[j - 1]);
  }
  return uses;
}

}  // namespace levelset
