#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>

#include <tbb/task_arena.h>

#include "core/error.hpp"
#include "distance/eikonal_march.hpp"
#include "distance/interface_init.hpp"
#include "distance/redistance_domain.hpp"
#include "distance/redistance.hpp"
#include "grid/band_accessor.hpp"
#include "grid/band_builder.hpp"
#include "shape_band.hpp"

namespace levelset {
namespace {

using test::make_shape_band;

// A smooth positive factor in [0.5, 1.5]: u*wobble keeps the zero level and the signs but
// destroys |grad u| = 1.
double wobble(const Vec3d& p) { return 1.0 + 0.5 * std::sin(3 * p.x) * std::sin(3 * p.y) * std::sin(3 * p.z); }

NarrowBand distort(const NarrowBand& band) {
  NarrowBand out = band;
  for (std::uint32_t b = 0; b < out.brick_count(); ++b) {
    const Coord o = brick_origin(out.bricks()[b].coord);
    out.update_active_in_brick(b, [&](int n, float v) { return float(double(v) * wobble(out.world(o + local_coord(n)))); });
  }
  return out;
}

RedistanceResult run(const NarrowBand& in, RedistanceMethod method, double half_width = 0.0) {
  RedistanceOptions o;
  o.method = method;
  o.half_width = half_width;
  return redistance(in, o);
}

const char* name(RedistanceMethod m) { return m == RedistanceMethod::Sweep ? "sweep" : "march"; }

struct Quality {
  double value_error = 0;           // max |d - exact| / h over the output's active voxels
  double grad_error = 0;            // max ||grad d| - 1|, |d| >= 1.5h, full stencil in the band
  double grad_error_interface = 0;  // the same at voxels next to the zero level
  double exact_grad_error = 0;      // the exact SDF's own central-difference error there
  double crossing_shift = 0;        // max edge-crossing displacement / h
  std::size_t grad_samples = 0, crossings = 0;
};

// The exact distance at a voxel: from `cache` (a band of the exact SDF on the same frame,
// float-rounded) where it has the voxel, else from the shape (the knot's SDF is slow).
struct ExactDistance {
  const AnalyticShape& shape;
  const NarrowBand& frame;
  const NarrowBand* cache;
  BandAccessor acc;
  ExactDistance(const AnalyticShape& s, const NarrowBand& f, const NarrowBand* c)
      : shape(s), frame(f), cache(c), acc(c ? *c : f) {}
  double operator()(const Coord& c) {
    if (cache)
      if (const auto v = acc.probe(c)) return *v;
    return shape.distance(frame.world(c));
  }
};

Quality measure(const NarrowBand& in, const NarrowBand& out, const AnalyticShape& shape,
                const NarrowBand* exact_band = nullptr) {
  Quality q;
  const double h = out.voxel_size();
  BandAccessor acc(out), acc_in(in);
  ExactDistance exact(shape, out, exact_band);
  static constexpr Coord kAxis[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  out.for_each_active([&](const Coord& c, float v) {
    q.value_error = std::max(q.value_error, std::abs(v - exact(c)) / h);
    double g2 = 0, e2 = 0;
    bool full = true, interface = false;
    for (int a = 0; a < 3; ++a) {
      const auto p = acc.probe(c + kAxis[a]), m = acc.probe(c - kAxis[a]);
      if (!p || !m) { full = false; break; }
      interface |= (*p < 0) != (v < 0) || (*m < 0) != (v < 0);
      const double g = (double(*p) - double(*m)) / (2 * h);
      const double e = (exact(c + kAxis[a]) - exact(c - kAxis[a])) / (2 * h);
      g2 += g * g;
      e2 += e * e;
    }
    if (!full) return;
    const double err = std::abs(std::sqrt(g2) - 1.0);
    if (interface) q.grad_error_interface = std::max(q.grad_error_interface, err);
    if (std::abs(v) < 1.5 * h) return;
    q.grad_error = std::max(q.grad_error, err);
    q.exact_grad_error = std::max(q.exact_grad_error, std::abs(std::sqrt(e2) - 1.0));
    ++q.grad_samples;
  });
  // Zero crossings along every edge with a sign change, before and after.
  in.for_each_active([&](const Coord& c, float u) {
    for (int a = 0; a < 3; ++a) {
      const Coord e = c + kAxis[a];
      const auto ue = acc_in.probe(e);
      if (!ue || (*ue < 0) == (u < 0)) continue;
      const auto dc = acc.probe(c), de = acc.probe(e);
      ASSERT_TRUE(dc && de) << "sign-change edge left the band";
      ASSERT_EQ(*dc < 0, u < 0);
      ASSERT_EQ(*de < 0, *ue < 0);
      const double before = double(u) / (double(u) - double(*ue));
      const double after = double(*dc) / (double(*dc) - double(*de));
      q.crossing_shift = std::max(q.crossing_shift, std::abs(after - before));
      ++q.crossings;
    }
  });
  return q;
}

void print(const std::string& what, RedistanceMethod m, const Quality& q, const RedistanceResult& r) {
  std::printf("[%s %s] voxels %zu, interface %llu, iterations %d, %.3f s | value err %.4f h | "
              "|grad|-1: %.4f (exact SDF %.4f, %zu samples), at interface %.4f | crossing shift %.4f h (%zu edges)\n",
              what.c_str(), name(m), r.band.active_voxel_count(), (unsigned long long)r.interface_voxels,
              r.sweep_iterations, r.seconds, q.value_error, q.grad_error, q.exact_grad_error, q.grad_samples,
              q.grad_error_interface, q.crossing_shift, q.crossings);
}

// Signs against the exact shape and the band invariant, in a box around the band. The exact
// sign of a voxel is the sample build_from_sdf took of the shape's SDF in `exact` (same
// frame) where `exact` has the brick, else one SDF sample at the brick's centre: a brick
// the exact band lacks holds no voxel within W*h >= h of the surface, so it has one sign.
void expect_signs_and_invariant(const NarrowBand& out, const AnalyticShape& shape, const NarrowBand& exact,
                                int margin) {
  IndexBox box = out.active_index_bounds();
  ASSERT_FALSE(box.empty());
  BandAccessor acc(out);
  std::map<std::uint64_t, bool> far_sign;
  auto exact_inside = [&](const Coord& c) {
    const Coord bc = brick_of(c);
    const std::uint32_t b = exact.find_brick(bc);
    if (b != kNoBrick) return exact.voxel_inside(b, local_index(c));
    auto [it, added] = far_sign.try_emplace(brick_key(bc), false);
    if (added) it->second = shape.distance(exact.world(brick_origin(bc) + Coord{4, 4, 4})) < 0.0;
    return it->second;
  };
  std::size_t wrong_sign = 0, broken = 0;
  for (int z = box.min.z - margin; z <= box.max.z + margin; ++z)
    for (int y = box.min.y - margin; y <= box.max.y + margin; ++y)
      for (int x = box.min.x - margin; x <= box.max.x + margin; ++x) {
        const Coord c{x, y, z};
        const bool inside = acc.is_inside(c);
        wrong_sign += inside != exact_inside(c);
        for (const Coord d : {Coord{1, 0, 0}, Coord{0, 1, 0}, Coord{0, 0, 1}}) {
          if (acc.is_inside(c + d) != inside) broken += !acc.is_active(c) || !acc.is_active(c + d);
        }
      }
  EXPECT_EQ(wrong_sign, 0u);
  EXPECT_EQ(broken, 0u);
}

// The output band is the requested one: no value beyond W*h, and every voxel of the exact
// band (same frame) with |d| <= (W - 0.05) h is active.
void expect_band_extent(const NarrowBand& out, const NarrowBand& exact) {
  const double h = out.voxel_size(), W = out.half_width();
  std::size_t beyond = 0, missing = 0;
  out.for_each_active([&](const Coord&, float v) { beyond += std::abs(double(v)) > W * h; });
  BandAccessor acc(out);
  exact.for_each_active([&](const Coord& c, float v) {
    missing += std::abs(double(v)) <= (W - 0.05) * h && !acc.is_active(c);
  });
  EXPECT_EQ(beyond, 0u);
  EXPECT_EQ(missing, 0u);
}

class RedistanceShapes : public ::testing::TestWithParam<RedistanceMethod> {};

TEST_P(RedistanceShapes, DistortedSphere) {
  const auto sb = make_shape_band("sphere", 128);
  const NarrowBand in = distort(sb.band);
  const RedistanceResult r = run(in, GetParam());
  const Quality q = measure(in, r.band, *sb.shape, &sb.band);
  print("sphere R=128", GetParam(), q, r);
  EXPECT_GT(q.grad_samples, 10000u);
  EXPECT_LT(q.value_error, 0.05);
  EXPECT_LT(q.grad_error, 1e-2);
  EXPECT_LT(q.crossing_shift, 0.05);
  // What the second-order scheme and the Taylor initialisation reach (measured 0.001 h and
  // 0.0003): a regression guard well below the targets above.
  EXPECT_LT(q.value_error, 0.005);
  EXPECT_LT(q.grad_error, 0.002);
  EXPECT_LT(q.grad_error_interface, 0.005);
  expect_signs_and_invariant(r.band, *sb.shape, sb.band, 6);
  expect_band_extent(r.band, sb.band);
}

TEST_P(RedistanceShapes, DistortedTorus) {
  const auto sb = make_shape_band("torus", 192);
  const NarrowBand in = distort(sb.band);
  const RedistanceResult r = run(in, GetParam());
  const Quality q = measure(in, r.band, *sb.shape, &sb.band);
  print("torus R=192", GetParam(), q, r);
  EXPECT_LT(q.value_error, 0.05);
  EXPECT_LT(q.grad_error, 1e-2);
  EXPECT_LT(q.crossing_shift, 0.05);
  expect_signs_and_invariant(r.band, *sb.shape, sb.band, 4);
  expect_band_extent(r.band, sb.band);
}

TEST_P(RedistanceShapes, DistortedKnot) {
  const auto sb = make_shape_band("knot", 256);
  const NarrowBand in = distort(sb.band);
  const RedistanceResult r = run(in, GetParam());
  const Quality q = measure(in, r.band, *sb.shape, &sb.band);
  print("knot R=256", GetParam(), q, r);
  EXPECT_LT(q.value_error, 0.05);
  EXPECT_LT(q.grad_error, 1e-2);
  EXPECT_LT(q.crossing_shift, 0.05);
  expect_signs_and_invariant(r.band, *sb.shape, sb.band, 2);
  expect_band_extent(r.band, sb.band);
}

INSTANTIATE_TEST_SUITE_P(Redistance, RedistanceShapes,
                         ::testing::Values(RedistanceMethod::Sweep, RedistanceMethod::March),
                         [](const auto& info) { return std::string(name(info.param)); });

// Largest |a - b| / h over voxels active in both; counts voxels active in only one, and the
// smallest |value| / h among those.
struct BandDiff {
  double max_diff = 0;
  std::size_t common = 0, only_one = 0;
  double min_only_one = 1e30;
};
BandDiff compare(const NarrowBand& a, const NarrowBand& b) {
  BandDiff d;
  const double h = a.voxel_size();
  BandAccessor acc_a(a), acc_b(b);
  a.for_each_active([&](const Coord& c, float v) {
    const auto w = acc_b.probe(c);
    if (!w) {
      ++d.only_one;
      d.min_only_one = std::min(d.min_only_one, std::abs(double(v)) / h);
      return;
    }
    ++d.common;
    d.max_diff = std::max(d.max_diff, std::abs(double(v) - double(*w)) / h);
  });
  b.for_each_active([&](const Coord& c, float v) {
    if (acc_a.is_active(c)) return;
    ++d.only_one;
    d.min_only_one = std::min(d.min_only_one, std::abs(double(v)) / h);
  });
  return d;
}

TEST_P(RedistanceShapes, GrowingMatchesBuildingWide) {
  // Same frame for both: frame_for_resolution depends on W, so build the W=5 band and the
  // W=2 band on the W=5 frame.
  const auto wide = make_shape_band("torus", 128, 5.0);
  SdfBuildOptions narrow_options;
  narrow_options.frame = wide.band.frame();
  narrow_options.frame.half_width = 2.0;
  const AnalyticShape* shape = wide.shape.get();
  const NarrowBand narrow =
      build_from_sdf([shape](const Vec3d& p) { return shape->distance(p); }, shape->bounds(), narrow_options).band;
  const RedistanceResult direct = run(distort(wide.band), GetParam());
  const RedistanceResult grown = run(distort(narrow), GetParam(), 5.0);
  EXPECT_EQ(grown.band.half_width(), 5.0);
  EXPECT_EQ(grown.interface_voxels, direct.interface_voxels);
  const BandDiff d = compare(direct.band, grown.band);
  std::printf("[grow 2->5 %s] common %zu, max diff %.2e h, only in one %zu (|d| >= %.3f h)\n", name(GetParam()),
              d.common, d.max_diff, d.only_one, d.min_only_one);
  EXPECT_GT(d.common, direct.band.active_voxel_count() * 99 / 100);
  // Interface voxels whose 3x3x3 stencil leaves the W=2 band fall back to the crossing
  // plane (first order in the curvature), so values differ by that error at most.
  EXPECT_LT(d.max_diff, 0.05);
  EXPECT_GT(d.min_only_one, 4.8);  // only voxels at the band's edge may be in one only
  const Quality q = measure(distort(narrow), grown.band, *shape, &wide.band);
  EXPECT_LT(q.value_error, 0.05);
  EXPECT_LT(q.grad_error, 1e-2);
  expect_signs_and_invariant(grown.band, *shape, wide.band, 3);
  expect_band_extent(grown.band, wide.band);
}

TEST_P(RedistanceShapes, ShrinkingKeepsTheInnerBand) {
  const auto wide = make_shape_band("knot", 128, 5.0);
  const NarrowBand in = distort(wide.band);
  const RedistanceResult full = run(in, GetParam());
  const RedistanceResult shrunk = run(in, GetParam(), 2.0);
  EXPECT_EQ(shrunk.band.half_width(), 2.0);
  EXPECT_FLOAT_EQ(shrunk.band.background(), float(2.0 * in.voxel_size()));
  const double h = in.voxel_size();
  // The shrunk band is the full result restricted to |d| <= 2h.
  std::size_t expected = 0;
  BandAccessor acc(shrunk.band);
  double max_diff = 0;
  full.band.for_each_active([&](const Coord& c, float v) {
    const auto w = acc.probe(c);
    if (std::abs(double(v)) <= 2.0 * h) {
      ++expected;
      ASSERT_TRUE(w.has_value());
      max_diff = std::max(max_diff, std::abs(double(*w) - double(v)) / h);
    } else {
      EXPECT_FALSE(w.has_value());
    }
  });
  EXPECT_EQ(shrunk.band.active_voxel_count(), expected);
  // Sweep solves the same domain and truncates (identical); March stops early, where the
  // second-order stencils may miss a value beyond the cut.
  EXPECT_LT(max_diff, GetParam() == RedistanceMethod::Sweep ? 1e-7 : 1e-3);
  EXPECT_LT(shrunk.band.brick_count(), full.band.brick_count());
  expect_signs_and_invariant(shrunk.band, *wide.shape, wide.band, 3);
}

TEST_P(RedistanceShapes, BitIdenticalForAnyThreadCount) {
  const auto sb = make_shape_band("knot", 96);
  const NarrowBand in = distort(sb.band);
  RedistanceResult one, two;
  tbb::task_arena(1).execute([&] { one = run(in, GetParam(), 4.0); });
  tbb::task_arena(2).execute([&] { two = run(in, GetParam(), 4.0); });
  EXPECT_TRUE(one.band.identical(two.band));
  EXPECT_EQ(one.sweep_iterations, two.sweep_iterations);
  EXPECT_EQ(one.interface_voxels, two.interface_voxels);
}

TEST_P(RedistanceShapes, ExactDistanceIsNearlyAFixedPoint) {
  const auto sb = make_shape_band("torus", 128);
  const RedistanceResult r = run(sb.band, GetParam());
  const BandDiff d = compare(sb.band, r.band);
  const RedistanceResult again = run(r.band, GetParam());
  const BandDiff d2 = compare(r.band, again.band);
  std::printf("[fixed point %s] exact input: max change %.4f h; second pass: max change %.4f h\n", name(GetParam()),
              d.max_diff, d2.max_diff);
  EXPECT_LT(d.max_diff, 0.01);
  EXPECT_GT(d.min_only_one, 2.9);
  EXPECT_LT(d2.max_diff, 0.002);
}

TEST_P(RedistanceShapes, FirstOrderIsCoarserButConsistent) {
  const auto sb = make_shape_band("sphere", 128);
  const NarrowBand in = distort(sb.band);
  RedistanceOptions o;
  o.method = GetParam();
  o.order = 1;
  const RedistanceResult r = redistance(in, o);
  const Quality q = measure(in, r.band, *sb.shape, &sb.band);
  print("sphere R=128 first order", GetParam(), q, r);
  EXPECT_LT(q.value_error, 0.05);
  EXPECT_LT(q.grad_error, 0.02);
  EXPECT_LT(q.crossing_shift, 0.05);
}

TEST_P(RedistanceShapes, InsideOutShapeKeepsFarInside) {
  // The complement of a sphere: values and signs negated, far_inside = true.
  const auto sb = make_shape_band("sphere", 64);
  BandBuilder builder(sb.band.frame());
  for (std::uint32_t b = 0; b < sb.band.brick_count(); ++b) {
    const Brick& br = sb.band.bricks()[b];
    BrickMask inside = sb.band.inside_mask(b);
    for (auto& w : inside.words) w = ~w;
    float dense[kBrickVoxels] = {};
    const float* v = sb.band.brick_values(b).data();
    br.active.for_each_set([&](int n) {
      dense[n] = -*v++;
      if (dense[n] == 0.0f) inside.reset(n);  // a zero value reads as outside
    });
    builder.add_brick(br.coord, br.active, inside, dense);
  }
  const NarrowBand in = distort(builder.finish(true));
  const RedistanceResult r = run(in, GetParam(), 2.0);
  EXPECT_TRUE(r.band.far_inside());
  BandAccessor acc(r.band), acc_in(in);
  const IndexBox box = in.active_index_bounds();
  for (int z = box.min.z - 12; z <= box.max.z + 12; ++z)
    for (int y = box.min.y - 12; y <= box.max.y + 12; ++y)
      for (int x = box.min.x - 12; x <= box.max.x + 12; ++x)
        ASSERT_EQ(acc.is_inside({x, y, z}), acc_in.is_inside({x, y, z})) << x << "," << y << "," << z;
  const Quality q = measure(in, r.band, *make_sphere({0, 0, 0}, 1.0));  // |d| error is sign-blind below
  EXPECT_LT(q.crossing_shift, 0.05);
  double worst = 0;
  r.band.for_each_active([&](const Coord& c, float v) {
    worst = std::max(worst, std::abs(double(v) + sb.shape->distance(r.band.world(c))) / r.band.voxel_size());
  });
  EXPECT_LT(worst, 0.05);
}

// Sweep and March solve the same discrete equations.
TEST(RedistanceMethods, SweepAndMarchAgree) {
  const auto sb = make_shape_band("knot", 128);
  const NarrowBand in = distort(sb.band);
  for (int order : {1, 2}) {
    RedistanceOptions o;
    o.order = order;
    o.method = RedistanceMethod::Sweep;
    const RedistanceResult s = redistance(in, o);
    o.method = RedistanceMethod::March;
    const RedistanceResult m = redistance(in, o);
    const BandDiff d = compare(s.band, m.band);
    std::printf("[sweep vs march, order %d] common %zu, max diff %.2e h, only in one %zu\n", order, d.common,
                d.max_diff, d.only_one);
    EXPECT_LT(d.max_diff, order == 1 ? 1e-5 : 1e-2);
    EXPECT_LE(d.only_one, s.band.active_voxel_count() / 10000);
    EXPECT_GE(s.sweep_iterations, 2);
    EXPECT_EQ(m.sweep_iterations, 0);
  }
}

// A band grown to W = 12: characteristics cross up to two bricks beyond the interface's, so
// the bricks' marches take several rounds to agree; first order, they reach the discrete
// solution that the sweep (an independent solver, run to convergence) reaches.
TEST(RedistanceMethods, MarchRoundsConvergeOnAWideBand) {
  const auto sb = make_shape_band("torus", 96);
  const NarrowBand in = distort(sb.band);
  RedistanceOptions o;
  o.order = 1;
  o.half_width = 12.0;
  o.max_sweep_iterations = 100;
  o.tolerance = 0.0;
  const RedistanceResult s = redistance(in, o);
  o.method = RedistanceMethod::March;
  const RedistanceResult m = redistance(in, o);
  const BandDiff d = compare(s.band, m.band);
  std::printf("[wide band, order 1] sweep %d iterations, march %d rounds; common %zu, max diff %.2e h, only in one %zu\n",
              s.sweep_iterations, m.march_rounds, d.common, d.max_diff, d.only_one);
  EXPECT_LT(s.sweep_iterations, o.max_sweep_iterations);
  EXPECT_GE(m.march_rounds, 3);
  EXPECT_LT(m.march_rounds, detail::kMaxMarchRounds);
  EXPECT_LT(d.max_diff, 1e-5);
  EXPECT_LE(d.only_one, s.band.active_voxel_count() / 10000);
  EXPECT_GT(s.band.active_voxel_count(), 3 * in.active_voxel_count());
}

// The march's per-voxel caps (RedistanceDomain::cap, the membranes' use): a voxel is accepted
// only up to its cap and then passes nothing on. With one cap c everywhere, every value up to
// c is computed from smaller ones only, so it equals the uncapped march's bit for bit, and
// every voxel the uncapped march put beyond c stays unknown; with caps that vary, a value
// can only grow (fewer upwind voxels), never shrink.
TEST(RedistanceMethods, MarchCapsStopVoxelsAtTheirCap) {
  const auto sb = make_shape_band("torus", 64);
  const NarrowBand in = distort(sb.band);
  auto march = [&](float cap, bool varying) {
    detail::RedistanceDomain w = detail::build_domain(in, 3, {});
    detail::init_interface(in, w);
    w.cap.assign(w.size() * kBrickVoxels, cap);
    if (varying)
      for (std::size_t i = 0; i < w.cap.size(); i += 3) w.cap[i] = 1.0f;  // every third voxel
    detail::march(w, 1, 6.0, 1e-6f, {});
    return std::vector<float>(w.dist.begin(), w.dist.end());
  };
  const std::vector<float> free = march(1e30f, false), capped = march(2.5f, false), varying = march(3.5f, true);
  ASSERT_EQ(free.size(), capped.size());
  std::size_t kept = 0, stopped = 0, grown = 0;
  for (std::size_t i = 0; i < free.size(); ++i) {
    if (free[i] <= 2.5f) {
      EXPECT_EQ(capped[i], free[i]) << i;
      ++kept;
    } else {
      EXPECT_EQ(capped[i], detail::kInf) << i;
      stopped += free[i] <= 6.0f;
    }
    if (varying[i] < detail::kInf) {
      EXPECT_GE(varying[i], free[i]) << i;
    }
    grown += varying[i] > free[i] && free[i] <= 3.5f;
  }
  EXPECT_GT(kept, 10000u);
  EXPECT_GT(stopped, 10000u);
  EXPECT_GT(grown, 100u);
}

// The iteration cap and the tolerance: one iteration leaves work undone; tolerance 0 runs
// to the exact fixed point, which the default tolerance (1e-6 h) matches closely.
TEST(RedistanceSweep, IterationCapAndTolerance) {
  const auto sb = make_shape_band("torus", 96);
  const NarrowBand in = distort(sb.band);
  RedistanceOptions o;
  const RedistanceResult converged = redistance(in, o);
  EXPECT_GE(converged.sweep_iterations, 2);
  EXPECT_LE(converged.sweep_iterations, o.max_sweep_iterations);
  o.max_sweep_iterations = 1;
  const RedistanceResult capped = redistance(in, o);
  EXPECT_EQ(capped.sweep_iterations, 1);
  EXPECT_GT(compare(converged.band, capped.band).max_diff, 1e-3);
  o.max_sweep_iterations = 8;
  o.tolerance = 0.0;
  for (int order : {1, 2}) {
    o.order = order;
    const RedistanceResult exact = redistance(in, o);
    RedistanceOptions d;
    d.order = order;
    const BandDiff diff = compare(exact.band, redistance(in, d).band);
    EXPECT_LT(diff.max_diff, 1e-4) << order;
    EXPECT_EQ(diff.only_one, 0u) << order;
  }
}

// A brick row with no band left after shrinking keeps a brick that carries its sign when
// that sign differs from far_inside. With a valid input that cannot happen (far along x every
// row has the far_inside sign), so this input is a prism infinite along x (cross-section y in
// [0.5, 30.5], z in [-12.5, 3.5]) stored in bricks x in [0, 32): its faces cross unallocated
// bricks at the ends. Its deep rows lie more than W = 1 from its faces; the output must
// still give every voxel the input's sign.
TEST(RedistanceSigns, RowWithoutBandKeepsItsSign) {
  auto sdf = [](double y, double z) {  // 2D box distance in (y, z)
    const double qy = std::abs(y - 15.5) - 15.0, qz = std::abs(z + 4.5) - 8.0;
    return std::hypot(std::max(qy, 0.0), std::max(qz, 0.0)) + std::min(std::max(qy, qz), 0.0);
  };
  const GridFrame frame{1.0, {0, 0, 0}, 10.0};
  BandBuilder builder(frame);
  for (int bz = -3; bz <= 0; ++bz)
    for (int by = -1; by <= 4; ++by)
      for (int bx = 0; bx < 4; ++bx) {
        BrickMask active, inside;
        float dense[kBrickVoxels];
        for (int n = 0; n < kBrickVoxels; ++n) {
          const Coord c = brick_origin({bx, by, bz}) + local_coord(n);
          const double d = sdf(c.y, c.z);
          dense[n] = float(1.5 * d);
          if (dense[n] < 0) inside.set(n);
          if (std::abs(d) <= 10.0) active.set(n);
        }
        builder.add_brick({bx, by, bz}, active, inside, dense);
      }
  const NarrowBand in = builder.finish(false);
  for (RedistanceMethod m : {RedistanceMethod::Sweep, RedistanceMethod::March}) {
    const RedistanceResult r = run(in, m, 1.0);
    for (int z = -28; z < 12; ++z)
      for (int y = -12; y < 44; ++y)
        for (int x = -20; x < 52; ++x)
          ASSERT_EQ(r.band.is_inside({x, y, z}), in.is_inside({x, y, z})) << name(m) << " " << x << "," << y << "," << z;
    std::size_t carriers = 0;
    for (std::uint32_t b = 0; b < r.band.brick_count(); ++b) carriers += r.band.bricks()[b].active.none();
    EXPECT_GT(carriers, 0u);
    EXPECT_LT(r.band.brick_count(), in.brick_count());
    // Away from the prism's edges and ends the distance is a plane's: exact.
    double worst = 0;
    r.band.for_each_active([&](const Coord& c, float v) {
      if (c.x > 2 && c.x < 29 && c.y > 3 && c.y < 28 && c.z > -10) worst = std::max(worst, std::abs(v - sdf(c.y, c.z)));
    });
    EXPECT_LT(worst, 1e-5) << name(m);
  }
}

}  // namespace
}  // namespace levelset
