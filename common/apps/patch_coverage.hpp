// patch_coverage: whether a position lies inside a sampled surface patch, in a gap between its
// samples, rather than off the surface or beyond its edge. The coarse flow's topology guard lets
// topology change far from the points (a bridge the start shell put between nearby parts must
// be able to open); a hole between the samples of a thin part is not far from the data in that
// sense, and opening it punched holes in every sheet sampled more sparsely than the coarse
// voxel (a sampled hemisphere: genus 31 after one step).
//
// Inputs: a PointIndex (world units), a position x, options (k neighbours, the largest angular
//   gap, the offset and flatness ratios).
// Method: the k nearest points' plane fit (centroid c, normal n = the covariance's smallest
//   eigenvector, residual sigma = sqrt of its eigenvalue) and r1, the nearest point's distance.
//   Inside the patch when x lies near the plane (|(x - c).n| <= offset_ratio r1: a voxel centre
//   beside a sampled sheet lies up to 0.87 voxels off it), the patch is flat
//   at that scale (sigma <= flatness r1: two sheets on either side of x, as across a bridge,
//   are not one patch), and the points surround x in the plane: the largest angle between
//   consecutive directions of their projections (x to p, in the plane) is at most
//   max_angular_gap (an edge or a corner of the patch leaves a gap of 180 degrees or more).
// Output: PatchCoverageResult (the decision and the measures behind it). Fewer than 3
//   neighbours: not inside.
// Cost: one k-nearest query and O(k log k). Threading: reentrant (const index).
#pragma once

#include <numbers>

#include "apps/point_distance.hpp"
#include "core/vec3.hpp"

namespace levelset::apps {

struct PatchCoverageOptions {
  int neighbors = 12;
  double max_angular_gap = 2.0 * std::numbers::pi / 3.0;  // radians
  double flatness = 0.5;                                  // residual, of the nearest point's distance
  double offset_ratio = 0.75;                             // offset from the plane, of the nearest point's distance
};

struct PatchCoverageResult {
  bool inside = false;       // x lies in a gap of a sampled patch
  double nearest = 0.0;      // r1 (world)
  double offset = 0.0;       // |(x - c).n| (world)
  double residual = 0.0;     // sigma (world)
  double angular_gap = 0.0;  // radians
};

PatchCoverageResult patch_coverage(const PointIndex& index, const Vec3d& x, const PatchCoverageOptions& options = {});

}  // namespace levelset::apps
