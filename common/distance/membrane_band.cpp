#include "distance/membrane_band.hpp"

#include <algorithm>
#include <array>
#include <span>
#include <bit>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "distance/eikonal_march.hpp"
#include "distance/redistance_domain.hpp"
#include "distance/voxel_winding.hpp"

namespace levelset {

namespace {

constexpr float kFar = std::numeric_limits<float>::infinity();

// Mask layout (brick_mask.hpp): word = z-slice, byte = y-row, bit = x.
constexpr std::uint64_t kCol0 = 0x0101010101010101ull;  // x = 0
constexpr std::uint64_t kCol7 = 0x8080808080808080ull;  // x = 7
constexpr std::uint64_t kRow0 = 0x00000000000000ffull;  // y = 0
constexpr std::uint64_t kRow7 = 0xff00000000000000ull;  // y = 7

Coord face_offset(int dir) {
  Coord d{0, 0, 0};
  d[dir >> 1] = (dir & 1) ? 1 : -1;
  return d;
}

// For every voxel, the sign of its neighbour in direction dir (Face order), and in `valid`
// the voxels whose neighbour is known (inside the brick, or in brick `nb` when given).
BrickMask neighbour_signs(const BrickMask& own, const BrickMask* nb, int dir, BrickMask& valid) {
  BrickMask r;
  for (int z = 0; z < 8; ++z) {
    const std::uint64_t w = own.words[z];
    const std::uint64_t o = nb ? nb->words[z] : 0;
    std::uint64_t s = 0, v = ~0ull;
    switch (dir) {
      case 0: s = ((w << 1) & ~kCol0) | ((o & kCol7) >> 7); v = nb ? ~0ull : ~kCol0; break;
      case 1: s = ((w >> 1) & ~kCol7) | ((o & kCol0) << 7); v = nb ? ~0ull : ~kCol7; break;
      case 2: s = (w << 8) | ((o & kRow7) >> 56); v = nb ? ~0ull : ~kRow0; break;
      case 3: s = (w >> 8) | ((o & kRow0) << 56); v = nb ? ~0ull : ~kRow7; break;
      case 4:
        s = z > 0 ? own.words[z - 1] : (nb ? nb->words[7] : 0);
        v = (z > 0 || nb) ? ~0ull : 0;
        break;
      default:
        s = z < 7 ? own.words[z + 1] : (nb ? nb->words[0] : 0);
        v = (z < 7 || nb) ? ~0ull : 0;
        break;
    }
    r.words[z] = s;
    valid.words[z] = v;
  }
  return r;
}

// Local index of the neighbour of voxel n in direction dir, with the brick offset it lands in
// (0 inside the brick).
int neighbour_voxel(int n, int dir, bool& crosses) {
  const int shift = 3 * (dir >> 1);
  const int c = (n >> shift) & 7;
  crosses = c == ((dir & 1) ? 7 : 0);
  if (crosses) return n ^ (7 << shift);
  return n + ((dir & 1) ? (1 << shift) : -(1 << shift));
}

int rank(const BrickMask& m, int n) {
  int r = 0;
  for (int w = 0; w < (n >> 6); ++w) r += std::popcount(m.words[w]);
  return r + m.rank_in_word(n);
}

float mesh_distance(const MembraneBrick& b, int n) {
  return b.active.test(n) ? b.distance[std::size_t(rank(b.active, n))] : kFar;
}

double query_w(const WindingNumberTree& tree, const GridFrame& f, const Coord& voxel, double beta) {
  const Vec3d p = f.origin + Vec3d{double(voxel.x), double(voxel.y), double(voxel.z)} * f.voxel_size;
  return winding_number(tree, p, beta);
}

// w at every voxel of a brick with no mesh within W h (w is smooth there): trilinear models of
// 8^3 and 4^3 blocks accepted when a direct query at the block centre agrees to
// kModelTolerance, direct queries on 2^3 blocks and wherever a model is within kDecisionMargin
// of 1/2.
struct FarBrick {
  const WindingNumberTree& tree;
  const GridFrame& frame;
  Coord origin;
  double beta;
  std::uint64_t queries = 0;
  std::array<float, kBrickVoxels> w{};
  BrickMask known;

  float direct(int n) {
    if (!known.test(n)) {
      w[std::size_t(n)] = float(query_w(tree, frame, origin + local_coord(n), beta));
      known.set(n);
      ++queries;
    }
    return w[std::size_t(n)];
  }

  // The direct values of the listed voxels not yet known, in one tree traversal
  // (winding_numbers: the values of one query each).
  void prefetch(std::span<const int> voxels) {
    std::array<int, kBrickVoxels> wanted;
    std::size_t count = 0;
    for (const int n : voxels) {
      if (known.test(n)) continue;
      known.set(n);
      wanted[count++] = n;
    }
    if (count == 0) return;
    std::array<double, kBrickVoxels> values;
    voxel_winding_numbers(tree, frame, origin, std::span(wanted.data(), count), beta, values);
    for (std::size_t i = 0; i < count; ++i) w[std::size_t(wanted[i])] = float(values[i]);
    queries += count;
  }

  void solve(const Coord& lo, int s) {
    auto corner = [&](int b) {
      return local_index(lo.x + ((b & 1) ? s - 1 : 0), lo.y + ((b & 2) ? s - 1 : 0),
                         lo.z + ((b & 4) ? s - 1 : 0));
    };
    const int h = s / 2;
    const int centre = local_index(lo.x + h, lo.y + h, lo.z + h);
    const int first[9] = {corner(0), corner(1), corner(2), corner(3), corner(4), corner(5), corner(6), corner(7), centre};
    prefetch(std::span(first, s == 2 ? 8 : 9));
    if (s == 2) return;
    double c[8];
    for (int b = 0; b < 8; ++b) c[b] = direct(corner(b));
    auto model = [&](int i, int j, int k) {
      const double tx = double(i - lo.x) / (s - 1), ty = double(j - lo.y) / (s - 1),
                   tz = double(k - lo.z) / (s - 1);
      double m = 0.0;
      for (int b = 0; b < 8; ++b)
        m += c[b] * ((b & 1) ? tx : 1 - tx) * ((b & 2) ? ty : 1 - ty) * ((b & 4) ? tz : 1 - tz);
      return m;
    };
    if (std::abs(double(direct(centre)) - model(lo.x + h, lo.y + h, lo.z + h)) <= kModelTolerance) {
      std::array<int, kBrickVoxels> ambiguous;
      std::size_t count = 0;
      for (int k = lo.z; k < lo.z + s; ++k)
        for (int j = lo.y; j < lo.y + s; ++j)
          for (int i = lo.x; i < lo.x + s; ++i) {
            const int n = local_index(i, j, k);
            if (known.test(n)) continue;
            const double m = model(i, j, k);
            if (std::abs(m - 0.5) <= kDecisionMargin) ambiguous[count++] = n;
            else w[std::size_t(n)] = float(m);
          }
      prefetch(std::span(ambiguous.data(), count));
      return;
    }
    for (int b = 0; b < 8; ++b)
      solve({lo.x + ((b & 1) ? h : 0), lo.y + ((b & 2) ? h : 0), lo.z + ((b & 4) ? h : 0)}, h);
  }
};

class Membranes {
 public:
  Membranes(const WindingNumberTree& tree, std::vector<MembraneBrick>& bricks, const MembraneOptions& o)
      : tree_(tree), bricks_(bricks), o_(o), input_count_(bricks.size()) {
    const double h = o.frame.voxel_size;
    threshold_ = float(h * (1.0 + 1e-5));
    reach_ = int(std::ceil(o.frame.half_width)) + 1;
    index_.reserve(bricks.size() * 2);
    for (std::size_t i = 0; i < bricks.size(); ++i) index_.emplace(brick_key(bricks[i].coord), std::uint32_t(i));
    membrane_.assign(bricks.size(), BrickMask{});
    // Searched bricks: the box's voxels grown by the reach.
    const BBox& box = o.search_bounds;
    for (int a = 0; a < 3; ++a) {
      const double lo = std::floor((box.min[a] - o.frame.origin[a]) / h) - reach_;
      const double hi = std::ceil((box.max[a] - o.frame.origin[a]) / h) + reach_;
      const double lim = double(kVoxelCoordLimit - 1);
      lo_[a] = int(std::clamp(lo, -lim, lim)) >> kBrickLog2;
      hi_[a] = int(std::clamp(hi, -lim, lim)) >> kBrickLog2;
    }
  }

  MembraneResult run() {
    explore();
    for (const BrickMask& m : membrane_) result_.membrane_voxels += std::uint64_t(m.count());
    if (result_.membrane_voxels > 0) distances();
    std::sort(bricks_.begin(), bricks_.end(),
              [](const MembraneBrick& a, const MembraneBrick& b) { return brick_key(a.coord) < brick_key(b.coord); });
    return result_;
  }

 private:
  std::uint32_t find(const Coord& c) const {
    if (!brick_in_range(c)) return kNoBrick;
    const auto it = index_.find(brick_key(c));
    return it == index_.end() ? kNoBrick : it->second;
  }

  // Ends of membrane edges in brick b (neighbours in other known bricks included).
  BrickMask membrane_voxels(std::uint32_t b) const {
    const MembraneBrick& br = bricks_[b];
    BrickMask out;
    for (int dir = 0; dir < 6; ++dir) {
      const std::uint32_t nb = find(br.coord + face_offset(dir));
      BrickMask valid;
      const BrickMask other = neighbour_signs(br.inside, nb == kNoBrick ? nullptr : &bricks_[nb].inside, dir, valid);
      BrickMask cand;
      bool any = false;
      for (int z = 0; z < 8; ++z) {
        cand.words[z] = (br.inside.words[z] ^ other.words[z]) & valid.words[z] & ~out.words[z];
        any |= cand.words[z] != 0;
      }
      if (!any) continue;
      cand.for_each_set([&](int n) {
        bool crosses = false;
        const int m = neighbour_voxel(n, dir, crosses);
        const MembraneBrick& mb = crosses ? bricks_[nb] : br;
        // Both ends' mesh distances: a mesh crossing the edge would make their sum <= h.
        const float dn = mesh_distance(br, n);
        if (dn <= threshold_ && mesh_distance(mb, m) <= threshold_ - dn) return;
        out.set(n);
      });
    }
    return out;
  }

  // Bricks within the reach of brick b's membrane voxels (b's own included).
  template <typename F>
  void for_each_reached(std::uint32_t b, F&& f) const {
    const BrickMask& m = membrane_[b];
    int lo[3] = {8, 8, 8}, hi[3] = {-1, -1, -1};
    m.for_each_set([&](int n) {
      const Coord l = local_coord(n);
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], l[a]);
        hi[a] = std::max(hi[a], l[a]);
      }
    });
    if (hi[0] < 0) return;
    int blo[3], bhi[3];
    for (int a = 0; a < 3; ++a) {
      blo[a] = (lo[a] - reach_) >> kBrickLog2;  // floor division
      bhi[a] = (hi[a] + reach_) >> kBrickLog2;
    }
    const Coord c = bricks_[b].coord;
    for (int dz = blo[2]; dz <= bhi[2]; ++dz)
      for (int dy = blo[1]; dy <= bhi[1]; ++dy)
        for (int dx = blo[0]; dx <= bhi[0]; ++dx) f(c + Coord{dx, dy, dz});
  }

  bool searched(const Coord& c) const {
    for (int a = 0; a < 3; ++a)
      if (c[a] < lo_[a] || c[a] > hi_[a]) return false;
    return brick_in_range(c);
  }

  void explore() {
    std::vector<std::uint32_t> check(bricks_.size());
    for (std::size_t i = 0; i < check.size(); ++i) check[i] = std::uint32_t(i);
    std::vector<std::uint64_t> truncated;
    while (!check.empty()) {
      o_.progress.check("membrane");
      std::vector<BrickMask> masks(check.size());
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, check.size(), 16), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) masks[i] = membrane_voxels(check[i]);
      });
      std::vector<std::uint64_t> wanted;
      for (std::size_t i = 0; i < check.size(); ++i) {
        const std::uint32_t b = check[i];
        if (masks[i] == membrane_[b]) continue;
        membrane_[b] = masks[i];
        for_each_reached(b, [&](const Coord& c) {
          if (find(c) != kNoBrick) return;
          if (searched(c)) wanted.push_back(brick_key(c));
          else if (brick_in_range(c)) truncated.push_back(brick_key(c));
        });
      }
      std::sort(wanted.begin(), wanted.end());
      wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
      // Evaluate the new bricks.
      const std::size_t first = bricks_.size();
      bricks_.resize(first + wanted.size());
      far_w_.resize(bricks_.size() - input_count_);
      std::vector<std::uint64_t> queries(wanted.size(), 0);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, wanted.size(), 1), [&](const auto& r) {
        o_.progress.check("membrane");
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const Coord c = brick_from_key(wanted[i]);
          FarBrick fb{tree_, o_.frame, brick_origin(c), o_.beta, 0, {}, {}};
          fb.solve({0, 0, 0}, kBrickDim);
          MembraneBrick& nb = bricks_[first + i];
          nb.coord = c;
          for (int n = 0; n < kBrickVoxels; ++n)
            if (fb.w[std::size_t(n)] > 0.5f) nb.inside.set(n);
          far_w_[first + i - input_count_] = fb.w;
          queries[i] = fb.queries;
        }
      });
      for (std::size_t i = 0; i < wanted.size(); ++i) {
        index_.emplace(wanted[i], std::uint32_t(first + i));
        result_.winding_queries += queries[i];
      }
      result_.bricks_added += wanted.size();
      membrane_.resize(bricks_.size());
      // Check again: the new bricks and the known bricks next to them (new edges on shared faces).
      std::vector<std::uint32_t> next;
      for (std::size_t i = 0; i < wanted.size(); ++i) {
        next.push_back(std::uint32_t(first + i));
        for (int dir = 0; dir < 6; ++dir) {
          const std::uint32_t nb = find(bricks_[first + i].coord + face_offset(dir));
          if (nb != kNoBrick && nb < first) next.push_back(nb);
        }
      }
      std::sort(next.begin(), next.end());
      next.erase(std::unique(next.begin(), next.end()), next.end());
      check = std::move(next);
    }
    std::sort(truncated.begin(), truncated.end());
    result_.truncated_bricks = std::uint64_t(std::unique(truncated.begin(), truncated.end()) - truncated.begin());
  }

  // d_membrane by fast marching from the membrane voxels, then the merge into the bricks.
  void distances() {
    const double h = o_.frame.voxel_size;
    // The march's domain: known bricks within reach of a membrane voxel, sorted by key.
    std::vector<std::uint64_t> keys;
    for (std::uint32_t b = 0; b < bricks_.size(); ++b)
      if (!membrane_[b].none())
        for_each_reached(b, [&](const Coord& c) {
          if (find(c) != kNoBrick) keys.push_back(brick_key(c));
        });
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    const std::size_t nd = keys.size();
    detail::RedistanceDomain w;
    w.coords.resize(nd);
    w.nbr.resize(nd);
    w.source.resize(nd);
    w.domain.resize(nd);
    w.fixed.resize(nd);
    w.inside.resize(nd);
    w.dist.assign(nd * kBrickVoxels, detail::kInf);
    auto find_domain = [&](const Coord& c) {
      if (!brick_in_range(c)) return kNoBrick;
      const auto it = std::lower_bound(keys.begin(), keys.end(), brick_key(c));
      return it != keys.end() && *it == brick_key(c) ? std::uint32_t(it - keys.begin()) : kNoBrick;
    };
    // Dense mesh distances and w at the membrane voxels (direct queries in the input's bricks).
    std::vector<float> dmesh(nd * kBrickVoxels), wv(nd * kBrickVoxels, 0.5f);
    std::vector<std::uint64_t> queries(nd, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nd, 4), [&](const auto& r) {
      o_.progress.check("membrane");
      for (std::size_t d = r.begin(); d != r.end(); ++d) {
        const Coord c = brick_from_key(keys[d]);
        const std::uint32_t k = find(c);
        const MembraneBrick& br = bricks_[k];
        w.coords[d] = c;
        for (int f = 0; f < 6; ++f) w.nbr[d][f] = find_domain(c + face_offset(f));
        w.source[d] = k;
        w.domain[d].words.fill(~0ull);
        w.fixed[d] = membrane_[k];
        w.inside[d] = br.inside;
        float* dm = dmesh.data() + d * kBrickVoxels;
        std::fill(dm, dm + kBrickVoxels, kFar);
        const float* src = br.distance.data();
        br.active.for_each_set([&](int n) { dm[n] = *src++; });
        float* wd = wv.data() + d * kBrickVoxels;
        if (k >= input_count_) {
          std::copy(far_w_[k - input_count_].begin(), far_w_[k - input_count_].end(), wd);
        } else {
          // One traversal for the brick's membrane voxels.
          std::array<int, kBrickVoxels> voxels;
          std::array<double, kBrickVoxels> values;
          std::size_t count = 0;
          membrane_[k].for_each_set([&](int n) { voxels[count++] = n; });
          voxel_winding_numbers(tree_, o_.frame, brick_origin(c), std::span(voxels.data(), count), o_.beta, values);
          count = 0;
          membrane_[k].for_each_set([&](int n) { wd[n] = float(values[count++]); });
          queries[d] += count;
        }
      }
    });
    for (std::uint64_t q : queries) result_.winding_queries += q;
    // Membrane voxels: distance (voxels) to the plane through their edges' crossings of 1/2.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nd, 4), [&](const auto& r) {
      for (std::size_t d = r.begin(); d != r.end(); ++d) {
        float* out = w.values(std::uint32_t(d));
        const float* dm = dmesh.data() + d * kBrickVoxels;
        const float* wd = wv.data() + d * kBrickVoxels;
        w.fixed[d].for_each_set([&](int n) {
          const bool in = w.inside[d].test(n);
          double g2 = 0.0;
          for (int a = 0; a < 3; ++a) {
            double t_axis = 2.0;
            for (int s = 0; s < 2; ++s) {
              const int dir = 2 * a + s;
              bool crosses = false;
              const int m = neighbour_voxel(n, dir, crosses);
              const std::uint32_t d2 = crosses ? w.nbr[d][dir] : std::uint32_t(d);
              if (d2 == kNoBrick || w.inside[d2].test(m) == in) continue;
              const float dmm = dmesh[std::size_t(d2) * kBrickVoxels + std::size_t(m)];
              if (dm[n] <= threshold_ && dmm <= threshold_ - dm[n]) continue;  // a mesh edge
              const double wn = wd[n] - 0.5, wm = wv[std::size_t(d2) * kBrickVoxels + std::size_t(m)] - 0.5;
              // A query that contradicts the stored sign puts that end on w = 1/2 (within the
              // tree's error: e.g. an opening's plane through voxel centres).
              const bool n_ok = (wn > 0.0) == in, m_ok = (wm > 0.0) != in;
              const double t = n_ok && m_ok ? wn / (wn - wm) : n_ok ? 1.0 : m_ok ? 0.0 : 0.5;
              t_axis = std::min(t_axis, std::clamp(t, 1e-3, 1.0));
            }
            if (t_axis <= 1.0) g2 += 1.0 / (t_axis * t_axis);
          }
          out[n] = g2 > 0.0 ? float(1.0 / std::sqrt(g2)) : 0.5f;
        });
      }
    });
    // Only voxels where the membrane may end up nearer than the mesh need its distance: a
    // voxel accepted farther than its mesh distance plus kMembraneMargin passes nothing on
    // (membrane_band.hpp).
    w.cap.resize(nd * kBrickVoxels);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nd * kBrickVoxels, 1 << 14), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) w.cap[i] = float(double(dmesh[i]) / h) + kMembraneMargin;
    });
    detail::march(w, 1, o_.frame.half_width, 1e-6f, o_.progress);
    merge(w, dmesh, h);
  }

  void merge(const detail::RedistanceDomain& w, const std::vector<float>& dmesh, double h) {
    const std::size_t nd = w.size();
    const float limit = float(o_.frame.half_width);
    std::vector<std::uint64_t> added(nd, 0), changed(nd, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nd, 4), [&](const auto& r) {
      for (std::size_t d = r.begin(); d != r.end(); ++d) {
        MembraneBrick& br = bricks_[w.source[d]];
        const float* dist = w.values(std::uint32_t(d));
        const float* dm = dmesh.data() + d * kBrickVoxels;
        BrickMask active = br.active, from_membrane;
        std::array<float, kBrickVoxels> value;
        for (int n = 0; n < kBrickVoxels; ++n) {
          value[std::size_t(n)] = dm[n];
          if (!(dist[n] <= limit)) continue;
          const float v = float(double(dist[n]) * h);
          if (v < dm[n]) {
            value[std::size_t(n)] = v;
            from_membrane.set(n);
            if (br.active.test(n)) ++changed[d];
            else ++added[d];
            active.set(n);
          }
        }
        if (from_membrane.none()) continue;
        std::vector<float> packed;
        std::vector<Vec3f> points;
        packed.reserve(std::size_t(active.count()));
        const Vec3f* old_point = br.closest_point.data();
        active.for_each_set([&](int n) {
          packed.push_back(value[std::size_t(n)]);
          if (!o_.closest_points) return;
          const Vec3f kept = br.active.test(n) ? *old_point++ : Vec3f{};
          points.push_back(from_membrane.test(n) ? membrane_point(w, std::uint32_t(d), n, h) : kept);
        });
        br.active = active;
        br.distance = std::move(packed);
        if (o_.closest_points) br.closest_point = std::move(points);
      }
    });
    for (std::size_t d = 0; d < nd; ++d) {
      result_.voxels_added += added[d];
      result_.voxels_changed += changed[d];
    }
  }

  // The voxel moved by -phi along grad phi, phi = the membrane distance signed by the voxels'
  // signs (central differences where both neighbours are known, one-sided otherwise).
  Vec3f membrane_point(const detail::RedistanceDomain& w, std::uint32_t d, int n, double h) const {
    auto phi = [&](std::uint32_t b, int v) {
      const float x = w.dist[std::size_t(b) * kBrickVoxels + std::size_t(v)];
      return w.inside[b].test(v) ? -double(x) : double(x);
    };
    const double centre = phi(d, n);
    Vec3d g{};
    for (int a = 0; a < 3; ++a) {
      double side[2];
      bool ok[2];
      for (int s = 0; s < 2; ++s) {
        bool crosses = false;
        const int m = neighbour_voxel(n, 2 * a + s, crosses);
        const std::uint32_t b = crosses ? w.nbr[d][2 * a + s] : d;
        ok[s] = b != kNoBrick && std::isfinite(phi(b, m));
        side[s] = ok[s] ? phi(b, m) : 0.0;
      }
      g[a] = ok[0] && ok[1] ? 0.5 * (side[1] - side[0]) : ok[1] ? side[1] - centre : ok[0] ? centre - side[0] : 0.0;
    }
    const Coord c = brick_origin(w.coords[d]) + local_coord(n);
    const Vec3d p = o_.frame.origin + Vec3d{double(c.x), double(c.y), double(c.z)} * h;
    const double len = length(g);
    const Vec3d q = len > 0.0 && std::isfinite(len) ? p - g * (centre * h / len) : p;
    return {float(q.x), float(q.y), float(q.z)};
  }

  const WindingNumberTree& tree_;
  std::vector<MembraneBrick>& bricks_;
  const MembraneOptions& o_;
  const std::size_t input_count_;
  float threshold_ = 0.0f;
  int reach_ = 4;
  int lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};
  std::unordered_map<std::uint64_t, std::uint32_t> index_;
  std::vector<BrickMask> membrane_;
  std::vector<std::array<float, kBrickVoxels>> far_w_;  // w of the added bricks
  MembraneResult result_;
};

}  // namespace

MembraneResult close_membranes(const WindingNumberTree& tree, std::vector<MembraneBrick>& bricks,
                               const MembraneOptions& options) {
  if (bricks.empty() || tree.nodes.empty()) return {};
  return Membranes(tree, bricks, options).run();
}

}  // namespace levelset
