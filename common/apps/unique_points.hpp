// unique_points: a point cloud without its duplicates (points closer than a tolerance), so
// that k-nearest statistics count distinct samples: a scan merged from overlapping views, or
// a file that lists every point three times, otherwise reads as three times denser (the
// sampling gap and the resolution follow it), and every local fit of k points sees k / 3
// distinct ones: a sphere given three times reconstructed to a few scraps (genus 26).
//
// Inputs: points (world units, finite); options.tolerance t (world, >= 0; 0: exact copies
//   only).
// Method: each point's cell in the grid of side t (t = 0: its exact coordinates); the points
//   sorted by cell (stable), the first point of each cell kept. So two points merge when they
//   share a cell: always for exact copies, for t > 0 whenever they are within t along every
//   axis of the same cell (two points closer than t across a cell face stay apart; the rule
//   is for copies and scanner jitter far below any voxel, not for thinning). A coordinate
//   beyond 2^62 cells is treated with t = 0 (exact) to avoid overflow.
// Output: the kept points in their input order and how many were merged into them.
// Cost: O(N log N) (one sort of 24-byte keys), O(N) memory. Threading: serial.
// Errors: Error{InvalidArgument} for a negative or non-finite tolerance.
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec3.hpp"

namespace levelset::apps {

struct UniquePointsOptions {
  double tolerance = 0.0;  // world; points sharing a cell of this side merge (0: exact copies)
};

struct UniquePointsResult {
  std::vector<Vec3d> points;  // the first point of each cell, in input order
  std::uint64_t merged = 0;   // points dropped as duplicates
};

UniquePointsResult unique_points(const std::vector<Vec3d>& points, const UniquePointsOptions& options = {});

}  // namespace levelset::apps
