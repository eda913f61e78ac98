// "Did you mean" for names typed by users (formula identifiers, job-file keys).
// edit_distance: Levenshtein distance (insertions, deletions, substitutions), O(|a| |b|) time,
//   O(|b|) memory. closest_name: the candidate nearest to `name` within max_distance edits
//   (the first of equals), or an empty string. Threading: pure functions.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace levelset {

inline std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t prev = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cur = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, prev + (a[i - 1] == b[j - 1] ? 0 : 1)});
      prev = cur;
    }
  }
  return row[b.size()];
}

template <typename Names>
std::string closest_name(std::string_view name, const Names& candidates, std::size_t max_distance = 2) {
  std::string best;
  std::size_t best_d = max_distance + 1;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(name, std::string_view(c));
    if (d < best_d) {
      best_d = d;
      best = std::string(std::string_view(c));
    }
  }
  return best;
}

}  // namespace levelset
