#include "apps/voronoi.hpp"

#include <utility>

namespace levelset::apps {

VoronoiResult voronoi_regions(const VoronoiOptions& options) {
  VoronoiResult r;
  r.field = fast_marching(options);
  const FastMarchingResult& f = r.field;
  const DenseGrid& g = f.grid;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const std::size_t v = g.index(i, j, k);
        const std::int32_t l = f.label[v];
        if (l < 0) {
          if (!f.blocked[v]) ++r.unreached;
          continue;
        }
        ++r.region_voxels[l];
        // Forward neighbours only would miss half the pairs' second node: check all six.
        const int c[3] = {i, j, k};
        const std::size_t stride[3] = {1, std::size_t(g.nx), std::size_t(g.nx) * std::size_t(g.ny)};
        bool boundary = false;
        for (int a = 0; a < 3 && !boundary; ++a) {
          if (c[a] > 0 && f.label[v - stride[a]] >= 0 && f.label[v - stride[a]] != l) boundary = true;
          if (c[a] + 1 < g.dim(a) && f.label[v + stride[a]] >= 0 && f.label[v + stride[a]] != l) boundary = true;
        }
        r.boundary_voxels += boundary;
      }
  return r;
}

}  // namespace levelset::apps
