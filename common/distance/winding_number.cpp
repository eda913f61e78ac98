#include "distance/winding_number.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include "core/error.hpp"
#include "distance/solid_angle.hpp"

namespace levelset {

namespace {

using Node = WindingNumberTree::Node;
// The moments the build accumulates per node (converted to WindingNumberTree::FarField).
struct Expansion {
  Vec3d normal;                     // sum of area-weighted normals, 1/2 (b - a) x (c - a)
  std::array<double, 9> first{};    // M[i*3+j] = sum a n_i (x - c)_j        (integrated)
  std::array<double, 18> second{};  // C[i*6+s] = sum a n_i (x - c)_j (x - c)_k, s = jk in
                                    // xx, yy, zz, xy, xz, yz               (integrated)
};
constexpr int kLeaf = WindingNumberTree::kLeafTriangles;
constexpr std::size_t kParallelGrain = 4096;  // triangles below which a subtree builds serially

// Symmetric index pairs of the second moment: xx, yy, zz, xy, xz, yz.
constexpr int kPairJ[6] = {0, 1, 2, 0, 0, 1};
constexpr int kPairK[6] = {0, 1, 2, 1, 2, 2};

std::size_t leaf_count(std::size_t n) {
  return n <= std::size_t(kLeaf) ? 1 : leaf_count(n / 2) + leaf_count(n - n / 2);
}
std::size_t node_count(std::size_t n) {
  return 2 * leaf_count(n) - 1;
}

struct Builder {
  const TriangleMesh& mesh;
  std::vector<Vec3d> centroid;     // per mesh triangle
  std::vector<double> area;        // per mesh triangle
  std::vector<std::uint32_t> ids;  // permuted mesh triangle indices
  WindingNumberTree& tree;
  std::vector<Expansion> moments;  // per node

  // Leaf moments directly from its triangles about the area-weighted centroid.
  void make_leaf(Node& node, Expansion& ex, std::size_t lo, std::size_t hi) {
    double total = 0.0;
    Vec3d sum{}, plain{};
    for (std::size_t i = lo; i < hi; ++i) {
      const std::uint32_t t = ids[i];
      total += area[t];
      sum += centroid[t] * area[t];
      plain += centroid[t];
    }
    const Vec3d c = total > 0.0 ? sum / total : plain / double(hi - lo);
    node.center = c;
    for (std::size_t i = lo; i < hi; ++i) {
      const std::uint32_t t = ids[i];
      const auto& f = mesh.triangles[t];
      const Vec3d& a = mesh.vertices[f[0]];
      const Vec3d& b = mesh.vertices[f[1]];
      const Vec3d& e = mesh.vertices[f[2]];
      tree.corners[i] = {a, b, e};
      tree.order[i] = t;
      const Vec3d an = cross(b - a, e - a) * 0.5;  // area-weighted normal
      ex.normal += an;
      const Vec3d g = centroid[t] - c;
      // Integral over the triangle of (x - c)(x - c)^T: a (g g^T + 1/12 sum (v - g')(v - g')^T).
      double cov[3][3];
      const Vec3d v0 = a - centroid[t], v1 = b - centroid[t], v2 = e - centroid[t];
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          cov[j][k] = g[j] * g[k] + (v0[j] * v0[k] + v1[j] * v1[k] + v2[j] * v2[k]) / 12.0;
      for (int i3 = 0; i3 < 3; ++i3) {
        for (int j = 0; j < 3; ++j) ex.first[i3 * 3 + j] += an[i3] * g[j];
        // an already carries the area; cov is per unit area.
        for (int s = 0; s < 6; ++s) ex.second[i3 * 6 + s] += an[i3] * cov[kPairJ[s]][kPairK[s]];
      }
      for (const Vec3d* v : {&a, &b, &e}) node.radius = std::max(node.radius, length(*v - c));
    }
    node.leaf = true;
    node.left = std::uint32_t(lo);
    node.right = std::uint32_t(hi);
  }

  // Inner node moments from its children (shifted to the node's centroid).
  void combine(Node& node, Expansion& ex, std::size_t l, std::size_t r, double area_l,
               double area_r, std::size_t lo, std::size_t hi) {
    const double total = area_l + area_r;
    const Node& nl = tree.nodes[l];
    const Node& nr = tree.nodes[r];
    node.center = total > 0.0 ? (nl.center * area_l + nr.center * area_r) / total
                              : (nl.center + nr.center) * 0.5;
    for (std::size_t c : {l, r}) {
      const Expansion& child = moments[c];
      const Vec3d d = tree.nodes[c].center - node.center;
      ex.normal += child.normal;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
          ex.first[i * 3 + j] += child.first[i * 3 + j] + child.normal[i] * d[j];
        for (int s = 0; s < 6; ++s) {
          const int j = kPairJ[s], k = kPairK[s];
          ex.second[i * 6 + s] += child.second[i * 6 + s] + child.first[i * 3 + j] * d[k] +
                                  child.first[i * 3 + k] * d[j] + child.normal[i] * d[j] * d[k];
        }
      }
    }
    double r2 = 0.0;
    for (std::size_t i = lo; i < hi; ++i)
      for (const Vec3d& v : tree.corners[i]) {
        const Vec3d d = v - node.center;
        r2 = std::max(r2, dot(d, d));
      }
    node.radius = std::sqrt(r2);
  }

  // Builds the subtree of ids[lo, hi) at node index `at`; returns its total area.
  double build(std::size_t at, std::size_t lo, std::size_t hi) {
    Node& node = tree.nodes[at];
    Expansion& ex = moments[at];
    const std::size_t n = hi - lo;
    if (n <= std::size_t(kLeaf)) {
      make_leaf(node, ex, lo, hi);
      double total = 0.0;
      for (std::size_t i = lo; i < hi; ++i) total += area[ids[i]];
      return total;
    }
    Vec3d bmin = centroid[ids[lo]], bmax = bmin;
    for (std::size_t i = lo + 1; i < hi; ++i) {
      bmin = min(bmin, centroid[ids[i]]);
      bmax = max(bmax, centroid[ids[i]]);
    }
    const Vec3d ext = bmax - bmin;
    const int axis = ext.x >= ext.y ? (ext.x >= ext.z ? 0 : 2) : (ext.y >= ext.z ? 1 : 2);
    const std::size_t mid = lo + n / 2;
    std::nth_element(ids.begin() + std::ptrdiff_t(lo), ids.begin() + std::ptrdiff_t(mid),
                     ids.begin() + std::ptrdiff_t(hi), [&](std::uint32_t p, std::uint32_t q) {
                       const double cp = centroid[p][axis], cq = centroid[q][axis];
                       return cp != cq ? cp < cq : p < q;
                     });
    const std::size_t left_at = at + 1;
    const std::size_t right_at = at + 1 + node_count(mid - lo);
    double area_l = 0.0, area_r = 0.0;
    if (n >= kParallelGrain) {
      tbb::parallel_invoke([&] { area_l = build(left_at, lo, mid); },
                           [&] { area_r = build(right_at, mid, hi); });
    } else {
      area_l = build(left_at, lo, mid);
      area_r = build(right_at, mid, hi);
    }
    node.leaf = false;
    node.left = std::uint32_t(left_at);
    node.right = std::uint32_t(right_at);
    combine(node, ex, left_at, right_at, area_l, area_r, lo, hi);
    return area_l + area_r;
  }
};

// The far-field polynomial of a node's moments (WindingNumberTree::FarField): the second-order
// expansion 1/r^3 [N.y + tr M] - 3/r^5 [y^T M y + 1/2 l.y] + 15/(2 r^7) sum_i y_i y^T C_i y,
// its monomials' coefficients collected once.
WindingNumberTree::FarField far_form(const Expansion& ex) {
  WindingNumberTree::FarField f;
  const auto& m = ex.first;
  f.normal = ex.normal;
  f.trace = m[0] + m[4] + m[8];
  // y^T M y with M's symmetric part.
  f.quad = {3.0 * m[0], 3.0 * m[4], 3.0 * m[8], 3.0 * (m[1] + m[3]), 3.0 * (m[2] + m[6]), 3.0 * (m[5] + m[7])};
  // Entry (j, k) of the symmetric C_i.
  auto C = [&](int i, int j, int k) {
    static constexpr int kSlot[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    return ex.second[std::size_t(i * 6 + kSlot[j][k])];
  };
  for (int k = 0; k < 3; ++k) {
    double l = C(k, 0, 0) + C(k, 1, 1) + C(k, 2, 2);
    for (int i = 0; i < 3; ++i) l += 2.0 * C(i, i, k);
    f.lin[k] = 1.5 * l;
  }
  enum { X, Y, Z };
  const double cubic[10] = {C(X, X, X),
                            C(Y, Y, Y),
                            C(Z, Z, Z),
                            C(Y, X, X) + 2.0 * C(X, X, Y),
                            C(Z, X, X) + 2.0 * C(X, X, Z),
                            C(X, Y, Y) + 2.0 * C(Y, X, Y),
                            C(Z, Y, Y) + 2.0 * C(Y, Y, Z),
                            C(X, Z, Z) + 2.0 * C(Z, X, Z),
                            C(Y, Z, Z) + 2.0 * C(Z, Y, Z),
                            2.0 * (C(X, Y, Z) + C(Y, X, Z) + C(Z, X, Y))};
  for (int i = 0; i < 10; ++i) f.cubic[std::size_t(i)] = 7.5 * cubic[i];
  return f;
}

// Solid angle of a node's triangles seen from p by the second-order expansion about its centre.
double far_field(const Node& node, const WindingNumberTree::FarField& f, const Vec3d& p) {
  const Vec3d y = node.center - p;
  const double xx = y.x * y.x, yy = y.y * y.y, zz = y.z * y.z;
  const double xy = y.x * y.y, xz = y.x * y.z, yz = y.y * y.z;
  const double r2 = xx + yy + zz;
  const double inv_r2 = 1.0 / r2;
  const double inv_r3 = inv_r2 / std::sqrt(r2);
  const double q1 = f.normal.x * y.x + f.normal.y * y.y + f.normal.z * y.z + f.trace;
  const double q2 = f.quad[0] * xx + f.quad[1] * yy + f.quad[2] * zz + f.quad[3] * xy + f.quad[4] * xz +
                    f.quad[5] * yz + f.lin.x * y.x + f.lin.y * y.y + f.lin.z * y.z;
  const double q3 = (f.cubic[0] * xx + f.cubic[3] * xy + f.cubic[4] * xz + f.cubic[5] * yy + f.cubic[7] * zz +
                     f.cubic[9] * yz) * y.x +
                    (f.cubic[1] * yy + f.cubic[6] * yz + f.cubic[8] * zz) * y.y + f.cubic[2] * zz * y.z;
  return (q1 + (q3 * inv_r2 - q2) * inv_r2) * inv_r3;
}

}  // namespace

WindingNumberTree build_winding_tree(const TriangleMesh& mesh) {
  const std::size_t nv = mesh.vertices.size();
  for (std::size_t i = 0; i < nv; ++i)
    if (!isfinite(mesh.vertices[i]))
      throw Error(ErrorCode::NonFinite, "vertex " + std::to_string(i), "non-finite coordinate");
  const std::size_t nt = mesh.triangles.size();
  for (std::size_t t = 0; t < nt; ++t)
    for (std::uint32_t v : mesh.triangles[t])
      if (v >= nv)
        throw Error(ErrorCode::InvalidArgument, "triangle " + std::to_string(t),
                    "vertex index " + std::to_string(v) + " out of range");
  if (nt >= 0xffffffffu)
    throw Error(ErrorCode::LimitExceeded, "mesh", "more than 2^32-2 triangles");
  WindingNumberTree tree;
  if (nt == 0) return tree;
  Builder b{mesh, std::vector<Vec3d>(nt), std::vector<double>(nt), std::vector<std::uint32_t>(nt),
            tree, {}};
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& f = mesh.triangles[t];
    const Vec3d& p = mesh.vertices[f[0]];
    const Vec3d& q = mesh.vertices[f[1]];
    const Vec3d& r = mesh.vertices[f[2]];
    b.centroid[t] = (p + q + r) / 3.0;
    b.area[t] = 0.5 * length(cross(q - p, r - p));
    b.ids[t] = std::uint32_t(t);
  }
  tree.nodes.resize(node_count(nt));
  b.moments.resize(tree.nodes.size());
  tree.corners.resize(nt);
  tree.order.resize(nt);
  b.build(0, 0, nt);
  tree.far.resize(tree.nodes.size());
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) tree.far[i] = far_form(b.moments[i]);
  return tree;
}

const WindingNumberTree& LazyWindingTree::get() const {
  if (given_) return *given_;
  std::call_once(once_, [this] {
    tbb::this_task_arena::isolate([this] { owned_.emplace(build_winding_tree(*mesh_)); });
  });
  return *owned_;
}

double winding_number(const WindingNumberTree& tree, const Vec3d& p, double beta) {
  if (tree.nodes.empty()) return 0.0;
  const double beta2 = beta * beta;
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  double omega = 0.0;
  while (top > 0) {
    const std::uint32_t at = stack[--top];
    const Node& node = tree.nodes[at];
    const Vec3d d = node.center - p;
    if (dot(d, d) > beta2 * node.radius * node.radius) {
      omega += far_field(node, tree.far[at], p);
    } else if (node.leaf) {
      for (std::uint32_t i = node.left; i < node.right; ++i) {
        const auto& t = tree.corners[i];
        omega += fast_triangle_solid_angle(p, t[0], t[1], t[2]);
      }
    } else {
      stack[top++] = node.right;
      stack[top++] = node.left;
    }
  }
  return omega / (4.0 * std::numbers::pi);
}

namespace {

// Lanes of the batch evaluations below: a chunk of points in coordinate arrays.
constexpr int kChunk = 32;

// far_field of one node at n points; each lane computes the scalar form's operations in its
// order (no contraction, see CMakeLists.txt), so the batch equals the single queries bit for bit.
__attribute__((target_clones("avx512f", "avx2", "default")))
void far_block(const Node& node, const WindingNumberTree::FarField& f, const double* px, const double* py,
               const double* pz, int n, double* out) {
  for (int i = 0; i < n; ++i) out[i] = far_field(node, f, Vec3d{px[i], py[i], pz[i]});
}

// acc[i] += the solid angles of a leaf's triangles at point i, triangle by triangle (the single
// query's order of sums).
__attribute__((target_clones("avx512f", "avx2", "default")))
void leaf_block(const std::array<Vec3d, 3>* triangles, std::uint32_t count, const double* px, const double* py,
                const double* pz, int n, double* acc) {
  for (std::uint32_t t = 0; t < count; ++t) {
    const std::array<Vec3d, 3>& c = triangles[t];
    for (int i = 0; i < n; ++i) acc[i] += fast_triangle_solid_angle(Vec3d{px[i], py[i], pz[i]}, c[0], c[1], c[2]);
  }
}

// Points idx[b, e) have reached node `at`: those far from it take its expansion, the rest go on
// down (idx permuted in place, the set kept). Each point sees the nodes its own query would, in
// the same order. Expansions and leaves are evaluated kChunk points at a time.
void batch_descend(const WindingNumberTree& tree, std::uint32_t at, std::span<const Vec3d> points,
                   double beta2, std::uint32_t* idx, std::size_t b, std::size_t e, double* omega) {
  const Node& node = tree.nodes[at];
  const double limit = beta2 * node.radius * node.radius;
  alignas(64) double px[kChunk], py[kChunk], pz[kChunk], value[kChunk];
  std::uint32_t which[kChunk];
  int n = 0;
  auto flush_far = [&] {
    far_block(node, tree.far[at], px, py, pz, n, value);
    for (int i = 0; i < n; ++i) omega[which[i]] += value[i];
    n = 0;
  };
  std::size_t near = b;
  for (std::size_t k = b; k < e; ++k) {
    const Vec3d& p = points[idx[k]];
    const Vec3d d = node.center - p;
    if (dot(d, d) > limit) {
      px[n] = p.x, py[n] = p.y, pz[n] = p.z, which[n] = idx[k];
      if (++n == kChunk) flush_far();
    } else {
      std::swap(idx[near++], idx[k]);
    }
  }
  if (n > 0) flush_far();
  if (near == b) return;
  if (node.leaf) {
    for (std::size_t k0 = b; k0 < near; k0 += kChunk) {
      const int m = int(std::min<std::size_t>(kChunk, near - k0));
      for (int i = 0; i < m; ++i) {
        const Vec3d& p = points[idx[k0 + std::size_t(i)]];
        px[i] = p.x, py[i] = p.y, pz[i] = p.z, value[i] = omega[idx[k0 + std::size_t(i)]];
      }
      leaf_block(&tree.corners[node.left], node.right - node.left, px, py, pz, m, value);
      for (int i = 0; i < m; ++i) omega[idx[k0 + std::size_t(i)]] = value[i];
    }
    return;
  }
  batch_descend(tree, node.left, points, beta2, idx, b, near, omega);
  batch_descend(tree, node.right, points, beta2, idx, b, near, omega);
}

}  // namespace

void winding_numbers(const WindingNumberTree& tree, std::span<const Vec3d> points, double beta,
                     std::span<double> out) {
  std::fill(out.begin(), out.end(), 0.0);
  if (tree.nodes.empty() || points.empty()) return;
  // Small batches (a brick's voxels, the callers' case) index from the stack: no allocation.
  std::array<std::uint32_t, 512> local;
  std::vector<std::uint32_t> heap(points.size() > local.size() ? points.size() : 0);
  std::uint32_t* idx = heap.empty() ? local.data() : heap.data();
  for (std::size_t i = 0; i < points.size(); ++i) idx[i] = std::uint32_t(i);
  batch_descend(tree, 0, points, beta * beta, idx, 0, points.size(), out.data());
  for (double& w : out) w /= 4.0 * std::numbers::pi;
}

double winding_number_exact(const TriangleMesh& mesh, const Vec3d& p) {
  double omega = 0.0;
  for (const auto& f : mesh.triangles)
    omega += triangle_solid_angle(p, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]);
  return omega / (4.0 * std::numbers::pi);
}

}  // namespace levelset
