// A snap pass's local fits of one brick's voxels (reconstruction_parts.hpp): the brick's
// neighbourhood, and one sheet fit per column or block of voxels that see the same points.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "apps/nearby_points.hpp"
#include "apps/reconstruction_parts.hpp"
#include "grid/interpolate.hpp"

namespace levelset::apps::detail {

namespace {

// Bricks with fewer fit voxels query the tree per voxel (a shared neighbourhood costs about
// as much as a few tree queries).
constexpr int kMinSharedFits = 4;
// The voxels of a column along the normal share one fit where its quadric patch is at least
// this many voxels wide (fit_voxels).
constexpr double kShareRadius = 4.0;
// 2x2 blocks of columns share one height fit where the brick's first shared patch is at least
// this many voxels wide (fit_voxels; a voxel lies within 0.71 voxel of its block's centre across
// the normal), unless the block's scale choice gives its largest patch less than
// kBlockLargeWeight (detail: then its columns share theirs). bench_reconstruct --sweep, 33
// meshes, against a fit per column: 20k points at 0.5 % noise about half the final level's fits
// and Chamfer 0.4 % better on average (none worse by 1 %), 0.1 % 18 % fewer and 0.2 % better;
// 50k at 0.1 % the same Chamfer on average. Sharing regardless of the scale choice took 58 %
// fewer at 20k / 0.1 % but cost the featured meshes 1-2.5 % at 50k / 0.1 % (anchor, fandisk,
// hand); sharing each block's 8-point plane fits as well moved the noise reading (handle at 20k
// / 0.1 % then took the clean path and lost 5 %).
// Under strong noise (FitSettings::wide_blocks: the fits' noise above the count law's
// reference, where the noise, not the detail, sets the patches) the blocks are 4x4 columns
// (a voxel within 2.1 voxels of the centre), each falling back to its 2x2 blocks where its own
// patch is narrower or its scale choice finds detail: 20k points at 0.5 % noise, a third
// fewer fits on the final level than 2x2 blocks and Chamfer 0.35 % better on average (none
// worse by 1 %), 50k at 0.5 % 0.12 % better. Under milder noise (the soft scale choice) 4x4
// blocks cost 0.2 % on average and 1.3-1.7 % on armadillo, bull and triceratops at 20k / 0.1 %.
constexpr double kBlockRadius = 12.0;
constexpr double kBlockLargeWeight = 0.5;

// The voxels of `voxels` grouped by key(v) (keys in [0, kColumns)): by_group holds their
// indices in key order, first[k] .. first[k + 1] those of key k (a counting sort, stable).
struct VoxelGroups {
  std::array<int, kColumns + 1> first{};
  std::array<int, kBrickVoxels> by_group;  // a brick has at most 512 voxels
};
template <class Key>
void group_voxels(const std::vector<FitVoxel>& voxels, Key key, VoxelGroups& g) {
  g.first.fill(0);
  for (const FitVoxel& v : voxels) ++g.first[std::size_t(key(v) + 1)];
  for (int k = 0; k < kColumns; ++k) g.first[std::size_t(k + 1)] += g.first[std::size_t(k)];
  std::array<int, kColumns> fill{};
  std::copy(g.first.begin(), g.first.begin() + kColumns, fill.begin());
  for (std::size_t v = 0; v < voxels.size(); ++v) g.by_group[std::size_t(fill[std::size_t(key(voxels[v]))]++)] = int(v);
}

int column_of(const FitVoxel& v) { return v.column; }
// A column's 2x2 block across the normal (its axis and its two coordinates halved).
int block_of(const FitVoxel& v) { return (v.column >> 6) << 4 | (v.column & 6) >> 1 | ((v.column >> 3) & 6) << 1; }
// Its 4x4 block (the coordinates quartered).
int block4_of(const FitVoxel& v) { return (v.column >> 6) << 2 | (v.column & 4) >> 2 | ((v.column >> 3) & 4) >> 1; }

// The fits of fit_voxels: a group of voxels takes one model made at their centroid along
// their mean normal, evaluated at each, or each voxel its own.
struct GroupFits {
  const NearbyPoints& near;
  const std::vector<FitVoxel>& voxels;
  const FitSettings& fs;
  std::vector<SheetFit>& fits;
  int models = 0;

  void own(const int* group, int count) {
    for (int j = 0; j < count; ++j) {
      const FitVoxel& v = voxels[std::size_t(group[j])];
      fits[std::size_t(group[j])] = sheet_fit(near, v.x, v.n, fs.neighbors, fs.height_neighbors, fs.min_band, fs.noise, fs.facing);
      ++models;
    }
  }
  // The group's model; none (and each voxel its own fit) for a lone voxel or normals that disagree.
  std::optional<SheetModel> shared(const int* group, int count) {
    Vec3d centroid{}, normal{};
    for (int j = 0; j < count; ++j) {
      centroid += voxels[std::size_t(group[j])].x;
      normal += voxels[std::size_t(group[j])].n;
    }
    const double nl = length(normal);
    if (count == 1 || !(nl > 0.9 * count)) {
      own(group, count);
      return std::nullopt;
    }
    ++models;
    return sheet_model(near, centroid / double(count), normal / nl, fs.neighbors, fs.height_neighbors, fs.min_band,
                       fs.noise, fs.facing);
  }
  void evaluate(const SheetModel& model, const int* group, int count) {
    for (int j = 0; j < count; ++j) fits[std::size_t(group[j])] = model.at(voxels[std::size_t(group[j])].x);
  }
  // The block's height model, each voxel's own plane fit (its k nearest points: cheap beside
  // the height fit's; the pass's noise reading, the plane fits' spread, stays each voxel's).
  void evaluate_heights(const SheetModel& model, const int* group, int count) {
    for (int j = 0; j < count; ++j) {
      const FitVoxel& v = voxels[std::size_t(group[j])];
      SheetFit& f = fits[std::size_t(group[j])];
      f = model.at(v.x);
      f.plane = sheet_plane(near, v.x, v.n, fs.neighbors, fs.min_band, fs.facing);
    }
  }
  // The voxels of a group split by key(v), each part (stably sorted) passed to f.
  template <class Key, class F>
  void split(const int* group, int count, Key key, F f) {
    std::array<int, kBrickVoxels> sorted;
    std::copy(group, group + count, sorted.begin());
    std::stable_sort(sorted.begin(), sorted.begin() + count,
                     [&](int a, int b) { return key(voxels[std::size_t(a)]) < key(voxels[std::size_t(b)]); });
    for (int j = 0; j < count;) {
      int e = j + 1;
      while (e < count && key(voxels[std::size_t(sorted[std::size_t(e)])]) == key(voxels[std::size_t(sorted[std::size_t(j)])])) ++e;
      f(&sorted[std::size_t(j)], e - j);
      j = e;
    }
  }
  void column(const int* group, int count) {
    if (const auto model = shared(group, count)) evaluate(*model, group, count);
  }
  // A block of size x size columns: one height model for all its voxels where its scale choice
  // finds no detail (and, for a 4x4 block, where its own patch is block_radius wide), else its
  // 2x2 blocks, else its columns.
  void block(const int* group, int count, int size) {
    const std::optional<SheetModel> model = shared(group, count);
    if (!model) return;
    if (model->has_height && model->large_weight >= kBlockLargeWeight &&
        (size == 2 || model->patch_radius() >= fs.block_radius))
      evaluate_heights(*model, group, count);
    else if (size == 4)
      split(group, count, block_of, [&](const int* g, int c) { block(g, c, 2); });
    else
      split(group, count, column_of, [&](const int* g, int c) { column(g, c); });
  }
};

}  // namespace

FitSettings snap_fit_settings(int neighbors, int height_neighbors, double min_band, double h, HeightNoise noise,
                              bool wide_blocks) {
  return {neighbors, height_neighbors, min_band, kShareRadius * h, kBlockRadius * h, wide_blocks, noise, {}};
}

std::vector<Vec3f> point_facing(const NarrowBand& band, const PointIndex& index, double max_depth) {
  const double h = band.voxel_size();
  std::vector<Vec3f> facing(index.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, index.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    BandAccessor acc(band);
    auto difference = [&](const Vec3d& p, const Vec3d& step) {
      return double(sample_trilinear(acc, band, p + step)) - double(sample_trilinear(acc, band, p - step));
    };
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Vec3d& p = index.points()[i];
      if (!(std::abs(double(sample_trilinear(acc, band, p))) <= max_depth)) continue;
      const Vec3d g{difference(p, {h, 0, 0}), difference(p, {0, h, 0}), difference(p, {0, 0, h})};
      const double gl = length(g);
      facing[i] = gl > 1e-6 * h ? Vec3f{float(g.x / gl), float(g.y / gl), float(g.z / gl)} : Vec3f{};
    }
  });
  return facing;
}

// One radius query around the box of the brick's fit voxels (bunny, 20k points, 0.1 %: the
// final level's fits, k = 46, 1.67 -> 1.37 s).
void prepare_brick_neighbours(const NarrowBand& band, std::uint32_t b, double window, int k, NearbyPoints& near) {
  Coord lo{kBrickDim, kBrickDim, kBrickDim}, hi{-1, -1, -1};
  const Coord origin = brick_origin(band.bricks()[b].coord);
  int count = 0;
  band.for_each_active_in_brick(b, [&](const Coord& c, float value) {
    if (!(std::abs(double(value)) < window)) return;
    const Coord l = c - origin;
    lo = {std::min(lo.x, l.x), std::min(lo.y, l.y), std::min(lo.z, l.z)};
    hi = {std::max(hi.x, l.x), std::max(hi.y, l.y), std::max(hi.z, l.z)};
    ++count;
  });
  if (count < kMinSharedFits) {
    near.prepare({}, -1.0, k);  // the tree answers
    return;
  }
  const Vec3d a = band.world(origin + lo), z = band.world(origin + hi);
  near.prepare((a + z) * 0.5, 0.5 * length(z - a), k);
}

// The sheet fit of every voxel (fits[v] for voxels[v]); returns how many fits were made. The
// voxels of one column along the normal (those within a voxel of the front: one to three) see
// the same points, so they share one fit, made at their centroid along their mean normal and
// evaluated at each (SheetModel::at), where its quadric patch is at least share_radius wide:
// the fits cost about half. Where the brick's first shared patch is at least block_radius wide
// (many points per fit: noisy data), a 2x2 block of columns shares one (4x4 under strong
// noise, FitSettings::wide_blocks, falling back to its 2x2 blocks), unless its scale choice
// found detail (SheetModel::large_weight below kBlockLargeWeight: then its columns share
// theirs). Narrower patches keep a fit per column: the snap's averaging of the offsets
// over neighbouring voxels needs independent fits (sharing 2x2x2 blocks cost 1-3 % of Chamfer
// on bench_reconstruct --sweep at 20k points with 16-point fits). A lone voxel, a column whose
// normals disagree, and every voxel of a brick whose first shared patch was narrower than
// share_radius take their own.
int fit_voxels(const NearbyPoints& near, const std::vector<FitVoxel>& voxels, const FitSettings& fs,
               std::vector<SheetFit>& fits) {
  fits.resize(voxels.size());
  GroupFits groups{near, voxels, fs, fits};
  VoxelGroups g;
  group_voxels(voxels, column_of, g);
  enum class Sharing { Undecided, Columns, Blocks, None } sharing = Sharing::Undecided;
  for (int k = 0; k < kColumns && sharing != Sharing::Blocks; ++k) {
    const int* group = &g.by_group[std::size_t(g.first[std::size_t(k)])];
    const int count = g.first[std::size_t(k + 1)] - g.first[std::size_t(k)];
    if (count == 0) continue;
    if (sharing == Sharing::None) {
      groups.own(group, count);
      continue;
    }
    const std::optional<SheetModel> model = groups.shared(group, count);
    if (!model) continue;
    if (model->has_height && model->patch_radius() < fs.share_radius) {
      sharing = Sharing::None;
      groups.own(group, count);
      continue;
    }
    if (sharing == Sharing::Undecided && fs.block_radius > 0.0 && model->has_height &&
        model->patch_radius() >= fs.block_radius) {
      sharing = Sharing::Blocks;  // the blocks below fit every voxel again
      continue;
    }
    sharing = Sharing::Columns;
    groups.evaluate(*model, group, count);
  }
  if (sharing != Sharing::Blocks) return groups.models;
  const int size = fs.wide_blocks ? 4 : 2;
  group_voxels(voxels, size == 4 ? block4_of : block_of, g);
  for (int k = 0; k < kColumns; ++k) {
    const int count = g.first[std::size_t(k + 1)] - g.first[std::size_t(k)];
    if (count > 0) groups.block(&g.by_group[std::size_t(g.first[std::size_t(k)])], count, size);
  }
  return groups.models;
}

}  // namespace levelset::apps::detail
