// segment_image: shape detection in a 3D image by a growing level set (thesis 3.4).
//
//   u_t + g (1 - eps H) |grad u| - attraction * s * grad g . grad u = 0
//
// g = 1 / (1 + (|grad(G_sigma * I)| / contrast)^p) is the edge indicator (apps/edge_indicator.hpp;
// thesis eq. 3.13 up to the contrast scale), H = k1 + k2 the mean curvature (speed.hpp
// convention: positive on a sphere, beta > 0 moves outward), eps the surface tension weight of
// eq. 3.12 (world units). The last term is the geodesic active contour attraction: advection with
// velocity -attraction * s * grad g (s = the image's smallest spacing, so it is measured in the
// same "per voxel" units as g's slope) pulls the front into the valley of g, so it stops on an
// edge instead of only slowing down (attraction = 0 gives the thesis's plain model).
//
// Inputs: an ImageVolume (world units by its spacing and origin); SegmentationOptions: seeds
//   (spheres in world coordinates of the image, radius 0 = options.seed_radius), the grid
//   (voxel size, default the image's smallest spacing; origin the image's, so an isotropic
//   image's voxels are grid voxels), edge and speed parameters, and when to stop.
// Method: 1. g and grad g on the image grid; 2. the band of the union of the seed spheres
//   (grid/build_from_sdf.hpp); 3. evolve/evolution.hpp with a speed reading `edge` (g
//   sampled trilinearly at voxel centres) and H, and the attraction as a velocity field;
//   the front moves with speed g (world units per time unit). u is kept a distance by extension
//   velocities and redistancing (options below). Stopping: a fixed number of steps,
//   a fixed time, or (both 0) until steady: every check_time the enclosed volume and area
//   (marching cubes) are measured and the run stops when the volume change over the interval,
//   divided by area * h (the front's mean normal motion in voxels), is at most
//   motion_tolerance, or at max_time / max_steps. Outside the image g = 0: fronts stop at the
//   image border.
// Output: SegmentationResult: the band, its surface and measures, optionally a label mask (1 for
//   image voxels whose centre is inside: trilinear level set value < 0).
// Cost: O(voxels) for g (plus the smoothing); per step O(active voxels) (27-point curvature
//   stencil); each check one marching cubes pass. Memory: about 6 floats per image voxel plus
//   the band: segmentation_memory_bytes estimates it from the image's dimensions alone, and
//   segment_image refuses (LimitExceeded) before allocating when image + estimate exceed
//   options.memory_budget. Callers that read the image check it before reading (the CLI and
//   the segment job read the header first).
// Threading: TBB everywhere; identical results for any thread count.
// Errors: Error{InvalidArgument} for no seeds, a non-finite or outside-the-image seed centre, a
//   seed radius below one grid voxel, bad parameters (negative or non-finite values, both steps
//   and time), those of edge_indicator; Error{LimitExceeded} when the image box holds more
//   grid voxels than max_grid_voxels or the memory estimate exceeds memory_budget; Error{Cancelled} by options.progress. An evolution that
//   meets a NaN stops with stop = NonFinite (nothing thrown), as evolve does.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "apps/edge_indicator.hpp"
#include "core/memory_budget.hpp"
#include "core/progress.hpp"
#include "evolve/evolution.hpp"
#include "grid/narrow_band.hpp"
#include "io/image_volume.hpp"
#include "surface/mesh_measures.hpp"
#include "surface/surface_result.hpp"

namespace levelset::apps {

struct SegmentationSeed {
  Vec3d center;         // world coordinates of the image
  double radius = 0.0;  // world units; 0: SegmentationOptions::seed_radius
};

struct SegmentationCheck {  // one steady-state check (on_check)
  int steps = 0;
  double time = 0, volume = 0, area = 0;
  double motion = 0;  // mean normal motion of the front since the last check, grid voxels
  std::uint64_t active_voxels = 0;
};

struct SegmentationOptions {
  std::vector<SegmentationSeed> seeds;
  double seed_radius = 0.0;       // world units; 0: 3 grid voxels (a seed of radius < 2 eps shrinks)
  EdgeIndicatorOptions edge;      // sigma (image voxels), contrast, power, percentiles
  double eps = -1.0;              // curvature weight (world units); < 0: one grid voxel
  double attraction = 2.0;        // geodesic attraction weight; 0: off
  double voxel_size = 0.0;        // grid spacing h; 0: the image's smallest spacing
  double half_width = 3.0;        // band half-width, voxels (>= 2)
  int steps = 0;                  // run exactly this many steps, or ...
  double time = 0.0;              // ... until this time; both 0: until steady
  double max_time = 0.0;          // cap for steady runs; 0: twice the image box diagonal
  int max_steps = 100000;         // cap on steps
  double check_time = 0.0;        // steady check interval (time); 0: 4 grid voxels
  double motion_tolerance = 0.1;  // steady: |volume change| / (area * h) over one interval, voxels
  // Keeping u a distance: g varies across the band (an edge slows the zero level while the band's
  // outer layers still move), so without redistancing the band thickens and fills the image.
  // Extension velocities do it exactly but cost 3x the time per step (same result within 0.02
  // voxel on the ball test), so redistancing is the default.
  bool extension = false;         // extension velocities: the speed of the closest point on the front
  int redistance_every = 20;      // redistance every N steps (0: not by count)
  double drift_tolerance = 0.2;   // ... and when the mean ||grad u| - 1| near the front exceeds this
  evolve::Scheme scheme = evolve::Scheme::Upwind1;
  int rk_order = 1;
  std::uint64_t max_grid_voxels = std::uint64_t{1} << 28;  // grid voxels in the image box (~6 floats each)
  // Image samples + segmentation_memory_bytes must fit (core/memory_budget.hpp, --memory-budget).
  std::uint64_t memory_budget = default_memory_budget();
  bool label_mask = false;        // fill SegmentationResult::label_mask
  std::function<void(const SegmentationCheck&)> on_check;
  ProgressHook progress;          // fraction of max_time (or steps / time); cancellable
};

struct SegmentationResult {
  NarrowBand band;
  SurfaceResult surface;          // marching cubes of the final band
  MeshMeasures measures;
  std::vector<std::uint8_t> label_mask;  // per image voxel (x fastest) when asked for
  std::uint64_t inside_voxels = 0;       // image voxels inside (when label_mask)
  int steps = 0;
  double time = 0;
  bool converged = false;         // steady by motion_tolerance
  double last_motion = 0;         // at the last check, grid voxels
  int checks = 0;
  double intensity_low = 0, intensity_high = 0;  // the normalisation range
  evolve::StopReason stop = evolve::StopReason::Completed;
  std::string message;
  double seconds_edges = 0, seconds_evolve = 0, seconds_surface = 0, seconds_total = 0;
};

SegmentationResult segment_image(const ImageVolume& image, const SegmentationOptions& options);

// What segment_image allocates at its peak beyond the image's own samples, from the image's
// dimensions and spacing only (image.samples may be empty: a header is enough): the edge
// indicator's working set (5 floats per image voxel while smoothing and differencing; g and
// grad g stay for the evolution), the label mask (1 byte per voxel, when asked for), and the
// band of a front as large as the image box's surface (grid voxels of options.voxel_size).
std::uint64_t segmentation_memory_bytes(const ImageVolume& image, const SegmentationOptions& options);

// Refuses (Error{LimitExceeded} at `where`, naming options.memory_budget and --memory-budget)
// an image whose samples, read from a file of file_bytes, plus segmentation_memory_bytes would
// not fit options.memory_budget. For callers that hold only the image's header.
void require_segmentation_budget(const ImageVolume& image, std::uint64_t file_bytes,
                                 const SegmentationOptions& options, const std::string& where);

// Image voxels whose centre lies inside the band's zero level (trilinear value < 0): 1, else 0;
// x fastest. TBB over z-slices.
std::vector<std::uint8_t> inside_mask(const NarrowBand& band, const ImageVolume& image);

}  // namespace levelset::apps
