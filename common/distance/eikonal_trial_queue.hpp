// TrialQueue: the fast marching trial set (eikonal_march.cpp), a min-queue of (value, voxel id)
// bucketed by value over [0, limit].
//
// push(e): stored when e.value <= limit (others are never accepted). pop(e): the smallest value
//   (ties: smallest id), false when empty. peek(): the entry pop() would give, or nullptr; a
//   push after an empty peek is still popped. assign(entries): bulk insertion.
// Values pushed must not be below the last popped one by more than rounding (the march only
//   pushes values above the one it accepted); such values go to the current slice.
// Cost: O(1) per push into a later slice (an append), one sort per slice when it becomes the
//   current one (entries of 1/256 voxel of values, cache-local), O(log k) for the rare push
//   into the current slice; memory O(n). Not thread-safe (one queue per marching side).
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

// Orders entries as the march accepts them: smaller value first, then smaller id.
struct EntryBefore {
  bool operator()(const HeapEntry& a, const HeapEntry& b) const {
    return a.value < b.value || (a.value == b.value && a.id < b.id);
  }
};

// The trial set: one bucket per slice of the value range [0, limit] (a global heap over the
// whole front misses the cache on every level). A bucket is appended to until it becomes the
// current slice, then sorted once and read in order; the few entries pushed into the current
// slice after that (values within 1/256 voxel of the one just accepted) go to a small heap
// merged with it. The march only ever pops the smallest value, and every pushed value lands in
// the current slice or a later one, so the pop order is exactly that of one global heap.
// Values above the limit are never accepted and are not stored.
class TrialQueue {
 public:
  explicit TrialQueue(double limit)
      : limit_(limit),
        slices_(std::size_t(std::clamp(std::ceil(limit * kSlicesPerVoxel), 1.0, double(kMaxSlices)))),
        per_unit_(double(slices_.size()) / limit) {}

  void push(const HeapEntry& e) {
    if (!(double(e.value) <= limit_)) return;
    const std::size_t s = slice_of(e.value);
    if (s == current_ && sorted_) {
      late_.push_back(e);
      std::push_heap(late_.begin(), late_.end(), HeapAfter{});
    } else {
      slices_[s].push_back(e);
    }
  }
  // Bulk insertion of the initial front (before the first pop or peek).
  void assign(const std::vector<HeapEntry>& entries) {
    for (const HeapEntry& e : entries) push(e);
  }
  bool pop(HeapEntry& e) {
    if (!advance()) return false;
    if (from_late()) {
      std::pop_heap(late_.begin(), late_.end(), HeapAfter{});
      e = late_.back();
      late_.pop_back();
    } else {
      e = slices_[current_][next_++];
    }
    return true;
  }
  // The entry pop() would give next (nullptr: none), for prefetching its voxel.
  const HeapEntry* peek() {
    if (!advance()) return nullptr;
    return from_late() ? &late_.front() : &slices_[current_][next_];
  }

 private:
  bool sorted_left() const { return next_ < slices_[current_].size(); }
  // Whether the next entry comes from the late heap rather than the sorted slice.
  bool from_late() const {
    return !late_.empty() && (!sorted_left() || EntryBefore{}(late_.front(), slices_[current_][next_]));
  }
  // Makes the current slice sorted and non-exhausted, moving on through empty ones, but never
  // past the last one: a push may follow an empty peek (the march pops a voxel, peeks, then
  // pushes its neighbours), and it must land in a slice that exists and is still to be popped.
  bool advance() {
    for (;;) {
      if (!sorted_) {
        std::sort(slices_[current_].begin(), slices_[current_].end(), EntryBefore{});
        next_ = 0;
        sorted_ = true;
      }
      if (sorted_left() || !late_.empty()) return true;
      if (current_ + 1 >= slices_.size()) return false;
      std::vector<HeapEntry>().swap(slices_[current_]);
      ++current_;
      sorted_ = false;
    }
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
  std::size_t current_ = 0, next_ = 0;  // the current slice and its next unread entry
  bool sorted_ = false;                 // the current slice has been sorted
  std::vector<HeapEntry> late_;         // pushed into the current slice after its sort (min-heap)
};

}  // namespace levelset::detail
