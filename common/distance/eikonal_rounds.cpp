#include "distance/eikonal_rounds.hpp"

#include <algorithm>
#include <atomic>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace levelset::detail {

std::vector<BrickMask> free_masks(const RedistanceDomain& w) {
  std::vector<BrickMask> free_mask(w.size());
  for (std::size_t b = 0; b < w.size(); ++b)
    for (int k = 0; k < 8; ++k) free_mask[b].words[k] = w.domain[b].words[k] & ~w.fixed[b].words[k];
  return free_mask;
}

int brick_rounds(const RedistanceDomain& w, const std::vector<BrickMask>& free_mask, int max_rounds,
                 float tolerance, std::string_view stage, const ProgressHook& progress, const BrickKernel& kernel) {
  const std::size_t n = w.size();
  std::vector<std::uint32_t> colour[2];
  for (std::uint32_t b = 0; b < n; ++b) {
    if (free_mask[b].none()) continue;
    const Coord c = w.coords[b];
    colour[(c.x + c.y + c.z) & 1].push_back(b);
  }
  // Per brick: bit f = the neighbour across face f changed its layer there; bit 6 = own work.
  std::vector<std::atomic<std::uint8_t>> flags(n);
  for (auto& f : flags) f.store(kOwnWork, std::memory_order_relaxed);
  std::vector<float> change(n, 0.0f);
  int rounds = 0;
  while (rounds < max_rounds) {
    bool any = false;
    float max_change = 0.0f;
    for (int c = 0; c < 2; ++c) {
      const std::vector<std::uint32_t>& list = colour[c];
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, list.size(), 4), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const std::uint32_t b = list[i];
          change[b] = -1.0f;  // not visited
          const std::uint8_t bits = flags[b].exchange(0, std::memory_order_relaxed);
          if (bits == 0) continue;
          const BrickPass s = kernel(b, bits);
          change[b] = s.max_change;
          if (s.more_work) flags[b].fetch_or(kOwnWork, std::memory_order_relaxed);
          for (int f = 0; f < 6; ++f) {
            const std::uint32_t nb = w.nbr[b][f];
            if ((s.changed_faces >> f & 1) && nb != kNoBrick)
              flags[nb].fetch_or(std::uint8_t(1u << (f ^ 1)), std::memory_order_relaxed);
          }
        }
      });
      for (std::uint32_t b : list) {
        if (change[b] < 0.0f) continue;
        any = true;
        max_change = std::max(max_change, change[b]);
      }
    }
    if (!any) break;
    ++rounds;
    progress.step(0.1 + 0.8 * double(rounds) / max_rounds, stage);
    if (max_change < tolerance) break;
  }
  return rounds;
}

}  // namespace levelset::detail
