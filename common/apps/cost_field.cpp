#include "apps/cost_field.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/text.hpp"
#include "formula/formula.hpp"
#include "grid/interpolate.hpp"

namespace levelset::apps {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string point_text(const Vec3d& p) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p.x, p.y, p.z);
  return buf;
}

// Checks one cost; +inf (blocked) passes.
void check_cost(double c, const Vec3d& where) {
  if (std::isnan(c)) throw Error(ErrorCode::NonFinite, "cost at " + point_text(where), "cost is NaN");
  if (!(c > 0.0))
    throw Error(ErrorCode::InvalidArgument, "cost at " + point_text(where),
                "cost must be > 0 (got " + std::to_string(c) + ")");
}

std::shared_ptr<const formula::Program> compile_cost_formula(const CostField& field) {
  formula::CompileOptions options;
  for (const auto& [name, value] : field.constants) options.constants[name] = value;
  auto program = std::make_shared<formula::Program>(formula::compile(field.formula, options));
  const std::uint32_t allowed = (1u << int(formula::Var::x)) | (1u << int(formula::Var::y)) |
                                (1u << int(formula::Var::z)) | (1u << int(formula::Var::h));
  if (program->uses() & ~allowed)
    throw Error(ErrorCode::InvalidArgument, "cost formula",
                "a cost formula may read only x, y, z and h: '" + field.formula + "'");
  return program;
}

// Runs f(k) for every z-slice in parallel, reporting progress and checking cancel per slice.
template <typename F>
void for_each_slice(const DenseGrid& grid, const ProgressHook& progress, std::string_view stage, F&& f) {
  std::atomic<int> done{0};
  tbb::parallel_for(tbb::blocked_range<int>(0, grid.nz, 1), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k != r.end(); ++k) {
      progress.check(stage);
      f(k);
      const int d = ++done;
      if (progress.on_progress && (d % 16 == 0 || d == grid.nz)) progress.step(double(d) / grid.nz, stage);
    }
  });
}

}  // namespace

CostGrid build_cost_grid(const DenseGrid& grid, const CostField& field, const Obstacles& obstacles,
                         const ProgressHook& progress) {
  validate_grid(grid, std::numeric_limits<std::uint64_t>::max(), "cost grid");
  const std::size_t n = std::size_t(grid.voxel_count());
  if (!field.values.empty() && field.values.size() != n)
    throw Error(ErrorCode::InvalidArgument, "cost values",
                std::to_string(field.values.size()) + " values for " + std::to_string(n) + " grid nodes");
  if (!obstacles.mask.empty() && obstacles.mask.size() != n)
    throw Error(ErrorCode::InvalidArgument, "obstacle mask",
                std::to_string(obstacles.mask.size()) + " entries for " + std::to_string(n) + " grid nodes");
  if (obstacles.band) {
    const double bg = obstacles.band->background();
    if (!(std::isfinite(obstacles.clearance) && std::abs(obstacles.clearance) < bg))
      throw Error(ErrorCode::InvalidArgument, "obstacle clearance",
                  "clearance must be finite and within the band's background distance " + format_number(bg));
  }
  if (!std::isfinite(field.uniform) || !(field.uniform > 0.0))
    throw Error(ErrorCode::InvalidArgument, "uniform cost", "must be finite and > 0");

  CostGrid out;
  out.grid = grid;
  out.cost.assign(n, field.uniform);
  std::shared_ptr<const formula::Program> program;
  if (!field.values.empty()) {
    std::copy(field.values.begin(), field.values.end(), out.cost.begin());
  } else if (field.function) {
    out.pointwise = field.function;
  } else if (!field.formula.empty()) {
    program = compile_cost_formula(field);
    const double h = grid.voxel_size;
    out.pointwise = [program, h](const Vec3d& p) {
      std::array<double, formula::kVarCount> v{};
      v[int(formula::Var::x)] = p.x;
      v[int(formula::Var::y)] = p.y;
      v[int(formula::Var::z)] = p.z;
      v[int(formula::Var::h)] = h;
      return program->evaluate_scalar(v);
    };
  }

  const double h = grid.voxel_size;
  // The first bad cost of each slice (the error names the lowest one after the loop, so the
  // message is the same for any thread count); -1: none.
  std::vector<std::int64_t> first_bad(std::size_t(grid.nz), -1);
  for_each_slice(grid, progress, "cost", [&](int k) {
    // Per-slice scratch for the formula: world coordinates of up to 512 nodes of a row.
    formula::Workspace ws;
    std::array<float, formula::kMaxSamples> xs, ys, zs, hs, res;
    for (int j = 0; j < grid.ny; ++j) {
      double* row = out.cost.data() + grid.index(0, j, k);
      if (field.values.empty() && field.function) {
        for (int i = 0; i < grid.nx; ++i) row[i] = field.function(grid.world(i, j, k));
      } else if (program) {
        std::array<const float*, formula::kVarCount> inputs{};
        inputs[int(formula::Var::x)] = xs.data();
        inputs[int(formula::Var::y)] = ys.data();
        inputs[int(formula::Var::z)] = zs.data();
        inputs[int(formula::Var::h)] = hs.data();
        for (int i0 = 0; i0 < grid.nx; i0 += formula::kMaxSamples) {
          const int m = std::min(formula::kMaxSamples, grid.nx - i0);
          for (int t = 0; t < m; ++t) {
            const Vec3d p = grid.world(i0 + t, j, k);
            xs[t] = float(p.x), ys[t] = float(p.y), zs[t] = float(p.z), hs[t] = float(h);
          }
          program->evaluate(inputs, m, res.data(), ws);
          for (int t = 0; t < m; ++t) row[i0 + t] = double(res[t]);
        }
      }
      for (int i = 0; i < grid.nx && first_bad[k] < 0; ++i)
        if (!(row[i] > 0.0)) first_bad[k] = std::int64_t(grid.index(i, j, k));  // NaN or <= 0
      if (!obstacles.mask.empty())
        for (int i = 0; i < grid.nx; ++i)
          if (obstacles.mask[grid.index(i, j, k)]) row[i] = kInf;
    }
    if (obstacles.band) {
      BandAccessor accessor(*obstacles.band);
      for (int j = 0; j < grid.ny; ++j)
        for (int i = 0; i < grid.nx; ++i)
          if (double(sample_trilinear(accessor, *obstacles.band, grid.world(i, j, k))) < obstacles.clearance)
            out.cost[grid.index(i, j, k)] = kInf;
    }
  });

  for (int k = 0; k < grid.nz; ++k)
    if (first_bad[k] >= 0) {
      const std::int64_t v = first_bad[k];
      const int i = int(v % grid.nx), j = int((v / grid.nx) % grid.ny);
      // The raw value (obstacles may have overwritten it): recompute it the way the slice did.
      const double c = field.values.empty() ? (out.pointwise ? out.pointwise(grid.world(i, j, k)) : field.uniform)
                                            : field.values[std::size_t(v)];
      check_cost(std::isnan(c) || !(c > 0.0) ? c : -0.0, grid.world(i, j, k));
    }

  double lo = kInf, hi = 0.0;
  for (const double c : out.cost) {
    if (c == kInf) {
      ++out.blocked;
    } else {
      lo = std::min(lo, c);
      hi = std::max(hi, c);
    }
  }
  out.min_cost = out.blocked == n ? 0.0 : lo;
  out.max_cost = hi;
  return out;
}

double cost_at(const CostGrid& costs, const Vec3d& p) {
  const DenseGrid& g = costs.grid;
  if (!g.contains(p)) throw Error(ErrorCode::InvalidArgument, "cost_at", "point " + point_text(p) + " is outside the grid");
  const Vec3d q = g.to_index_space(p);
  int base[3];
  double t[3];
  int nearest[3];
  for (int a = 0; a < 3; ++a) {
    const double qa = std::clamp(q[a], 0.0, double(g.dim(a) - 1));
    base[a] = std::min(int(std::floor(qa)), g.dim(a) - 2);
    t[a] = qa - base[a];
    nearest[a] = std::clamp(int(std::lround(qa)), 0, g.dim(a) - 1);
  }
  if (costs.cost[g.index(nearest[0], nearest[1], nearest[2])] == kInf) return kInf;
  if (costs.pointwise) {
    const double c = costs.pointwise(p);
    check_cost(c, p);
    return c;
  }
  double acc = 0.0, wsum = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
    const double w = (dx ? t[0] : 1 - t[0]) * (dy ? t[1] : 1 - t[1]) * (dz ? t[2] : 1 - t[2]);
    const double c = costs.cost[g.index(base[0] + dx, base[1] + dy, base[2] + dz)];
    if (w == 0.0 || c == kInf) continue;
    acc += w * c;
    wsum += w;
  }
  return wsum > 0.0 ? acc / wsum : kInf;
}

}  // namespace levelset::apps
