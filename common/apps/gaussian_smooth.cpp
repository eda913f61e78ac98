#include "apps/gaussian_smooth.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.hpp"

namespace levelset::apps {

namespace {

// One pass along `axis` from src into dst.
void convolve_axis(const ImageVolume& src, ImageVolume& dst, int axis, const std::vector<double>& kernel,
                   const ProgressHook& progress) {
  const std::int64_t n[3] = {src.nx, src.ny, src.nz};
  const std::int64_t stride[3] = {1, src.nx, src.nx * src.ny};
  const int a = axis, b = (axis + 1) % 3, c = (axis + 2) % 3;
  const std::int64_t lines = n[b] * n[c];
  const std::int64_t len = n[a];
  const int r = int(kernel.size() / 2);
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, lines, 64), [&](const tbb::blocked_range<std::int64_t>& range) {
    progress.check("smooth");
    std::vector<float> line(std::size_t(len + 2 * r));
    for (std::int64_t l = range.begin(); l != range.end(); ++l) {
      const std::int64_t start = (l % n[b]) * stride[b] + (l / n[b]) * stride[c];
      for (std::int64_t i = -r; i < len + r; ++i) {
        const std::int64_t s = std::clamp<std::int64_t>(i, 0, len - 1);
        line[std::size_t(i + r)] = src.samples[std::size_t(start + s * stride[a])];
      }
      for (std::int64_t i = 0; i < len; ++i) {
        double sum = 0;
        for (int k = 0; k <= 2 * r; ++k) sum += kernel[std::size_t(k)] * line[std::size_t(i + k)];
        dst.samples[std::size_t(start + i * stride[a])] = float(sum);
      }
    }
  });
}

}  // namespace

ImageVolume gaussian_smooth(const ImageVolume& image, double sigma, const ProgressHook& progress) {
  if (!std::isfinite(sigma) || sigma < 0 || sigma > 64)
    throw Error(ErrorCode::InvalidArgument, "gaussian_smooth", "sigma must be in [0, 64] voxels");
  ImageVolume out = image;
  if (sigma == 0 || image.voxel_count() == 0) return out;
  const int r = int(std::ceil(3 * sigma));
  std::vector<double> kernel(std::size_t(2 * r + 1));
  double total = 0;
  for (int k = -r; k <= r; ++k) total += kernel[std::size_t(k + r)] = std::exp(-0.5 * k * k / (sigma * sigma));
  for (double& k : kernel) k /= total;
  ImageVolume tmp = image;
  convolve_axis(image, tmp, 0, kernel, progress);
  progress.step(1.0 / 3, "smooth");
  convolve_axis(tmp, out, 1, kernel, progress);
  progress.step(2.0 / 3, "smooth");
  convolve_axis(out, tmp, 2, kernel, progress);
  progress.step(1.0, "smooth");
  return tmp;
}

}  // namespace levelset::apps
