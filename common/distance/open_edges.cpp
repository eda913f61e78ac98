#include "distance/open_edges.hpp"

#include <cstring>
#include <numeric>

#include "core/error.hpp"
#include "core/index_hash_table.hpp"
#include "distance/edge_uses.hpp"

namespace levelset {

namespace {

// The bits of a coordinate with -0 read as +0 (they compare equal, so they must hash equal).
std::uint64_t coordinate_bits(double v) {
  if (v == 0.0) v = 0.0;
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

}  // namespace

std::vector<std::uint32_t> weld_exact(std::span<const Vec3d> positions) {
  const std::size_t n = positions.size();
  if (n >= 0xffffffffu) throw Error(ErrorCode::LimitExceeded, "weld_exact", "2^32 - 1 or more vertices");
  // In index order, each position maps to the first index holding it: the lowest. NaN
  // coordinates equal nothing, so such a vertex stays on its own.
  IndexHashTable table(n);
  std::vector<std::uint32_t> id(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const Vec3d& p = positions[i];
    const std::uint64_t hash = coordinate_bits(p.x) ^ IndexHashTable::mix(coordinate_bits(p.y) + 0x9e3779b97f4a7c15ull) ^
                               (IndexHashTable::mix(coordinate_bits(p.z)) << 1);
    id[i] = table.find_or_insert(hash, i, [&](std::uint32_t j) { return positions[j] == p; });
  }
  return id;
}

std::vector<std::array<std::uint32_t, 2>> open_edges(const TriangleMesh& mesh,
                                                     std::span<const std::uint32_t> welded,
                                                     const std::vector<bool>& counts) {
  const std::vector<EdgeUse> uses = sorted_edge_uses(mesh, welded, counts);
  std::vector<std::array<std::uint32_t, 2>> open;
  for (std::size_t i = 0; i < uses.size();) {
    int net = 0;
    std::size_t j = i;
    for (; j < uses.size() && uses[j].same_edge(uses[i]); ++j) net += uses[j].forward ? 1 : -1;
    if (net != 0 && uses[i].lo != uses[i].hi) open.push_back({uses[i].lo, uses[i].hi});
    i = j;
  }
  return open;
}

}  // namespace levelset
