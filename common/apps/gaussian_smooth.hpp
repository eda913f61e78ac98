// gaussian_smooth: separable Gaussian filter G_sigma * I of a 3D image (thesis 3.4, eq. 3.13).
//
// Inputs: an ImageVolume; sigma in image voxels (the same count of voxels along each axis, as
//   the thesis filters the raw voxel grid); sigma = 0 returns a copy.
// Method: three 1D passes with a normalised kernel of radius ceil(3 sigma); the border sample is
//   repeated beyond the image (so a constant image stays constant).
// Output: an image with the same grid. Cost: O(voxels * (6 sigma + 1) * 3). Memory: 2 images.
// Threading: TBB over image lines; identical results for any thread count.
// Errors: Error{InvalidArgument} for sigma < 0, non-finite or above 64 voxels.
#pragma once

#include "core/progress.hpp"
#include "io/image_volume.hpp"

namespace levelset::apps {

ImageVolume gaussian_smooth(const ImageVolume& image, double sigma, const ProgressHook& progress = {});

}  // namespace levelset::apps
