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
using Expansion = WindingNumberTree::Expansion;
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
      const Expansion& child = tree.expansions[c];
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
    Expansion& ex = tree.expansions[at];
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

// Solid angle of a node's triangles seen from p by the second-order expansion about its centre.
double far_field(const Node& node, const Expansion& ex, const Vec3d& p) {
  const Vec3d y = node.center - p;
  const double r2 = dot(y, y);
  const double inv_r = 1.0 / std::sqrt(r2);
  const double inv_r2 = inv_r * inv_r;
  const double inv_r3 = inv_r2 * inv_r;
  const double inv_r5 = inv_r3 * inv_r2;
  const double inv_r7 = inv_r5 * inv_r2;
  const auto& m = ex.first;
  const auto& c = ex.second;
  // Zeroth order (dipole).
  double omega = dot(ex.normal, y) * inv_r3;
  // First order: tr(M)/r^3 - 3 y^T M y / r^5.
  double ymy = 0.0;
  for (int i = 0; i < 3; ++i)
    ymy += y[i] * (m[i * 3 + 0] * y.x + m[i * 3 + 1] * y.y + m[i * 3 + 2] * y.z);
  omega += (m[0] + m[4] + m[8]) * inv_r3 - 3.0 * ymy * inv_r5;
  // Second order: 1/2 [ -3/r^5 (2 sum_ik C_i(ik) y_k + sum_i y_i tr C_i) + 15/r^7 sum_i y_i y^T C_i
  // y ].
  double lin = 0.0, cubic = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double* ci = &c[std::size_t(i) * 6];
    // Row i of the symmetric matrix C_i: entries (i, k).
    const double row[3][3] = {{ci[0], ci[3], ci[4]}, {ci[3], ci[1], ci[5]}, {ci[4], ci[5], ci[2]}};
    lin += 2.0 * (row[i][0] * y.x + row[i][1] * y.y + row[i][2] * y.z) +
           y[i] * (ci[0] + ci[1] + ci[2]);
    const double yCy = ci[0] * y.x * y.x + ci[1] * y.y * y.y + ci[2] * y.z * y.z +
                       2.0 * (ci[3] * y.x * y.y + ci[4] * y.x * y.z + ci[5] * y.y * y.z);
    cubic += y[i] * yCy;
  }
  omega += 0.5 * (-3.0 * lin * inv_r5 + 15.0 * cubic * inv_r7);
  return omega;
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
            tree};
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
  tree.expansions.resize(tree.nodes.size());
  tree.corners.resize(nt);
  tree.order.resize(nt);
  b.build(0, 0, nt);
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
      omega += far_field(node, tree.expansions[at], p);
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

// Points idx[b, e) have reached node `at`: those far from it take its expansion, the rest go on
// down (idx permuted in place, the set kept). Each point sees the nodes its own query would, in
// the same order.
void batch_descend(const WindingNumberTree& tree, std::uint32_t at, std::span<const Vec3d> points,
                   double beta2, std::uint32_t* idx, std::size_t b, std::size_t e, double* omega) {
  const Node& node = tree.nodes[at];
  const double limit = beta2 * node.radius * node.radius;
  std::size_t near = b;
  for (std::size_t k = b; k < e; ++k) {
    const Vec3d d = node.center - points[idx[k]];
    if (dot(d, d) > limit) omega[idx[k]] += far_field(node, tree.expansions[at], points[idx[k]]);
    else std::swap(idx[near++], idx[k]);
  }
  if (near == b) return;
  if (node.leaf) {
    for (std::size_t k = b; k < near; ++k)
      for (std::uint32_t i = node.left; i < node.right; ++i) {
        const auto& t = tree.corners[i];
        omega[idx[k]] += fast_triangle_solid_angle(points[idx[k]], t[0], t[1], t[2]);
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
