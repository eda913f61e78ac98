// redistance()'s refusals and edge cases: bad options with the option named, an empty band,
// a band with no zero level, cancellation through the progress hook.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"
#include "distance/redistance.hpp"
#include "shape_band.hpp"

namespace levelset {
namespace {

using test::make_shape_band;

RedistanceResult run(const NarrowBand& in, RedistanceMethod method, double half_width = 0.0) {
  RedistanceOptions o;
  o.method = method;
  o.half_width = half_width;
  return redistance(in, o);
}

TEST(RedistanceErrors, RejectsBadOptions) {
  const auto sb = make_shape_band("sphere", 32);
  auto expect_invalid = [&](RedistanceOptions o) {
    try {
      redistance(sb.band, o);
      ADD_FAILURE() << "options accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    }
  };
  RedistanceOptions o;
  o.half_width = 0.5;
  expect_invalid(o);
  o.half_width = -3;
  expect_invalid(o);
  o.half_width = std::nan("");
  expect_invalid(o);
  o.half_width = std::numeric_limits<double>::infinity();
  expect_invalid(o);
  o.half_width = 2000;
  expect_invalid(o);
  o = {};
  o.max_sweep_iterations = 0;
  expect_invalid(o);
  o = {};
  o.tolerance = -1;
  expect_invalid(o);
  o = {};
  o.order = 3;
  expect_invalid(o);
  o = {};
  o.half_width = 1.0;
  EXPECT_NO_THROW(redistance(sb.band, o));
}

TEST(RedistanceErrors, EmptyBandGivesEmptyBand) {
  const GridFrame frame{0.25, {1, 2, 3}, 3.0};
  for (RedistanceMethod m : {RedistanceMethod::Sweep, RedistanceMethod::March}) {
    NarrowBand empty(frame);
    empty.set_far_inside(true);
    RedistanceResult r = run(empty, m);
    EXPECT_EQ(r.band.brick_count(), 0u);
    EXPECT_EQ(r.band.voxel_size(), 0.25);
    EXPECT_TRUE(r.band.origin() == (Vec3d{1, 2, 3}));
    EXPECT_EQ(r.band.half_width(), 3.0);
    EXPECT_TRUE(r.band.far_inside());
    EXPECT_EQ(r.interface_voxels, 0u);
    r = run(empty, m, 5.0);
    EXPECT_EQ(r.band.half_width(), 5.0);
    // Bricks but no zero crossing: nothing to measure from, no active voxel left.
    NarrowBand positive(frame);
    for (int i = 0; i < 10; ++i) positive.set_value({i, 0, 0}, 0.1f);
    r = run(positive, m);
    EXPECT_EQ(r.band.active_voxel_count(), 0u);
    EXPECT_EQ(r.interface_voxels, 0u);
    EXPECT_FALSE(r.band.is_inside({3, 0, 0}));
  }
}

TEST(RedistanceErrors, CancellationStopsTheWork) {
  const auto sb = make_shape_band("sphere", 64);
  for (RedistanceMethod m : {RedistanceMethod::Sweep, RedistanceMethod::March}) {
    auto token = std::make_shared<CancelToken>();
    RedistanceOptions o;
    o.method = m;
    o.progress.cancel = token;
    int calls = 0;
    double last = -1;
    o.progress.on_progress = [&](double f, std::string_view) {
      EXPECT_GE(f, last);
      last = f;
      ++calls;
    };
    EXPECT_NO_THROW(redistance(sb.band, o));
    EXPECT_GE(calls, 3);
    EXPECT_EQ(last, 1.0);
    // Cancel from inside the operation, after the first report.
    o.progress.on_progress = [&](double, std::string_view) { token->cancel(); };
    try {
      redistance(sb.band, o);
      ADD_FAILURE() << "not cancelled";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Cancelled);
    }
  }
}

}  // namespace
}  // namespace levelset
