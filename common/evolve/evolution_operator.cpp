// evolve()'s spatial operator (evolution_operator.hpp): per-brick tiles, the one-sided and
// central derivatives, curvature, the speed, the rates, and the edge layer's stencils.
#include "evolve/evolution_operator.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <span>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "evolve/axis_lines.hpp"
#include "evolve/curvature.hpp"
#include "evolve/curvature_batch.hpp"
#include "evolve/gradient_batch.hpp"
#include "grid/tile.hpp"

namespace levelset::evolve::detail {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

constexpr double kSqrt3 = 1.7320508075688772;

// Per-thread buffers for one brick (at most 512 active voxels).
struct Scratch {
  std::vector<float> tile = std::vector<float>(std::size_t(kDim) * kDim * kDim);
  std::vector<std::uint32_t> rows = std::vector<std::uint32_t>(std::size_t(kDim) * kDim);
  std::array<float, kBrickVoxels> d, x, y, z, nx, ny, nz, mean, gauss, k1, k2, grad, beta_a, beta_p;
  std::array<float, kBrickVoxels> dist, dgx, dgy, dgz, dn, img, edge, roi;
  std::array<std::array<OneSided, 3>, kBrickVoxels> os;
  std::array<double, kBrickVoxels> gnorm;  // |grad u| by central differences, by brick voxel index
  std::unique_ptr<AxisLines> lines;
  std::unique_ptr<UpwindSides> sides;
  std::array<Vec3d, kBrickVoxels> vel;
  std::array<int, kBrickVoxels> curvature_at_tile;  // tile index whose curvature a voxel takes; -1: none
  // Per brick row (y + 8 z), bit x: the voxel's 19-point curvature stencil is all active
  // (whole), its six face neighbours are active (interior).
  std::array<std::uint8_t, kBrickDim * kBrickDim> whole, interior;
  // Per tile row (y, z) with y, z in [-1, 8]: bit x - kLo says the voxel and its six face
  // neighbours are active (not an edge voxel); filled for the edge stencils only.
  std::array<std::uint32_t, (kBrickDim + 2) * (kBrickDim + 2)> inner;
  // The band's bricks around this one (Neighborhood slots), for band value indices.
  std::array<const Brick*, 27> around_bricks;
};

bool active_at(const Scratch& s, int x, int y, int z) {
  return (s.rows[std::size_t((y - kLo) + kDim * (z - kLo))] >> (x - kLo)) & 1u;
}

// Whether the 19-point curvature stencil around tile position p (centre, faces, edges) is
// all active: inactive samples hold +-W h, not the field, and a curvature read through them is
// wrong by up to 1 / (2 h).
bool curvature_stencil_active(const Scratch& s, const Coord& p) {
  auto row = [&](int y, int z) { return s.rows[std::size_t((y - kLo) + kDim * (z - kLo))] >> (p.x - 1 - kLo); };
  constexpr std::uint32_t three = 7u, middle = 2u;
  if ((row(p.y, p.z) & three) != three) return false;
  for (int d = -1; d <= 1; d += 2) {
    if ((row(p.y + d, p.z) & three) != three || (row(p.y, p.z + d) & three) != three) return false;
    if (!(row(p.y + d, p.z - 1) & middle) || !(row(p.y + d, p.z + 1) & middle)) return false;
  }
  return true;
}

// Where a voxel takes its curvature from (a tile index), or -1. Near the band's edge the
// stencil reads inactive samples; there the voxel takes the curvature of the first voxel
// with a whole stencil on the way toward the front (stepping to the active 6-neighbour of
// smallest |u|, at most 3 steps). Level sets of a distance function are parallel, so that
// is the curvature of a neighbouring level set, off by O(h k^2); a garbage curvature here
// fed the parabolic part with rates of 1 / h and made the band drift and grow (issue 13).
// -1 (no curvature) where no such voxel is near (a band too thin for the stencil). For voxels
// whose own stencil is not whole (Scratch::whole, which the caller read): the first test is
// skipped.
int curvature_source(const Scratch& s, const Coord& l) {
  Coord p = l;
  for (int hop = 0;; ++hop) {
    if (hop > 0 && curvature_stencil_active(s, p)) return tile_index(p.x, p.y, p.z);
    if (hop == 3) return -1;
    const float here = std::abs(s.tile[std::size_t(tile_index(p.x, p.y, p.z))]);
    Coord best = p;
    float best_value = here;
    for (int f = 0; f < 6; ++f) {
      Coord q = p;
      q[f >> 1] += (f & 1) ? 1 : -1;
      if (q[f >> 1] <= kLo || q[f >> 1] >= kHi - 1 || !active_at(s, q.x, q.y, q.z)) continue;
      const float v = std::abs(s.tile[std::size_t(tile_index(q.x, q.y, q.z))]);
      if (v < best_value) {
        best_value = v;
        best = q;
      }
    }
    if (best == p) return -1;
    p = best;
  }
}

// Scratch::whole and Scratch::interior from the tile's active rows, a row at a time: bit i of
// three(r) says bits i - 1, i and i + 1 of r are set.
void stencil_rows(Scratch& s) {
  auto row = [&](int y, int z) { return s.rows[std::size_t((y - kLo) + kDim * (z - kLo))]; };
  auto three = [](std::uint32_t r) { return r & (r >> 1) & (r << 1); };
  for (int z = 0; z < kBrickDim; ++z)
    for (int y = 0; y < kBrickDim; ++y) {
      const std::uint32_t faces =
          three(row(y, z)) & row(y - 1, z) & row(y + 1, z) & row(y, z - 1) & row(y, z + 1);
      const std::uint32_t whole = three(row(y, z)) & three(row(y - 1, z)) & three(row(y + 1, z)) &
                                  three(row(y, z - 1)) & three(row(y, z + 1)) & row(y - 1, z - 1) &
                                  row(y - 1, z + 1) & row(y + 1, z - 1) & row(y + 1, z + 1);
      s.interior[std::size_t(y + kBrickDim * z)] = std::uint8_t(faces >> -kLo);
      s.whole[std::size_t(y + kBrickDim * z)] = std::uint8_t(whole >> -kLo);
    }
}

// Scratch::inner and Scratch::around_bricks, for the edge stencils.
void edge_rows(const NarrowBand& band, const Neighborhood& around, Scratch& s) {
  auto row = [&](int y, int z) { return s.rows[std::size_t((y - kLo) + kDim * (z - kLo))]; };
  for (int z = -1; z <= kBrickDim; ++z)
    for (int y = -1; y <= kBrickDim; ++y) {
      const std::uint32_t r = row(y, z);
      s.inner[std::size_t((y + 1) + (kBrickDim + 2) * (z + 1))] =
          r & (r >> 1) & (r << 1) & row(y - 1, z) & row(y + 1, z) & row(y, z - 1) & row(y, z + 1);
    }
  for (std::size_t k = 0; k < 27; ++k) s.around_bricks[k] = around[k] == kNoBrick ? nullptr : &band.bricks()[around[k]];
}

// Whether active voxel l (brick-local, within one voxel of the brick) has an inactive face
// neighbour.
bool is_edge(const Scratch& s, const Coord& l) {
  return !((s.inner[std::size_t((l.y + 1) + (kBrickDim + 2) * (l.z + 1))] >> (l.x - kLo)) & 1u);
}

// Band value index of the active voxel at brick-local coordinates q (within one brick of the
// brick itself).
std::uint32_t value_index(const Scratch& s, const Coord& q) {
  const int bx = q.x < 0 ? -1 : (q.x >= kBrickDim ? 1 : 0), by = q.y < 0 ? -1 : (q.y >= kBrickDim ? 1 : 0),
            bz = q.z < 0 ? -1 : (q.z >= kBrickDim ? 1 : 0);
  const Brick& br = *s.around_bricks[std::size_t(Neighborhood::slot(bx, by, bz))];
  return std::uint32_t(br.value_offset + std::uint32_t(br.slot(local_index(q.x & 7, q.y & 7, q.z & 7))));
}

// The extrapolation of edge voxel l from the interior (see EdgeStencil): quadratic through the
// next three active voxels along a direction (linear through two), the first one not itself
// an edge voxel, on the direction where u changes fastest.
EdgeStencil edge_stencil(const Scratch& s, const Coord& l) {
  EdgeStencil e;
  double step = -1.0;
  int best_face = -1, best_count = 0;
  for (int f = 0; f < 6; ++f) {
    const int a = f >> 1, dir = (f & 1) ? 1 : -1;
    Coord q[3] = {l, l, l};
    int n = 0;
    for (; n < 3; ++n) {
      q[n][a] += dir * (n + 1);
      if (n + 1 > kStencilReach || !active_at(s, q[n].x, q[n].y, q[n].z)) break;
    }
    if (n < 2 || is_edge(s, q[0])) continue;
    const float* t = s.tile.data();
    const double u1 = t[tile_index(q[0].x, q[0].y, q[0].z)], u2 = t[tile_index(q[1].x, q[1].y, q[1].z)];
    if (std::abs(u1 - u2) <= step) continue;
    step = std::abs(u1 - u2);
    best_face = f;
    best_count = n;
  }
  if (best_face < 0) return e;
  // Band value indices for the chosen direction only.
  e.count = std::uint8_t(best_count);
  for (int k = 0; k < best_count; ++k) {
    Coord q = l;
    q[best_face >> 1] += ((best_face & 1) ? 1 : -1) * (k + 1);
    e.source[std::size_t(k)] = value_index(s, q);
  }
  e.coef = best_count == 3 ? std::array<float, 3>{3.0f, -3.0f, 1.0f} : std::array<float, 3>{2.0f, -1.0f, 0.0f};
  for (int f = 0; f < 6; ++f) {
    Coord q = l;
    q[f >> 1] += (f & 1) ? 1 : -1;
    if (active_at(s, q.x, q.y, q.z)) e.neighbor[e.neighbors++] = value_index(s, q);
  }
  return e;
}

// The one-sided derivatives the upwind terms read: pure advection by a constant velocity needs
// one side per moving axis (the velocity's upwind side), anything else both.
SidesWanted sides_wanted(const EvolutionOptions& o, bool advection_only) {
  SidesWanted w;
  const bool constant = o.velocity.kind == Velocity::Kind::Constant;
  for (std::size_t a = 0; a < 3; ++a) {
    const double v = o.velocity.constant[int(a)];
    w.minus[a] = !advection_only || !constant || v > 0.0;
    w.plus[a] = !advection_only || !constant || v < 0.0;
  }
  return w;
}

// One thread's share of the operator's reductions.
struct OperatorStats {
  double max_hyp = 0, max_speed = 0, max_front = 0, drift_sum = 0;
  std::uint64_t drift_count = 0, crossings = 0;
  float min_value = std::numeric_limits<float>::infinity(), max_value = -std::numeric_limits<float>::infinity();
  OperatorSeconds seconds;
};

// The rates of one brick's `count` active voxels from the scratch's one-sided derivatives,
// speeds, velocities and |grad u|, with the CFL and front-speed reductions.
void brick_rates(const Scratch& s, const EvolutionOptions& o, int count, double h, float* rate_out, OperatorStats& stats) {
  const bool moving = has_speed(o), velocity = has_velocity(o);
  const bool advective = moving && o.speed.has_advective, parabolic = moving && o.speed.has_parabolic;
  const bool upwind = advective || velocity;
  const bool llf = o.hamiltonian == Hamiltonian::LaxFriedrichs;
  double max_hyp = stats.max_hyp, max_speed = stats.max_speed, max_front = stats.max_front;  // in registers
  for (int i = 0; i < count; ++i) {
    const std::size_t u = std::size_t(i);
    const double ba = advective ? double(s.beta_a[u]) : 0.0;
    const double bp = parabolic ? double(s.beta_p[u]) : 0.0;
    const Vec3d vel = velocity ? s.vel[u] : Vec3d{};
    double rate = 0.0;
    if (upwind) {
      const OneSided* d = s.os[u].data();
      const double vw[3] = {vel.x, vel.y, vel.z};
      if (llf) {
        const double alpha[3] = {std::abs(ba) + std::abs(vw[0]), std::abs(ba) + std::abs(vw[1]),
                                 std::abs(ba) + std::abs(vw[2])};
        rate -= llf_hamiltonian(d, ba, vw, alpha) / h;
      } else {
        if (advective && ba != 0.0) rate -= ba * godunov_gradient_norm(d, ba) / h;
        if (velocity) rate -= upwind_advection(d, vw) / h;
      }
    }
    if (parabolic) rate -= bp * double(s.grad[u]);
    rate_out[u] = float(rate);
    const double vsum = std::abs(vel.x) + std::abs(vel.y) + std::abs(vel.z);
    max_hyp = std::max(max_hyp, kSqrt3 * std::abs(ba) + vsum);
    const double sp = std::abs(ba) + std::abs(bp) + (velocity ? length(vel) : 0.0);
    max_speed = std::max(max_speed, sp);
    // The front's speed: voxels next to the zero level only (curvatures blow up near the
    // skeleton, deep in the band, without the front moving).
    if (std::abs(s.d[u]) < 1.5 * h) max_front = std::max(max_front, sp);
  }
  stats.max_hyp = max_hyp;
  stats.max_speed = max_speed;
  stats.max_front = max_front;
}

// Pure advection by a constant velocity: brick_rates' arithmetic (upwind_advection, in the same
// order) straight from the side arrays, for every voxel at once; the reductions are the
// velocity's.
void constant_advection_rates(const UpwindSides& sides, const Vec3d& vel, const float* d, int count, double h,
                              float* rate_out, OperatorStats& stats) {
  const double* side[3];
  for (int a = 0; a < 3; ++a) side[a] = vel[a] > 0.0 ? sides.minus[std::size_t(a)].data() : sides.plus[std::size_t(a)].data();
  const double vx = vel.x, vy = vel.y, vz = vel.z;
  const bool mx = vx > 0.0 || vx < 0.0, my = vy > 0.0 || vy < 0.0, mz = vz > 0.0 || vz < 0.0;  // axis moves
  bool front = false;
  for (int k = 0; k < count; ++k) {
    double sum = 0.0;
    sum += mx ? vx * side[0][k] : 0.0;
    sum += my ? vy * side[1][k] : 0.0;
    sum += mz ? vz * side[2][k] : 0.0;
    rate_out[k] = float(0.0 - sum / h);
  }
  for (int k = 0; d && k < count; ++k) front |= std::abs(d[k]) < 1.5 * h;
  const double sp = length(vel);
  stats.max_hyp = std::max(stats.max_hyp, std::abs(vel.x) + std::abs(vel.y) + std::abs(vel.z));
  stats.max_speed = std::max(stats.max_speed, sp);
  if (front) stats.max_front = std::max(stats.max_front, sp);
}

// What an operator run computes, from its setup (the same for every brick).
struct OperatorPlan {
  bool moving, advective, parabolic, velocity, upwind, advection_only, constant_advection;
  std::uint32_t needs;
  SidesWanted sides;
  // Whether the per-voxel pass runs: RK3's later stages of pure advection by a constant
  // velocity need nothing from it (no speed, statistics or edges).
  bool voxel_pass;
  explicit OperatorPlan(const OperatorSetup& setup) {
    const EvolutionOptions& o = setup.options;
    moving = has_speed(o);
    advective = moving && o.speed.has_advective;
    parabolic = moving && o.speed.has_parabolic;
    velocity = has_velocity(o);
    needs = moving ? o.speed.needs : 0u;
    upwind = advective || velocity;
    advection_only = velocity && !advective && o.hamiltonian == Hamiltonian::Godunov;
    constant_advection = advection_only && o.velocity.kind == Velocity::Kind::Constant;
    sides = sides_wanted(o, advection_only);
    voxel_pass = !constant_advection || setup.want_stats || setup.want_edges;
  }
};

// The per-voxel pass over one brick's active voxels (k-th in ascending local index): values,
// speed inputs (positions, fields, normals, |grad u|, where each curvature comes from),
// velocities, one-sided derivatives, drift, edges and their stencils. Returns the count.
// The brick's active voxels with an inactive face neighbour (Scratch::interior).
std::size_t edge_voxel_count(const Brick& br, const Scratch& s) {
  int edges = 0;
  for (int r = 0; r < kBrickDim * kBrickDim; ++r)
    edges += std::popcount(unsigned(std::uint8_t(br.active.words[std::size_t(r >> 3)] >> (8 * (r & 7)))) &
                           ~unsigned(s.interior[std::size_t(r)]) & 0xffu);
  return std::size_t(edges);
}

// The k-th voxel's position and the fields its speed reads, at world point `world` (returned).
Vec3d sample_fields(const Vec3d& world, const SpeedFields& f, std::uint32_t needs, int k, Scratch& s) {
  const std::size_t u = std::size_t(k);
  s.x[u] = float(world.x);
  s.y[u] = float(world.y);
  s.z[u] = float(world.z);
  if (needs & kNeedsDist) s.dist[u] = float(f.dist(world));
  if (needs & kNeedsDistGradient) {
    const Vec3d g = f.dist_gradient(world);
    s.dgx[u] = float(g.x);
    s.dgy[u] = float(g.y);
    s.dgz[u] = float(g.z);
  }
  if (needs & kNeedsImage) s.img[u] = float(f.image(world));
  if (needs & kNeedsEdge) s.edge[u] = float(f.edge(world));
  if (needs & kNeedsRoi) s.roi[u] = float(f.roi(world));
  return world;
}

// The k-th voxel's one-sided derivatives from the brick's batch (UpwindSides).
void voxel_one_sided(int k, bool advection_only, Scratch& s) {
  auto& d = s.os[std::size_t(k)];
  for (int a = 0; a < 3; ++a) d[std::size_t(a)] = s.sides->at(a, k);
  if (advection_only) {
    // Pure advection upwinds each axis by the velocity's sign: the other side reads 0.
    const Vec3d& vel = s.vel[std::size_t(k)];
    for (int a = 0; a < 3; ++a) {
      if (!(vel[a] > 0.0)) d[std::size_t(a)].minus = 0.0;
      if (!(vel[a] < 0.0)) d[std::size_t(a)].plus = 0.0;
    }
  }
}

int voxel_pass(const NarrowBand& band, const Neighborhood& around, std::uint32_t b, const OperatorSetup& setup,
               const OperatorPlan& plan, Scratch& s, OperatorOutput& out, OperatorStats& stats) {
  const EvolutionOptions& o = setup.options;
  const std::uint32_t needs = plan.needs;
  const bool velocity = plan.velocity, parabolic = plan.parabolic, upwind = plan.upwind;
  const bool advection_only = plan.advection_only, constant_advection = plan.constant_advection;
  const double h = band.voxel_size();
  const Brick& br = band.bricks()[b];
  const Coord origin = brick_origin(br.coord);
  const std::size_t first = br.value_offset;
  if (setup.want_edges) {
    edge_rows(band, around, s);
    // One allocation for the brick's edge stencils (at most one per edge voxel).
    out.edge_stencils[b].reserve(edge_voxel_count(br, s));
  }
  // |grad u| for the whole brick at once (vector code); the loop below reads it by voxel.
  if (parabolic || setup.want_stats || (needs & (kNeedsNormal | kNeedsGradNorm)))
    central_gradient_norms(s.tile.data() + tile_index(0, 0, 0), kTileStride[1], kTileStride[2], h, s.gnorm.data());
  // The reductions in locals (kept in registers; stats' fields would be stored and reloaded
  // per voxel), combined in the same order, so the sums are unchanged.
  double drift_sum = stats.drift_sum;
  std::uint64_t drift_count = stats.drift_count, crossings = stats.crossings;
  float min_value = stats.min_value, max_value = stats.max_value;
  int k = 0;
  br.active.for_each_set([&](int n) {
    const Coord l = local_coord(n);
    const float* v = s.tile.data() + tile_index(l.x, l.y, l.z);
    s.d[std::size_t(k)] = *v;
    constexpr std::uint32_t kFieldNeeds = kNeedsDist | kNeedsDistGradient | kNeedsImage | kNeedsEdge | kNeedsRoi;
    const Vec3d world = (needs & (kNeedsPosition | kFieldNeeds)) || (velocity && o.velocity.kind == Velocity::Kind::Field)
                            ? sample_fields(band.world(origin + l), o.fields, needs, k, s)
                            : Vec3d{};
    if (velocity && !constant_advection)
      s.vel[std::size_t(k)] = o.velocity.kind == Velocity::Kind::Constant ? o.velocity.constant
                                                                          : o.velocity.field(world, setup.time);
    if (upwind && !constant_advection) voxel_one_sided(k, advection_only, s);
    // Central gradient: for the parabolic part, normals, |grad u| and the drift near the front.
    const bool near = setup.want_stats && std::abs(*v) < 2 * h;
    const bool want_grad = parabolic || near || (needs & (kNeedsNormal | kNeedsGradNorm));
    const double gn = want_grad ? s.gnorm[std::size_t(n)] : 0.0;
    if (needs & (kNeedsMean | kNeedsPrincipal | kNeedsGauss))
      s.curvature_at_tile[std::size_t(k)] =
          (s.whole[std::size_t(l.y + kBrickDim * l.z)] >> l.x) & 1u ? tile_index(l.x, l.y, l.z) : curvature_source(s, l);
    s.grad[std::size_t(k)] = float(gn);
    if (needs & kNeedsNormal) {
      const Vec3d g = Vec3d{double(v[1]) - double(v[-1]), double(v[kDim]) - double(v[-kDim]),
                            double(v[kDim * kDim]) - double(v[-kDim * kDim])} * (0.5 / h);
      const Vec3d nrm = gn > 0 ? g / gn : Vec3d{};
      s.nx[std::size_t(k)] = float(nrm.x);
      s.ny[std::size_t(k)] = float(nrm.y);
      s.nz[std::size_t(k)] = float(nrm.z);
      if (needs & kNeedsDistGradient)
        s.dn[std::size_t(k)] = float(double(s.dgx[std::size_t(k)]) * nrm.x + double(s.dgy[std::size_t(k)]) * nrm.y +
                                     double(s.dgz[std::size_t(k)]) * nrm.z);
    }
    if (near) {
      drift_sum += std::abs(gn - 1.0);
      ++drift_count;
    }
    min_value = std::min(min_value, *v);
    max_value = std::max(max_value, *v);
    if (setup.want_edges)
      crossings += unsigned((v[0] < 0.0f) != (v[1] < 0.0f)) + unsigned((v[0] < 0.0f) != (v[kDim] < 0.0f)) +
                         unsigned((v[0] < 0.0f) != (v[kDim * kDim] < 0.0f));
    if (setup.want_edges && !((s.interior[std::size_t(l.y + kBrickDim * l.z)] >> l.x) & 1u)) {
      out.edge[first + std::size_t(k)] = 1;
      EdgeStencil e = edge_stencil(s, l);
      if (e.count > 0) {
        e.target = std::uint32_t(first + std::size_t(k));
        out.edge_stencils[b].push_back(e);
      }
    }
    ++k;
  });
  stats.drift_sum = drift_sum;
  stats.drift_count = drift_count;
  stats.crossings = crossings;
  stats.min_value = min_value;
  stats.max_value = max_value;
  return k;
}

// Mean, Gaussian and (when the speed reads them) principal curvatures of the brick's voxels.
void brick_curvatures(const Brick& br, std::uint32_t needs, int count, double h, Scratch& s) {
  if (needs & kNeedsPrincipal) {
    for (int i = 0; i < count; ++i) {
      const int at = s.curvature_at_tile[std::size_t(i)];
      const Curvature c = at >= 0 ? curvature_at(s.tile.data() + at, kTileStride, h) : Curvature{};
      s.mean[std::size_t(i)] = float(c.mean);
      s.gauss[std::size_t(i)] = float(c.gauss);
      s.k1[std::size_t(i)] = float(c.k1);
      s.k2[std::size_t(i)] = float(c.k2);
    }
  } else if (needs & (kNeedsGauss | kNeedsMean)) {
    mean_gauss_curvature_brick(s.tile.data(), tile_index(0, 0, 0), kTileStride, br.active, s.curvature_at_tile.data(), h,
                               s.mean.data(), s.gauss.data());
  }
}

// The speed's betas for the brick's voxels (or the extension velocities), into the scratch
// and, when wanted, the output.
void brick_speeds(const OperatorSetup& setup, std::uint32_t needs, std::size_t first, int count, double h,
                  Scratch& s, OperatorOutput& out) {
  const SpeedFunction& speed = setup.options.speed;
  if (setup.beta_a_override) {
    std::copy_n(setup.beta_a_override + first, count, s.beta_a.data());
    std::copy_n(setup.beta_p_override + first, count, s.beta_p.data());
  } else {
    std::fill_n(s.beta_a.data(), count, 0.0f);
    std::fill_n(s.beta_p.data(), count, 0.0f);
    SpeedBatch batch;
    batch.count = count;
    batch.time = setup.time;
    batch.h = h;
    batch.kavg = setup.kavg;
    batch.d = s.d.data();
    if (needs & kNeedsPosition) {
      batch.x = s.x.data();
      batch.y = s.y.data();
      batch.z = s.z.data();
    }
    if (needs & kNeedsNormal) {
      batch.nx = s.nx.data();
      batch.ny = s.ny.data();
      batch.nz = s.nz.data();
    }
    if (needs & (kNeedsMean | kNeedsPrincipal | kNeedsGauss)) batch.mean = s.mean.data();
    if (needs & kNeedsGauss) batch.gauss = s.gauss.data();
    if (needs & kNeedsPrincipal) {
      batch.gauss = s.gauss.data();
      batch.k1 = s.k1.data();
      batch.k2 = s.k2.data();
    }
    if (needs & kNeedsGradNorm) batch.grad = s.grad.data();
    if (needs & kNeedsDist) batch.dist = s.dist.data();
    if (needs & kNeedsDistGradient) {
      batch.dgx = s.dgx.data();
      batch.dgy = s.dgy.data();
      batch.dgz = s.dgz.data();
      if (needs & kNeedsNormal) batch.dn = s.dn.data();
    }
    if (needs & kNeedsImage) batch.img = s.img.data();
    if (needs & kNeedsEdge) batch.edge = s.edge.data();
    if (needs & kNeedsRoi) batch.roi = s.roi.data();
    speed.eval(batch, SpeedOutput{s.beta_a.data(), s.beta_p.data()});
  }
  if (setup.want_betas) {
    std::copy_n(s.beta_a.data(), count, out.beta_a.data() + first);
    std::copy_n(s.beta_p.data(), count, out.beta_p.data() + first);
  }
}

// The spatial operator on one brick: rates (and betas, edges) for its active voxels.
void brick_operator(const NarrowBand& band, std::span<const float> decoded, std::uint32_t b, const OperatorSetup& setup,
                    const OperatorPlan& plan, Scratch& s, OperatorOutput& out, OperatorStats& stats) {
  OperatorSeconds& out_seconds = stats.seconds;
  const auto t_start = Clock::now();
  const EvolutionOptions& o = setup.options;
  const double h = band.voxel_size();
  const Brick& br = band.bricks()[b];
  const std::size_t first = br.value_offset;
  // Without the per-voxel pass only the axis lines read the tile: the star is enough.
  const Neighborhood around = plan.voxel_pass ? brick_neighborhood(band, b) : brick_star(band, b);
  gather_box(band, decoded, around, kLo, kHi, s.tile, s.rows, plan.voxel_pass ? GatherRegion::Box : GatherRegion::Star);
  if (plan.voxel_pass) stencil_rows(s);
  if (plan.upwind) {
    if (!s.lines) s.lines = std::make_unique<AxisLines>();
    if (!s.sides) s.sides = std::make_unique<UpwindSides>();
    fill_axis_lines(s.tile.data(), s.rows.data(), stencil_reach(o.scheme), *s.lines);
    upwind_sides(*s.lines, br.active, o.scheme, plan.sides, *s.sides);
  }
  const int count = plan.voxel_pass ? voxel_pass(band, around, b, setup, plan, s, out, stats) : br.active_count();
  const auto t_curvature = Clock::now();
  out_seconds.gradient += std::chrono::duration<double>(t_curvature - t_start).count();
  brick_curvatures(br, plan.needs, count, h, s);
  const auto t_speed = Clock::now();
  out_seconds.curvature += std::chrono::duration<double>(t_speed - t_curvature).count();
  if (plan.moving) brick_speeds(setup, plan.needs, first, count, h, s, out);
  const auto t_rates = Clock::now();
  out_seconds.speed += std::chrono::duration<double>(t_rates - t_speed).count();
  if (plan.constant_advection)
    constant_advection_rates(*s.sides, o.velocity.constant, setup.want_stats ? s.d.data() : nullptr, count, h,
                             out.rate.data() + first, stats);
  else
    brick_rates(s, o, count, h, out.rate.data() + first, stats);
  out_seconds.rates += since(t_rates);
}

}  // namespace

OperatorOutput run_operator(const NarrowBand& band, const OperatorSetup& setup) {
  OperatorOutput out;
  out.min_value = std::numeric_limits<float>::infinity();
  out.max_value = -std::numeric_limits<float>::infinity();
  const std::size_t n = band.active_voxel_count();
  out.rate.resize(n);  // uninitialised: brick_operator writes every active voxel's rate
  if (setup.want_betas) {
    out.beta_a.assign(n, 0.0f);
    out.beta_p.assign(n, 0.0f);
  }
  if (setup.want_edges) {
    out.edge.assign(n, 0);
    out.edge_stencils.resize(band.brick_count());
  }
  tbb::combinable<OperatorStats> stats;
  tbb::enumerable_thread_specific<Scratch> scratch;
  const OperatorPlan plan(setup);
  const DecodedBricks decoded = decode_bricks(band);
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, std::uint32_t(band.brick_count()), 8),
                    [&](const tbb::blocked_range<std::uint32_t>& r) {
    Scratch& s = scratch.local();
    OperatorStats& st = stats.local();
    for (std::uint32_t b = r.begin(); b != r.end(); ++b)
      brick_operator(band, decoded.values(), b, setup, plan, s, out, st);
  });
  stats.combine_each([&](const OperatorStats& st) {
    out.max_hyperbolic = std::max(out.max_hyperbolic, st.max_hyp);
    out.max_speed = std::max(out.max_speed, st.max_speed);
    out.max_front_speed = std::max(out.max_front_speed, st.max_front);
    out.seconds.gradient += st.seconds.gradient;
    out.seconds.curvature += st.seconds.curvature;
    out.seconds.speed += st.seconds.speed;
    out.seconds.rates += st.seconds.rates;
    out.drift_sum += st.drift_sum;
    out.drift_count += st.drift_count;
    out.crossings += st.crossings;
    out.min_value = std::min(out.min_value, st.min_value);
    out.max_value = std::max(out.max_value, st.max_value);
  });
  return out;
}

}  // namespace levelset::evolve::detail
