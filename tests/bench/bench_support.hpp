// bench_support: what the OpenVDB comparison benchmarks (bench_*.cpp) share. Header-only.
//
// is_quick(argc, argv)     true when the first argument is --quick (the ctest smoke run).
// run_bench(name, failure, body)
//                          main's exit code for body() (true: every check passed): 0; 1 when
//                          it returns false (then "name: failure" on stderr, unless failure is
//                          null) or throws levelset::Error ("name: what" on stderr).
// best_of(runs, f)         the smallest wall-clock time (seconds) of `runs` >= 1 calls of f.
// best_of_interleaved(runs, f...)
//                          the same for several functions called in turn (f1, f2, ..., f1, ...),
//                          so that each side of a ratio sees the same phases of a machine whose
//                          speed drifts (this project's VMs: 30 % between consecutive runs).
// RatioSummary             collects a bench's time ratios (ours / OpenVDB's, or ours / another
//                          reference, lower is better) per kind of row; print() ends the bench
//                          with one "summary" line per kind: the worst ratio, its row, the
//                          target and whether every row met it.
// vdb_mesh(mesh)           a TriangleMesh as OpenVDB's points and triangles (meshToLevelSet).
// vdb_from_band(band)      an openvdb::FloatGrid level set holding the band's active voxels
//                          and values (same index space: OpenVDB's origin 0 = ours, so
//                          leaves = bricks), inactive voxels signed by signedFloodFill.
// band_from_vdb(grid, W)   the reverse: a NarrowBand (origin 0, the grid's voxel size,
//                          half-width W) holding exactly the grid's active voxels, signs of
//                          inactive voxels from the grid's values.
// Threading: band_from_vdb fills bricks in parallel (TBB); the rest runs on the caller.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/malloc_policy.hpp"
#include "grid/band_builder.hpp"
#include "grid/narrow_band.hpp"
#include "io/triangle_mesh.hpp"

namespace levelset::bench {

// Every bench runs with levelsetd's malloc settings (core/malloc_policy.hpp), set before main
// and shared by both sides of each comparison: freed buffers stay in the process.
inline const bool kKeepsFreedMemory = keep_freed_memory();

inline bool is_quick(int argc, char** argv) { return argc > 1 && std::strcmp(argv[1], "--quick") == 0; }

template <typename Body>
int run_bench(const char* name, const char* failure, Body&& body) {
  bool ok = false;
  try {
    ok = body();
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 1;
  }
  if (!ok && failure != nullptr) std::fprintf(stderr, "%s: %s\n", name, failure);
  return ok ? 0 : 1;
}

template <typename F>
double best_of(int runs, F&& f) {
  double best = 1e300;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

template <typename... F>
std::array<double, sizeof...(F)> best_of_interleaved(int runs, F&&... f) {
  std::array<double, sizeof...(F)> best;
  best.fill(1e300);
  for (int i = 0; i < runs; ++i) {
    std::size_t k = 0;
    (
        [&] {
          const auto t0 = std::chrono::steady_clock::now();
          f();
          best[k] = std::min(best[k], std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
          ++k;
        }(),
        ...);
  }
  return best;
}

class RatioSummary {
 public:
  explicit RatioSummary(const char* bench) : bench_(bench) {}
  void add(const std::string& kind, double target, const std::string& row, double ratio) {
    Kind& k = kinds_[kind];
    k.target = target;
    ++k.rows;
    if (!(ratio <= k.worst)) k.worst = ratio, k.row = row;  // NaN counts as worst
  }
  void print() const {
    for (const auto& [name, k] : kinds_)
      std::printf("summary %s %s: worst ratio %.3fx (%s) over %d rows, target <= %.2fx: %s\n", bench_, name.c_str(),
                  k.worst, k.row.c_str(), k.rows, k.target, k.worst <= k.target ? "met" : "NOT met");
  }

 private:
  struct Kind {
    double target = 0, worst = -1;
    int rows = 0;
    std::string row;
  };
  const char* bench_;
  std::map<std::string, Kind> kinds_;
};

struct VdbMesh {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
};

inline VdbMesh vdb_mesh(const TriangleMesh& mesh) {
  VdbMesh out;
  for (const auto& v : mesh.vertices) out.points.emplace_back(float(v.x), float(v.y), float(v.z));
  for (const auto& t : mesh.triangles) out.triangles.emplace_back(t[0], t[1], t[2]);
  return out;
}

inline openvdb::FloatGrid::Ptr vdb_from_band(const NarrowBand& band) {
  auto grid = openvdb::FloatGrid::create(band.background());
  grid->setTransform(openvdb::math::Transform::createLinearTransform(band.voxel_size()));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  auto acc = grid->getAccessor();
  band.for_each_active([&](const Coord& c, float v) { acc.setValueOn(openvdb::Coord(c.x, c.y, c.z), v); });
  openvdb::tools::signedFloodFill(grid->tree());
  return grid;
}

inline NarrowBand band_from_vdb(const openvdb::FloatGrid& grid, double half_width) {
  const double h = grid.voxelSize()[0];
  BandBuilder builder(GridFrame{h, {0, 0, 0}, half_width});
  std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
  for (auto it = grid.tree().cbeginLeaf(); it; ++it) leaves.push_back(&*it);
  tbb::parallel_for(std::size_t(0), leaves.size(), [&](std::size_t i) {
    const auto& leaf = *leaves[i];
    const openvdb::Coord o = leaf.origin();
    BrickMask active, inside;
    float dense[kBrickVoxels];
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
          // OpenVDB leaf offsets run z fastest; ours x fastest.
          const openvdb::Index off = leaf.coordToOffset(o + openvdb::Coord(x, y, z));
          const int n = local_index(x, y, z);
          dense[n] = leaf.getValue(off);
          if (leaf.isValueOn(off)) active.set(n);
          if (dense[n] < 0.0f) inside.set(n);
        }
    if (!active.none()) builder.add_brick(brick_of(Coord{o.x(), o.y(), o.z()}), active, inside, dense);
  });
  return builder.finish(false);
}

}  // namespace levelset::bench
