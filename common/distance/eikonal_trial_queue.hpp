// TrialQueue: the fast marching trial set (eikonal_march.cpp), a min-queue of (value, voxel id)
// bucketed by value over [0, limit].
//
// push(e): stored when e.value <= limit (others are never accepted). pop(e): the smallest value
//   (ties: smallest id), false when empty. peek(): the entry pop() would give, or nullptr; a
//   push after an empty peek is still popped. assign(entries): bulk insertion.
// Values pushed must not be below the last popped one by more than rounding (the march only
//   pushes values above the one it accepted); such values go to the current slice.
// Cost: O(log n) per push and pop within a slice of 1/256 voxel; memory O(n). Not thread-safe
//   (one queue per marching side).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace levelset::detail {

struct HeapEntry {
  float value;
  std::uint32_t id;  // brick * 512 + voxel
};
struct HeapAfter {
  bool operator()(const HeapEntry& a, const HeapEntry& b) const {
    return a.value > b.value || (a.value == b.value && a.id > b.id);
  }
};

// The trial set: binary min-heaps, one per slice of the value range [0, limit] (a global
// heap over the whole front misses the cache on every level). The march only ever pops the
// smallest value, and every pushed value lands in the current slice or a later one, so the
// pop order is exactly that of one global heap. Values above the limit are never accepted
// and are not stored.
class TrialQueue {
 public:
  explicit TrialQueue(double limit)
      : limit_(limit),
        slices_(std::size_t(std::clamp(std::ceil(limit * kSlicesPerVoxel), 1.0, double(kMaxSlices)))),
        per_unit_(double(slices_.size()) / limit) {}

  void push(const HeapEntry& e) {
    if (!(double(e.value) <= limit_)) return;
    std::vector<HeapEntry>& h = slices_[slice_of(e.value)];
    h.push_back(e);
    std::push_heap(h.begin(), h.end(), HeapAfter{});
  }
  // Bulk insertion of the initial front.
  void assign(const std::vector<HeapEntry>& entries) {
    for (const HeapEntry& e : entries)
      if (double(e.value) <= limit_) slices_[slice_of(e.value)].push_back(e);
    for (auto& h : slices_) std::make_heap(h.begin(), h.end(), HeapAfter{});
  }
  bool pop(HeapEntry& e) {
    if (!advance()) return false;
    std::vector<HeapEntry>& h = slices_[current_];
    std::pop_heap(h.begin(), h.end(), HeapAfter{});
    e = h.back();
    h.pop_back();
    return true;
  }
  // The entry pop() would give next (nullptr: none), for prefetching its voxel.
  const HeapEntry* peek() {
    if (!advance()) return nullptr;
    return &slices_[current_].front();
  }

 private:
  // Moves to the first non-empty slice, but never past the last one: a push may follow an
  // empty peek (the march pops a voxel, peeks, then pushes its neighbours), and it must land in
  // a slice that exists and is still to be popped.
  bool advance() {
    while (current_ + 1 < slices_.size() && slices_[current_].empty()) {
      slices_[current_].shrink_to_fit();
      ++current_;
    }
    return !slices_[current_].empty();
  }
  static constexpr double kSlicesPerVoxel = 256.0;
  static constexpr std::size_t kMaxSlices = 1 << 16;
  std::size_t slice_of(float v) const {
    const double k = std::floor(double(v) * per_unit_);
    const std::size_t last = slices_.size() - 1;
    const std::size_t s = k <= 0.0 ? 0 : (k >= double(last) ? last : std::size_t(k));
    return std::max(s, current_);  // below the current slice (rounding): still the minimum
  }
  double limit_;
  std::vector<std::vector<HeapEntry>> slices_;
  double per_unit_;
  std::size_t current_ = 0;
};

}  // namespace levelset::detail
