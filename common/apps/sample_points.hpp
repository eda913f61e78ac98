// Seeded point samples of surfaces: the input of the reconstruction's built-in job and tests.
//
// sample_mesh_surface: `count` points uniform by area on a triangle mesh (triangle chosen by
//   its area through a cumulative table, then uniform barycentric coordinates), plus isotropic
//   Gaussian noise of standard deviation noise (world units, 0: none).
// sample_shape_surface: the same on an analytic shape's exact surface: the marching-cubes mesh
//   of its band at `resolution` is sampled by area and every sample is projected onto the zero
//   level (two Newton steps p -= d(p) grad d(p), grad by central differences), then noise.
//   The density is uniform by area up to the mesh's O(h^2) area distortion.
// Random numbers: std::mt19937_64(seed) mapped by our own code (53-bit uniforms, Box-Muller),
//   so the samples are identical on every platform and for any thread count (serial).
// Errors: Error{Cancelled} through options.progress; Error{InvalidArgument} for count 0 or above 2^28, a negative or non-finite noise,
//   a mesh without area or with an index out of range.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "core/vec3.hpp"
#include "geometry/analytic_shapes.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::apps {

struct SurfaceSampleOptions {
  std::size_t count = 20000;
  double noise = 0.0;           // standard deviation of the Gaussian noise, world units
  std::uint64_t seed = 1;
  int resolution = 128;         // sample_shape_surface: the mesh it samples first
  ProgressHook progress;        // checked per 2^16 points and inside the shape's meshing
};

std::vector<Vec3d> sample_mesh_surface(const TriangleMesh& mesh, const SurfaceSampleOptions& options);
std::vector<Vec3d> sample_shape_surface(const AnalyticShape& shape, const SurfaceSampleOptions& options);

}  // namespace levelset::apps
