#include "apps/edge_indicator.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <tuple>

#include "apps/gaussian_smooth.hpp"
#include "core/error.hpp"

namespace levelset::apps {

namespace {

// Percentiles of an evenly strided subsample (deterministic, O(2^20 log)).
std::pair<double, double> robust_range(const std::vector<float>& s, double lo, double hi) {
  const std::size_t step = std::max<std::size_t>(1, s.size() >> 20);
  std::vector<float> sub;
  sub.reserve(s.size() / step + 1);
  for (std::size_t i = 0; i < s.size(); i += step) sub.push_back(s[i]);
  auto pick = [&](double q) {
    const std::size_t k = std::min(sub.size() - 1, std::size_t(q * double(sub.size() - 1) + 0.5));
    std::nth_element(sub.begin(), sub.begin() + std::ptrdiff_t(k), sub.end());
    return double(sub[k]);
  };
  double a = pick(lo), b = pick(hi);
  if (!(b > a)) {  // (nearly) constant at these percentiles: fall back to the full range
    a = *std::min_element(s.begin(), s.end());
    b = *std::max_element(s.begin(), s.end());
  }
  return {a, b > a ? b : a + std::max(1.0, std::abs(a))};  // a + 1 == a for |a| >= 2^53
}

// Central differences (one-sided at the border) of `f` at voxel (i,j,k), world units.
template <typename Get>
Vec3d difference(const ImageVolume& im, std::int64_t i, std::int64_t j, std::int64_t k, Get&& f) {
  const std::int64_t idx[3] = {i, j, k};
  const std::int64_t n[3] = {im.nx, im.ny, im.nz};
  Vec3d d;
  for (int a = 0; a < 3; ++a) {
    if (n[a] == 1) continue;
    std::int64_t lo[3] = {i, j, k}, hi[3] = {i, j, k};
    lo[a] = std::max<std::int64_t>(idx[a] - 1, 0);
    hi[a] = std::min<std::int64_t>(idx[a] + 1, n[a] - 1);
    d[a] = (f(im.index(hi[0], hi[1], hi[2])) - f(im.index(lo[0], lo[1], lo[2]))) /
           (double(hi[a] - lo[a]) * im.spacing[a]);
  }
  return d;
}

void for_each_slice(const ImageVolume& im, const ProgressHook& progress, const std::function<void(std::int64_t)>& f) {
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, im.nz), [&](const tbb::blocked_range<std::int64_t>& r) {
    progress.check("edges");
    for (std::int64_t k = r.begin(); k != r.end(); ++k) f(k);
  });
}

}  // namespace

EdgeIndicator edge_indicator(const ImageVolume& image, const EdgeIndicatorOptions& o) {
  if (image.voxel_count() == 0 || image.samples.size() != image.voxel_count())
    throw Error(ErrorCode::InvalidArgument, "edge_indicator", "empty image or samples not matching its size");
  if (!std::isfinite(o.contrast) || o.contrast <= 0)
    throw Error(ErrorCode::InvalidArgument, "edge_indicator", "contrast must be a positive number");
  if (o.power != 1 && o.power != 2) throw Error(ErrorCode::InvalidArgument, "edge_indicator", "power must be 1 or 2");
  if (!(o.low_percentile >= 0 && o.low_percentile < o.high_percentile && o.high_percentile <= 1))
    throw Error(ErrorCode::InvalidArgument, "edge_indicator", "percentiles must satisfy 0 <= low < high <= 1");
  EdgeIndicator e;
  std::tie(e.intensity_low, e.intensity_high) = robust_range(image.samples, o.low_percentile, o.high_percentile);
  ImageVolume normal = image;
  const double lo = e.intensity_low, scale = 1.0 / (e.intensity_high - e.intensity_low);
  for (float& v : normal.samples) v = float(std::clamp((double(v) - lo) * scale, 0.0, 1.0));
  const ImageVolume smooth = gaussian_smooth(normal, o.sigma, o.progress);
  normal = {};
  const double voxel = std::min({image.spacing.x, image.spacing.y, image.spacing.z});
  e.g = smooth;
  for_each_slice(image, o.progress, [&](std::int64_t k) {
    for (std::int64_t j = 0; j < image.ny; ++j)
      for (std::int64_t i = 0; i < image.nx; ++i) {
        const double m = length(difference(smooth, i, j, k, [&](std::size_t x) { return double(smooth.samples[x]); })) *
                         voxel / o.contrast;
        e.g.samples[image.index(i, j, k)] = float(1.0 / (1.0 + (o.power == 2 ? m * m : m)));
      }
  });
  o.progress.step(1.0, "edges");
  e.gradient.resize(image.voxel_count());
  for_each_slice(image, o.progress, [&](std::int64_t k) {
    for (std::int64_t j = 0; j < image.ny; ++j)
      for (std::int64_t i = 0; i < image.nx; ++i) {
        const Vec3d d = difference(e.g, i, j, k, [&](std::size_t x) { return double(e.g.samples[x]); });
        e.gradient[image.index(i, j, k)] = {float(d.x), float(d.y), float(d.z)};
      }
  });
  return e;
}

namespace {

// Trilinear interpolation over the 8 voxels around p; voxels outside the image count as zero.
template <typename T, typename Get>
T trilinear(const ImageVolume& im, const Vec3d& world, Get&& get) {
  const Vec3d q = im.to_index(world);
  T sum{};
  if (!(q.x > -1 && q.y > -1 && q.z > -1 && q.x < double(im.nx) && q.y < double(im.ny) && q.z < double(im.nz)))
    return sum;
  const std::int64_t i0 = std::int64_t(std::floor(q.x)), j0 = std::int64_t(std::floor(q.y)),
                     k0 = std::int64_t(std::floor(q.z));
  const double fx = q.x - double(i0), fy = q.y - double(j0), fz = q.z - double(k0);
  for (int c = 0; c < 8; ++c) {
    const std::int64_t i = i0 + (c & 1), j = j0 + ((c >> 1) & 1), k = k0 + (c >> 2);
    if (i < 0 || j < 0 || k < 0 || i >= im.nx || j >= im.ny || k >= im.nz) continue;
    const double w = ((c & 1) ? fx : 1 - fx) * (((c >> 1) & 1) ? fy : 1 - fy) * ((c >> 2) ? fz : 1 - fz);
    sum += get(im.index(i, j, k)) * w;
  }
  return sum;
}

}  // namespace

double EdgeIndicator::sample(const Vec3d& world) const {
  return trilinear<double>(g, world, [&](std::size_t x) { return double(g.samples[x]); });
}

Vec3d EdgeIndicator::sample_gradient(const Vec3d& world) const {
  return trilinear<Vec3d>(g, world, [&](std::size_t x) {
    const Vec3f& v = gradient[x];
    return Vec3d{v.x, v.y, v.z};
  });
}

}  // namespace levelset::apps
