#include "geometry/analytic_shapes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "core/error.hpp"

namespace levelset {

namespace {

constexpr double kPi = std::numbers::pi;

void require_positive(double v, const char* what) {
  if (!(std::isfinite(v) && v > 0))
    throw Error(ErrorCode::InvalidArgument, what, "must be finite and > 0");
}

BBox box_around(const Vec3d& c, const Vec3d& e) {
  BBox b;
  b.extend(c - e);
  b.extend(c + e);
  return b;
}

class Sphere final : public AnalyticShape {
 public:
  Sphere(const Vec3d& c, double r) : c_(c), r_(r) { require_positive(r, "sphere radius"); }
  double distance(const Vec3d& p) const override { return length(p - c_) - r_; }
  BBox bounds() const override { return box_around(c_, {r_, r_, r_}); }
  std::string name() const override { return "sphere"; }
  double volume() const override { return 4.0 / 3.0 * kPi * r_ * r_ * r_; }
  double area() const override { return 4.0 * kPi * r_ * r_; }
  int genus() const override { return 0; }

 private:
  Vec3d c_;
  double r_;
};

class Box final : public AnalyticShape {
 public:
  Box(const Vec3d& c, const Vec3d& e) : c_(c), e_(e) {
    require_positive(e.x, "box half extent x");
    require_positive(e.y, "box half extent y");
    require_positive(e.z, "box half extent z");
  }
  double distance(const Vec3d& p) const override {
    const Vec3d d = p - c_;
    const Vec3d q{std::abs(d.x) - e_.x, std::abs(d.y) - e_.y, std::abs(d.z) - e_.z};
    const Vec3d qp = max(q, Vec3d{0, 0, 0});
    return length(qp) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
  }
  BBox bounds() const override { return box_around(c_, e_); }
  std::string name() const override { return "box"; }
  double volume() const override { return 8.0 * e_.x * e_.y * e_.z; }
  double area() const override { return 8.0 * (e_.x * e_.y + e_.y * e_.z + e_.x * e_.z); }
  int genus() const override { return 0; }

 private:
  Vec3d c_, e_;
};

class Torus final : public AnalyticShape {
 public:
  Torus(const Vec3d& c, double major, double minor) : c_(c), R_(major), r_(minor) {
    require_positive(major, "torus major radius");
    require_positive(minor, "torus minor radius");
    if (minor >= major)
      throw Error(ErrorCode::InvalidArgument, "torus", "minor radius must be < major radius");
  }
  double distance(const Vec3d& p) const override {
    const Vec3d d = p - c_;
    const double rho = std::hypot(d.x, d.y) - R_;
    return std::hypot(rho, d.z) - r_;
  }
  BBox bounds() const override { return box_around(c_, {R_ + r_, R_ + r_, r_}); }
  std::string name() const override { return "torus"; }
  double volume() const override { return 2.0 * kPi * kPi * R_ * r_ * r_; }
  double area() const override { return 4.0 * kPi * kPi * R_ * r_; }
  int genus() const override { return 1; }

 private:
  Vec3d c_;
  double R_, r_;
};

// Distance in the meridian half-plane (x along the axis, rho >= 0) to the profile made of
// the two sphere arcs and the bar segment; exact because the closest point of a surface
// of revolution lies in the meridian plane of the query point.
class Dumbbell final : public AnalyticShape {
 public:
  Dumbbell(const Vec3d& c, double rs, double half_distance, double rb)
      : c_(c), rs_(rs), d_(half_distance), rb_(rb) {
    require_positive(rs, "dumbbell sphere radius");
    require_positive(half_distance, "dumbbell half distance");
    require_positive(rb, "dumbbell bar radius");
    if (rb >= rs) throw Error(ErrorCode::InvalidArgument, "dumbbell", "bar radius must be < sphere radius");
    xj_ = d_ - std::sqrt(rs_ * rs_ - rb_ * rb_);  // x where the bar meets the right sphere
    if (xj_ <= 0)
      throw Error(ErrorCode::InvalidArgument, "dumbbell", "spheres overlap: increase the distance");
    theta_j_ = kPi - std::asin(rb_ / rs_);
  }
  double distance(const Vec3d& p) const override {
    const Vec3d q = p - c_;
    const double x = std::abs(q.x);  // symmetric in x
    const double rho = std::hypot(q.y, q.z);
    // Right sphere arc: angles [0, theta_j] measured from +x in the meridian plane.
    const double ax = x - d_, ar = rho;
    const double ang = std::atan2(ar, ax);
    double dist;
    if (ang <= theta_j_) {
      dist = std::abs(std::hypot(ax, ar) - rs_);
    } else {
      dist = std::hypot(x - xj_, rho - rb_);  // junction point
    }
    // Bar segment rho = rb, x in [-xj, xj] (use |x| so only [0, xj] matters).
    const double sx = std::min(x, xj_);
    dist = std::min(dist, std::hypot(x - sx, rho - rb_));
    const bool inside = std::hypot(ax, ar) < rs_ || (x <= d_ && rho < rb_);
    return inside ? -dist : dist;
  }
  BBox bounds() const override { return box_around(c_, {d_ + rs_, rs_, rs_}); }
  std::string name() const override { return "dumbbell"; }
  int genus() const override { return 0; }

 private:
  Vec3d c_;
  double rs_, d_, rb_, xj_, theta_j_;
};

// Tube around a (p,q) torus knot C(t) = ((R + r cos qt) cos pt, (R + r cos qt) sin pt, r sin qt).
// The curve is sampled into chunks with bounding spheres; the nearest sample segment seeds a
// Newton solve of C'(t).(C(t)-x) = 0, which gives the exact distance to the smooth curve.
class TorusKnot final : public AnalyticShape {
 public:
  TorusKnot(const Vec3d& c, int p, int q, double R, double r, double a)
      : c_(c), p_(p), q_(q), R_(R), r_(r), a_(a) {
    require_positive(R, "knot major radius");
    require_positive(r, "knot minor radius");
    require_positive(a, "knot tube radius");
    if (p < 1 || q < 1 || std::gcd(p, q) != 1)
      throw Error(ErrorCode::InvalidArgument, "knot", "p and q must be coprime positive integers");
    if (r + a >= R) throw Error(ErrorCode::InvalidArgument, "knot", "r + tube radius must be < R");
    samples_.resize(kSamples);
    for (int i = 0; i < kSamples; ++i) samples_[i] = curve(param(i));
    for (int k = 0; k < kChunks; ++k) {
      Vec3d lo = samples_[k * kChunk], hi = lo;
      for (int i = 0; i <= kChunk; ++i) {
        lo = min(lo, samples_[(k * kChunk + i) % kSamples]);
        hi = max(hi, samples_[(k * kChunk + i) % kSamples]);
      }
      chunk_center_[k] = (lo + hi) * 0.5;
      // Chord sag is far below this slack for kSamples segments on this curve.
      chunk_radius_[k] = length(hi - lo) * 0.5;
    }
    // Tight bounds from a dense sampling (error ~1e-7 of the size), grown by the tube.
    for (int i = 0; i < 65536; ++i) bounds_.extend(c_ + curve(2.0 * kPi * i / 65536));
    bounds_.min -= Vec3d{a_, a_, a_};
    bounds_.max += Vec3d{a_, a_, a_};
  }

  double distance(const Vec3d& x) const override {
    const Vec3d p = x - c_;
    // Best segment: evaluate the chunk with the smallest lower bound first, then only
    // chunks whose lower bound can still beat the best distance found.
    double lower[kChunks];
    int first = 0;
    for (int k = 0; k < kChunks; ++k) {
      lower[k] = std::max(0.0, length(p - chunk_center_[k]) - chunk_radius_[k]);
      if (lower[k] < lower[first]) first = k;
    }
    double best = std::numeric_limits<double>::infinity();
    int best_seg = 0;
    auto scan_chunk = [&](int k) {
      for (int i = k * kChunk; i < (k + 1) * kChunk; ++i) {
        const double dseg = segment_distance(p, samples_[i], samples_[(i + 1) % kSamples]);
        if (dseg < best) {
          best = dseg;
          best_seg = i;
        }
      }
    };
    scan_chunk(first);
    for (int k = 0; k < kChunks; ++k)
      if (k != first && lower[k] < best) scan_chunk(k);
    // Refine on the smooth curve; the search interval spans the neighbouring segments.
    const double d = refine(p, best_seg);
    return d - a_;
  }

  BBox bounds() const override { return bounds_; }
  std::string name() const override { return "knot"; }
  int genus() const override { return 1; }

 private:
  static constexpr int kSamples = 1024, kChunk = 16, kChunks = kSamples / kChunk;

  double param(int i) const { return 2.0 * kPi * i / kSamples; }
  Vec3d curve(double t) const {
    const double s = R_ + r_ * std::cos(q_ * t);
    return {s * std::cos(p_ * t), s * std::sin(p_ * t), r_ * std::sin(q_ * t)};
  }
  Vec3d curve_d1(double t) const {
    const double s = R_ + r_ * std::cos(q_ * t), ds = -r_ * q_ * std::sin(q_ * t);
    return {ds * std::cos(p_ * t) - s * p_ * std::sin(p_ * t),
            ds * std::sin(p_ * t) + s * p_ * std::cos(p_ * t), r_ * q_ * std::cos(q_ * t)};
  }
  Vec3d curve_d2(double t) const {
    const double s = R_ + r_ * std::cos(q_ * t), ds = -r_ * q_ * std::sin(q_ * t),
                 dds = -r_ * q_ * q_ * std::cos(q_ * t);
    const double c = std::cos(p_ * t), sn = std::sin(p_ * t);
    return {dds * c - 2 * ds * p_ * sn - s * p_ * p_ * c, dds * sn + 2 * ds * p_ * c - s * p_ * p_ * sn,
            -r_ * q_ * q_ * std::sin(q_ * t)};
  }
  static double segment_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
    const Vec3d ab = b - a;
    const double t = std::clamp(dot(p - a, ab) / dot(ab, ab), 0.0, 1.0);
    return length(p - (a + ab * t));
  }
  // Newton on g(t) = C'(t).(C(t)-p) within the segment's parameter interval (widened).
  double refine(const Vec3d& p, int seg) const {
    const double t0 = param(seg), t1 = t0 + 2.0 * kPi / kSamples;
    const Vec3d a = samples_[seg], b = samples_[(seg + 1) % kSamples];
    const Vec3d ab = b - a;
    const double u = std::clamp(dot(p - a, ab) / dot(ab, ab), 0.0, 1.0);
    const double lo = t0 - (t1 - t0), hi = t1 + (t1 - t0);
    double t = t0 + u * (t1 - t0);
    for (int it = 0; it < 12; ++it) {
      const Vec3d diff = curve(t) - p, d1 = curve_d1(t), d2 = curve_d2(t);
      const double g = dot(d1, diff), dg = dot(d2, diff) + dot(d1, d1);
      if (dg <= 0) break;
      const double step = g / dg;
      t = std::clamp(t - step, lo, hi);
      if (std::abs(step) < 1e-13) break;
    }
    return std::min(length(curve(t) - p), std::min(length(a - p), length(b - p)));
  }

  Vec3d c_;
  int p_, q_;
  double R_, r_, a_;
  std::vector<Vec3d> samples_;
  BBox bounds_;
  Vec3d chunk_center_[kChunks];
  double chunk_radius_[kChunks];
};

}  // namespace

std::unique_ptr<AnalyticShape> make_sphere(const Vec3d& c, double r) {
  return std::make_unique<Sphere>(c, r);
}
std::unique_ptr<AnalyticShape> make_box(const Vec3d& c, const Vec3d& e) {
  return std::make_unique<Box>(c, e);
}
std::unique_ptr<AnalyticShape> make_torus(const Vec3d& c, double major, double minor) {
  return std::make_unique<Torus>(c, major, minor);
}
std::unique_ptr<AnalyticShape> make_dumbbell(const Vec3d& c, double rs, double hd, double rb) {
  return std::make_unique<Dumbbell>(c, rs, hd, rb);
}
std::unique_ptr<AnalyticShape> make_torus_knot(const Vec3d& c, int p, int q, double major,
                                               double minor, double tube) {
  return std::make_unique<TorusKnot>(c, p, q, major, minor, tube);
}

const std::vector<std::string>& builtin_shape_names() {
  static const std::vector<std::string> names = {"sphere", "box", "torus", "dumbbell", "knot"};
  return names;
}

std::unique_ptr<AnalyticShape> make_builtin_shape(std::string_view name) {
  if (name == "sphere") return make_sphere({0, 0, 0}, 1.0);
  if (name == "box") return make_box({0, 0, 0}, {1.0, 0.75, 0.5});
  if (name == "torus") return make_torus({0, 0, 0}, 1.0, 0.35);
  if (name == "dumbbell") return make_dumbbell({0, 0, 0}, 0.5, 0.75, 0.15);
  if (name == "knot") return make_torus_knot({0, 0, 0}, 2, 3, 1.0, 0.4, 0.15);
  std::string known;
  for (const auto& n : builtin_shape_names()) known += (known.empty() ? "" : ", ") + n;
  throw Error(ErrorCode::InvalidArgument, std::string(name), "unknown shape; known: " + known);
}

}  // namespace levelset
