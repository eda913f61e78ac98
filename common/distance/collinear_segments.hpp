// uncovered_segment_parts: of segments that share lines, the parts no lower-numbered segment on
// the same line covers.
//
// Why: a degenerate face whose vertices lie on one line has its longest edge as its closest
// points, and the characteristic scan gives it that edge's whole cylinder. Subdividing such
// faces (scans with slid vertices, CGAL's degtri_sliding.off) leaves many of them on one line,
// each overlapping the others: every voxel near the line was evaluated against each (36
// evaluations per band voxel there at W = 12). A point of the line inside a lower-numbered
// segment is at the same distance from both (to the tolerance), and ties go to the lowest
// triangle anyway, so only the uncovered parts need their cylinders: each point of the line is
// scanned once, by the lowest-numbered segment holding it.
//
// Inputs: segments (world units; a != b), in the order that ranks them (the lowest index wins);
//   tolerance (world units): how far a segment's ends may lie from another's line and still
//   count as on it.
// Output: per segment i the parts [offsets[i], offsets[i + 1]) of `parts`, each a sub-segment of
//   segment i (none where lower-numbered segments cover all of it). A segment no other shares a
//   line with is one part, itself. Every point of every segment lies within 2 * tolerance of a
//   part of a segment at or below its index.
// Method: segments are grouped by their quantised line (direction with a canonical sign, the
//   foot of the perpendicular from the origin), which may split a group at a quantisation edge
//   (then less is saved, nothing is lost); within a group, members whose ends lie within the
//   tolerance of its first member's line are intervals along that line, subtracted in index
//   order from the union of those before.
// Cost: O(S log S) (a line dashed into many disjoint pieces included: each piece of a group's
//   union is merged away at most once). Threading: none. Errors: none.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/vec3.hpp"

namespace levelset {

struct SegmentParts {
  std::vector<std::uint32_t> offsets;       // segments + 1
  std::vector<std::array<Vec3d, 2>> parts;  // sub-segments, per segment in order along it
};

SegmentParts uncovered_segment_parts(std::span<const std::array<Vec3d, 2>> segments, double tolerance);

}  // namespace levelset
