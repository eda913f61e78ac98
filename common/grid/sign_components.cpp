#include "grid/sign_components.hpp"

#include <algorithm>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "grid/band_accessor.hpp"

namespace levelset {

namespace {
constexpr std::uint8_t kInside = 1, kActive = 2;
}

SignComponentsResult sign_components(const NarrowBand& band, const SignComponentsOptions& options) {
  for (int n : {options.inside_connectivity, options.outside_connectivity})
    if (n != 6 && n != 26)
      throw Error(ErrorCode::InvalidArgument, "sign_components", "connectivity must be 6 or 26, got " + std::to_string(n));
  if (options.max_voxels > (std::uint64_t(1) << 32))
    throw Error(ErrorCode::InvalidArgument, "sign_components", "max_voxels must be at most 2^32");
  SignComponentsResult result;
  IndexBox box = band.active_index_bounds();
  if (box.empty()) return result;
  box.min = box.min - Coord{1, 1, 1};
  box.max = box.max + Coord{1, 1, 1};
  result.box = box;
  const long nx = long(box.max.x) - box.min.x + 1, ny = long(box.max.y) - box.min.y + 1, nz = long(box.max.z) - box.min.z + 1;
  if (double(nx) * double(ny) * double(nz) > double(options.max_voxels))
    throw Error(ErrorCode::LimitExceeded, "sign_components",
                "the band's box has " + std::to_string(nx) + "x" + std::to_string(ny) + "x" + std::to_string(nz) +
                    " voxels, over the limit of " + std::to_string(options.max_voxels));
  const std::size_t total = std::size_t(nx * ny * nz);
  std::vector<std::uint8_t> state(total);
  tbb::parallel_for(tbb::blocked_range<long>(0, nz), [&](const tbb::blocked_range<long>& r) {
    options.progress.check("sign components");
    BandAccessor acc(band);
    for (long k = r.begin(); k != r.end(); ++k)
      for (long j = 0; j < ny; ++j)
        for (long i = 0; i < nx; ++i) {
          const Coord c{box.min.x + int(i), box.min.y + int(j), box.min.z + int(k)};
          const std::optional<float> v = acc.probe(c);
          const bool in = v ? *v < 0.0f : acc.is_inside(c);
          state[std::size_t((k * ny + j) * nx + i)] = std::uint8_t((in ? kInside : 0) | (v ? kActive : 0));
        }
  });
  result.label.assign(total, -1);
  std::vector<std::uint32_t> stack;  // box indices: under max_voxels <= 2^32
  std::uint64_t visited = 0;
  for (std::size_t start = 0; start < total; ++start) {
    if (result.label[start] >= 0) continue;
    const std::int32_t id = std::int32_t(result.components.size());
    SignComponent comp;
    comp.inside = state[start] & kInside;
    const bool diagonals = (comp.inside ? options.inside_connectivity : options.outside_connectivity) == 26;
    result.label[start] = id;
    stack.push_back(std::uint32_t(start));
    while (!stack.empty()) {
      const std::size_t n = stack.back();
      stack.pop_back();
      if ((++visited & 0xfffff) == 0) options.progress.check("sign components");
      ++comp.voxels;
      if (!(state[n] & kActive)) comp.all_active = false;
      const long i = long(n % std::size_t(nx)), j = long((n / std::size_t(nx)) % std::size_t(ny)),
                 k = long(n / std::size_t(nx * ny));
      if (i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1) comp.touches_box = true;
      bool front = false;
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int taxicab = (dx != 0) + (dy != 0) + (dz != 0);
            if (taxicab == 0) continue;
            const long a = i + dx, b = j + dy, c = k + dz;
            if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz) continue;
            const std::size_t m = std::size_t((c * ny + b) * nx + a);
            const bool same = ((state[m] ^ state[n]) & kInside) == 0;
            if (!same) {
              if (taxicab == 1) front = true;
              continue;
            }
            if (taxicab > 1 && !diagonals) continue;
            if (result.label[m] < 0) {
              result.label[m] = id;
              stack.push_back(std::uint32_t(m));
            }
          }
      if (front) comp.front.push_back(Coord{box.min.x + int(i), box.min.y + int(j), box.min.z + int(k)});
    }
    std::sort(comp.front.begin(), comp.front.end(), [](const Coord& p, const Coord& q) {
      return p.z != q.z ? p.z < q.z : p.y != q.y ? p.y < q.y : p.x < q.x;
    });
    result.components.push_back(std::move(comp));
  }
  return result;
}

}  // namespace levelset
