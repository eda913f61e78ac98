#include "apps/sample_points.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "core/error.hpp"
#include "grid/build_from_sdf.hpp"
#include "surface/marching_cubes.hpp"

namespace levelset::apps {

namespace {

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return double(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double gaussian() {
    const double u1 = 1.0 - uniform(), u2 = uniform();  // u1 in (0, 1]
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  std::mt19937_64 engine_;
};

void check(const SurfaceSampleOptions& o) {
  if (o.count == 0 || o.count > (std::size_t{1} << 28))
    throw Error(ErrorCode::InvalidArgument, "sample points", "count must be in [1, 2^28]");
  if (!std::isfinite(o.noise) || o.noise < 0.0)
    throw Error(ErrorCode::InvalidArgument, "sample points", "noise must be finite and >= 0");
}

}  // namespace

std::vector<Vec3d> sample_mesh_surface(const TriangleMesh& mesh, const SurfaceSampleOptions& o) {
  check(o);
  std::vector<double> cumulative(mesh.triangles.size());
  double total = 0.0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (std::uint32_t v : tri)
      if (v >= mesh.vertices.size()) throw Error(ErrorCode::InvalidArgument, "sample points", "vertex index out of range");
    const Vec3d& a = mesh.vertices[tri[0]];
    total += 0.5 * length(cross(mesh.vertices[tri[1]] - a, mesh.vertices[tri[2]] - a));
    cumulative[t] = total;
  }
  if (!(total > 0.0) || !std::isfinite(total))
    throw Error(ErrorCode::InvalidArgument, "sample points", "the mesh has no area");
  Random rng(o.seed);
  std::vector<Vec3d> points(o.count);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if ((i & 0xffff) == 0) o.progress.check("sample points");
    Vec3d& p = points[i];
    const double pick = rng.uniform() * total;
    const std::size_t t = std::min(std::size_t(std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin()),
                                   cumulative.size() - 1);
    double u = rng.uniform(), v = rng.uniform();
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    const auto& tri = mesh.triangles[t];
    const Vec3d& a = mesh.vertices[tri[0]];
    p = a + (mesh.vertices[tri[1]] - a) * u + (mesh.vertices[tri[2]] - a) * v;
    if (o.noise > 0.0) p += Vec3d{rng.gaussian(), rng.gaussian(), rng.gaussian()} * o.noise;
  }
  return points;
}

std::vector<Vec3d> sample_shape_surface(const AnalyticShape& shape, const SurfaceSampleOptions& o) {
  check(o);
  if (o.resolution < 16 || o.resolution > 2048)
    throw Error(ErrorCode::InvalidArgument, "sample points", "resolution must be in [16, 2048]");
  const BBox bounds = shape.bounds();
  SdfBuildOptions build;
  build.frame = frame_for_resolution(bounds, o.resolution, 2.0);
  build.progress = o.progress;
  const NarrowBand band = build_from_sdf([&](const Vec3d& p) { return shape.distance(p); }, bounds, build).band;
  MarchingCubesOptions mc;
  mc.progress = o.progress;
  const TriangleMesh mesh = marching_cubes(band, mc).mesh;
  SurfaceSampleOptions clean = o;
  clean.noise = 0.0;
  std::vector<Vec3d> points = sample_mesh_surface(mesh, clean);
  const Vec3d ext = bounds.extent();
  const double eps = 1e-6 * std::max({ext.x, ext.y, ext.z});
  for (std::size_t i = 0; i < points.size(); ++i) {
    if ((i & 0xffff) == 0) o.progress.check("sample points");
    Vec3d& p = points[i];
    for (int it = 0; it < 2; ++it) {
      const double d = shape.distance(p);
      Vec3d g{};
      for (int a = 0; a < 3; ++a) {
        Vec3d e{};
        e[a] = eps;
        g[a] = (shape.distance(p + e) - shape.distance(p - e)) / (2 * eps);
      }
      const double gl = length(g);
      if (gl > 0.0) p -= g * (d / (gl * gl));
    }
  }
  if (o.noise > 0.0) {
    Random rng(o.seed ^ 0x9e3779b97f4a7c15ull);
    for (Vec3d& p : points) p += Vec3d{rng.gaussian(), rng.gaussian(), rng.gaussian()} * o.noise;
  }
  return points;
}

}  // namespace levelset::apps
