#include "apps/point_distance.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>

#include <nanoflann.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "apps/point_fit_detail.hpp"
#include "core/error.hpp"

namespace levelset::apps {

namespace {

// nanoflann's dataset interface over the copied points.
struct PointSource {
  const std::vector<Vec3d>* points = nullptr;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[i][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointSource>,
                                                   PointSource, 3, std::uint32_t>;

using detail::kMaxNeighbors;
using detail::Moments;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

struct PointIndex::Tree {
  PointSource source;
  KdTree tree;
  explicit Tree(const std::vector<Vec3d>& points)
      : source{&points}, tree(3, source, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {}
};

PointIndex::PointIndex(std::span<const Vec3d> points) : points_(points.begin(), points.end()) {
  if (points_.empty()) throw Error(ErrorCode::InvalidArgument, "point index", "no points");
  if (points_.size() >= (std::size_t{1} << 31))
    throw Error(ErrorCode::LimitExceeded, "point index", "more than 2^31 points");
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const Vec3d& p = points_[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error(ErrorCode::NonFinite, "point " + std::to_string(i), "non-finite coordinate");
  }
  tree_ = std::make_unique<Tree>(points_);
}

PointIndex::~PointIndex() = default;

PointIndex::Nearest PointIndex::nearest(const Vec3d& x) const {
  std::uint32_t i = 0;
  double d2 = 0.0;
  const double q[3] = {x.x, x.y, x.z};
  tree_->tree.knnSearch(q, 1, &i, &d2);
  return {i, std::sqrt(d2)};
}

int PointIndex::k_nearest(const Vec3d& x, int k, std::uint32_t* indices, double* distances_squared) const {
  const double q[3] = {x.x, x.y, x.z};
  return int(tree_->tree.knnSearch(q, std::size_t(std::max(k, 0)), indices, distances_squared));
}

void PointIndex::within(const Vec3d& x, double radius, std::vector<std::pair<std::uint32_t, double>>& out) const {
  out.clear();
  const double q[3] = {x.x, x.y, x.z};
  tree_->tree.radiusSearch(q, radius * radius, out, nanoflann::SearchParams(32, 0.0f, false));
}

namespace {

// nanoflann's radius result set, stopping the search once `cap` points were found.
struct CappedRadiusSet {
  double radius2;
  std::size_t cap;
  std::vector<std::pair<std::uint32_t, double>>& out;
  bool overflow = false;
  void clear() { out.clear(); }
  std::size_t size() const { return out.size(); }
  bool full() const { return true; }
  double worstDist() const { return radius2; }
  bool addPoint(double d2, std::uint32_t index) {
    if (!(d2 < radius2)) return true;
    if (out.size() >= cap) {
      overflow = true;
      return false;
    }
    out.emplace_back(index, d2);
    return true;
  }
};

}  // namespace

bool PointIndex::within(const Vec3d& x, double radius, std::size_t cap,
                        std::vector<std::pair<std::uint32_t, double>>& out) const {
  out.clear();
  const double q[3] = {x.x, x.y, x.z};
  CappedRadiusSet set{radius * radius, cap, out};
  tree_->tree.radiusSearchCustomCallback(q, set, nanoflann::SearchParams(32, 0.0f, false));
  return !set.overflow;
}

double sample_gap(const PointIndex& index, int k, double quantile, std::size_t samples) {
  const std::size_t n = index.size();
  if (n < 2 || samples == 0) return 0.0;
  if (!std::isfinite(quantile)) throw Error(ErrorCode::NonFinite, "sample_gap", "quantile is not finite");
  // The point itself is its own nearest: k + 1 neighbours, at most the set and the query buffer.
  const int want = int(std::clamp<std::size_t>(std::size_t(std::max(k, 1)) + 1, 2, std::min<std::size_t>(kMaxNeighbors, n)));
  const std::size_t stride = std::max<std::size_t>(1, (n + samples - 1) / samples);
  std::array<std::uint32_t, kMaxNeighbors> idx{};
  std::array<double, kMaxNeighbors> d2{};
  std::vector<double> gaps;
  for (std::size_t i = 0; i < n; i += stride) {
    const int got = index.k_nearest(index.points()[i], want, idx.data(), d2.data());
    gaps.push_back(std::sqrt(d2[std::size_t(got - 1)]));
  }
  const std::size_t at = std::min(gaps.size() - 1, std::size_t(std::clamp(quantile, 0.0, 1.0) * double(gaps.size() - 1)));
  std::nth_element(gaps.begin(), gaps.begin() + std::ptrdiff_t(at), gaps.end());
  return gaps[at];
}

PointDistanceResult point_distance(const PointIndex& index, std::span<const Vec3d> queries,
                                   const PointDistanceOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  PointDistanceResult r;
  r.distance.resize(queries.size());
  r.direction.resize(queries.size());
  r.closest.resize(queries.size());
  constexpr std::size_t kBatch = 4096;
  const std::size_t batches = (queries.size() + kBatch - 1) / kBatch;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, batches), [&](const tbb::blocked_range<std::size_t>& br) {
    for (std::size_t b = br.begin(); b != br.end(); ++b) {
      options.progress.check("point distance");
      const std::size_t end = std::min(queries.size(), (b + 1) * kBatch);
      for (std::size_t i = b * kBatch; i < end; ++i) {
        const Vec3d& x = queries[i];
        if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z))
          throw Error(ErrorCode::NonFinite, "point distance", "query " + std::to_string(i) + " is not finite");
        const PointIndex::Nearest n = index.nearest(x);
        r.distance[i] = n.distance;
        r.closest[i] = n.index;
        r.direction[i] = n.distance > 0.0 ? (x - index.points()[n.index]) / n.distance : Vec3d{};
      }
    }
  });
  options.progress.step(1.0, "point distance");
  r.seconds = seconds_since(t0);
  return r;
}


LocalFit local_fit(const PointIndex& index, const Vec3d& x, int k) {
  std::array<std::uint32_t, kMaxNeighbors> idx{};
  std::array<double, kMaxNeighbors> d2{};
  const int n = index.k_nearest(x, std::clamp(k, 1, kMaxNeighbors), idx.data(), d2.data());
  if (n == 0) return {};
  Moments m;
  for (int i = 0; i < n; ++i) m.add(x - index.points()[idx[std::size_t(i)]]);
  return m.fit(std::sqrt(d2[0]));
}



PointFitFieldResult point_fit_field(const PointIndex& index, const NarrowBand& where,
                                    const PointFitFieldOptions& options) {
  if (options.neighbors < 1 || options.neighbors > kMaxNeighbors)
    throw Error(ErrorCode::InvalidArgument, "point fit", "neighbors must be in [1, 256], got " +
                                                             std::to_string(options.neighbors));
  const auto t0 = std::chrono::steady_clock::now();
  PointFitFieldResult r;
  r.fits.resize(where.active_voxel_count());
  const std::uint32_t bricks = std::uint32_t(where.brick_count());
  constexpr std::uint32_t kBatch = 64;
  const std::uint32_t batches = (bricks + kBatch - 1) / kBatch;
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, batches), [&](const tbb::blocked_range<std::uint32_t>& br) {
    for (std::uint32_t bb = br.begin(); bb != br.end(); ++bb) {
      options.progress.check("point fit");
      for (std::uint32_t b = bb * kBatch; b < std::min(bricks, (bb + 1) * kBatch); ++b) {
        std::size_t slot = where.bricks()[b].value_offset;
        where.for_each_active_in_brick(b, [&](const Coord& c, float) {
          r.fits[slot++] = local_fit(index, where.world(c), options.neighbors);
        });
      }
    }
  });
  options.progress.step(1.0, "point fit");
  r.seconds = seconds_since(t0);
  return r;
}

}  // namespace levelset::apps
