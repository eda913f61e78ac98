#include "apps/point_denoise.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "geometry/symmetric_eigen.hpp"

namespace levelset::apps {

ProjectToPlanesResult project_to_planes(const PointIndex& index,
                                        const ProjectToPlanesOptions& options) {
  const int k = options.neighbors;
  if (k < 4 || k > 64)
    throw Error(ErrorCode::InvalidArgument, "project_to_planes",
                "neighbors must be in [4, 64], got " + std::to_string(k));
  if (!(options.max_move >= 0.0) || !std::isfinite(options.max_move))
    throw Error(ErrorCode::InvalidArgument, "project_to_planes",
                "max_move must be finite and >= 0");
  const double cap =
      options.max_move > 0.0 ? options.max_move : std::numeric_limits<double>::infinity();
  const std::vector<Vec3d>& pts = index.points();
  ProjectToPlanesResult r;
  r.points = pts;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pts.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      options.progress.check("project to planes");
                      std::array<std::uint32_t, 64> ids{};
                      std::array<double, 64> dist2{};
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const int found = index.k_nearest(pts[i], k, ids.data(), dist2.data());
                        if (found < 4) continue;
                        Vec3d c{0, 0, 0};
                        for (int j = 0; j < found; ++j) c = c + pts[ids[std::size_t(j)]];
                        c = c / double(found);
                        std::array<double, 6> m{};  // xx yy zz xy xz yz
                        for (int j = 0; j < found; ++j) {
                          const Vec3d v = pts[ids[std::size_t(j)]] - c;
                          m[0] += v.x * v.x, m[1] += v.y * v.y, m[2] += v.z * v.z,
                              m[3] += v.x * v.y, m[4] += v.x * v.z, m[5] += v.y * v.z;
                        }
                        const double lambda =
                            smallest_eigenvalue(m[0], m[1], m[2], m[3], m[4], m[5]);
                        const Vec3d n = eigenvector_of(m[0], m[1], m[2], m[3], m[4], m[5], lambda);
                        r.points[i] = pts[i] - n * std::clamp(dot(pts[i] - c, n), -cap, cap);
                      }
                    });
  return r;
}

}  // namespace levelset::apps
