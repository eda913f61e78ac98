#include "grid/band_builder.hpp"

#include <algorithm>
#include <string>

#include <tbb/enumerable_thread_specific.h>

#include "core/error.hpp"

namespace levelset {

namespace {
struct StagedBrick {
  std::uint64_t key;
  BrickRecord record;
  std::uint32_t staged_offset;  // first value in the owning thread's staged values
  std::uint32_t owner;          // index of the thread-local staging it lives in
};
struct LocalStaging {
  std::vector<StagedBrick> bricks;
  std::vector<float> values;
};
}  // namespace

struct BandBuilder::Staging {
  tbb::enumerable_thread_specific<LocalStaging> local;
};

BandBuilder::BandBuilder(const GridFrame& frame)
    : frame_(frame), staging_(std::make_unique<Staging>()) {
  NarrowBand validate(frame);  // throws on a bad frame before any work is done
  (void)validate;
}

BandBuilder::~BandBuilder() = default;

void BandBuilder::add_brick(const Coord& brick, const BrickMask& active, const BrickMask& inside,
                            const float* dense_values) {
  if (!brick_in_range(brick))
    throw Error(ErrorCode::LimitExceeded, "brick",
                "brick (" + std::to_string(brick.x) + "," + std::to_string(brick.y) + "," +
                    std::to_string(brick.z) + ") is outside the index range");
  LocalStaging& s = staging_->local.local();
  StagedBrick sb{brick_key(brick), {brick, active, inside}, 0, 0};
  if (s.values.size() >= 0xffffffffu)
    throw Error(ErrorCode::LimitExceeded, "BandBuilder", "more than 2^32-1 staged voxels");
  sb.staged_offset = static_cast<std::uint32_t>(s.values.size());
  active.for_each_set([&](int n) { s.values.push_back(dense_values[n]); });
  s.bricks.push_back(sb);
}

NarrowBand BandBuilder::finish(bool far_inside) {
  std::vector<LocalStaging*> owners;
  std::vector<StagedBrick> all;
  for (LocalStaging& s : staging_->local) {
    const auto owner = static_cast<std::uint32_t>(owners.size());
    owners.push_back(&s);
    for (StagedBrick sb : s.bricks) {
      sb.owner = owner;
      all.push_back(sb);
    }
  }
  std::sort(all.begin(), all.end(),
            [](const StagedBrick& a, const StagedBrick& b) { return a.key < b.key; });
  for (std::size_t i = 1; i < all.size(); ++i) {
    if (all[i].key == all[i - 1].key) {
      const Coord c = all[i].record.coord;
      throw Error(ErrorCode::InvalidArgument, "BandBuilder",
                  "brick (" + std::to_string(c.x) + "," + std::to_string(c.y) + "," +
                      std::to_string(c.z) + ") added twice");
    }
  }
  std::vector<BrickRecord> records(all.size());
  std::vector<std::uint64_t> offsets(all.size());
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    records[i] = all[i].record;
    offsets[i] = total;
    total += static_cast<std::uint64_t>(all[i].record.active.count());
    if (total >= 0xffffffffull)
      throw Error(ErrorCode::LimitExceeded, "BandBuilder", "more than 2^32-1 active voxels");
  }
  std::vector<float> values(total);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, all.size(), 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const StagedBrick& sb = all[i];
                        const float* src = owners[sb.owner]->values.data() + sb.staged_offset;
                        std::copy_n(src, sb.record.active.count(), values.data() + offsets[i]);
                      }
                    });
  staging_ = std::make_unique<Staging>();
  return NarrowBand::assemble(frame_, std::move(records), std::move(values), far_inside);
}

}  // namespace levelset
