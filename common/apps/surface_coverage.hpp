// surface_coverage: the share of the points that a reconstructed surface passes near, a check
// of the result against its data. A surface can be closed and manifold and still miss the data:
// a sampled open sheet collapses to a scrap, a part thinner than a voxel vanishes. The number
// says so where the mesh measures cannot.
//
// Inputs: a NarrowBand (the surface is its zero level; world units), points (world), a
//   distance r (world, > 0), at most `samples` points tested (every ceil(N / samples)-th, so
//   the answer is deterministic), and an optional box: points outside it are not counted (a
//   reconstruction's isolated points, outside every grid).
// Output: the fraction of the tested points whose trilinear band value is within r of zero
//   (1 when no point is tested). A point in the band's far region reads +-W h, so r must be
//   below W h to mean anything; larger r are clamped to 0.99 W h.
// Cost: O(samples) trilinear reads. Threading: serial, reentrant.
// Errors: Error{InvalidArgument} for r not a positive finite number or samples == 0.
#pragma once

#include <cstddef>
#include <optional>
#include <span>

#include "core/bbox.hpp"
#include "core/vec3.hpp"
#include "grid/narrow_band.hpp"

namespace levelset::apps {

struct SurfaceCoverageOptions {
  double distance = 0.0;      // r (world)
  std::size_t samples = 10000;
  std::optional<BBox> within;  // count only the points inside this box
};

struct SurfaceCoverageResult {
  double fraction = 1.0;
  std::size_t tested = 0;
};

SurfaceCoverageResult surface_coverage(const NarrowBand& band, std::span<const Vec3d> points,
                                       const SurfaceCoverageOptions& options);

}  // namespace levelset::apps
