// uncovered_segment_parts: every point of every segment is covered once, by a part of the
// lowest-numbered segment on its line that holds it; segments on no shared line stay whole.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "distance/collinear_segments.hpp"

namespace levelset {
namespace {

using Segment = std::array<Vec3d, 2>;

double distance_to_segment(const Vec3d& p, const Segment& s) {
  const Vec3d d = s[1] - s[0];
  const double t = std::clamp(dot(p - s[0], d) / dot(d, d), 0.0, 1.0);
  return length(p - (s[0] + d * t));
}

// A part lies on its segment: both ends within `tol` of it.
void expect_parts_on_segments(const std::vector<Segment>& segments, const SegmentParts& out, double tol) {
  ASSERT_EQ(out.offsets.size(), segments.size() + 1);
  for (std::size_t i = 0; i < segments.size(); ++i)
    for (std::uint32_t k = out.offsets[i]; k < out.offsets[i + 1]; ++k) {
      EXPECT_LE(distance_to_segment(out.parts[k][0], segments[i]), tol) << i;
      EXPECT_LE(distance_to_segment(out.parts[k][1], segments[i]), tol) << i;
    }
}

// Every sampled point of segment i is within tol of a part of some segment j <= i.
void expect_covered(const std::vector<Segment>& segments, const SegmentParts& out, double tol) {
  for (std::size_t i = 0; i < segments.size(); ++i)
    for (int s = 0; s <= 50; ++s) {
      const Vec3d p = segments[i][0] + (segments[i][1] - segments[i][0]) * (s / 50.0);
      bool found = false;
      for (std::size_t j = 0; j <= i && !found; ++j)
        for (std::uint32_t k = out.offsets[j]; k < out.offsets[j + 1] && !found; ++k)
          found = distance_to_segment(p, out.parts[k]) <= tol;
      EXPECT_TRUE(found) << "segment " << i << " sample " << s;
    }
}

double total_length(const SegmentParts& out) {
  double sum = 0;
  for (const auto& part : out.parts) sum += length(part[1] - part[0]);
  return sum;
}

TEST(CollinearSegments, OverlapsOnOneLineAreScannedOnce) {
  // On the x axis: [1, 4], [4, 6], [1, 5] (reversed), [0.5, 2]: union [0.5, 6].
  const std::vector<Segment> segments = {
      {Vec3d{1, 0, 0}, Vec3d{4, 0, 0}}, {Vec3d{4, 0, 0}, Vec3d{6, 0, 0}},
      {Vec3d{5, 0, 0}, Vec3d{1, 0, 0}}, {Vec3d{0.5, 0, 0}, Vec3d{2, 0, 0}}};
  const SegmentParts out = uncovered_segment_parts(segments, 1e-9);
  expect_parts_on_segments(segments, out, 1e-12);
  expect_covered(segments, out, 1e-12);
  EXPECT_EQ(out.offsets[1] - out.offsets[0], 1u);  // the first is whole
  EXPECT_EQ(out.offsets[3] - out.offsets[2], 0u);  // [1, 5] lies inside [1, 4] and [4, 6]
  EXPECT_EQ(out.offsets[4] - out.offsets[3], 1u);  // [0.5, 1] is new
  EXPECT_NEAR(total_length(out), 5.5, 1e-12);      // each point of the union once
}

TEST(CollinearSegments, ParallelAndCrossingSegmentsStayWhole) {
  const std::vector<Segment> segments = {
      {Vec3d{0, 0, 0}, Vec3d{2, 0, 0}},
      {Vec3d{0, 1e-6, 0}, Vec3d{2, 1e-6, 0}},  // parallel, beyond the tolerance
      {Vec3d{1, -1, 0}, Vec3d{1, 1, 0}},       // crossing
      {Vec3d{0, 0, 0}, Vec3d{0, 0, 0}}};       // a point
  const SegmentParts out = uncovered_segment_parts(segments, 1e-9);
  for (std::size_t i = 0; i < segments.size(); ++i) {
    ASSERT_EQ(out.offsets[i + 1] - out.offsets[i], 1u) << i;
    EXPECT_EQ(out.parts[out.offsets[i]][0], segments[i][0]);
    EXPECT_EQ(out.parts[out.offsets[i]][1], segments[i][1]);
  }
}

// Random overlapping segments on a few slanted lines (their ends rounded as computed points
// are), with decoys near the lines: covered once per line, nothing lost.
TEST(CollinearSegments, RandomSegmentsOnSlantedLines) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), along(-3.0, 3.0);
  std::vector<Segment> segments;
  std::vector<double> union_length;
  for (int line = 0; line < 4; ++line) {
    const Vec3d origin{10 * unit(rng), 10 * unit(rng), 10 * unit(rng)};
    Vec3d d{unit(rng), unit(rng), unit(rng)};
    d = d / length(d);
    for (int s = 0; s < 40; ++s) {
      const double a = along(rng), b = along(rng);
      segments.push_back({origin + d * a, origin + d * b});
      if (s % 8 == 0) segments.push_back({origin + d * a + Vec3d{0, 1e-3, 0}, origin + d * b});  // decoy
    }
  }
  const SegmentParts out = uncovered_segment_parts(segments, 1e-9);
  expect_parts_on_segments(segments, out, 1e-9);
  expect_covered(segments, out, 2e-9);
  // Far less than all the segments' length: each line's union about once (+ the decoys whole).
  double all = 0;
  for (const auto& s : segments) all += length(s[1] - s[0]);
  EXPECT_LT(total_length(out), 0.5 * all);
}

// A line dashed into 200k disjoint pieces, then one segment over all of them: its parts are
// the 200k gaps, found without a pass over the union per insert (that was quadratic: a hostile
// mesh of collinear slivers would hang the scan).
TEST(CollinearSegments, ManyDisjointPiecesOnOneLine) {
  constexpr int kPieces = 200000;
  std::vector<Segment> segments;
  segments.reserve(kPieces + 1);
  for (int i = 0; i < kPieces; ++i) segments.push_back({Vec3d{2.0 * i, 0, 0}, Vec3d{2.0 * i + 1.0, 0, 0}});
  segments.push_back({Vec3d{-1, 0, 0}, Vec3d{2.0 * kPieces, 0, 0}});
  const SegmentParts out = uncovered_segment_parts(segments, 1e-9);
  ASSERT_EQ(out.offsets.size(), segments.size() + 1);
  for (int i = 0; i < kPieces; ++i) ASSERT_EQ(out.offsets[std::size_t(i) + 1] - out.offsets[std::size_t(i)], 1u);
  // The long one: the gap before the first piece and one after each piece.
  EXPECT_EQ(out.offsets[kPieces + 1] - out.offsets[kPieces], std::uint32_t(kPieces + 1));
  EXPECT_NEAR(total_length(out), 2.0 * kPieces + 1.0, 1e-6);
}

}  // namespace
}  // namespace levelset
