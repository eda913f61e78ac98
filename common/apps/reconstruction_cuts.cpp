// Cuts through the inside (reconstruction_parts.hpp): which inside voxels a snap may cut
// after the carving found a sheet of the inside spanning a gap (cutting_reach), and the
// scraps a cut leaves (drop_web_scraps).
#include <algorithm>
#include <cstdint>
#include <optional>
#include <unordered_set>
#include <vector>

#include "apps/reconstruction_parts.hpp"
#include "grid/band_accessor.hpp"

namespace levelset::apps::detail {

std::vector<std::uint64_t> cutting_reach(const NarrowBand& band, const std::vector<float>& next,
                                         const std::vector<std::uint64_t>& zone) {
  std::vector<std::uint64_t> leaving;  // inside now, outside in `next`
  std::size_t i = 0;
  band.for_each_active([&](const Coord& c, float v) {
    if (v < 0.0f && next[i] >= 0.0f) leaving.push_back(key_of(c));
    ++i;
  });
  std::sort(leaving.begin(), leaving.end());
  std::vector<std::uint8_t> reached(leaving.size(), 0);
  std::vector<std::size_t> stack;
  for (std::size_t k = 0; k < leaving.size(); ++k)
    if (std::binary_search(zone.begin(), zone.end(), leaving[k])) {
      reached[k] = 1;
      stack.push_back(k);
    }
  while (!stack.empty()) {
    const Coord c = coord_of(leaving[stack.back()]);
    stack.pop_back();
    for (int d = 0; d < 27; ++d) {
      const std::uint64_t key = key_of(c + Coord{d % 3 - 1, (d / 3) % 3 - 1, d / 9 - 1});
      const auto it = std::lower_bound(leaving.begin(), leaving.end(), key);
      if (it == leaving.end() || *it != key) continue;
      const std::size_t j = std::size_t(it - leaving.begin());
      if (reached[j]) continue;
      reached[j] = 1;
      stack.push_back(j);
    }
  }
  std::vector<std::uint64_t> out;
  for (std::size_t k = 0; k < leaving.size(); ++k)
    if (reached[k]) out.push_back(leaving[k]);
  return out;
}

// The inside scraps a cut web leaves (inside pieces of fewer than kMinPierceVoxels voxels,
// 6-connected, every voxel active, beside a cut voxel: the web's rim was within the clearance
// of a point and stayed; CGAL's bear_bis at 20k points, 0.5 % noise, kept one voxel apart)
// turned outside. Each piece is found by a flood fill from the cut's inside neighbours that
// stops past kMinPierceVoxels voxels or at an inactive one: O(cut voxels * 27 * 64) probes,
// no grid-sized memory.
void drop_web_scraps(NarrowBand& band, const std::vector<std::uint64_t>& cut) {
  const Coord steps[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  BandAccessor acc(band);
  std::unordered_set<std::uint64_t> seen;
  std::vector<std::uint64_t> piece, scraps;
  auto visited = [&](std::uint64_t k) {
    return std::find(piece.begin(), piece.end(), k) != piece.end();
  };
  for (const std::uint64_t k : cut) {
    const Coord c = coord_of(k);
    for (int d = 0; d < 27; ++d) {
      const Coord start = c + Coord{d % 3 - 1, (d / 3) % 3 - 1, d / 9 - 1};
      const std::uint64_t s = key_of(start);
      const std::optional<float> u = acc.probe(start);
      if (!u || *u >= 0.0f || seen.count(s) != 0) continue;
      // Flood fill over active inside voxels; small: a linear search of the piece suffices.
      piece.assign(1, s);
      bool small = true;
      for (std::size_t at = 0; at < piece.size() && small; ++at) {
        const Coord v = coord_of(piece[at]);
        for (const Coord& step : steps) {
          const Coord q = v + step;
          if (!acc.is_inside(q) || visited(key_of(q))) continue;
          if (!acc.probe(q) || piece.size() >= kMinPierceVoxels) {
            small = false;  // reaches the band's interior, or too large for a scrap
            break;
          }
          piece.push_back(key_of(q));
        }
      }
      if (small) scraps.insert(scraps.end(), piece.begin(), piece.end());
      seen.insert(piece.begin(), piece.end());
    }
  }
  if (scraps.empty()) return;
  std::vector<float> values(band.values().begin(), band.values().end());
  const float eps = float(1e-3 * band.voxel_size());
  for (const std::uint64_t k : scraps) {
    const Coord c = coord_of(k);
    const Brick& br = band.bricks()[acc.locate(brick_of(c))];
    float& v = values[br.value_offset + br.slot(local_index(c))];
    v = std::max(-v, eps);
  }
  band.swap_values(values);
}

}  // namespace levelset::apps::detail
