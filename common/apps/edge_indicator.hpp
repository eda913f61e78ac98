// edge_indicator: the stopping function g = 1 / (1 + (|grad(G_sigma * I)| / contrast)^p) of an
//   image and its gradient (thesis 3.4, eq. 3.13; Malladi-Sethian-Vemuri; geodesic active
//   contours use grad g).
//
// Inputs: an ImageVolume; EdgeIndicatorOptions.
// Method: intensities are normalised to [0, 1] by a robust range (the low and high percentiles
//   of the samples, from at most 2^20 evenly strided samples; values outside are clamped), then
//   smoothed (apps/gaussian_smooth.hpp, sigma in image voxels). The gradient is taken by central
//   differences (one-sided at the border) in world units and scaled by the smallest spacing, so
//   |grad| is "normalised intensity change per voxel": a clean step of full contrast smoothed
//   with sigma = 1 voxel peaks near 0.4. g is 1 in flat regions and small on edges; grad g by
//   central differences in world units.
// Output: EdgeIndicator: g and grad g on the image grid, with trilinear samplers that return 0
//   (and a zero gradient) outside the image's voxel box, so a front stops at the image border.
// Cost: O(voxels) plus the smoothing. Memory: 4 floats + 1 float (g) per voxel.
// Threading: TBB over z-slices; deterministic. Samplers are safe to call concurrently.
// Errors: Error{InvalidArgument} for an empty image, contrast <= 0 or non-finite, p not 1 or 2,
//   percentiles not 0 <= low < high <= 1, and the smoothing's errors.
#pragma once

#include <vector>

#include "core/progress.hpp"
#include "core/vec3.hpp"
#include "io/image_volume.hpp"

namespace levelset::apps {

struct EdgeIndicatorOptions {
  double sigma = 1.0;             // Gaussian smoothing, image voxels (0: none)
  double contrast = 0.02;         // normalised intensity change per voxel where g = 1/2
  int power = 2;                  // p: 1 or 2
  double low_percentile = 0.01;   // robust intensity range mapped to [0, 1]
  double high_percentile = 0.99;
  ProgressHook progress;
};

struct EdgeIndicator {
  ImageVolume g;                  // the stopping function on the image grid
  std::vector<Vec3f> gradient;    // grad g, world units^-1, same indexing as g.samples
  double intensity_low = 0, intensity_high = 1;  // the range mapped to [0, 1]

  double sample(const Vec3d& world) const;            // trilinear; 0 outside the image
  Vec3d sample_gradient(const Vec3d& world) const;    // trilinear; 0 outside the image
};

EdgeIndicator edge_indicator(const ImageVolume& image, const EdgeIndicatorOptions& options = {});

}  // namespace levelset::apps
