// Region tools on 3D images (io/image_volume.hpp) for shape detection and its checks:
//   downsample_image: box average over factor^3 voxels (the last partial blocks dropped);
//     spacing x factor, origin at the first block's centre. Error{InvalidArgument} for a factor
//     < 1 or larger than a side.
//   seed_voxels_above: lattice voxels (every `stride` along x and y, every max(1, stride / 2)
//     along z) whose (2r+1)^3 neighbourhood lies entirely above t: seeds a user would click
//     well inside bright structures. Returns voxel indices (x fastest).
//   threshold_component: the 6-connected components of {I > t} that contain the seed voxels
//     (a seed at or below t starts none), as a 0/1 mask.
//   dice: 2 |A and B| / (|A| + |B|) of two 0/1 masks of equal size (1 when both are empty).
// Cost: O(voxels). Threading: serial (downsample_image: TBB over slices). progress: checked
//   per slice / per 2^20 voxels (Error{Cancelled}).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "io/image_volume.hpp"

namespace levelset::apps {

ImageVolume downsample_image(const ImageVolume& image, int factor, const ProgressHook& progress = {});
std::vector<std::size_t> seed_voxels_above(const ImageVolume& image, float t, int stride, int box_radius,
                                           const ProgressHook& progress = {});
std::vector<std::uint8_t> threshold_component(const ImageVolume& image, float t, const std::vector<std::size_t>& seeds,
                                              const ProgressHook& progress = {});
double dice(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b);

}  // namespace levelset::apps
