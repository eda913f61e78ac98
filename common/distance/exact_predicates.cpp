#include "distance/exact_predicates.hpp"

#include <cmath>
#include <vector>

namespace levelset {

namespace {

// Floating-point expansions: sums of non-overlapping doubles in increasing magnitude, zero
// components eliminated (Shewchuk 1997). The sign of an expansion is that of its last
// (largest) component.
using Expansion = std::vector<double>;

inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

inline void fast_two_sum(double a, double b, double& x, double& y) {  // requires |a| >= |b|
  x = a + b;
  y = b - (x - a);
}

inline void two_diff(double a, double b, double& x, double& y) {
  x = a - b;
  const double bv = a - x;
  const double av = x + bv;
  y = (a - av) + (bv - b);
}

inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

// e + b.
Expansion grow(const Expansion& e, double b) {
  Expansion h;
  h.reserve(e.size() + 1);
  double q = b;
  for (double ei : e) {
    double sum, err;
    two_sum(q, ei, sum, err);
    if (err != 0.0) h.push_back(err);
    q = sum;
  }
  if (q != 0.0 || h.empty()) h.push_back(q);
  return h;
}

Expansion add(const Expansion& e, const Expansion& f) {
  Expansion h = e;
  for (double fi : f) h = grow(h, fi);
  return h;
}

Expansion negate(Expansion e) {
  for (double& v : e) v = -v;
  return e;
}

// e * b.
Expansion scale(const Expansion& e, double b) {
  Expansion h;
  h.reserve(2 * e.size());
  if (e.empty()) return h;
  double q, err;
  two_product(e[0], b, q, err);
  if (err != 0.0) h.push_back(err);
  for (std::size_t i = 1; i < e.size(); ++i) {
    double p1, p0, sum;
    two_product(e[i], b, p1, p0);
    two_sum(q, p0, sum, err);
    if (err != 0.0) h.push_back(err);
    fast_two_sum(p1, sum, q, err);
    if (err != 0.0) h.push_back(err);
  }
  if (q != 0.0 || h.empty()) h.push_back(q);
  return h;
}

Expansion multiply(const Expansion& e, const Expansion& f) {
  Expansion r{0.0};
  for (double fi : f) r = add(r, scale(e, fi));
  return r;
}

Expansion difference(double a, double b) {
  double x, y;
  two_diff(a, b, x, y);
  Expansion e;
  if (y != 0.0) e.push_back(y);
  if (x != 0.0 || e.empty()) e.push_back(x);
  return e;
}

int sign(const Expansion& e) {
  for (auto it = e.rbegin(); it != e.rend(); ++it)
    if (*it != 0.0) return *it > 0.0 ? 1 : -1;
  return 0;
}

// (p * q) - (r * s) for expansions.
Expansion cross_term(const Expansion& p, const Expansion& q, const Expansion& r,
                     const Expansion& s) {
  return add(multiply(p, q), negate(multiply(r, s)));
}

}  // namespace

int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy) {
  const Expansion acx = difference(ax, cx), acy = difference(ay, cy);
  const Expansion bcx = difference(bx, cx), bcy = difference(by, cy);
  return sign(cross_term(acx, bcy, acy, bcx));
}

int orient3d_exact(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const Expansion adx = difference(a.x, d.x), ady = difference(a.y, d.y),
                  adz = difference(a.z, d.z);
  const Expansion bdx = difference(b.x, d.x), bdy = difference(b.y, d.y),
                  bdz = difference(b.z, d.z);
  const Expansion cdx = difference(c.x, d.x), cdy = difference(c.y, d.y),
                  cdz = difference(c.z, d.z);
  const Expansion t1 = multiply(adz, cross_term(bdx, cdy, cdx, bdy));
  const Expansion t2 = multiply(bdz, cross_term(cdx, ady, adx, cdy));
  const Expansion t3 = multiply(cdz, cross_term(adx, bdy, bdx, ady));
  return sign(add(add(t1, t2), t3));
}

}  // namespace levelset
