#include "distance/closest_triangle_propagation.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "core/error.hpp"
#include "distance/triangle_bvh.hpp"
#include "geometry/point_triangle.hpp"

namespace levelset {

namespace {

// Triangles around each vertex, vertices welded by exact position so that soups (STL, split
// normals) still have neighbours across their seams.
struct VertexRings {
  std::vector<std::uint32_t> canonical;  // per input vertex: its welded id
  std::vector<std::uint32_t> offsets;    // per welded id, CSR into triangles
  std::vector<std::uint32_t> triangles;
  // Per triangle: a bounding sphere (centroid, farthest vertex) for cheap rejections.
  std::vector<Vec3d> centres;
  std::vector<double> radii;

  std::span<const std::uint32_t> ring(std::uint32_t input_vertex) const {
    const std::uint32_t w = canonical[input_vertex];
    return {triangles.data() + offsets[w], offsets[w + 1] - offsets[w]};
  }
};

VertexRings build_rings(const TriangleMesh& mesh) {
  const std::size_t nv = mesh.vertices.size();
  std::vector<std::uint32_t> order(nv);
  for (std::size_t i = 0; i < nv; ++i) order[i] = std::uint32_t(i);
  auto less = [&](std::uint32_t a, std::uint32_t b) {
    const Vec3d &p = mesh.vertices[a], &q = mesh.vertices[b];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    if (p.z != q.z) return p.z < q.z;
    return a < b;
  };
  tbb::parallel_sort(order.begin(), order.end(), less);
  VertexRings rings;
  rings.canonical.resize(nv);
  std::uint32_t welded = 0;
  for (std::size_t i = 0; i < nv; ++i) {
    if (i > 0 && !(mesh.vertices[order[i]] == mesh.vertices[order[i - 1]])) ++welded;
    rings.canonical[order[i]] = welded;
  }
  const std::size_t nw = nv == 0 ? 0 : std::size_t(welded) + 1;
  rings.offsets.assign(nw + 1, 0);
  for (const auto& f : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++rings.offsets[rings.canonical[f[k]] + 1];
  for (std::size_t w = 0; w < nw; ++w) rings.offsets[w + 1] += rings.offsets[w];
  rings.triangles.resize(rings.offsets[nw]);
  std::vector<std::uint32_t> fill(rings.offsets.begin(), rings.offsets.end() - 1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) rings.triangles[fill[rings.canonical[mesh.triangles[t][k]]]++] = std::uint32_t(t);
  rings.centres.resize(mesh.triangles.size());
  rings.radii.resize(mesh.triangles.size());
  tbb::parallel_for(std::size_t(0), mesh.triangles.size(), [&](std::size_t t) {
    const auto& f = mesh.triangles[t];
    const Vec3d &a = mesh.vertices[f[0]], &b = mesh.vertices[f[1]], &c = mesh.vertices[f[2]];
    const Vec3d centre = (a + b + c) / 3.0;
    rings.centres[t] = centre;
    rings.radii[t] = std::sqrt(std::max({dot(a - centre, a - centre), dot(b - centre, b - centre),
                                         dot(c - centre, c - centre)})) * (1.0 + 1e-12);
  });
  return rings;
}

// The bricks the band can reach: every brick within `reach` bricks (Chebyshev) of a shell
// brick, sorted by key, with each brick's 27-neighbourhood as slots (kNoBrick outside).
struct BrickSet {
  std::vector<Coord> bricks;
  std::vector<std::uint32_t> neighbours;  // 27 per brick: (dx+1) + 3 (dy+1) + 9 (dz+1)
};

BrickSet dilate_bricks(const std::vector<Coord>& shell, int reach) {
  std::vector<std::uint64_t> keys;
  keys.reserve(shell.size() * std::size_t((2 * reach + 1) * (2 * reach + 1) * (2 * reach + 1)));
  for (const Coord& b : shell)
    for (int dz = -reach; dz <= reach; ++dz)
      for (int dy = -reach; dy <= reach; ++dy)
        for (int dx = -reach; dx <= reach; ++dx) {
          const Coord n = b + Coord{dx, dy, dz};
          if (brick_in_range(n)) keys.push_back(brick_key(n));
        }
  tbb::parallel_sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  BrickSet set;
  set.bricks.resize(keys.size());
  // Keys pack (x, y, z) + offset in 21 bits each (coord.hpp); decode rather than keep pairs.
  constexpr std::int64_t off = kBrickCoordLimit;
  constexpr std::uint64_t mask = (std::uint64_t{1} << kBrickCoordBits) - 1;
  tbb::parallel_for(std::size_t(0), keys.size(), [&](std::size_t i) {
    const std::uint64_t k = keys[i];
    set.bricks[i] = {std::int32_t(std::int64_t(k & mask) - off),
                     std::int32_t(std::int64_t((k >> kBrickCoordBits) & mask) - off),
                     std::int32_t(std::int64_t((k >> (2 * kBrickCoordBits)) & mask) - off)};
  });
  set.neighbours.assign(keys.size() * 27, kNoBrick);
  tbb::parallel_for(std::size_t(0), keys.size(), [&](std::size_t i) {
    for (int j = 0; j < 27; ++j) {
      const Coord n = set.bricks[i] + Coord{j % 3 - 1, (j / 3) % 3 - 1, j / 9 - 1};
      if (!brick_in_range(n)) continue;
      const auto it = std::lower_bound(keys.begin(), keys.end(), brick_key(n));
      if (it != keys.end() && *it == brick_key(n)) set.neighbours[i * 27 + j] = std::uint32_t(it - keys.begin());
    }
  });
  return set;
}

enum : std::uint8_t { kFree = 0, kTentative = 1, kFinal = 2 };
inline constexpr std::uint64_t kNoVoxel = ~std::uint64_t{0};

struct Offsets26 {
  std::array<Coord, 26> d;
  Offsets26() {
    int k = 0;
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
          if (x != 0 || y != 0 || z != 0) d[k++] = {x, y, z};
  }
};

// Voxel id = brick slot * 512 + local index.
inline std::uint64_t neighbour_id(const BrickSet& set, std::uint64_t id, const Coord& d) {
  const std::uint64_t slot = id / kBrickVoxels;
  const Coord l = local_coord(int(id % kBrickVoxels));
  const int x = l.x + d.x, y = l.y + d.y, z = l.z + d.z;
  const int bx = x < 0 ? 0 : (x >= kBrickDim ? 2 : 1);
  const int by = y < 0 ? 0 : (y >= kBrickDim ? 2 : 1);
  const int bz = z < 0 ? 0 : (z >= kBrickDim ? 2 : 1);
  const std::uint32_t nslot = set.neighbours[slot * 27 + std::uint64_t(bx + 3 * by + 9 * bz)];
  if (nslot == kNoBrick) return kNoVoxel;
  return std::uint64_t(nslot) * kBrickVoxels + std::uint64_t(local_index(x & 7, y & 7, z & 7));
}

// The best triangle for one voxel: candidates from its assigned neighbours, then the walk.
class VoxelSolver {
 public:
  VoxelSolver(const TriangleMesh& mesh, const VertexRings& rings) : mesh_(mesh), rings_(rings) {}

  struct Best {
    double d2 = std::numeric_limits<double>::infinity();
    std::uint32_t tri = kNoTriangle;
    Vec3d barycentric;
  };

  void reset(const Vec3d& p) {
    p_ = p;
    seen_count_ = 0;
    best_ = Best{};
    best_distance_ = std::numeric_limits<double>::infinity();
  }
  void offer(std::uint32_t tri) {
    for (int i = 0; i < seen_count_; ++i)
      if (seen_[i] == tri) return;
    if (seen_count_ < kMaxSeen) seen_[seen_count_++] = tri;
    // Bounding sphere farther than the best: this triangle cannot be nearer.
    const Vec3d dc = p_ - rings_.centres[tri];
    const double reach = best_distance_ + rings_.radii[tri];
    if (dot(dc, dc) > reach * reach) return;
    const auto& f = mesh_.triangles[tri];
    const TrianglePoint q = closest_point_on_triangle(p_, mesh_.vertices[f[0]], mesh_.vertices[f[1]],
                                                      mesh_.vertices[f[2]]);
    ++evaluations_;
    if (q.distance_squared < best_.d2 || (q.distance_squared == best_.d2 && tri < best_.tri)) {
      best_ = {q.distance_squared, tri, q.barycentric};
      best_distance_ = std::sqrt(q.distance_squared);
    }
  }
  // Local descent over the mesh: try every triangle around the best one's vertices and move
  // while one is nearer.
  void walk() {
    for (int step = 0; step < 64 && best_.tri != kNoTriangle; ++step) {
      const Best before = best_;
      const auto& f = mesh_.triangles[before.tri];
      for (int k = 0; k < 3; ++k)
        for (std::uint32_t t : rings_.ring(f[k])) offer(t);
      if (best_.tri == before.tri) return;
      ++walk_steps_;
    }
  }
  const Best& best() const { return best_; }
  std::uint64_t evaluations() const { return evaluations_; }
  std::uint64_t walk_steps() const { return walk_steps_; }

 private:
  static constexpr int kMaxSeen = 96;
  const TriangleMesh& mesh_;
  const VertexRings& rings_;
  Vec3d p_;
  Best best_;
  double best_distance_ = 0;
  std::uint32_t seen_[kMaxSeen];
  int seen_count_ = 0;
  std::uint64_t evaluations_ = 0, walk_steps_ = 0;
};

struct VerifyCounts {
  std::uint64_t verified = 0, corrected = 0, rim_added = 0;
};

// The exact pass: every propagated voxel asks the tree for a triangle strictly nearer than its
// propagated one (a tight bound: few boxes reach into that ball), then voxels next to the band
// that propagation left out ask for any triangle within W*h, repeated from each voxel added.
VerifyCounts verify_exactly(const TriangleMesh& mesh, const BrickSet& set, ClosestTriangleField& field,
                            const PropagateOptions& options, std::vector<std::uint8_t>& shell_mark) {  // shell_mark: any scratch of one byte per voxel
  const TriangleBvh tree(mesh);
  const double h = options.frame.voxel_size, w = options.frame.half_width;
  const double band2 = (w * h) * (w * h);
  const double rim_bound = std::nextafter(band2, std::numeric_limits<double>::infinity());
  const double shell2 = (options.shell_radius * h) * (options.shell_radius * h);
  const Vec3d origin = options.frame.origin;
  const Offsets26 offsets;
  auto world = [&](std::uint64_t id) {
    const Coord b = brick_origin(set.bricks[id / kBrickVoxels]);
    const Coord l = local_coord(int(id % kBrickVoxels));
    return origin + Vec3d{double(b.x + l.x), double(b.y + l.y), double(b.z + l.z)} * h;
  };
  auto distance2_to = [&](const Vec3d& p, std::uint32_t tri) {
    const auto& f = mesh.triangles[tri];
    return closest_point_on_triangle(p, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]])
        .distance_squared;
  };
  std::atomic<std::uint64_t> verified{0}, corrected{0};
  const std::size_t nvox = field.owner.size();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nvox, kBrickVoxels),
                    [&](const tbb::blocked_range<std::size_t>& range) {
    std::uint64_t v = 0, c = 0;
    for (std::size_t id = range.begin(); id != range.end(); ++id) {
      if (field.owner[id] == kNoTriangle) continue;
      const Vec3d p = world(id);
      const double d2 = distance2_to(p, field.owner[id]);
      if (d2 <= shell2) continue;  // the shell's scan is exact
      ++v;
      const BvhHit hit = tree.nearest(p, d2);
      if (hit.tri == kNoBvhTriangle) continue;
      field.owner[id] = hit.tri;
      field.distance[id] = static_cast<float>(std::sqrt(hit.distance_squared));
      ++c;
    }
    verified += v;
    corrected += c;
  });
  // The rim: free neighbours of band voxels, then of every voxel that joins (each asked once:
  // atomic mark).
  tbb::parallel_for(std::size_t(0), nvox, [&](std::size_t id) { shell_mark[id] = field.owner[id] != kNoTriangle; });
  std::vector<std::uint64_t> front;
  for (std::size_t id = 0; id < nvox; ++id)
    if (shell_mark[id]) front.push_back(id);
  std::uint64_t rim_added = 0;
  tbb::enumerable_thread_specific<std::vector<std::uint64_t>> found;
  std::vector<std::uint64_t> candidates;
  while (!front.empty()) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, front.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& range) {
      auto& out = found.local();
      for (std::size_t i = range.begin(); i != range.end(); ++i)
        for (const Coord& d : offsets.d) {
          const std::uint64_t u = neighbour_id(set, front[i], d);
          if (u == kNoVoxel) continue;
          std::atomic_ref<std::uint8_t> mark(shell_mark[u]);
          if (mark.load(std::memory_order_relaxed) == 0 && mark.exchange(1, std::memory_order_relaxed) == 0)
            out.push_back(u);
        }
    });
    candidates.clear();
    for (auto& l : found) {
      candidates.insert(candidates.end(), l.begin(), l.end());
      l.clear();
    }
    tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t i) {
      const std::uint64_t u = candidates[i];
      const BvhHit hit = tree.nearest(world(u), rim_bound);
      if (hit.tri == kNoBvhTriangle) return;
      field.owner[u] = hit.tri;
      field.distance[u] = static_cast<float>(std::sqrt(hit.distance_squared));
    });
    front.clear();
    for (std::uint64_t u : candidates)
      if (field.owner[u] != kNoTriangle) front.push_back(u);
    rim_added += front.size();
  }
  return {verified.load(), corrected.load(), rim_added};
}

void check_shell(const ClosestTriangleField& shell) {
  const std::size_t n = shell.bricks.size() * std::size_t(kBrickVoxels);
  if (shell.distance.size() != n || shell.owner.size() != n)
    throw Error(ErrorCode::InvalidArgument, "closest triangle field",
                "distance and owner arrays must hold 512 entries per brick");
  for (std::size_t i = 1; i < shell.bricks.size(); ++i)
    if (!(brick_key(shell.bricks[i - 1]) < brick_key(shell.bricks[i])))
      throw Error(ErrorCode::InvalidArgument, "closest triangle field", "bricks are not sorted by key");
}

// The distance-ordered front over the dilated bricks: voxels are finalised in increasing
// distance (bucket k holds tentative distances in [(k-1) d, k d), d = bucket_width; the shell is
// bucket 0), so the neighbour towards a voxel's closest point, nearer by more than d, is final
// before it (Dial's shortest paths with the exact evaluation as the edge weight).
class DistanceOrderedFront {
 public:
  DistanceOrderedFront(const TriangleMesh& mesh, const BrickSet& set, ClosestTriangleField& field,
                       const PropagateOptions& options)
      : set_(set), field_(field), options_(options), rings_(build_rings(mesh)), solvers_(mesh, rings_),
        state_(field.owner.size(), kFree), bucket_(field.owner.size(), 0), pulled_(field.owner.size(), 0) {
    const double h = options.frame.voxel_size, w = options.frame.half_width;
    band2_ = (w * h) * (w * h);
    queue2_ = ((w + 1.0) * h) * ((w + 1.0) * h);
    bucket_width_ = options.bucket_width * h;
  }

  // Shell values into their slots (both lists sorted by key: one merge); they are final.
  void seed(const ClosestTriangleField& shell) {
    std::size_t j = 0;
    for (std::size_t i = 0; i < shell.bricks.size(); ++i) {
      const std::uint64_t key = brick_key(shell.bricks[i]);
      while (brick_key(set_.bricks[j]) != key) ++j;  // every shell brick is in the set
      for (int n = 0; n < kBrickVoxels; ++n) {
        const std::size_t src = i * kBrickVoxels + std::size_t(n), dst = j * kBrickVoxels + std::size_t(n);
        if (shell.owner[src] == kNoTriangle) continue;
        field_.distance[dst] = shell.distance[src];
        field_.owner[dst] = shell.owner[src];
        state_[dst] = kFinal;
        finalized_.push_back(dst);
      }
    }
  }

  std::uint64_t run() {
    std::uint64_t layers = 0;
    const double w = options_.frame.half_width, h = options_.frame.voxel_size;
    const double expected = std::max(1.0, (w - options_.shell_radius) * h / bucket_width_);
    for (std::uint32_t k = 0; k < buckets_.size(); ++k) {
      if (k > 0) {
        finalise(k);
        options_.progress.step(std::min(1.0, double(k) / expected), "propagate");
      }
      if (finalized_.empty()) continue;
      ++layers;
      pull(k);
    }
    return layers;
  }

  std::vector<std::uint8_t>& scratch() { return state_; }
  std::uint64_t evaluations() const {
    std::uint64_t n = 0;
    for (const VoxelSolver& s : solvers_) n += s.evaluations();
    return n;
  }
  std::uint64_t walk_steps() const {
    std::uint64_t n = 0;
    for (const VoxelSolver& s : solvers_) n += s.walk_steps();
    return n;
  }

 private:
  Vec3d world(std::uint64_t id) const {
    const Coord b = brick_origin(set_.bricks[id / kBrickVoxels]);
    const Coord l = local_coord(int(id % kBrickVoxels));
    return options_.frame.origin + Vec3d{double(b.x + l.x), double(b.y + l.y), double(b.z + l.z)} * options_.frame.voxel_size;
  }
  std::uint8_t state_of(std::uint64_t id) {
    return std::atomic_ref<std::uint8_t>(state_[id]).load(std::memory_order_relaxed);
  }
  template <class Locals>
  static void gather(Locals& locals, std::vector<std::uint64_t>& out) {
    out.clear();
    for (auto& l : locals) {
      out.insert(out.end(), l.begin(), l.end());
      l.clear();
    }
  }

  // Finalise bucket k: the descent from each tentative triangle, then the value is fixed.
  void finalise(std::uint32_t k) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, buckets_[k].size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& range) {
      VoxelSolver& solver = solvers_.local();
      auto& out = ids_local_.local();
      for (std::size_t i = range.begin(); i != range.end(); ++i) {
        const std::uint64_t id = buckets_[k][i];
        std::uint8_t expected = kTentative;
        if (bucket_[id] != k ||
            !std::atomic_ref<std::uint8_t>(state_[id]).compare_exchange_strong(expected, kFinal, std::memory_order_relaxed))
          continue;  // stale entry (moved to another bucket) or a duplicate
        solver.reset(world(id));
        solver.offer(field_.owner[id]);
        solver.walk();
        if (!(solver.best().d2 <= band2_)) {  // beyond the band after all: final, outside
          field_.distance[id] = std::numeric_limits<float>::infinity();
          field_.owner[id] = kNoTriangle;
          continue;
        }
        field_.distance[id] = static_cast<float>(std::sqrt(solver.best().d2));
        field_.owner[id] = solver.best().tri;
        out.push_back(id);
      }
    });
    gather(ids_local_, finalized_);
    std::vector<std::uint64_t>().swap(buckets_[k]);
  }

  // Every non-final neighbour of a voxel finalised in bucket k (once each: pulled = k + 1)
  // offers the triangles of its neighbours finalised there and queues a better tentative value.
  void pull(std::uint32_t k) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, finalized_.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& range) {
      auto& out = ids_local_.local();
      for (std::size_t i = range.begin(); i != range.end(); ++i)
        for (const Coord& d : offsets_.d) {
          const std::uint64_t u = neighbour_id(set_, finalized_[i], d);
          if (u == kNoVoxel || state_of(u) == kFinal) continue;
          std::atomic_ref<std::uint32_t> mark(pulled_[u]);
          if (mark.load(std::memory_order_relaxed) != k + 1 && mark.exchange(k + 1, std::memory_order_relaxed) != k + 1)
            out.push_back(u);
        }
    });
    gather(ids_local_, claimed_);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, claimed_.size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& range) {
      VoxelSolver& solver = solvers_.local();
      auto& out = queued_local_.local();
      for (std::size_t i = range.begin(); i != range.end(); ++i) {
        const std::uint64_t id = claimed_[i];
        solver.reset(world(id));
        const std::uint32_t before = field_.owner[id];
        if (before != kNoTriangle) solver.offer(before);
        for (const Coord& d : offsets_.d) {
          const std::uint64_t u = neighbour_id(set_, id, d);
          if (u != kNoVoxel && state_of(u) == kFinal && bucket_[u] == k && field_.owner[u] != kNoTriangle)
            solver.offer(field_.owner[u]);
        }
        const auto& best = solver.best();
        // Tentative up to a voxel beyond the band: the descent when it is finalised may bring
        // a voxel whose neighbours' triangles lie just outside back within the band.
        if (best.tri == before || !(best.d2 <= queue2_)) continue;
        field_.distance[id] = static_cast<float>(std::sqrt(best.d2));
        field_.owner[id] = best.tri;
        const auto target = std::max<std::uint32_t>(k + 1, std::uint32_t(std::sqrt(best.d2) / bucket_width_) + 1);
        bucket_[id] = target;
        std::atomic_ref<std::uint8_t>(state_[id]).store(kTentative, std::memory_order_relaxed);
        out.emplace_back(target, id);
      }
    });
    for (auto& l : queued_local_) {
      for (const auto& [b, id] : l) {
        if (b >= buckets_.size()) buckets_.resize(b + 1);
        buckets_[b].push_back(id);
      }
      l.clear();
    }
  }

  const BrickSet& set_;
  ClosestTriangleField& field_;
  const PropagateOptions& options_;
  const VertexRings rings_;
  const Offsets26 offsets_;
  tbb::enumerable_thread_specific<VoxelSolver> solvers_;
  tbb::enumerable_thread_specific<std::vector<std::uint64_t>> ids_local_;
  tbb::enumerable_thread_specific<std::vector<std::pair<std::uint32_t, std::uint64_t>>> queued_local_;
  std::vector<std::uint8_t> state_;
  std::vector<std::uint32_t> bucket_, pulled_;
  std::vector<std::vector<std::uint64_t>> buckets_ = std::vector<std::vector<std::uint64_t>>(2);
  std::vector<std::uint64_t> finalized_, claimed_;
  double band2_ = 0, queue2_ = 0, bucket_width_ = 0;
};

}  // namespace

PropagateResult propagate_closest_triangles(const TriangleMesh& mesh, ClosestTriangleField shell,
                                            const PropagateOptions& options) {
  check_shell(shell);
  PropagateResult result;
  if (!(options.shell_radius < options.frame.half_width) || shell.bricks.empty()) {
    result.field = std::move(shell);
    return result;
  }
  const int reach = int(std::ceil((options.frame.half_width + 1.0) / kBrickDim));
  const BrickSet set = dilate_bricks(shell.bricks, reach);
  const std::size_t nvox = set.bricks.size() * std::size_t(kBrickVoxels);
  ClosestTriangleField& field = result.field;
  field.bricks = set.bricks;
  field.distance.assign(nvox, std::numeric_limits<float>::infinity());
  field.owner.assign(nvox, kNoTriangle);
  DistanceOrderedFront front(mesh, set, field, options);
  front.seed(shell);
  shell = ClosestTriangleField{};
  result.layers = front.run();
  result.evaluations = front.evaluations();
  result.walk_steps = front.walk_steps();
  if (options.exact) {
    const VerifyCounts counts = verify_exactly(mesh, set, field, options, front.scratch());
    result.verified = counts.verified;
    result.corrected = counts.corrected;
    result.rim_added = counts.rim_added;
  }
  return result;
}

}  // namespace levelset
