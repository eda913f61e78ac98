// speed_fields: the fields a speed formula may read besides the level set (thesis 4.9, table
// 4.1 B and J), from what a job or a daemon session carries:
//   points -> dist (world distance to the nearest point), dgx dgy dgz (its gradient, the unit
//             vector from that point; dn is dgx nx + dgy ny + dgz nz);
//   roi    -> roi (a stored level set sampled trilinearly; +-its background outside its band).
// Either may be null (the fields it gives stay unset: a speed reading them is refused by the
// evolution with the field's name). The functions keep their data alive (shared_ptr) and are
// safe to call concurrently (one band accessor per thread). Cost: dist O(log N) per sample,
// roi 8 voxel reads.
#pragma once

#include <memory>

#include "evolve/speed.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::jobs {

evolve::SpeedFields speed_fields(std::shared_ptr<const PointCloud> points, std::shared_ptr<const NarrowBand> roi);

}  // namespace levelset::jobs
