#include "surface/iso_range.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/text.hpp"

namespace levelset {

double max_band_iso(const NarrowBand& band) {
  return std::max(0.0, band.background() - std::sqrt(3.0) * band.voxel_size());
}

void check_iso_in_band(const NarrowBand& band, double iso, std::string_view where) {
  if (!std::isfinite(iso))
    throw Error(ErrorCode::NonFinite, std::string(where), "the iso value must be finite, found " + format_number(iso));
  const double bound = max_band_iso(band);
  if (std::abs(iso) <= bound) return;
  const double h = band.voxel_size();
  throw Error(ErrorCode::InvalidArgument, std::string(where),
              "iso " + format_number(iso) + " (" + format_number(iso / h) +
                  " voxels) leaves the band: with a half-width of " +
                  format_number(band.background() / h) + " voxels the surface stays inside it for |iso| <= " +
                  format_number(bound) + " (" + format_number(bound / h) +
                  " voxels); rebuild the band wider (--band) to contour further out");
}

}  // namespace levelset
