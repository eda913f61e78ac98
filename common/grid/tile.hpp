// Dense tiles: a brick's values plus a halo from its neighbours, for stencil kernels.
//
// gather_tile fills a dense (8+2*halo)^3 float array for one brick: active voxels carry
// their values, inactive ones +-background() by their sign (also in unallocated bricks).
// Kernels then run plain loops (which the compiler vectorizes) without any lookups, and
// scatter_active writes results back to the brick's active voxels only.
// Layout: x fastest; tile index of local voxel (x,y,z), x,y,z in [-halo, 8+halo), is
// (x+halo) + dim*((y+halo) + dim*(z+halo)) with dim = 8+2*halo.
// Cost: O(dim^3) plus up to 26 neighbour resolutions (face links, rarely a hash lookup).
// Threading: reads only; one tile buffer per thread.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/uninitialized_vector.hpp"
#include "grid/narrow_band.hpp"

namespace levelset {

struct TileShape {
  int halo = 1;
  int dim() const { return kBrickDim + 2 * halo; }
  std::size_t size() const { return std::size_t(dim()) * dim() * dim(); }
  std::size_t index(int x, int y, int z) const {
    const int d = dim();
    return std::size_t(x + halo) + std::size_t(d) * (std::size_t(y + halo) + std::size_t(d) * std::size_t(z + halo));
  }
};

// halo in [0, 8]. out.size() must be TileShape{halo}.size().
void gather_tile(const NarrowBand& band, std::uint32_t brick, int halo, std::span<float> out);
// Same, and active_rows (size dim^2, one entry per tile row (y, z) at (y+halo) + dim*(z+halo))
// gets bit x+halo set where voxel (x, y, z) is active (stored in the band).
void gather_tile(const NarrowBand& band, std::uint32_t brick, int halo, std::span<float> out,
                 std::span<std::uint32_t> active_rows);

// A brick and its 26 neighbours (kNoBrick where unallocated), slot(dx, dy, dz) for offsets in
// {-1, 0, 1}^3. Face links, a hash lookup only for a brick no face path reaches.
struct Neighborhood : std::array<std::uint32_t, 27> {
  static constexpr int slot(int dx, int dy, int dz) { return (dx + 1) + 3 * (dy + 1) + 9 * (dz + 1); }
  static constexpr Coord offset(int k) { return {k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1}; }
};
Neighborhood brick_neighborhood(const NarrowBand& band, std::uint32_t brick);
// The brick and its six face neighbours only (face links; the other slots kNoBrick): enough
// for a GatherRegion::Star gather, which reads no other slot except to take an unallocated
// face neighbour's sign, and then falls back to the band's row rule.
Neighborhood brick_star(const NarrowBand& band, std::uint32_t brick);

// The general form: the box [lo, hi)^3 of brick-local voxel coordinates (-8 <= lo <= 0,
// 8 <= hi <= 16; dim = hi - lo), index (x-lo) + dim*((y-lo) + dim*(z-lo)); active_rows may be
// empty, else it has dim^2 entries (bit x-lo of entry (y-lo) + dim*(z-lo)).
// gather_tile(halo) is gather_box(-halo, 8 + halo).
void gather_box(const NarrowBand& band, std::uint32_t brick, int lo, int hi, std::span<float> out,
                std::span<std::uint32_t> active_rows);
// With the neighbourhood already resolved (around[slot(0, 0, 0)] is the brick).
void gather_box(const NarrowBand& band, const Neighborhood& around, int lo, int hi, std::span<float> out,
                std::span<std::uint32_t> active_rows);

// Dense 512 values of one brick (halo 0) into out[local_index]. With AVX-512 (checked when the
// program loads) 16 voxels per expanding load; decode_brick_portable is the plain form, for
// tests on such machines.
void decode_brick(const NarrowBand& band, std::uint32_t brick, std::span<float, kBrickVoxels> out);
void decode_brick_portable(const NarrowBand& band, std::uint32_t brick, std::span<float, kBrickVoxels> out);

// Every brick decoded once (decode_brick; 512 values per brick, in brick order; TBB), for a
// pass that gathers a box around every brick: a box then copies rows from the decoded bricks
// instead of decoding each neighbour again (a 14^3 box decodes 5.4 bricks' worth of voxels).
// Memory: 2 KiB per brick (huge pages advised when large).
struct DecodedBricks {
  UninitializedVector<float> data;
  std::span<const float> values() const { return {data.data(), data.size()}; }
};
DecodedBricks decode_bricks(const NarrowBand& band);
// Which part of the box a gather fills: all of it, or the star (the brick and the parts of its
// six face neighbours: what lines along the axes through the brick's voxels read, 61% of a
// 14^3 box). Outside the star the values are left as they were and the active rows read 0.
enum class GatherRegion { Box, Star };
// The inside sign of a neighbourhood's unallocated bricks (bit Neighborhood::slot), resolved
// on first need by the band's x-row rule (a search over the bricks): a pass that gathers the
// same brick's box again passes the signs the first gather resolved.
struct NeighborSigns {
  std::uint32_t known = 0;
  std::uint32_t inside = 0;
};
// The signs gather_box resolves for the box [lo, hi)^3 around around's brick, all at once.
NeighborSigns resolve_neighbor_signs(const NarrowBand& band, const Neighborhood& around, int lo, int hi);
// gather_box from decode_bricks(band): the same output, by row copies. signs: null, or
// resolved / reused signs of this neighbourhood's unallocated bricks.
void gather_box(const NarrowBand& band, std::span<const float> decoded, const Neighborhood& around, int lo, int hi,
                std::span<float> out, std::span<std::uint32_t> active_rows, GatherRegion region = GatherRegion::Box,
                NeighborSigns* signs = nullptr);

// Writes tile values back to the active voxels of the brick (inactive voxels untouched,
// signs of active voxels updated). tile is laid out with the given halo.
void scatter_active(NarrowBand& band, std::uint32_t brick, int halo, std::span<const float> tile);

}  // namespace levelset
