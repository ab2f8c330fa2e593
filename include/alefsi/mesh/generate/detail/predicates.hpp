#pragma once
/// \file mesh/generate/detail/predicates.hpp
/// Robust 2D geometric predicates: `orient2d` and `incircle`.
///
/// Each predicate first evaluates the determinant in double precision and accepts the sign
/// when it exceeds Shewchuk's static forward-error bound (J. R. Shewchuk, "Adaptive
/// precision floating-point arithmetic and fast robust geometric predicates", 1997).
/// Otherwise it re-evaluates the determinant EXACTLY with floating-point expansions
/// (error-free two-sum / two-product, zero-eliminating expansion sums and scalings), so the
/// returned sign is always the sign of the exact determinant of the given doubles.
/// (This is the filter + exact stage of Shewchuk's scheme, without his intermediate
/// adaptive stages B and C; the exact stage is only reached for (nearly) degenerate input.)
///
/// Requirements: IEEE-754 double arithmetic with round-to-nearest-even, no `-ffast-math`
/// (which would break the error-free transformations), finite input without overflow or
/// underflow in the products. FMA contraction by the compiler is harmless: the products in
/// the exact stage use `std::fma` (or Dekker splitting without hardware FMA) explicitly, and
/// contraction only reduces the rounding error of the filter stage.
#include <algorithm>
#include <cmath>

namespace alefsi::detail {

/// A point in the plane (plain struct: the mesher's hot loops do not need Eigen).
struct XY {
  double x, y;
};

namespace expansion {

/// x + y == a + b exactly, x = fl(a + b).
inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

/// x + y == a - b exactly, x = fl(a - b).
inline void two_diff(double a, double b, double& x, double& y) {
  x = a - b;
  const double bv = a - x;
  const double av = x + bv;
  y = (a - av) + (bv - b);
}

/// x + y == a * b exactly, x = fl(a * b).
inline void two_prod(double a, double b, double& x, double& y) {
  x = a * b;
#ifdef FP_FAST_FMA
  y = std::fma(a, b, -x);
#else
  // Dekker's splitting (exact without hardware FMA; nothing here can be contracted)
  constexpr double splitter = 134217729.0;  // 2^27 + 1
  double c = splitter * a;
  const double ahi = c - (c - a), alo = a - ahi;
  c = splitter * b;
  const double bhi = c - (c - b), blo = b - bhi;
  const double err1 = x - ahi * bhi, err2 = err1 - alo * bhi, err3 = err2 - ahi * blo;
  y = alo * blo - err3;
#endif
}

// Expansions: arrays of nonoverlapping doubles in increasing magnitude, no zero entries;
// the empty expansion (length 0) is zero. The value is the exact sum of the components.

/// a - b as an expansion of length <= 2.
inline int diff(double a, double b, double* h) {
  double x, y;
  two_diff(a, b, x, y);
  int k = 0;
  if (y != 0) h[k++] = y;
  if (x != 0) h[k++] = x;
  return k;
}

/// h = e + f (Shewchuk's fast expansion sum with zero elimination); h holds elen + flen.
inline int sum(int elen, const double* e, int flen, const double* f, double* h) {
  int i = 0, j = 0, k = 0;
  auto next = [&]() {
    if (j >= flen || (i < elen && std::abs(e[i]) < std::abs(f[j]))) return e[i++];
    return f[j++];
  };
  const int n = elen + flen;
  if (n == 0) return 0;
  double q = next();
  for (int c = 1; c < n; ++c) {
    const double g = next();
    double hh;
    two_sum(q, g, q, hh);
    if (hh != 0) h[k++] = hh;
  }
  if (q != 0) h[k++] = q;
  return k;
}

/// h = b * e; h holds 2 * elen.
inline int scale(int elen, const double* e, double b, double* h) {
  if (elen == 0 || b == 0) return 0;
  int k = 0;
  double q, hh;
  two_prod(e[0], b, q, hh);
  if (hh != 0) h[k++] = hh;
  for (int i = 1; i < elen; ++i) {
    double p1, p0, s;
    two_prod(e[i], b, p1, p0);
    two_sum(q, p0, s, hh);
    if (hh != 0) h[k++] = hh;
    two_sum(p1, s, q, hh);
    if (hh != 0) h[k++] = hh;
  }
  if (q != 0) h[k++] = q;
  return k;
}

/// h = e * f; h holds 2 * elen * flen, t1 holds 2 * elen, t2 holds 2 * elen * flen.
inline int mul(int elen, const double* e, int flen, const double* f, double* h, double* t1, double* t2) {
  int hl = 0;
  for (int j = 0; j < flen; ++j) {
    const int tl = scale(elen, e, f[j], t1);
    const int nl = sum(hl, h, tl, t1, t2);
    std::copy(t2, t2 + nl, h);
    hl = nl;
  }
  return hl;
}

inline void negate(int elen, double* e) {
  for (int i = 0; i < elen; ++i) e[i] = -e[i];
}

/// Value with the sign of the expansion (its largest component).
inline double sign_value(int elen, const double* e) { return elen ? e[elen - 1] : 0.0; }

}  // namespace expansion

/// Exact orientation: > 0 if a, b, c are counterclockwise, < 0 clockwise, 0 collinear.
inline double orient2d_exact(const XY& a, const XY& b, const XY& c) {
  using namespace expansion;
  double acx[2], acy[2], bcx[2], bcy[2];
  const int lacx = diff(a.x, c.x, acx), lacy = diff(a.y, c.y, acy);
  const int lbcx = diff(b.x, c.x, bcx), lbcy = diff(b.y, c.y, bcy);
  double p1[8], p2[8], t1[4], t2[8], d[16];
  const int l1 = mul(lacx, acx, lbcy, bcy, p1, t1, t2);
  const int l2 = mul(lacy, acy, lbcx, bcx, p2, t1, t2);
  negate(l2, p2);
  const int ld = sum(l1, p1, l2, p2, d);
  return sign_value(ld, d);
}

/// Robust orientation: the sign is always that of the exact determinant
/// | ax-cx  ay-cy ; bx-cx  by-cy |; the magnitude is approximate (twice the signed area).
inline double orient2d(const XY& a, const XY& b, const XY& c) {
  constexpr double eps = 1.1102230246251565e-16;  // 2^-53
  constexpr double errbound = (3.0 + 16.0 * eps) * eps;
  const double detleft = (a.x - c.x) * (b.y - c.y);
  const double detright = (a.y - c.y) * (b.x - c.x);
  const double det = detleft - detright;
  double detsum;
  if (detleft > 0) {
    if (detright <= 0) return det;
    detsum = detleft + detright;
  } else if (detleft < 0) {
    if (detright >= 0) return det;
    detsum = -detleft - detright;
  } else {
    return det;
  }
  if (det >= errbound * detsum || -det >= errbound * detsum) return det;
  return orient2d_exact(a, b, c);
}

/// Exact incircle: > 0 if d lies inside the circle through the counterclockwise a, b, c.
inline double incircle_exact(const XY& a, const XY& b, const XY& c, const XY& d) {
  using namespace expansion;
  double adx[2], ady[2], bdx[2], bdy[2], cdx[2], cdy[2];
  const int ladx = diff(a.x, d.x, adx), lady = diff(a.y, d.y, ady);
  const int lbdx = diff(b.x, d.x, bdx), lbdy = diff(b.y, d.y, bdy);
  const int lcdx = diff(c.x, d.x, cdx), lcdy = diff(c.y, d.y, cdy);
  double t1[32], t2[512];
  // 2x2 minors (<= 16 components each)
  auto minor = [&](int lpx, const double* px, int lpy, const double* py, int lqx, const double* qx, int lqy,
                   const double* qy, double* out) {
    double u[8], v[8];
    const int lu = mul(lpx, px, lqy, qy, u, t1, t2);
    const int lv = mul(lqx, qx, lpy, py, v, t1, t2);
    negate(lv, v);
    return sum(lu, u, lv, v, out);
  };
  auto lift = [&](int lx, const double* x, int ly, const double* y, double* out) {
    double u[8], v[8];
    const int lu = mul(lx, x, lx, x, u, t1, t2);
    const int lv = mul(ly, y, ly, y, v, t1, t2);
    return sum(lu, u, lv, v, out);
  };
  double bc[16], ca[16], ab[16], al[16], bl[16], cl[16];
  const int lbc = minor(lbdx, bdx, lbdy, bdy, lcdx, cdx, lcdy, cdy, bc);
  const int lca = minor(lcdx, cdx, lcdy, cdy, ladx, adx, lady, ady, ca);
  const int lab = minor(ladx, adx, lady, ady, lbdx, bdx, lbdy, bdy, ab);
  const int lal = lift(ladx, adx, lady, ady, al);
  const int lbl = lift(lbdx, bdx, lbdy, bdy, bl);
  const int lcl = lift(lcdx, cdx, lcdy, cdy, cl);
  double ta[512], tb[512], tc[512], s1[1024], s2[1536];
  const int la = mul(lal, al, lbc, bc, ta, t1, t2);
  const int lb = mul(lbl, bl, lca, ca, tb, t1, t2);
  const int lc = mul(lcl, cl, lab, ab, tc, t1, t2);
  const int l1 = sum(la, ta, lb, tb, s1);
  const int l2 = sum(l1, s1, lc, tc, s2);
  return sign_value(l2, s2);
}

/// Robust incircle: the sign is that of the exact determinant (> 0: d strictly inside the
/// circumcircle of the counterclockwise triangle a, b, c; 0: cocircular).
inline double incircle(const XY& a, const XY& b, const XY& c, const XY& d) {
  constexpr double eps = 1.1102230246251565e-16;
  constexpr double errbound = (10.0 + 96.0 * eps) * eps;
  const double adx = a.x - d.x, bdx = b.x - d.x, cdx = c.x - d.x;
  const double ady = a.y - d.y, bdy = b.y - d.y, cdy = c.y - d.y;
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double alift = adx * adx + ady * ady;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double blift = bdx * bdx + bdy * bdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double clift = cdx * cdx + cdy * cdy;
  const double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
  const double permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * alift +
                           (std::abs(cdxady) + std::abs(adxcdy)) * blift +
                           (std::abs(adxbdy) + std::abs(bdxady)) * clift;
  const double bound = errbound * permanent;
  if (det > bound || -det > bound) return det;
  return incircle_exact(a, b, c, d);
}

}  // namespace alefsi::detail
