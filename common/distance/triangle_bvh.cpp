#include "distance/triangle_bvh.hpp"

#include <algorithm>
#include <limits>
#include <map>

#include <tbb/parallel_invoke.h>

#include "geometry/point_triangle.hpp"

namespace levelset {

namespace {

constexpr std::uint32_t kLeafSize = 4;

// Nodes of a subtree over n triangles (median splits): the layout is a function of n alone, so
// the tree is the same for any thread count.
std::uint32_t subtree_nodes(std::uint32_t n, std::map<std::uint32_t, std::uint32_t>& memo) {
  if (n <= kLeafSize) return 1;
  const auto it = memo.find(n);
  if (it != memo.end()) return it->second;
  const std::uint32_t count = 1 + subtree_nodes(n / 2, memo) + subtree_nodes(n - n / 2, memo);
  memo.emplace(n, count);
  return count;
}

double box_distance2(const Vec3d& p, const Vec3d& lo, const Vec3d& hi) {
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double d = p[a] < lo[a] ? lo[a] - p[a] : (p[a] > hi[a] ? p[a] - hi[a] : 0.0);
    d2 += d * d;
  }
  return d2;
}

}  // namespace

TriangleBvh::TriangleBvh(const TriangleMesh& mesh) {
  const auto n = std::uint32_t(mesh.triangles.size());
  if (n == 0) return;
  std::map<std::uint32_t, std::uint32_t> memo;
  nodes_.resize(subtree_nodes(n, memo));
  leaves_.resize(n);
  std::vector<Vec3d> centroids(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    const auto& f = mesh.triangles[t];
    leaves_[t] = {mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]], t};
    centroids[t] = (leaves_[t].a + leaves_[t].b + leaves_[t].c) / 3.0;
  }
  build(0, 0, n, centroids, 0);
}

void TriangleBvh::build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, std::vector<Vec3d>& centroids,
                        int depth) {
  Node& out = nodes_[node];
  const double inf = std::numeric_limits<double>::infinity();
  out.lo = {inf, inf, inf};
  out.hi = {-inf, -inf, -inf};
  Vec3d clo = out.lo, chi = out.hi;
  for (std::uint32_t i = begin; i < end; ++i) {
    const Leaf& l = leaves_[i];
    out.lo = min(out.lo, min(min(l.a, l.b), l.c));
    out.hi = max(out.hi, max(max(l.a, l.b), l.c));
    clo = min(clo, centroids[i]);
    chi = max(chi, centroids[i]);
  }
  if (end - begin <= kLeafSize) {
    out.first = begin;
    out.count = end - begin;
    return;
  }
  const Vec3d extent = chi - clo;
  const int axis = extent.x >= extent.y ? (extent.x >= extent.z ? 0 : 2) : (extent.y >= extent.z ? 1 : 2);
  const std::uint32_t mid = begin + (end - begin) / 2;
  // Sort leaves and centroids together through an index permutation of the range.
  std::vector<std::uint32_t> order(end - begin);
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = begin + i;
  std::nth_element(order.begin(), order.begin() + (mid - begin), order.end(), [&](std::uint32_t x, std::uint32_t y) {
    if (centroids[x][axis] != centroids[y][axis]) return centroids[x][axis] < centroids[y][axis];
    return leaves_[x].tri < leaves_[y].tri;
  });
  std::vector<Leaf> leaves(order.size());
  std::vector<Vec3d> cs(order.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) {
    leaves[i] = leaves_[order[i]];
    cs[i] = centroids[order[i]];
  }
  std::copy(leaves.begin(), leaves.end(), leaves_.begin() + begin);
  std::copy(cs.begin(), cs.end(), centroids.begin() + begin);
  std::map<std::uint32_t, std::uint32_t> memo;
  const std::uint32_t left = node + 1, right = node + 1 + subtree_nodes(mid - begin, memo);
  out.first = left;
  out.count = 0;
  out.right = right;
  if (end - begin > 8192 && depth < 16)
    tbb::parallel_invoke([&] { build(left, begin, mid, centroids, depth + 1); },
                         [&] { build(right, mid, end, centroids, depth + 1); });
  else {
    build(left, begin, mid, centroids, depth + 1);
    build(right, mid, end, centroids, depth + 1);
  }
}

BvhHit TriangleBvh::nearest(const Vec3d& p, double bound2) const {
  BvhHit best{bound2, kNoBvhTriangle};
  if (nodes_.empty()) return best;
  std::uint32_t stack[64];
  int top = 0;
  if (box_distance2(p, nodes_[0].lo, nodes_[0].hi) < best.distance_squared) stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (box_distance2(p, node.lo, node.hi) >= best.distance_squared) continue;  // bound shrank
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const Leaf& l = leaves_[i];
        const double d2 = closest_point_on_triangle(p, l.a, l.b, l.c).distance_squared;
        if (d2 < best.distance_squared) best = {d2, l.tri};
      }
      continue;
    }
    const double dl = box_distance2(p, nodes_[node.first].lo, nodes_[node.first].hi);
    const double dr = box_distance2(p, nodes_[node.right].lo, nodes_[node.right].hi);
    // Nearer child last (popped first); the depth is at most ~log2(F) + 1, far below 64.
    if (dl < dr) {
      if (dr < best.distance_squared) stack[top++] = node.right;
      if (dl < best.distance_squared) stack[top++] = node.first;
    } else {
      if (dl < best.distance_squared) stack[top++] = node.first;
      if (dr < best.distance_squared) stack[top++] = node.right;
    }
  }
  return best;
}

}  // namespace levelset
