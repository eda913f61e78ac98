#include "distance/closest_point_transform.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "core/error.hpp"
#include "core/text.hpp"
#include "distance/brick_triangle_lists.hpp"
#include "distance/characteristic_scan.hpp"
#include "distance/inside_masks.hpp"
#include "distance/membrane_band.hpp"
#include "distance/orient_faces.hpp"
#include "distance/unique_faces.hpp"
#include "distance/winding_number.hpp"
#include "geometry/point_triangle.hpp"
#include "io/validate_mesh.hpp"

namespace levelset {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void check_budget(const TriangleMesh& mesh, const CptOptions& options) {
  if (mesh.triangles.empty())
    throw Error(ErrorCode::InvalidArgument, "mesh", "the mesh has no triangles");
  validate_mesh(mesh);
  const BBox box = mesh.bounds();
  const double h = options.frame.voxel_size;
  const double pad = 2.0 * (options.frame.half_width + 1.0);
  double voxels = 1.0;
  for (int a = 0; a < 3; ++a) voxels *= std::ceil((box.max[a] - box.min[a]) / h) + pad;
  if (!(voxels <= double(options.max_domain_voxels)))
    throw Error(ErrorCode::LimitExceeded, "mesh",
                "the mesh spans " + format_number(voxels) + " voxels at voxel size " +
                    format_number(h) + ", more than the voxel budget of " +
                    std::to_string(options.max_domain_voxels) + "; increase the voxel size");
}

// Scan-converts the slab of one triangle within one brick and keeps per-voxel minima.
// dist2 / dist: the best squared distance and distance per voxel so far (dist is kept for
// the cheap bounding-sphere rejection below).
void scan_triangle(const Vec3d& a, const Vec3d& b, const Vec3d& c, std::uint32_t tri,
                   const Coord& brick, const GridFrame& frame, double radius_voxels, double band2,
                   double* dist2, double* dist, std::uint32_t* owner) {
  const double h = frame.voxel_size;
  const double r = radius_voxels * h * (1.0 + 1e-12) + 1e-12 * h;  // inclusive at the rim
  const Coord o = brick_origin(brick);
  // Voxel range of the triangle's inflated bounding box, clipped to the brick.
  int lo[3], hi[3];
  const Vec3d tmin = min(min(a, b), c), tmax = max(max(a, b), c);
  for (int ax = 0; ax < 3; ++ax) {
    lo[ax] = std::max(0, int(std::ceil((tmin[ax] - r - frame.origin[ax]) / h)) - o[ax]);
    hi[ax] = std::min(kBrickDim - 1, int(std::floor((tmax[ax] + r - frame.origin[ax]) / h)) - o[ax]);
    if (lo[ax] > hi[ax]) return;
  }
  // Slab along the dominant normal axis: |n.(p - a)| <= r bounds that coordinate per column
  // (flat triangles only: a nearly collinear one's computed normal is noise).
  const TrianglePlane plane = triangle_plane(a, b, c);
  const Vec3d& n = plane.n;
  int axis = 2;
  if (plane.flat) {
    const Vec3d an{std::abs(n.x), std::abs(n.y), std::abs(n.z)};
    axis = an.x >= an.y ? (an.x >= an.z ? 0 : 2) : (an.y >= an.z ? 1 : 2);
  }
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const bool slab = plane.flat && std::abs(n[axis]) > 1e-3 && plane.error < 1e-9;
  // Bounding sphere: |p - centre| - radius bounds the triangle distance from below.
  const Vec3d centre = (a + b + c) / 3.0;
  const double radius = std::sqrt(std::max(dot(a - centre, a - centre),
                                           std::max(dot(b - centre, b - centre), dot(c - centre, c - centre))));
  for (int jv = lo[v]; jv <= hi[v]; ++jv) {
    for (int ju = lo[u]; ju <= hi[u]; ++ju) {
      int k0 = lo[axis], k1 = hi[axis];
      Vec3d p;
      p[u] = frame.origin[u] + (o[u] + ju) * h;
      p[v] = frame.origin[v] + (o[v] + jv) * h;
      if (slab) {
        // Plane coordinate along the axis at this column, then +- r / |n_axis|.
        const double along = a[axis] - (n[u] * (p[u] - a[u]) + n[v] * (p[v] - a[v])) / n[axis];
        const double spread = r / std::abs(n[axis]);
        k0 = std::max(k0, int(std::ceil((along - spread - frame.origin[axis]) / h)) - o[axis]);
        k1 = std::min(k1, int(std::floor((along + spread - frame.origin[axis]) / h)) - o[axis]);
      }
      Coord l;
      l[u] = ju;
      l[v] = jv;
      for (int k = k0; k <= k1; ++k) {
        p[axis] = frame.origin[axis] + (o[axis] + k) * h;
        l[axis] = k;
        const int idx = local_index(l.x, l.y, l.z);
        // Lower bounds first (sphere, then plane): skip voxels this triangle cannot improve.
        const Vec3d pc = p - centre;
        const double reach = radius + dist[idx];
        if (dot(pc, pc) >= reach * reach) continue;
        if (slab) {
          const double pd = dot(n, p - a);
          if (pd * pd >= dist2[idx]) continue;
        }
        const double d2 = closest_point_on_triangle(p, a, b, c).distance_squared;
        if (d2 <= band2 && d2 < dist2[idx]) {
          dist2[idx] = d2;
          dist[idx] = std::sqrt(d2);
          owner[idx] = tri;
        }
      }
    }
  }
}

// The slab scan: the exact distances of every voxel within `radius` voxels of the mesh, per
// listed brick (lists binned with that margin): each brick scan-converts its triangles' slabs.
ClosestTriangleField slab_scan(const TriangleMesh& mesh, const BrickTriangleLists& lists,
                                const GridFrame& frame, double radius, const ProgressHook& progress) {
  const std::size_t nb = lists.bricks.size();
  ClosestTriangleField shell;
  shell.bricks = lists.bricks;
  shell.distance.assign(nb * kBrickVoxels, std::numeric_limits<float>::infinity());
  shell.owner.assign(nb * kBrickVoxels, kNoTriangle);
  const double r = radius * frame.voxel_size, band2 = r * r;
  const std::size_t batch = 2048;
  for (std::size_t start = 0; start < nb; start += batch) {
    const std::size_t end = std::min(nb, start + batch);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(start, end, 4),
                      [&](const tbb::blocked_range<std::size_t>& range) {
      double dist2[kBrickVoxels], dist[kBrickVoxels];
      for (std::size_t i = range.begin(); i != range.end(); ++i) {
        std::fill(dist2, dist2 + kBrickVoxels, std::numeric_limits<double>::infinity());
        std::fill(dist, dist + kBrickVoxels, std::numeric_limits<double>::infinity());
        std::uint32_t* owner = shell.owner.data() + i * kBrickVoxels;
        for (std::uint64_t k = lists.offsets[i]; k < lists.offsets[i + 1]; ++k) {
          const std::uint32_t tri = lists.triangles[k];
          const auto& f = mesh.triangles[tri];
          scan_triangle(mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]], tri,
                        lists.bricks[i], frame, radius, band2, dist2, dist, owner);
        }
        float* out = shell.distance.data() + i * kBrickVoxels;
        for (int n = 0; n < kBrickVoxels; ++n)
          if (dist2[n] <= band2) out[n] = static_cast<float>(dist[n]);
      }
    });
    progress.step(0.15 + 0.3 * double(end) / double(nb), "distance");
  }
  return shell;
}

// The bricks holding band voxels, each with its triangles from the shell's lists (none for
// bricks beyond the shell: no triangle meets them). Both inputs are sorted by key.
BrickTriangleLists band_brick_lists(const ClosestTriangleField& field, const BrickTriangleLists& lists) {
  BrickTriangleLists out;
  out.margin = lists.margin;
  out.offsets.push_back(0);
  std::size_t j = 0;
  for (std::size_t i = 0; i < field.bricks.size(); ++i) {
    const std::uint32_t* owner = field.owner.data() + i * kBrickVoxels;
    if (std::all_of(owner, owner + kBrickVoxels, [](std::uint32_t o) { return o == kNoTriangle; })) continue;
    const std::uint64_t key = brick_key(field.bricks[i]);
    while (j < lists.bricks.size() && brick_key(lists.bricks[j]) < key) ++j;
    if (j < lists.bricks.size() && brick_key(lists.bricks[j]) == key)
      out.triangles.insert(out.triangles.end(), lists.triangles.begin() + std::ptrdiff_t(lists.offsets[j]),
                           lists.triangles.begin() + std::ptrdiff_t(lists.offsets[j + 1]));
    out.bricks.push_back(field.bricks[i]);
    out.offsets.push_back(out.triangles.size());
  }
  return out;
}

// Per listed brick: active mask, distances packed in active order, closest points on request.
std::vector<MembraneBrick> pack_bricks(const TriangleMesh& mesh, const ClosestTriangleField& field,
                                       const BrickTriangleLists& band, const CptOptions& options) {
  std::vector<MembraneBrick> per_brick(band.bricks.size());
  // Slot of each listed brick in the field (both sorted). The binning's lists may hold a brick
  // a little beyond the band (its culling is conservative) that the field lacks: empty.
  constexpr std::size_t kNoSlot = ~std::size_t{0};
  std::vector<std::size_t> slot(band.bricks.size(), kNoSlot);
  for (std::size_t i = 0, j = 0; i < band.bricks.size(); ++i) {
    while (j < field.bricks.size() && brick_key(field.bricks[j]) < brick_key(band.bricks[i])) ++j;
    if (j < field.bricks.size() && field.bricks[j] == band.bricks[i]) slot[i] = j;
  }
  tbb::parallel_for(std::size_t(0), band.bricks.size(), [&](std::size_t i) {
    MembraneBrick& out = per_brick[i];
    out.coord = band.bricks[i];
    if (slot[i] == kNoSlot) return;
    const Coord o = brick_origin(out.coord);
    const float* distance = field.distance.data() + slot[i] * kBrickVoxels;
    const std::uint32_t* owner = field.owner.data() + slot[i] * kBrickVoxels;
    for (int n = 0; n < kBrickVoxels; ++n) {
      if (owner[n] == kNoTriangle) continue;
      out.active.set(n);
      out.distance.push_back(distance[n]);
      if (!options.closest_points) continue;
      const auto& f = mesh.triangles[owner[n]];
      const Coord l = local_coord(n);
      const Vec3d p = options.frame.origin +
                      Vec3d{double(o.x + l.x), double(o.y + l.y), double(o.z + l.z)} * options.frame.voxel_size;
      const Vec3d q = closest_point_on_triangle(p, mesh.vertices[f[0]], mesh.vertices[f[1]],
                                                mesh.vertices[f[2]]).point;
      out.closest_point.push_back({float(q.x), float(q.y), float(q.z)});
    }
  });
  return per_brick;
}

// The method when the caller leaves it to us. The slab scan's work grows with W^3 per triangle,
// the characteristic scan's with the band's voxels (one to two evaluations each) plus a fixed
// cost per polyhedron; the slab scan is cheaper only for narrow bands around very coarse
// meshes. Measured at W = 3, 2 threads (slab / characteristic, triangles per surface voxel):
// knot.off R = 512 0.33 / 0.38 s (0.008), eight.off R = 512 0.14 / 0.16 s (0.002), elephant.off
// R = 512 0.22 / 0.22 s (0.018), knot.off R = 256 0.15 / 0.11 s (0.033), fandisk.off R = 512
// 0.35 / 0.30 s (0.023), bunny00.off R = 512 0.82 / 0.59 s (0.12).
CptMethod choose_method(const TriangleMesh& mesh, const GridFrame& frame) {
  if (frame.half_width > 3.0) return CptMethod::characteristic;
  double area = 0;
  for (const auto& f : mesh.triangles)
    area += 0.5 * length(cross(mesh.vertices[f[1]] - mesh.vertices[f[0]], mesh.vertices[f[2]] - mesh.vertices[f[0]]));
  const double surface_voxels = area / (frame.voxel_size * frame.voxel_size);
  return double(mesh.triangles.size()) < 0.015 * surface_voxels ? CptMethod::slab_scan : CptMethod::characteristic;
}

}  // namespace

CptResult closest_point_transform(const TriangleMesh& mesh, const CptOptions& options) {
  const auto t_start = Clock::now();
  NarrowBand validate(options.frame);
  (void)validate;
  check_budget(mesh, options);
  CptResult result;
  result.triangles = mesh.triangles.size();

  // Sign mesh: every face once, then consistently oriented (distances use the mesh as given).
  // Mostly serial sorts and a walk, so it runs beside the binning and the scan, which fill the
  // other threads; the signs wait for it.
  OrientResult oriented;
  tbb::task_group orienting;
  orienting.run([&] {
    const auto t0 = Clock::now();
    OrientOptions orient;
    orient.welded = true;  // unique_faces welds
    oriented = orient_faces(unique_faces(mesh).mesh, orient);
    result.seconds.orient = since(t0);
  });
  // Joins the orientation task on every exit; after an error or a cancel in the scan, the
  // scan's exception is the one that propagates.
  struct Join {
    tbb::task_group& group;
    ~Join() {
      try {
        group.wait();
      } catch (...) {
      }
    }
  } join{orienting};

  auto t = Clock::now();
  const CptMethod method =
      options.method == CptMethod::automatic ? choose_method(mesh, options.frame) : options.method;
  result.method = method;
  const bool slab = method == CptMethod::slab_scan;
  // Bricks near the mesh with their triangles: the slab scan's (within W*h), or a shell within
  // one voxel (every brick within sqrt(3)/2 h of a triangle) that the characteristic scan
  // dilates and the signs use.
  BinTrianglesOptions bin;
  bin.frame = options.frame;
  bin.margin = (slab ? options.frame.half_width : 1.0) * options.frame.voxel_size;
  bin.progress = options.progress;
  BrickTriangleLists lists = bin_triangles_to_bricks(mesh, bin);
  result.brick_triangle_pairs = lists.triangles.size();
  result.seconds.bin = since(t);
  options.progress.step(0.15, "bin");

  // Unsigned distances and closest triangles.
  t = Clock::now();
  ClosestTriangleField field;
  if (slab) {
    field = slab_scan(mesh, lists, options.frame, options.frame.half_width, options.progress);
  } else {
    CharacteristicScanOptions scan;
    scan.frame = options.frame;
    scan.progress = options.progress;
    CharacteristicScanResult scanned = characteristic_scan(mesh, lists.bricks, scan);
    field = std::move(scanned.field);
    result.polyhedra = scanned.polyhedra;
    result.evaluations = scanned.evaluations;
  }
  result.seconds.distance = since(t);
  options.progress.step(0.7, "distance");

  orienting.wait();
  result.faces_flipped = oriented.faces_flipped;

  // Signs: winding numbers of the consistently oriented mesh, one mask per brick, over the
  // band's bricks with their triangles (the masks need every triangle meeting a brick; those
  // are all within the lists' margin).
  t = Clock::now();
  // Built only if needed: closed meshes get exact signs from rays and jumps alone.
  const LazyWindingTree tree(oriented.mesh);
  InsideMasksOptions sign_options;
  sign_options.frame = options.frame;
  sign_options.progress = options.progress;
  // The band's bricks with their triangles. The masks need every triangle meeting a brick
  // listed (margin >= h/2 for the closed path); near open edges they read the bricks'
  // neighbours, which the band holds (a rim lies on the mesh). Beyond that their result does
  // not depend on the lists' margin, so both scans give the same signs and membranes.
  BrickTriangleLists sign_lists = band_brick_lists(field, lists);
  InsideMasksResult signs = compute_inside_masks(oriented.mesh, tree, sign_lists, sign_options);
  result.winding_queries = signs.winding_queries;
  result.ray_queries = signs.ray_queries;
  result.open_edges = signs.open_edges;
  const std::size_t nb = sign_lists.bricks.size();
  std::vector<MembraneBrick> per_brick = pack_bricks(mesh, field, sign_lists, options);
  field = ClosestTriangleField{};
  for (std::size_t i = 0; i < nb; ++i) per_brick[i].inside = signs.inside[i];
  result.seconds.sign = since(t);
  options.progress.step(0.9, "sign");

  // Open meshes: the sign also changes where w crosses 1/2 away from the mesh (across holes);
  // put those membranes into the band (membrane_band.hpp). Closed meshes have no open edges,
  // so w is piecewise constant and every sign change lies on the mesh: nothing to do.
  if (signs.open_edges > 0) {
    t = Clock::now();
    MembraneOptions membrane;
    membrane.frame = options.frame;
    membrane.search_bounds = oriented.mesh.bounds();
    membrane.closest_points = options.closest_points;
    membrane.progress = options.progress;
    const MembraneResult closed = close_membranes(tree.get(), per_brick, membrane);
    result.membrane_voxels = closed.membrane_voxels;
    result.membrane_bricks_added = closed.bricks_added;
    result.membrane_voxels_added = closed.voxels_added;
    result.membrane_truncated_bricks = closed.truncated_bricks;
    result.winding_queries += closed.winding_queries;
    result.seconds.membrane = since(t);
    options.progress.step(0.95, "membrane");
  }

  // Pack bricks with active voxels in key order (per_brick is sorted by key).
  t = Clock::now();
  const std::size_t np = per_brick.size();
  std::vector<BrickRecord> records;
  std::vector<std::uint64_t> offsets;
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < np; ++i) {
    if (per_brick[i].active.none()) continue;
    records.push_back({per_brick[i].coord, per_brick[i].active, per_brick[i].inside});
    offsets.push_back(total);
    total += per_brick[i].distance.size();
  }
  if (total >= 0xffffffffull)
    throw Error(ErrorCode::LimitExceeded, "band", "more than 2^32-1 active voxels");
  std::vector<float> values(total);
  if (options.closest_points) result.closest_points.resize(total);
  std::vector<std::size_t> kept;
  kept.reserve(records.size());
  for (std::size_t i = 0; i < np; ++i)
    if (!per_brick[i].active.none()) kept.push_back(i);
  tbb::parallel_for(std::size_t(0), kept.size(), [&](std::size_t j) {
    const MembraneBrick& bd = per_brick[kept[j]];
    const BrickMask& inside = records[j].inside;
    float* dst = values.data() + offsets[j];
    std::size_t k = 0;
    // The sign is the inside mask's, always: an inside voxel whose distance rounds to 0 (or
    // to a subnormal) gets -FLT_MIN, not -0 (-0 < 0 is false: it would read as outside).
    // Voxels exactly on the surface otherwise get a sign from the rounding of the distance
    // (exactly 0 or ~1e-18), a random inside/outside pattern that changes the topology of
    // the zero level (CGAL's corner.off at R = 128: genus 0 -> 6 under marching cubes).
    constexpr float kTiny = std::numeric_limits<float>::min();
    bd.active.for_each_set([&](int n) {
      dst[k] = inside.test(n) ? -std::max(bd.distance[k], kTiny) : bd.distance[k];
      ++k;
    });
    if (options.closest_points)
      std::copy(bd.closest_point.begin(), bd.closest_point.end(),
                result.closest_points.begin() + std::ptrdiff_t(offsets[j]));
  });
  result.band = NarrowBand::assemble(options.frame, std::move(records), std::move(values), false);
  result.seconds.assemble = since(t);
  result.seconds.total = since(t_start);
  options.progress.step(1.0, "done");
  return result;
}

}  // namespace levelset
