#include "apps/image_regions.hpp"

#include <algorithm>

#include <tbb/parallel_for.h>

#include "core/error.hpp"

namespace levelset::apps {

ImageVolume downsample_image(const ImageVolume& im, int f, const ProgressHook& progress) {
  if (f < 1 || f > im.nx || f > im.ny || f > im.nz)
    throw Error(ErrorCode::InvalidArgument, "downsample", "factor " + std::to_string(f) + " does not fit the image");
  ImageVolume out;
  out.nx = im.nx / f;
  out.ny = im.ny / f;
  out.nz = im.nz / f;
  out.spacing = im.spacing * double(f);
  out.origin = im.origin + im.spacing * (0.5 * (f - 1));
  out.samples.assign(out.voxel_count(), 0.0f);
  const float w = 1.0f / float(f * f * f);
  tbb::parallel_for(std::int64_t{0}, out.nz, [&](std::int64_t K) {
    progress.check("downsample");
    for (std::int64_t k = K * f; k < (K + 1) * f; ++k)
      for (std::int64_t j = 0; j < out.ny * f; ++j)
        for (std::int64_t i = 0; i < out.nx * f; ++i) out.samples[out.index(i / f, j / f, K)] += im.at(i, j, k) * w;
  });
  return out;
}

std::vector<std::size_t> seed_voxels_above(const ImageVolume& im, float t, int stride, int r, const ProgressHook& progress) {
  std::vector<std::size_t> seeds;
  const int stride_z = std::max(1, stride / 2);
  for (std::int64_t k = r; k + r < im.nz; ++k) {
    progress.check("seeds");
    for (std::int64_t j = r; j + r < im.ny; ++j)
      for (std::int64_t i = r; i + r < im.nx; ++i) {
        if (i % stride != 0 || j % stride != 0 || k % stride_z != 0) continue;
        bool all = true;
        for (int dz = -r; dz <= r && all; ++dz)
          for (int dy = -r; dy <= r && all; ++dy)
            for (int dx = -r; dx <= r && all; ++dx) all = im.at(i + dx, j + dy, k + dz) > t;
        if (all) seeds.push_back(im.index(i, j, k));
      }
  }
  return seeds;
}

std::vector<std::uint8_t> threshold_component(const ImageVolume& im, float t, const std::vector<std::size_t>& seeds,
                                              const ProgressHook& progress) {
  std::vector<std::uint8_t> in(im.voxel_count(), 0);
  std::vector<std::size_t> stack;
  for (const std::size_t s : seeds) {
    if (s >= in.size() || !(im.samples[s] > t)) continue;  // a seed below t starts no component
    in[s] = 1;
    stack.push_back(s);
  }
  const std::int64_t step[3] = {1, im.nx, im.nx * im.ny};
  const std::int64_t n[3] = {im.nx, im.ny, im.nz};
  for (std::uint64_t popped = 0; !stack.empty(); ++popped) {
    if ((popped & 0xfffff) == 0) progress.check("threshold component");
    const std::size_t v = stack.back();
    stack.pop_back();
    const std::int64_t c[3] = {std::int64_t(v) % im.nx, (std::int64_t(v) / im.nx) % im.ny, std::int64_t(v) / (im.nx * im.ny)};
    for (int a = 0; a < 3; ++a)
      for (int d : {-1, 1}) {
        if (c[a] + d < 0 || c[a] + d >= n[a]) continue;
        const std::size_t w = std::size_t(std::int64_t(v) + d * step[a]);
        if (!in[w] && im.samples[w] > t) {
          in[w] = 1;
          stack.push_back(w);
        }
      }
  }
  return in;
}

double dice(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  if (a.size() != b.size()) throw Error(ErrorCode::InvalidArgument, "dice", "masks of different sizes");
  std::uint64_t both = 0, na = 0, nb = 0;
  for (std::size_t v = 0; v < a.size(); ++v) {
    both += (a[v] != 0 && b[v] != 0) ? 1 : 0;
    na += a[v] != 0;
    nb += b[v] != 0;
  }
  return na + nb == 0 ? 1.0 : 2.0 * double(both) / double(na + nb);
}

}  // namespace levelset::apps
