// ImageVolume: a dense 3D scalar image (CT / MRI volume) as plain data.
//
// Sample (i,j,k), 0 <= i < nx ..., is stored at samples[i + nx*(j + ny*k)] (x fastest) and sits
// at world position origin + (i*sx, j*sy, k*sz) (voxel centres; spacing per axis, world units,
// > 0). Samples are float32 whatever the file's type (integers converted exactly up to 2^24).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/bbox.hpp"
#include "core/vec3.hpp"

namespace levelset {

struct ImageVolume {
  std::int64_t nx = 0, ny = 0, nz = 0;
  Vec3d spacing{1.0, 1.0, 1.0};
  Vec3d origin{};
  std::vector<float> samples;

  std::uint64_t voxel_count() const { return std::uint64_t(nx) * std::uint64_t(ny) * std::uint64_t(nz); }
  std::size_t index(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return std::size_t(i + nx * (j + ny * k));
  }
  float at(std::int64_t i, std::int64_t j, std::int64_t k) const { return samples[index(i, j, k)]; }
  Vec3d world(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return origin + Vec3d{double(i) * spacing.x, double(j) * spacing.y, double(k) * spacing.z};
  }
  // Continuous index coordinates of a world point.
  Vec3d to_index(const Vec3d& p) const {
    const Vec3d d = p - origin;
    return {d.x / spacing.x, d.y / spacing.y, d.z / spacing.z};
  }
  // The box of the voxel centres (empty for an empty image).
  BBox bounds() const {
    BBox b;
    if (voxel_count() == 0) return b;
    b.extend(origin);
    b.extend(world(nx - 1, ny - 1, nz - 1));
    return b;
  }
};

}  // namespace levelset
