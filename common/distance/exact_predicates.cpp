#include "distance/exact_predicates.hpp"

#include <cmath>

namespace levelset {

namespace {

// Floating-point expansions: sums of non-overlapping doubles in increasing magnitude, zero
// components eliminated (Shewchuk 1997). The sign of an expansion is that of its last
// (largest) component. Capacities are compile-time bounds (a difference has 2 components, a
// product of m- and n-component expansions at most 2mn, a sum m + n), so the exact path works
// on the stack: it runs per degenerate grid line in the sign code (meshes whose vertices lie on
// grid lines, as marching cubes' do), where a heap allocation per operation dominated.
template <int Cap>
struct Expansion {
  double c[Cap];
  int n = 0;
  void push(double v) { c[n++] = v; }
};

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

// h += b, in place (h's capacity must hold one more component). Writing never overtakes
// reading: after reading component i at most i + 1 components have been written.
template <int Cap>
void grow_in_place(Expansion<Cap>& h, double b) {
  double q = b;
  int out = 0;
  for (int i = 0; i < h.n; ++i) {
    double sum, err;
    two_sum(q, h.c[i], sum, err);
    if (err != 0.0) h.c[out++] = err;
    q = sum;
  }
  if (q != 0.0 || out == 0) h.c[out++] = q;
  h.n = out;
}

template <int N, int M>
Expansion<N + M> add(const Expansion<N>& e, const Expansion<M>& f) {
  Expansion<N + M> h;
  for (int i = 0; i < e.n; ++i) h.c[i] = e.c[i];
  h.n = e.n;
  for (int i = 0; i < f.n; ++i) grow_in_place(h, f.c[i]);
  return h;
}

template <int N>
Expansion<N> negate(Expansion<N> e) {
  for (int i = 0; i < e.n; ++i) e.c[i] = -e.c[i];
  return e;
}

// e * b.
template <int N>
Expansion<2 * N> scale(const Expansion<N>& e, double b) {
  Expansion<2 * N> h;
  if (e.n == 0) return h;
  double q, err;
  two_product(e.c[0], b, q, err);
  if (err != 0.0) h.push(err);
  for (int i = 1; i < e.n; ++i) {
    double p1, p0, sum;
    two_product(e.c[i], b, p1, p0);
    two_sum(q, p0, sum, err);
    if (err != 0.0) h.push(err);
    fast_two_sum(p1, sum, q, err);
    if (err != 0.0) h.push(err);
  }
  if (q != 0.0 || h.n == 0) h.push(q);
  return h;
}

template <int N, int M>
Expansion<2 * N * M> multiply(const Expansion<N>& e, const Expansion<M>& f) {
  Expansion<2 * N * M> r;  // empty: zero
  for (int i = 0; i < f.n; ++i) {
    const Expansion<2 * N> term = scale(e, f.c[i]);
    for (int k = 0; k < term.n; ++k) grow_in_place(r, term.c[k]);
  }
  return r;
}

Expansion<2> difference(double a, double b) {
  double x, y;
  two_diff(a, b, x, y);
  Expansion<2> e;
  if (y != 0.0) e.push(y);
  if (x != 0.0 || e.n == 0) e.push(x);
  return e;
}

template <int N>
int sign(const Expansion<N>& e) {
  for (int i = e.n - 1; i >= 0; --i)
    if (e.c[i] != 0.0) return e.c[i] > 0.0 ? 1 : -1;
  return 0;
}

// (p * q) - (r * s).
Expansion<16> cross_term(const Expansion<2>& p, const Expansion<2>& q, const Expansion<2>& r,
                         const Expansion<2>& s) {
  return add(multiply(p, q), negate(multiply(r, s)));
}

}  // namespace

int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy) {
  const Expansion<2> acx = difference(ax, cx), acy = difference(ay, cy);
  const Expansion<2> bcx = difference(bx, cx), bcy = difference(by, cy);
  return sign(cross_term(acx, bcy, acy, bcx));
}

int orient3d_exact(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const Expansion<2> adx = difference(a.x, d.x), ady = difference(a.y, d.y),
                     adz = difference(a.z, d.z);
  const Expansion<2> bdx = difference(b.x, d.x), bdy = difference(b.y, d.y),
                     bdz = difference(b.z, d.z);
  const Expansion<2> cdx = difference(c.x, d.x), cdy = difference(c.y, d.y),
                     cdz = difference(c.z, d.z);
  const Expansion<64> t1 = multiply(adz, cross_term(bdx, cdy, cdx, bdy));
  const Expansion<64> t2 = multiply(bdz, cross_term(cdx, ady, adx, cdy));
  const Expansion<64> t3 = multiply(cdz, cross_term(adx, bdy, bdx, ady));
  return sign(add(add(t1, t2), t3));
}

}  // namespace levelset
