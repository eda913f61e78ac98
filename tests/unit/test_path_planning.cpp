// Path planning and fast marching (thesis 3.6) against closed forms: straight lines under
// unit cost, circular geodesics of the Poincare half-plane (cost 1/y), the path around a
// sphere (tangent segments + arc); convergence order of the arrival time; errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>

#include <tbb/task_arena.h>

#include "apps/path_planning.hpp"
#include "core/error.hpp"
#include "geometry/analytic_shapes.hpp"
#include "grid/build_from_sdf.hpp"

namespace levelset::apps {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A slab a few nodes thick around z = 0: planar problems whose 3D solution is symmetric in
// z, so the slab's march is the 3D march restricted to it.
DenseGrid slab(double x0, double x1, double y0, double y1, double h) {
  BBox b;
  b.extend({x0, y0, -2 * h});
  b.extend({x1, y1, 2 * h});
  return dense_grid_for_voxel_size(b, h);
}

// The Poincare half-plane: cost 1/y; geodesics are circles centred on y = 0.
struct Poincare {
  Vec3d a, b;
  double time() const {
    const double dx = b.x - a.x, dy = b.y - a.y;
    return std::acosh(1.0 + (dx * dx + dy * dy) / (2.0 * a.y * b.y));
  }
  double length() const {
    const double xc = (b.x * b.x + b.y * b.y - a.x * a.x - a.y * a.y) / (2.0 * (b.x - a.x));
    const double r = std::hypot(a.x - xc, a.y);
    return r * std::abs(std::atan2(b.y, b.x - xc) - std::atan2(a.y, a.x - xc));
  }
};

// Shortest path from a to b around a sphere (centre c, radius R) in the plane of a, b, c,
// when the sphere hides b from a: two tangent segments and the arc between them.
double around_sphere(const Vec3d& a, const Vec3d& b, const Vec3d& c, double R) {
  const double da = levelset::length(a - c), db = levelset::length(b - c);
  const double phi = std::acos(dot(a - c, b - c) / (da * db));
  const double arc = phi - std::acos(R / da) - std::acos(R / db);
  EXPECT_GT(arc, 0.0) << "the sphere must hide b from a";
  return std::sqrt(da * da - R * R) + std::sqrt(db * db - R * R) + R * arc;
}

PathOptions options_on(const DenseGrid& g, const Vec3d& a, const Vec3d& b) {
  PathOptions o;
  o.grid = g;
  o.start = a;
  o.goal = b;
  return o;
}

void report(const char* what, const PathResult& r, double exact_length, double exact_time) {
  std::printf("[%s] length %.6f (exact %.6f, %+.3f%%), time %.6f (exact %.6f, %+.3f%%), %zu points\n", what,
              r.length, exact_length, 100.0 * (r.length / exact_length - 1.0), r.arrival_time, exact_time,
              100.0 * (r.arrival_time / exact_time - 1.0), r.points.size());
}

void expect_path_ends(const PathResult& r, const Vec3d& a, const Vec3d& b) {
  ASSERT_GE(r.points.size(), 2u);
  EXPECT_EQ(r.points.front(), a);
  EXPECT_EQ(r.points.back(), b);
}

}  // namespace

TEST(PathPlanning, UniformCostGivesTheStraightSegment) {
  const BBox box{{0, 0, 0}, {1, 1, 1}};
  const Vec3d a{0.213, 0.307, 0.391}, b{0.81, 0.72, 0.66};  // off the nodes
  const PathResult r = plan_path(options_on(dense_grid_for_resolution(box, 40), a, b));
  const double exact = length(b - a);
  report("straight, h 1/40", r, exact, exact);
  expect_path_ends(r, a, b);
  EXPECT_NEAR(r.length, exact, 0.01 * exact);
  EXPECT_NEAR(r.arrival_time, exact, 0.01 * exact);
  // Every traced point lies within a voxel of the segment.
  for (const Vec3d& p : r.points) {
    const double s = std::clamp(dot(p - a, b - a) / dot(b - a, b - a), 0.0, 1.0);
    EXPECT_LT(length(p - (a + (b - a) * s)), 0.025);
  }
}

TEST(PathPlanning, MarchStopsSoonAfterTheGoalWithTheSameResult) {
  const BBox box{{0, 0, 0}, {1, 1, 1}};
  PathOptions o = options_on(dense_grid_for_resolution(box, 32), {0.2, 0.25, 0.3}, {0.45, 0.5, 0.4});
  const PathResult early = plan_path(o);
  o.keep_field = true;
  const PathResult full = plan_path(o);
  EXPECT_EQ(full.accepted, o.grid.voxel_count());
  EXPECT_LT(early.accepted, full.accepted / 2);  // a clipped ball of radius ~0.46 of the unit cube
  EXPECT_NEAR(early.length, full.length, 1e-9);
  EXPECT_NEAR(early.arrival_time, full.arrival_time, 1e-12);
}

TEST(PathPlanning, PoincareHalfPlaneGeodesicIsACircularArc) {
  const Poincare exact{{-0.8, 1.0, 0.0}, {0.8, 1.2, 0.0}};
  PathOptions o = options_on(slab(-1.0, 1.0, 0.7, 1.7, 0.01), exact.a, exact.b);
  o.cost.formula = "1/y";
  const PathResult r = plan_path(o);
  report("Poincare 1/y, h 0.01", r, exact.length(), exact.time());
  expect_path_ends(r, exact.a, exact.b);
  EXPECT_NEAR(r.length, exact.length(), 0.01 * exact.length());
  EXPECT_NEAR(r.arrival_time, exact.time(), 0.01 * exact.time());
  // The straight segment is shorter but slower: the path bulges up to the circle's top.
  EXPECT_GT(r.length, levelset::length(exact.b - exact.a) * 1.01);
}

TEST(PathPlanning, PathWrapsAroundASphereObstacle) {
  const Vec3d c{0, 0, 0};
  const double R = 0.5;
  const Vec3d a{-1.0, 0.0, 0.0}, b{0.9, 0.25, 0.0};
  const double exact = around_sphere(a, b, c, R);
  // The obstacle as a level set (inside = blocked), on its own grid.
  const std::unique_ptr<AnalyticShape> sphere = make_sphere(c, R);
  SdfBuildOptions band_options;
  band_options.frame = frame_for_resolution(sphere->bounds(), 64, 3.0);
  const NarrowBand band =
      build_from_sdf([&](const Vec3d& p) { return sphere->distance(p); }, sphere->bounds(), band_options).band;
  PathOptions o = options_on(slab(-1.1, 1.0, -0.3, 0.75, 0.01), a, b);
  o.obstacles.band = &band;
  const PathResult r = plan_path(o);
  report("sphere band, h 0.01", r, exact, exact);
  expect_path_ends(r, a, b);
  EXPECT_GT(r.blocked, 0u);
  EXPECT_NEAR(r.length, exact, 0.01 * exact);
  EXPECT_NEAR(r.arrival_time, exact, 0.01 * exact);
  for (const Vec3d& p : r.points) EXPECT_GT(levelset::length(p - c), R - 0.01);  // never through it
}

// A clearance keeps the path that far from the obstacle: around a sphere of radius R it
// is the path around radius R + clearance.
TEST(PathPlanning, ClearanceInflatesTheObstacle) {
  const Vec3d c{0, 0, 0};
  const double R = 0.45, clearance = 0.05;
  const Vec3d a{-1.0, 0.0, 0.0}, b{0.9, 0.25, 0.0};
  const double exact = around_sphere(a, b, c, R + clearance);
  const std::unique_ptr<AnalyticShape> sphere = make_sphere(c, R);
  SdfBuildOptions band_options;
  band_options.frame = frame_for_resolution(sphere->bounds(), 64, 6.0);  // background 6 h > clearance
  const NarrowBand band =
      build_from_sdf([&](const Vec3d& p) { return sphere->distance(p); }, sphere->bounds(), band_options).band;
  PathOptions o = options_on(slab(-1.1, 1.0, -0.3, 0.75, 0.01), a, b);
  o.obstacles.band = &band;
  o.obstacles.clearance = clearance;
  const PathResult r = plan_path(o);
  report("sphere + clearance, h 0.01", r, exact, exact);
  EXPECT_NEAR(r.length, exact, 0.01 * exact);
  EXPECT_NEAR(r.arrival_time, exact, 0.01 * exact);
  for (const Vec3d& p : r.points) EXPECT_GT(levelset::length(p - c), R + clearance - 0.01);
  o.obstacles.clearance = 1.0;  // beyond the band: only signs are known there
  EXPECT_THROW(plan_path(o), Error);
}

TEST(PathPlanning, MaskObstacleAndRk4AgreeWithTheBand) {
  const Vec3d c{0, 0, 0};
  const double R = 0.5;
  const Vec3d a{-1.0, 0.0, 0.0}, b{0.9, 0.25, 0.0};
  const double exact = around_sphere(a, b, c, R);
  PathOptions o = options_on(slab(-1.1, 1.0, -0.3, 0.75, 0.01), a, b);
  const DenseGrid& g = o.grid;
  o.obstacles.mask.assign(g.voxel_count(), 0);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) o.obstacles.mask[g.index(i, j, k)] = length(g.world(i, j, k) - c) < R;
  o.trace.rk_order = 4;
  const PathResult r = plan_path(o);
  report("sphere mask rk4, h 0.01", r, exact, exact);
  EXPECT_NEAR(r.length, exact, 0.01 * exact);
  EXPECT_NEAR(r.arrival_time, exact, 0.01 * exact);
}

// Arrival time error at the goal of the Poincare problem. The seed layer keeps a fixed
// world radius (0.1), so the point source does not limit the order: second order cuts the
// error by about 4 when the voxel halves (3 asserted), first order by about 2, and order 2
// beats order 1.
TEST(PathPlanning, ArrivalTimeErrorDropsWithTheVoxelSize) {
  const Poincare exact{{-0.6, 1.0, 0.0}, {0.6, 1.2, 0.0}};
  const auto error = [&](double h, int order) {
    FastMarchingOptions o;
    o.grid = slab(-0.8, 0.8, 0.8, 1.6, h);
    o.seeds = {Seed{exact.a, 0}};
    o.cost.function = [](const Vec3d& p) { return 1.0 / p.y; };
    o.order = order;
    o.seed_radius = 0.1 / h;
    return std::abs(sample_time(fast_marching(o), exact.b) - exact.time());
  };
  const double e1 = error(0.04, 2), e2 = error(0.02, 2), e4 = error(0.01, 2);
  EXPECT_GT(e1 / e2, 3.0) << e1 << " " << e2;
  EXPECT_GT(e2 / e4, 3.0) << e2 << " " << e4;
  const double f2 = error(0.02, 1), f4 = error(0.01, 1);
  std::printf("[arrival time error, h 0.04 0.02 0.01] order 2: %.2e %.2e %.2e; order 1: - %.2e %.2e\n", e1, e2, e4,
              f2, f4);
  EXPECT_GT(f2 / f4, 1.5) << f2 << " " << f4;
  EXPECT_LT(e2, 0.25 * f2);
}

TEST(PathPlanning, UnreachableGoalIsAnError) {
  // A closed box shell around the goal.
  const BBox box{{0, 0, 0}, {1, 1, 1}};
  PathOptions o = options_on(dense_grid_for_resolution(box, 20), {0.1, 0.1, 0.1}, {0.7, 0.7, 0.7});
  const DenseGrid& g = o.grid;
  o.obstacles.mask.assign(g.voxel_count(), 0);
  for (int k = 11; k <= 17; ++k)
    for (int j = 11; j <= 17; ++j)
      for (int i = 11; i <= 17; ++i)
        o.obstacles.mask[g.index(i, j, k)] = i == 11 || i == 17 || j == 11 || j == 17 || k == 11 || k == 17;
  try {
    plan_path(o);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    EXPECT_NE(std::string(e.reason()).find("unreachable"), std::string::npos) << e.reason();
  }
  o.keep_field = true;
  o.goal = {0.3, 0.3, 0.3};
  const PathResult r = plan_path(o);
  EXPECT_EQ(r.field.time[g.index(14, 14, 14)], kInf);  // the inside of the shell
  EXPECT_EQ(r.field.label[g.index(14, 14, 14)], -1);
}

TEST(PathPlanning, BadInputIsRejected) {
  const BBox box{{0, 0, 0}, {1, 1, 1}};
  const DenseGrid g = dense_grid_for_resolution(box, 10);
  const auto code_of = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return e.code();
    }
    ADD_FAILURE() << "no error";
    return ErrorCode::Cancelled;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(code_of([&] { plan_path(options_on(g, {nan, 0.5, 0.5}, {0.5, 0.5, 0.5})); }), ErrorCode::NonFinite);
  EXPECT_EQ(code_of([&] { plan_path(options_on(g, {0.5, 0.5, 0.5}, {0.5, nan, 0.5})); }), ErrorCode::NonFinite);
  EXPECT_EQ(code_of([&] { plan_path(options_on(g, {0.5, 0.5, 0.5}, {1.5, 0.5, 0.5})); }), ErrorCode::InvalidArgument);
  EXPECT_EQ(code_of([&] { plan_path(options_on(g, {-0.5, 0.5, 0.5}, {0.5, 0.5, 0.5})); }), ErrorCode::InvalidArgument);
  // Absurd sizes fail before any allocation.
  EXPECT_EQ(code_of([&] { dense_grid_for_voxel_size(box, 1e-6); }), ErrorCode::LimitExceeded);
  EXPECT_EQ(code_of([&] { dense_grid_for_voxel_size(box, 0.0); }), ErrorCode::InvalidArgument);
  EXPECT_EQ(code_of([&] { dense_grid_for_voxel_size(BBox{}, 0.1); }), ErrorCode::InvalidArgument);
  PathOptions huge = options_on(g, {0.5, 0.5, 0.5}, {0.6, 0.5, 0.5});
  huge.grid.nx = huge.grid.ny = huge.grid.nz = 1 << 20;
  EXPECT_EQ(code_of([&] { plan_path(huge); }), ErrorCode::LimitExceeded);
  // Costs: NaN, zero, a formula reading a band variable, a start inside an obstacle.
  PathOptions o = options_on(g, {0.21, 0.5, 0.5}, {0.85, 0.5, 0.5});
  o.cost.function = [nan](const Vec3d&) { return nan; };
  EXPECT_EQ(code_of([&] { plan_path(o); }), ErrorCode::NonFinite);
  o.cost.function = [](const Vec3d& p) { return p.x - 0.5; };
  EXPECT_EQ(code_of([&] { plan_path(o); }), ErrorCode::InvalidArgument);
  o.cost.function = nullptr;
  o.cost.formula = "1 + H";
  EXPECT_EQ(code_of([&] { plan_path(o); }), ErrorCode::InvalidArgument);
  o.cost.formula = "1 + (";
  EXPECT_EQ(code_of([&] { plan_path(o); }), ErrorCode::ParseError);
  o.cost.formula.clear();
  o.obstacles.mask.assign(g.voxel_count(), 0);
  o.obstacles.mask[g.index(2, 5, 5)] = 1;  // the node nearest the start
  EXPECT_EQ(code_of([&] { plan_path(o); }), ErrorCode::InvalidArgument);
  o.obstacles.mask.resize(7);
  EXPECT_EQ(code_of([&] { plan_path(o); }), ErrorCode::InvalidArgument);
  o.obstacles.mask.clear();
  o.trace.step = 0.0;
  EXPECT_EQ(code_of([&] { plan_path(o); }), ErrorCode::InvalidArgument);
  o.trace.step = 0.5;
  o.order = 3;
  EXPECT_EQ(code_of([&] { plan_path(o); }), ErrorCode::InvalidArgument);
}

TEST(PathPlanning, CancelAndDeterminism) {
  const BBox box{{0, 0, 0}, {1, 1, 1}};
  FastMarchingOptions o;
  o.grid = dense_grid_for_resolution(box, 24);
  o.seeds = {Seed{{0.2, 0.3, 0.4}, 0}, Seed{{0.8, 0.6, 0.5}, 1}};
  o.cost.formula = "1 + 0.5*sin(6*x)*y";
  const auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    FastMarchingResult r;
    arena.execute([&] { r = fast_marching(o); });
    return r;
  };
  const FastMarchingResult one = run(1), two = run(2);
  EXPECT_EQ(one.time, two.time);
  EXPECT_EQ(one.label, two.label);
  auto token = std::make_shared<CancelToken>();
  token->cancel();
  o.progress.cancel = token;
  try {
    fast_marching(o);
    FAIL() << "expected Cancelled";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Cancelled);
  }
}

}  // namespace levelset::apps
