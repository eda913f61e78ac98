#include "jobs/speed_fields.hpp"

#include <cmath>

#include "apps/point_distance.hpp"
#include "grid/band_accessor.hpp"
#include "grid/interpolate.hpp"

namespace levelset::jobs {

evolve::SpeedFields speed_fields(std::shared_ptr<const PointCloud> points, std::shared_ptr<const NarrowBand> roi) {
  evolve::SpeedFields f;
  if (points && !points->points.empty()) {
    auto index = std::make_shared<const apps::PointIndex>(points->points);
    f.dist = [index](const Vec3d& p) { return index->nearest(p).distance; };
    f.dist_gradient = [index](const Vec3d& p) {
      const apps::PointIndex::Nearest n = index->nearest(p);
      const Vec3d d = p - index->points()[n.index];
      return n.distance > 0.0 ? d / n.distance : Vec3d{0, 0, 0};
    };
  }
  if (roi) {
    f.roi = [roi](const Vec3d& p) {
      // One accessor per thread and band: the evolution calls this from its workers.
      thread_local const NarrowBand* band = nullptr;
      thread_local std::unique_ptr<BandAccessor> accessor;
      if (band != roi.get() || !accessor) {
        accessor = std::make_unique<BandAccessor>(*roi);
        band = roi.get();
      }
      return double(sample_trilinear(*accessor, *roi, p));
    };
  }
  return f;
}

}  // namespace levelset::jobs
