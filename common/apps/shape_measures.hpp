// measure_shape: size, topology and roughness of a narrow band's zero level, the before/after
// report of the shape operations (offset, fairing, min/max flow, CSG).
//
// Inputs: a NarrowBand (world distances, negative inside, half-width >= 3 voxels for the
//   curvature stencils).
// Outputs (ShapeMeasures), all on the marching-cubes mesh of the zero level:
//   area, volume, components, genus, watertight (surface/mesh_measures.hpp);
//   sphere: the least-squares sphere through the mesh vertices (algebraic fit
//     |x|^2 = 2 c.x + (r^2 - |c|^2), then the radial deviation |x - c| - r: its RMS and
//     largest magnitude): the deviation from a round shape;
//   curvature: the mean curvature H = k1 + k2 sampled from the band at every mesh vertex
//     (apps/band_curvature.hpp), weighted by the vertex area (a third of the adjacent
//     triangles' areas): its mean, variance and largest |H|. The variance is the roughness
//     measure of fairing (a sphere has variance 0).
// Units: world (area world^2, volume world^3, H 1/world, variance 1/world^2).
// Cost: the mesh O(bricks * 11^3 + output), 216 accessor reads per vertex.
// Threading: TBB (meshing and the per-vertex curvature); sums run in vertex order, so the
//   result is identical for any thread count.
// Errors: those of marching_cubes; an empty zero level gives zeros.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::apps {

struct SphereFit {
  Vec3d center{};
  double radius = 0;
  double rms_deviation = 0;  // RMS of |x - center| - radius over the points
  double max_deviation = 0;  // largest | |x - center| - radius |
};

// Least-squares sphere through points (at least 4, not coplanar; otherwise a zero fit).
SphereFit fit_sphere(std::span<const Vec3d> points);

struct CurvatureStats {
  double mean = 0;      // area-weighted mean of H
  double variance = 0;  // area-weighted variance of H
  double max_abs = 0;   // largest |H| at a vertex
};

// H at every vertex of mesh, sampled from band (one value per vertex, in vertex order).
std::vector<double> vertex_mean_curvatures(const NarrowBand& band, const TriangleMesh& mesh);
// Area-weighted statistics of per-vertex values (a third of each triangle's area per corner).
CurvatureStats weighted_curvature_stats(const TriangleMesh& mesh, std::span<const double> h);

struct ShapeMeasures {
  double area = 0, volume = 0;
  std::uint64_t components = 0;
  double genus = 0;
  std::uint64_t vertices = 0, triangles = 0;
  bool watertight = false;
  SphereFit sphere;
  CurvatureStats curvature;
};

ShapeMeasures measure_shape(const NarrowBand& band);

}  // namespace levelset::apps
