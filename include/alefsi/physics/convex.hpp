#pragma once
/// \file physics/convex.hpp
/// Convex shapes given by their support functions, and the distance between two of them by
/// the Gilbert–Johnson–Keerthi algorithm (GJK), in 2D and 3D: the exact contact geometry of
/// non-circular bodies (issue 16), where a body's mesh surface is only a polygon/polyhedron.
///
/// A shape is a convex core plus a margin (a radius swept around it): a point plus r is a ball,
/// a segment plus r a capsule, a rectangle plus r a rounded rectangle. The core is known by its
/// support function s(d), a point of the core farthest along d (any d != 0). Shapes here are in
/// their body frame, centred at their centre of mass:
///
///   * `convex::Ball<D>`: radius r (core: the origin; margin r);
///   * `convex::Ellipsoid<D>`: semi-axes along the body axes (an ellipse in 2D):
///     s(d) = A^2 d / |A d|, A = diag(semi_axes);
///   * `convex::Capsule<D>`: the segment from -L e_x to L e_x swept by radius r;
///   * `convex::Polytope<D>`: the convex hull of vertices (a convex polygon in 2D), optionally
///     rounded by a margin.
///
/// `convex::Support<D>` holds any of them type-erased (`support_of(shape)`), and `placed()` moves
/// one to a world position and rotation. `convex::distance(A, B)` returns the signed distance
/// between the two shapes (margins included) and a nearest point on each.
///
/// GJK (Gilbert, Johnson and Keerthi 1988; the distance form of van den Bergen 1999, "A fast and
/// robust GJK implementation for collision detection of convex objects", J. Graphics Tools
/// 4(2)): the point v of the Minkowski difference A - B nearest the origin is approached through
/// simplices of support points w = s_A(-v) - s_B(v). Every step brackets the core distance:
/// v.w / |v| <= dist <= |v|. The loop stops when the bracket is below `tolerance` times |v|
/// (and an absolute floor 1e-14 times the shapes' size). For polytopes it terminates exactly;
/// for smooth cores (ellipsoids) it converges without terminating exactly, hence the tolerance.
/// The sub-problem, the point of a simplex (at most D + 1 points) nearest the origin, is solved
/// over its faces: the nearest point of each face's affine hull with positive barycentric
/// weights, the nearest of these (Johnson's criterion written as a search; at most 15 faces).
///
/// When the cores intersect, the signed distance is not computed: `distance` returns
/// -(margin_A + margin_B), an upper bound on it (<= 0), with both points at a common point of
/// the cores and `intersecting` set. Contact models floor the gap anyway.
///
///     const convex::Ellipsoid<2> e{{0.3, 0.1}};
///     const auto A = convex::placed<2>(convex::support_of<2>(e), {0, 0}, Eigen::Rotation2D<Real>(0.4).toRotationMatrix());
///     const auto B = convex::placed<2>(convex::support_of<2>(convex::Ball<2>{0.1}), {0.5, 0}, Mat<2>::Identity());
///     const convex::Distance<2> d = convex::distance<2>(A, B);  // d.distance, d.a, d.b
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi::convex {

/// A convex shape: the support function of its core and the radius swept around it.
template <class S, int D>
concept SupportShape = requires(const S& s, const Vec<D>& d) {
  { s.support(d) } -> std::convertible_to<Vec<D>>;
  { s.margin() } -> std::convertible_to<Real>;
};

/// A ball (a disk in 2D) of radius r about the origin.
template <int D>
struct Ball {
  Real radius = 1;
  Vec<D> support(const Vec<D>&) const { return Vec<D>::Zero(); }
  Real margin() const { return radius; }
  void validate(const std::string& who = "ball") const {
    ALEFSI_CHECK_ARG(radius > 0 && std::isfinite(radius), who + ".radius", "must be positive and finite, got ", radius);
  }
};

/// An ellipsoid (an ellipse in 2D) with these semi-axes along the body axes.
template <int D>
struct Ellipsoid {
  Vec<D> semi_axes = Vec<D>::Ones();
  Vec<D> support(const Vec<D>& d) const {
    const Vec<D> ad = semi_axes.cwiseProduct(d);
    const Real n = ad.norm();
    return n > 0 ? Vec<D>(semi_axes.cwiseProduct(ad) / n) : Vec<D>(Vec<D>::Zero());
  }
  Real margin() const { return 0; }
  void validate(const std::string& who = "ellipsoid") const {
    for (int i = 0; i < D; ++i)
      ALEFSI_CHECK_ARG(semi_axes[i] > 0 && std::isfinite(semi_axes[i]), who + ".semi_axes[" + std::to_string(i) + "]",
                       "must be positive and finite, got ", semi_axes[i]);
  }
};

/// A capsule: the segment from -half_length e_x to half_length e_x swept by `radius` (a
/// stadium in 2D, a spherocylinder in 3D).
template <int D>
struct Capsule {
  Real half_length = 1;
  Real radius = 0.5;
  Vec<D> support(const Vec<D>& d) const {
    Vec<D> p = Vec<D>::Zero();
    p[0] = d[0] >= 0 ? half_length : -half_length;
    return p;
  }
  Real margin() const { return radius; }
  void validate(const std::string& who = "capsule") const {
    ALEFSI_CHECK_ARG(half_length >= 0 && std::isfinite(half_length), who + ".half_length",
                     "must be >= 0 and finite, got ", half_length);
    ALEFSI_CHECK_ARG(radius > 0 && std::isfinite(radius), who + ".radius", "must be positive and finite, got ", radius);
  }
};

/// The convex hull of `vertices` (a convex polygon in 2D, a convex polyhedron in 3D), rounded
/// by `rounding` (0: sharp). Vertices inside the hull are allowed and never returned.
template <int D>
struct Polytope {
  std::vector<Vec<D>> vertices;
  Real rounding = 0;
  Vec<D> support(const Vec<D>& d) const {
    std::size_t best = 0;
    Real h = -std::numeric_limits<Real>::infinity();
    for (std::size_t i = 0; i < vertices.size(); ++i)
      if (const Real x = vertices[i].dot(d); x > h) h = x, best = i;
    return vertices.empty() ? Vec<D>(Vec<D>::Zero()) : vertices[best];
  }
  Real margin() const { return rounding; }
  void validate(const std::string& who = "polytope") const {
    ALEFSI_CHECK_ARG(vertices.size() >= std::size_t(D + 1), who + ".vertices", "a ", D == 2 ? "polygon" : "polyhedron",
                     " needs at least ", D + 1, " vertices, got ", vertices.size());
    for (std::size_t i = 0; i < vertices.size(); ++i)
      ALEFSI_CHECK_ARG(vertices[i].allFinite(), who + ".vertices", "vertex ", i, " is not finite");
    ALEFSI_CHECK_ARG(rounding >= 0 && std::isfinite(rounding), who + ".rounding", "must be >= 0 and finite, got ",
                     rounding);
    // full-dimensional: some D + 1 vertices span a simplex of positive measure
    Real scale = 0;
    for (const auto& v : vertices) scale = std::max(scale, (v - vertices[0]).norm());
    Mat<D> E = Mat<D>::Zero();
    int rank = 0;
    for (std::size_t i = 1; i < vertices.size() && rank < D; ++i) {
      Vec<D> e = vertices[i] - vertices[0];
      for (int k = 0; k < rank; ++k) e -= E.col(k).dot(e) * E.col(k);
      if (e.norm() > 1e-10 * scale) E.col(rank++) = e.normalized();
    }
    ALEFSI_CHECK_ARG(rank == D, who + ".vertices", "the vertices span no ", D == 2 ? "area" : "volume");
  }
};

/// Any shape, type-erased: its core's support function and its margin. Empty: no shape.
template <int D>
struct Support {
  std::function<Vec<D>(const Vec<D>&)> core;
  Real sweep = 0;
  Vec<D> support(const Vec<D>& d) const { return core(d); }
  Real margin() const { return sweep; }
  explicit operator bool() const { return bool(core); }
};

/// `shape` as a `Support` (validated; the shape is copied into it).
template <int D, SupportShape<D> S>
Support<D> support_of(const S& shape) {
  if constexpr (requires { shape.validate(); }) shape.validate();
  return {[shape](const Vec<D>& d) { return Vec<D>(shape.support(d)); }, Real(shape.margin())};
}

/// A body-frame shape placed in the world: x = centre + Q y for y in the shape, Q a rotation.
/// s_world(d) = centre + Q s(Q^T d).
template <int D, SupportShape<D> S>
Support<D> placed(const S& shape, const Vec<D>& centre, const Mat<D>& Q) {
  return {[shape, centre, Q](const Vec<D>& d) { return Vec<D>(centre + Q * shape.support(Vec<D>(Q.transpose() * d))); },
          Real(shape.margin())};
}

/// The result of `distance`.
template <int D>
struct Distance {
  Real distance = std::numeric_limits<Real>::infinity();  ///< signed (margins included); see file comment
  Vec<D> a = Vec<D>::Zero(), b = Vec<D>::Zero();          ///< nearest points on A and on B
  /// unit, from B's core towards A's (the outward normal of B at b, the inward of A at a, also
  /// when the margins overlap); 0 when the cores intersect
  Vec<D> normal = Vec<D>::Zero();
  int iterations = 0;
  bool intersecting = false;  ///< the cores intersect: `distance` is only an upper bound
  bool converged = true;      ///< false: stopped at the iteration limit (the bracket is wider)
};

namespace detail {

/// Support points of A - B with the points of A and B they come from.
template <int D>
struct Simplex {
  std::array<Vec<D>, D + 1> w, a, b;
  int n = 0;
};

/// The barycentric weights (into lam, at idx[0..K]) of the point of the affine hull of the
/// simplex points idx[0..K] nearest the origin: minimise |p0 + E mu|, (E^T E) mu = -E^T p0,
/// lambda_0 = 1 - sum mu. False if the face is degenerate or a weight is not positive.
template <int K, int D>
bool face_weights(const Simplex<D>& s, const std::array<int, D + 1>& idx, Real scale, std::array<Real, D + 1>& lam) {
  const Vec<D>& p0 = s.w[idx[0]];
  Eigen::Matrix<Real, D, K> E;
  for (int k = 0; k < K; ++k) E.col(k) = s.w[idx[k + 1]] - p0;
  const Eigen::Matrix<Real, K, K> G = E.transpose() * E;
  const Real det = G.determinant();
  if (!(std::abs(det) > 1e-24 * std::pow(scale, K))) return false;  // degenerate face
  const Eigen::Matrix<Real, K, 1> mu = G.inverse() * Eigen::Matrix<Real, K, 1>(-E.transpose() * p0);
  Real sum = 0;
  for (int k = 0; k < K; ++k) {
    if (!(mu[k] > 0)) return false;
    lam[idx[k + 1]] = mu[k], sum += mu[k];
  }
  lam[idx[0]] = 1 - sum;
  return lam[idx[0]] > 0;
}

/// The point of conv(W) nearest the origin, W the simplex's n points: over every face (subset),
/// the nearest point of its affine hull if its barycentric weights are all positive; the
/// nearest of those. Returns the weights (0 off the chosen face) and whether the origin is
/// inside a full-dimensional simplex.
template <int D>
std::pair<std::array<Real, D + 1>, bool> nearest_in_simplex(const Simplex<D>& s) {
  std::array<Real, D + 1> best{};
  Real best_d = std::numeric_limits<Real>::infinity();
  bool inside = false;
  Real scale = 0;
  for (int i = 0; i < s.n; ++i) scale = std::max(scale, s.w[i].squaredNorm());
  for (unsigned mask = 1; mask < (1u << s.n); ++mask) {
    std::array<int, D + 1> idx{};
    int m = 0;
    for (int i = 0; i < s.n; ++i)
      if (mask & (1u << i)) idx[m++] = i;
    std::array<Real, D + 1> lam{};
    bool positive = true;
    if (m == 1) lam[idx[0]] = 1;
    else if (m == 2) positive = face_weights<1, D>(s, idx, scale, lam);
    else if (m == 3) positive = face_weights<2, D>(s, idx, scale, lam);
    else if constexpr (D == 3) positive = face_weights<3, D>(s, idx, scale, lam);
    if (!positive) continue;
    Vec<D> v = Vec<D>::Zero();
    for (int i = 0; i < s.n; ++i) v += lam[i] * s.w[i];
    const Real d = m == D + 1 ? Real(0) : v.squaredNorm();
    if (d < best_d) best_d = d, best = lam, inside = m == D + 1;
  }
  return {best, inside};
}

}  // namespace detail

/// The signed distance between shapes A and B (margins included), a nearest point on each,
/// by GJK to a relative `tolerance` on the core distance (file comment).
template <int D, SupportShape<D> SA, SupportShape<D> SB>
Distance<D> distance(const SA& A, const SB& B, Real tolerance = 1e-12, int max_iterations = 200) {
  detail::Simplex<D> s;
  auto support = [&](const Vec<D>& d, int i) {
    s.a[i] = A.support(Vec<D>(-d));
    s.b[i] = B.support(d);
    s.w[i] = s.a[i] - s.b[i];
  };
  Distance<D> out;
  const Real ma = A.margin(), mb = B.margin();
  support(Vec<D>::Unit(0), 0);  // a first point of A - B: v = w
  s.n = 1;
  Vec<D> v = s.w[0], pa = s.a[0], pb = s.b[0];
  Real scale2 = s.w[0].squaredNorm();
  out.converged = false;
  for (out.iterations = 1;; ++out.iterations) {
    if (out.iterations > max_iterations) {
      out.iterations = max_iterations;
      break;
    }
    const Real vv = v.squaredNorm();
    if (vv <= 1e-28 * std::max(scale2, Real(1e-300))) {  // the cores touch
      out.intersecting = true, out.converged = true;
      break;
    }
    // w = s_{A-B}(-v): support of A along -v, of B along v
    const int slot = s.n;
    if (slot > D) break;  // cannot happen: a full simplex either holds the origin or is reduced
    support(v, slot);
    const Vec<D> w = s.w[slot];
    scale2 = std::max(scale2, w.squaredNorm());
    // the bracket v.w / |v| <= dist <= |v|, in squares: vv - v.w <= tol |v|^2
    if (vv - v.dot(w) <= std::max(tolerance * vv, 1e-28 * scale2)) {
      out.converged = true;
      break;
    }
    bool repeated = false;
    for (int i = 0; i < slot; ++i) repeated |= (s.w[i] - w).squaredNorm() <= 1e-30 * scale2;
    if (repeated) {  // no new support point: v is as near as round-off allows
      out.converged = true;
      break;
    }
    s.n = slot + 1;
    const auto [lam, inside] = detail::nearest_in_simplex<D>(s);
    detail::Simplex<D> kept;
    Vec<D> nv = Vec<D>::Zero(), na = Vec<D>::Zero(), nb = Vec<D>::Zero();
    for (int i = 0; i < s.n; ++i) {
      if (lam[i] <= 0) continue;
      nv += lam[i] * s.w[i], na += lam[i] * s.a[i], nb += lam[i] * s.b[i];
      kept.w[kept.n] = s.w[i], kept.a[kept.n] = s.a[i], kept.b[kept.n] = s.b[i], ++kept.n;
    }
    if (inside) {
      out.intersecting = true, out.converged = true;
      pa = na, pb = na;
      v = Vec<D>::Zero();
      break;
    }
    if (nv.squaredNorm() >= vv) {  // no progress (round-off): keep the previous v
      out.converged = true;
      break;
    }
    s = kept, v = nv, pa = na, pb = nb;
  }
  if (out.intersecting) {
    out.distance = -(ma + mb);
    out.a = out.b = pa;
    return out;
  }
  const Real dn = v.norm();  // v = pa - pb: from B's core towards A's
  const Vec<D> u = v / dn;
  out.normal = u;
  out.distance = dn - ma - mb;
  out.a = pa - ma * u;
  out.b = pb + mb * u;
  return out;
}

}  // namespace alefsi::convex
