// close_membranes: closes the narrow band of an open mesh across its holes, so that the zero
// level of closest_point_transform's band is a closed surface for every input.
//
// Why: the CPT signs voxels by the generalized winding number w (inside: w > 1/2). Across a
//   hole w changes continuously; where it crosses 1/2 -- the hole's "membrane", a surface
//   spanning the hole's rim -- the sign changes with no mesh nearby. Where the hole is wider
//   than the band, that sign change lies outside the band: the zero level has no voxels there
//   and the extracted surface is open (CGAL's cube-ouvert.off: genus 0.5, open).
// Inputs: the bricks of a band under construction (MembraneBrick: active mask, sign of every
//   voxel, unsigned mesh distances of the active voxels; sorted by brick key, each brick once),
//   the winding tree of the oriented mesh that gave the signs, MembraneOptions (frame: h,
//   origin, W; the searched world box, normally the mesh bounds).
// Output (in place): a membrane edge is a pair of 6-adjacent voxels of opposite sign whose
//   mesh distances sum to more than h (so no mesh crosses the edge: d_a + d_b <= h for any
//   edge the mesh crosses); its ends are membrane voxels. Every voxel within W voxels of a
//   membrane voxel is then active, valued
//     sign * min(d_mesh, d_membrane)
//   where d_mesh is the CPT's distance (+inf beyond the band) and d_membrane the distance to
//   the membrane: continuous (also across the membrane and at the hole's rim, where both
//   vanish), |grad| = 1 away from kinks, and with the zero level on w = 1/2 between membrane
//   voxels. Bricks are added where the membrane leaves the input's bricks (their voxels signed
//   by w, evaluated as below); the result stays sorted by key. Voxels that were active keep
//   their value where the mesh is nearer than the membrane: a band without membrane edges (a
//   closed mesh) is returned bit for bit unchanged. closest_point (options.closest_points:
//   every brick carries one per active voxel) gets, for voxels whose value now comes from the membrane, the voxel moved by -value along
//   the membrane distance's gradient (an estimate of the nearest membrane point).
// Method:
//   1. Membrane voxels per brick (mask algebra on the signs, distances checked per candidate).
//   2. Exploration, brick by brick: bricks within W + 1 voxels of a membrane voxel that are
//      missing are evaluated (w at voxel centres: trilinear over 8^3 / 4^3 blocks checked at
//      the block centre to kModelTolerance, direct tree queries on 2^3 blocks and wherever the
//      model is within kDecisionMargin of 1/2), their membrane voxels found, and so on until
//      the membrane closes on itself or reaches the mesh. Every membrane component touches the
//      mesh (w is harmonic off the mesh: no closed level surface), so it is reached from the
//      input's bricks.
//   3. d_membrane: on membrane voxels, the distance to the plane through the crossings of
//      w = 1/2 on their membrane edges (linear interpolation of direct w queries; an end whose
//      query contradicts its stored sign counts as lying on w = 1/2, within the tree's error),
//      as in redistance's interface step;
//      then fast marching (eikonal_march, first order) out to W voxels, and no farther than
//      kMembraneMargin voxels beyond a voxel's mesh distance: the merge keeps the membrane's
//      value only where it is below the mesh's, and along a characteristic (a straight line
//      from the membrane) the distance to the membrane grows at rate 1, the mesh's at rate at
//      most 1, so the membrane cannot win again downstream of a voxel where it lost; the margin
//      covers most of the march's discrete paths: against the march without the cap, over
//      the 48 open CGAL meshes at R = 128 and W = 3, 6, 12, no active voxel changes and values
//      move by at most 0.009 h (21k of their voxels move at all), far below the march's own
//      first-order error, while its work shrinks (b9_mesh at W = 12: of 349k voxels reached,
//      52k take the membrane's value and 240k lie more than a voxel beyond their mesh
//      distance). Margins of 4 and 8 voxels change less but save little.
// Cost: nothing beyond one pass over the bricks without membrane voxels; otherwise
//   O(membrane voxels) direct queries plus ~9-80 per added brick, and the march over the bricks
//   within W of the membrane (4 bytes per voxel of those bricks).
// Threading: TBB per brick (evaluation, membrane voxels, merge, and the march: eikonal_march
//   runs bricks of a checkerboard colour in parallel). Results
//   do not depend on the thread count.
// Limits: bricks are only added within the searched box grown by W + 1 voxels; a membrane
//   reaching past it (w > 1/2 far from the mesh, only for meshes wound several times around
//   a region) stays open there and is counted in `truncated_bricks`.
// Errors: Error{Cancelled} from the progress hook.
#pragma once

#include <cstdint>
#include <vector>

#include "core/bbox.hpp"
#include "core/progress.hpp"
#include "core/vec3.hpp"
#include "distance/winding_number.hpp"
#include "grid/brick_mask.hpp"
#include "grid/coord.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

inline constexpr double kModelTolerance = 2e-3;
inline constexpr double kDecisionMargin = 5e-3;
inline constexpr float kMembraneMargin = 2.0f;  // voxels (see Method, step 3)

struct MembraneBrick {
  Coord coord;
  BrickMask active;                  // voxels holding a distance
  BrickMask inside;                  // sign of every voxel (w > 1/2)
  std::vector<float> distance;       // unsigned world distances, packed in active order
  std::vector<Vec3f> closest_point;  // packed in active order, or empty (not tracked)
};

struct MembraneOptions {
  GridFrame frame;     // voxel size h, origin, band half-width W (voxels)
  BBox search_bounds;  // world box where bricks may be added (grown by W + 1 voxels)
  double beta = 3.0;   // winding tree accuracy for the membrane's queries
  bool closest_points = false;  // bricks carry closest_point: keep it per active voxel
  ProgressHook progress;
};

struct MembraneResult {
  std::uint64_t membrane_voxels = 0;   // ends of membrane edges (final band)
  std::uint64_t bricks_added = 0;      // bricks evaluated beyond the input's
  std::uint64_t voxels_added = 0;      // active voxels gained
  std::uint64_t voxels_changed = 0;    // voxels active before whose value is now the membrane's
  std::uint64_t winding_queries = 0;
  std::uint64_t truncated_bricks = 0;  // wanted outside the searched box (membrane left open)
};

MembraneResult close_membranes(const WindingNumberTree& tree, std::vector<MembraneBrick>& bricks,
                               const MembraneOptions& options);

}  // namespace levelset
