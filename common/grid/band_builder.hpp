// BandBuilder: bulk construction of a NarrowBand from bricks produced in parallel.
//
// Contract: add_brick may be called concurrently from TBB workers, once per brick
// coordinate, with the brick's active mask, inside mask (for every voxel) and its dense
// 512 values (only active ones are read). finish() sorts bricks by key, packs values and
// builds the hash and neighbour tables, so the result is the same whatever order or thread
// the bricks came from. Duplicate brick coordinates throw Error{InvalidArgument}.
// Cost: O(active voxels + bricks log bricks); memory: staged values once plus the result.
#pragma once

#include <memory>

#include "grid/narrow_band.hpp"

namespace levelset {

class BandBuilder {
 public:
  explicit BandBuilder(const GridFrame& frame);
  ~BandBuilder();
  BandBuilder(const BandBuilder&) = delete;
  BandBuilder& operator=(const BandBuilder&) = delete;

  void add_brick(const Coord& brick, const BrickMask& active, const BrickMask& inside,
                 const float* dense_values);
  NarrowBand finish(bool far_inside = false);

 private:
  struct Staging;
  GridFrame frame_;
  std::unique_ptr<Staging> staging_;
};

}  // namespace levelset
