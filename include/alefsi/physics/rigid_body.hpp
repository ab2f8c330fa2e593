#pragma once
/// \file physics/rigid_body.hpp
/// Rigid bodies in 2D (3 DOF) and 3D (6 DOF): state, the rigid-velocity operator H of
/// eq. (8)-(9), the body's place in the monolithic system, and `RigidBodyTraits<D>`: what
/// differs between 2D and 3D bodies (number of rigid DOFs, rows of H, the inertia term and its
/// Jacobian, the orientation and its update), read by sim/ale_flow.hpp.
///
/// A body is a hole of the fluid mesh whose surface facets carry `tag`. Its velocity is
/// Z = (V1, V2, w3): the velocity of a surface point x is H(x) Z + u_s(x) with
///     H(x) = [[1, 0, -(y - yg)], [0, 1, (x - xg)]]
/// and u_s the slip velocity (zero unless given). Body surface nodes follow the exact rigid
/// motion x = x_g + R(theta - theta_0) (x_0 - x_g0), so a body keeps its shape.
/// A *free* body's Z are unknowns of the flow system: its rows are eq. (11),
///     M (delta_l Z) / dt - M g + (fluid terms through the columns of H) = 0,
/// with M = diag(m, m, I). A massless free body (m = 0 and I = 0, e.g. `massless_sphere`) has
/// no inertia rows: its rows are the force and torque balance, what a squirmer or a phoretic
/// particle satisfies in Stokes flow (the system stays nonsingular as long as the fluid
/// problem is, e.g. with a Dirichlet wall). A *prescribed* body moves with Z(t) given by the user; its surface
/// velocities are then Dirichlet data.
///
///     RigidBody2D disk{.tag = 5, .mass = pi * r * r * rho_s, .inertia = 0.5 * mass * r * r,
///                      .centre = {1.0, 4.5}};
///     flow.add_body(disk);
///
/// In 3D (`RigidBody3D`), Z = (V, w) in world axes, H(x) = [I | -[x - x_g]_x], the orientation
/// is a unit quaternion q (body frame -> world), and the rotation rows are the Newton-Euler
/// equation in world axes, I_w (delta_l w) / dt + w x (I_w w) with I_w = R(q) I_body R(q)^T.
///
///     auto ball = sphere_body(7, Vec<3>(0, 0, 0), 0.5, 1.0);   // m = rho 4/3 pi r^3, I = 2/5 m r^2
///     flow3d.add_body(ball);
#include <array>
#include <cmath>
#include <concepts>
#include <functional>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/fem/quadrature.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/physics/convex.hpp"

namespace alefsi {

struct RigidBody2D {
  int tag = 0;            ///< boundary tag of the body's surface
  Real mass = 0;          ///< per unit length
  Real inertia = 0;       ///< I_33 about the centre of mass, per unit length
  Vec<2> centre = Vec<2>::Zero();  ///< centre of mass at t0
  Real angle = 0;         ///< orientation at t0
  Vec<3> velocity = Vec<3>::Zero();  ///< Z at t0: (V1, V2, w3)
  /// If set, the body is driven: Z(t) is given and the body has no unknowns.
  std::function<Vec<3>(Real t)> prescribed;
  /// A constant external force and torque (F1, F2, T3) on a free body (besides gravity).
  Vec<3> external_load = Vec<3>::Zero();
  /// Slip velocity u_s(r) in the body frame (r = x - x_g rotated back to the initial
  /// orientation); the result is rotated with the body. Empty: no slip.
  std::function<Vec<2>(const Vec<2>& r)> slip;
  /// > 0: the body is a disk of this radius. Its surface is then kept on the exact circle
  /// when the mesh is adapted, and collision distances are exact.
  Real radius = 0;
  /// The exact convex shape (physics/convex.hpp) in the body frame: centred at the centre of
  /// mass, its axes turned by `angle` at t0 (so an ellipse with semi-axes (a, b) and this
  /// `angle` is the mesher's Ellipse{centre, a, b, angle}). Set: collision distances and contact
  /// points are the shape's (GJK), not the mesh surface's facets. Empty: the facets'.
  convex::Support<2> shape;
  /// > 0: the body's exact area, for exact buoyancy (Buoyancy::exact) of a body that is not a
  /// disk; its centre of buoyancy is taken at the centre of mass (a body of uniform density).
  Real volume = 0;

  bool free() const { return !prescribed; }

  void validate(std::size_t index) const {
    const std::string who = "bodies[" + std::to_string(index) + "]";
    if (free()) {
      ALEFSI_CHECK_ARG(mass >= 0 && std::isfinite(mass), who + ".mass",
                       "must be positive and finite (or 0 for a massless, force-free body), got ", mass);
      if (mass == 0)
        ALEFSI_CHECK_ARG(inertia == 0, who + ".inertia", "a massless (force-free) body has no inertia: must be 0, got ",
                         inertia);
      else
        ALEFSI_CHECK_ARG(inertia > 0 && std::isfinite(inertia), who + ".inertia", "must be positive and finite, got ",
                         inertia);
    }
    ALEFSI_CHECK_ARG(centre.allFinite() && velocity.allFinite(), who, "non-finite initial state");
    ALEFSI_CHECK_ARG(radius >= 0 && std::isfinite(radius), who + ".radius", "must be >= 0 and finite, got ", radius);
    ALEFSI_CHECK_ARG(volume >= 0 && std::isfinite(volume), who + ".volume", "must be >= 0 and finite, got ", volume);
  }
};

/// A free disk of radius r and density rho_s (per unit length: m = rho_s pi r^2, I = m r^2 / 2).
inline RigidBody2D disk_body(int tag, const Vec<2>& centre, Real radius, Real density) {
  ALEFSI_CHECK_ARG(radius > 0 && std::isfinite(radius), "radius", "must be positive and finite, got ", radius);
  ALEFSI_CHECK_ARG(density > 0 && std::isfinite(density), "density", "must be positive and finite, got ", density);
  RigidBody2D b;
  b.tag = tag;
  b.mass = density * std::numbers::pi * radius * radius;
  b.inertia = 0.5 * b.mass * radius * radius;
  b.centre = centre;
  b.radius = radius;
  return b;
}

namespace detail {
/// u_s = Q - (Q.n) n with n = r / |r|; with `half` != 0 only where r.half > 0, zero where
/// r.half < 0 and half the value on the dividing set |r.half| <= 1e-9 |r| |half| (see
/// tangential_slip).
template <int D>
Vec<D> tangential_slip_value(const Vec<D>& Q, const Vec<D>& half, const Vec<D>& r) {
  const Vec<D> n = r.normalized();
  const Vec<D> u = Q - Q.dot(n) * n;
  if (half.squaredNorm() == 0) return u;
  const Real side = r.dot(half), tol = 1e-9 * r.norm() * half.norm();
  if (side > tol) return u;
  if (side < -tol) return Vec<D>::Zero();
  return 0.5 * u;  // on the dividing line (2D: two points) / circle (3D)
}
}  // namespace detail

/// Slip velocities for RigidBody2D::slip and RigidBody3D::slip (body frame; n = r / |r|, exact
/// for disks and spheres centred at the centre of mass).
///
/// `tangential_slip(Q)`: the tangential projection of a constant field Q, u_s = Q - (Q.n) n
/// (the paper's sections 6.1 and 6.4); with `half` set, only on the half surface r.half > 0
/// (zero where r.half < 0). On the dividing set r.half = 0 (two points of a disk, the circle
/// of a sphere; |r.half| <= 1e-9 |r| |half|) the value is half the one-sided one, the mean of
/// the two sides: a mesh whose edges follow that circle then carries, at its nodes there, the
/// value whose consistent surface quadrature (P2: the edge midpoints carry the weight) equals
/// the mean of the two one-sided interpolants, so the O(h) error of a one-sided convention
/// cancels (exactly on a mesh mirror-symmetric about the dividing plane; docs/theory.md).
/// On a disk, Q = -B1 e gives the squirmer mode B1 sin(theta) e_theta (theta from e), which
/// swims along +e at B1 / 2 in an unbounded 2D fluid (Blake 1971). On a sphere, Q = -B1 e is
/// the mode B1 sin(theta) e_theta, swimming at 2 B1 / 3; with a half space, for any Q and unit
/// `half` e, the unbounded sphere translates at V = -<u_s> = -Q / 3 and turns at
/// w = -3 / (8 pi R^3) int n x u_s dS = -3 / (8 R) e x Q (Fair & Anderson 1989; paper 6.1).
///
///     squirmer.slip = tangential_slip(Vec<3>(-1, 0, 0), Vec<3>(1, 0, 0));  // V = (1/3, 0, 0)
inline std::function<Vec<2>(const Vec<2>&)> tangential_slip(const Vec<2>& Q, const Vec<2>& half = Vec<2>::Zero()) {
  ALEFSI_CHECK_ARG(Q.allFinite(), "Q", "must be finite");
  ALEFSI_CHECK_ARG(half.allFinite(), "half", "must be finite");
  return [Q, half](const Vec<2>& r) -> Vec<2> { return detail::tangential_slip_value<2>(Q, half, r); };
}
/// 3D overload of tangential_slip (constrained so that a 2-vector expression picks the 2D one).
template <class DerivedQ>
  requires(DerivedQ::SizeAtCompileTime == 3)
std::function<Vec<3>(const Vec<3>&)> tangential_slip(const Eigen::MatrixBase<DerivedQ>& Qexpr,
                                                     const Vec<3>& half = Vec<3>::Zero()) {
  const Vec<3> Q = Qexpr;
  ALEFSI_CHECK_ARG(Q.allFinite(), "Q", "must be finite");
  ALEFSI_CHECK_ARG(half.allFinite(), "half", "must be finite");
  return [Q, half](const Vec<3>& r) -> Vec<3> { return detail::tangential_slip_value<3>(Q, half, r); };
}
/// The squirmer modes u_s = (B1 sin(theta) + B2 sin(theta) cos(theta)) e_theta, theta the angle
/// of r from the unit swimming axis e (body frame), e_theta its counter-clockwise tangent.
/// 2D unbounded: swims along e at U = B1 / 2; B2 (pusher < 0, puller > 0) adds no speed.
inline std::function<Vec<2>(const Vec<2>&)> squirmer_slip(Real B1, Real B2, const Vec<2>& e = Vec<2>(1, 0)) {
  ALEFSI_CHECK_ARG(std::isfinite(B1) && std::isfinite(B2), "B1", "modes must be finite");
  ALEFSI_CHECK_ARG(std::abs(e.norm() - 1) < 1e-12, "e", "swimming axis must be a unit vector");
  return [=](const Vec<2>& r) -> Vec<2> {
    const Vec<2> n = r.normalized(), ep(-e[1], e[0]);
    const Real c = n.dot(e), s = n.dot(ep);
    const Vec<2> et = -s * e + c * ep;
    return (B1 * s + B2 * s * c) * et;
  };
}

/// 3D: u_s = (B1 + B2 cos(theta)) ((e.n) n - e), theta the angle of n = r / |r| from the unit
/// swimming axis e (sin(theta) e_theta = (e.n) n - e). Unbounded: swims along e at
/// U = 2 B1 / 3 (Blake 1971); B2 (pusher < 0, puller > 0) adds no speed.
inline std::function<Vec<3>(const Vec<3>&)> squirmer_slip(Real B1, Real B2, const Vec<3>& e) {
  ALEFSI_CHECK_ARG(std::isfinite(B1) && std::isfinite(B2), "B1", "modes must be finite");
  ALEFSI_CHECK_ARG(std::abs(e.norm() - 1) < 1e-12, "e", "swimming axis must be a unit vector");
  return [=](const Vec<3>& r) -> Vec<3> {
    const Vec<3> n = r.normalized();
    const Real c = n.dot(e);
    return (B1 + B2 * c) * (c * n - e);
  };
}

/// Rows of H(x) for a point at offset r = x - x_g: u_c = sum_C H(c, C) Z_C.
inline std::array<Vec<3>, 2> rigid_rows(const Vec<2>& r) {
  return {Vec<3>(1.0, 0.0, -r[1]), Vec<3>(0.0, 1.0, r[0])};
}

inline Vec<2> rotate(const Vec<2>& v, Real angle) {
  const Real c = std::cos(angle), s = std::sin(angle);
  return {c * v[0] - s * v[1], s * v[0] + c * v[1]};
}

/// Rigid velocity V + w x r.
inline Vec<2> rigid_velocity(const Vec<3>& Z, const Vec<2>& r) { return {Z[0] - Z[2] * r[1], Z[1] + Z[2] * r[0]}; }

/// A rigid body in 3D. The velocity of a surface point x (offset r = x - x_g) is
///     u = V + w x r + R(q) u_s(R(q)^T r),
/// with Z = (V, w) in world axes and R(q) the rotation of the unit quaternion q, which maps the
/// body frame (where `inertia` and `slip` are given) to world axes.
struct RigidBody3D {
  int tag = 0;                      ///< boundary tag of the body's surface
  Real mass = 0;                    ///< m
  Mat<3> inertia = Mat<3>::Zero();  ///< inertia tensor about the centre of mass, body frame (SPD)
  Vec<3> centre = Vec<3>::Zero();   ///< centre of mass at t0
  Eigen::Quaternion<Real> orientation = Eigen::Quaternion<Real>::Identity();  ///< q at t0 (unit)
  Vec<6> velocity = Vec<6>::Zero();  ///< Z at t0: (V1, V2, V3, w1, w2, w3), world axes
  /// If set, the body is driven: Z(t) is given and the body has no unknowns.
  std::function<Vec<6>(Real t)> prescribed;
  /// A constant external force and torque (F1, F2, F3, T1, T2, T3), world axes, on a free body
  /// (besides gravity; the torque is about the centre of mass).
  Vec<6> external_load = Vec<6>::Zero();
  /// Slip velocity u_s(r) in the body frame (r in body axes); the result is rotated with the
  /// body. Empty: no slip.
  std::function<Vec<3>(const Vec<3>& r)> slip;
  /// > 0: the body is a sphere of this radius (informative; surface nodes are checked against it).
  Real radius = 0;
  /// The exact convex shape (physics/convex.hpp) in the body frame (the frame `orientation`
  /// turns to the world), centred at the centre of mass. Set: collision distances and contact
  /// points are the shape's (GJK), not the mesh surface's facets. Empty: the facets'.
  convex::Support<3> shape;
  /// > 0: the body's exact volume, for exact buoyancy (Buoyancy::exact) of a body that is not a
  /// sphere; its centre of buoyancy is taken at the centre of mass (a body of uniform density).
  Real volume = 0;

  bool free() const { return !prescribed; }

  void validate(std::size_t index) const {
    const std::string who = "bodies[" + std::to_string(index) + "]";
    if (free() && mass == 0) {
      ALEFSI_CHECK_ARG(inertia.isZero(0), who + ".inertia", "a massless (force-free) body has no inertia: must be 0");
    } else if (free()) {
      ALEFSI_CHECK_ARG(mass > 0 && std::isfinite(mass), who + ".mass",
                       "must be positive and finite (or 0 for a massless, force-free body), got ", mass);
      ALEFSI_CHECK_ARG(inertia.allFinite() && (inertia - inertia.transpose()).norm() <= 1e-12 * inertia.norm(),
                       who + ".inertia", "must be a finite symmetric 3x3 tensor");
      const Eigen::SelfAdjointEigenSolver<Mat<3>> es(inertia, Eigen::EigenvaluesOnly);
      ALEFSI_CHECK_ARG(es.eigenvalues().minCoeff() > 0, who + ".inertia",
                       "must be positive definite, smallest eigenvalue ", es.eigenvalues().minCoeff());
    }
    ALEFSI_CHECK_ARG(orientation.coeffs().allFinite() && std::abs(orientation.norm() - 1) <= 1e-12,
                     who + ".orientation", "must be a unit quaternion, |q| = ", orientation.norm());
    ALEFSI_CHECK_ARG(centre.allFinite() && velocity.allFinite(), who, "non-finite initial state");
    ALEFSI_CHECK_ARG(external_load.allFinite(), who + ".external_load", "must be finite");
    ALEFSI_CHECK_ARG(radius >= 0 && std::isfinite(radius), who + ".radius", "must be >= 0 and finite, got ", radius);
    ALEFSI_CHECK_ARG(volume >= 0 && std::isfinite(volume), who + ".volume", "must be >= 0 and finite, got ", volume);
  }
};

/// A free sphere of radius r and density rho_s: m = rho_s 4/3 pi r^3, I = 2/5 m r^2 Id.
inline RigidBody3D sphere_body(int tag, const Vec<3>& centre, Real radius, Real density) {
  ALEFSI_CHECK_ARG(radius > 0 && std::isfinite(radius), "radius", "must be positive and finite, got ", radius);
  ALEFSI_CHECK_ARG(density > 0 && std::isfinite(density), "density", "must be positive and finite, got ", density);
  RigidBody3D b;
  b.tag = tag;
  b.mass = density * 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  b.inertia = 0.4 * b.mass * radius * radius * Mat<3>::Identity();
  b.centre = centre;
  b.radius = radius;
  return b;
}

/// A free, massless sphere (m = 0, I = 0): its rows are the pure force and torque balance of
/// the fluid on it (plus any external load), as for a phoretic particle or a squirmer in
/// Stokes flow (paper 6.1); see RigidBody3D::validate.
inline RigidBody3D massless_sphere(int tag, const Vec<3>& centre, Real radius) {
  ALEFSI_CHECK_ARG(radius > 0 && std::isfinite(radius), "radius", "must be positive and finite, got ", radius);
  RigidBody3D b;
  b.tag = tag;
  b.centre = centre;
  b.radius = radius;
  return b;
}

/// The flux of the interpolant (velocity degree 1 or 2) of a field f through a body's polygonal
/// surface: `facets` are its facets' corners as offsets from the centre (any frame, f in the same
/// one), oriented outwards (away from the centre). 3D: a flat triangle's flux is |f| / 3 times
/// the sum of f.n over its edge midpoints (degree 2: the corner weights vanish) or its corners
/// (degree 1); 2D: an edge's is Simpson's rule (degree 2) or the trapezoidal rule (degree 1).
template <int D, class F>
Real surface_flux(const std::vector<std::array<Vec<D>, D>>& facets, const F& f, int velocity_degree) {
  Real phi = 0;
  for (const auto& x : facets) {
    Vec<D> n;  // outward, |n| = the facet's measure
    if constexpr (D == 2) n = Vec<2>(x[1][1] - x[0][1], x[0][0] - x[1][0]);
    else n = 0.5 * (x[1] - x[0]).cross(x[2] - x[0]);
    Vec<D> sum = Vec<D>::Zero();
    for (const auto& p : x) sum += p;
    if (n.dot(sum) < 0) n = -n;
    if constexpr (D == 2) {
      phi += velocity_degree == 2 ? n.dot(f(x[0]) + 4 * f(Vec<2>(0.5 * (x[0] + x[1]))) + f(x[1])) / 6
                                  : n.dot(f(x[0]) + f(x[1])) / 2;
    } else {
      for (int i = 0; i < 3; ++i)
        phi += n.dot(velocity_degree == 2 ? f(Vec<3>(0.5 * (x[i] + x[(i + 1) % 3]))) : f(x[i])) / 3;
    }
  }
  return phi;
}

/// The same flux through a surface of curved facets (isoparametric P2: velocity degree 2 on
/// cells with quadratic geometry, fem/geometry.hpp). A facet is its D corners, then its edge
/// points: 2D, an edge's two ends and its point; 3D, a triangle's corners x_0, x_1, x_2 and the
/// points of its edges 01, 12, 20. The facet is the P2 map of its nodes and the interpolant of
/// f takes f's values there, so the flux is the integral over the reference facet of
/// f_h . (dx/ds) rotated (2D) or f_h . (dx/ds_1 x dx/ds_2) (3D): a polynomial of degree 3 (2D)
/// or 4 (3D), integrated exactly. This is the flux the continuity equations of the curved cells
/// sum to (the divergence theorem on the mapped cells, which their rule integrates exactly).
/// With every edge point at its edge's midpoint it is `surface_flux` at degree 2. Oriented as
/// `surface_flux`: away from the centre, judged on the corners.
template <int D, class F>
Real curved_surface_flux(const std::vector<std::array<Vec<D>, D*(D + 1) / 2>>& facets, const F& f) {
  static_assert(D == 2 || D == 3, "D must be 2 or 3");
  constexpr int n = D * (D + 1) / 2;  // P2 nodes of a facet
  const auto& rule = simplex_quadrature<D - 1>(4);
  Real phi = 0;
  std::array<Vec<D>, n> fx;
  for (const auto& x : facets) {
    Vec<D> straight;  // the corners' normal: only its side of the facet is used
    if constexpr (D == 2) straight = Vec<2>(x[1][1] - x[0][1], x[0][0] - x[1][0]);
    else straight = (x[1] - x[0]).cross(x[2] - x[0]);
    Vec<D> sum = Vec<D>::Zero();
    for (int i = 0; i < D; ++i) sum += x[std::size_t(i)];
    const Real side = straight.dot(sum) < 0 ? -1 : 1;
    for (int a = 0; a < n; ++a) fx[std::size_t(a)] = f(x[std::size_t(a)]);
    for (int q = 0; q < rule.size(); ++q) {
      const Vec<D - 1>& s = rule.points[std::size_t(q)];
      std::array<Real, n> N;
      std::array<Vec<D - 1>, n> dN;  // d N / d s
      if constexpr (D == 2) {
        const Real l0 = 1 - s[0], l1 = s[0];
        N = {l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), 4 * l0 * l1};
        dN = {Vec<1>(1 - 4 * l0), Vec<1>(4 * l1 - 1), Vec<1>(4 * (l0 - l1))};
      } else {
        const Real l[3] = {1 - s[0] - s[1], s[0], s[1]};
        const Vec<2> g[3] = {Vec<2>(-1, -1), Vec<2>(1, 0), Vec<2>(0, 1)};  // grad of l_i
        for (int i = 0; i < 3; ++i) {
          const int j = (i + 1) % 3;
          N[std::size_t(i)] = l[i] * (2 * l[i] - 1);
          dN[std::size_t(i)] = (4 * l[i] - 1) * g[i];
          N[std::size_t(3 + i)] = 4 * l[i] * l[j];
          dN[std::size_t(3 + i)] = 4 * (l[i] * g[j] + l[j] * g[i]);
        }
      }
      Vec<D> fh = Vec<D>::Zero();
      Eigen::Matrix<Real, D, D - 1> T = Eigen::Matrix<Real, D, D - 1>::Zero();  // dx / ds
      for (int a = 0; a < n; ++a) {
        fh += N[std::size_t(a)] * fx[std::size_t(a)];
        T += x[std::size_t(a)] * dN[std::size_t(a)].transpose();
      }
      Vec<D> normal;  // |normal| ds = the facet's measure element
      if constexpr (D == 2) normal = Vec<2>(T(1, 0), -T(0, 0));
      else normal = Vec<3>(T.col(0)).cross(Vec<3>(T.col(1)));
      phi += side * rule.weights[std::size_t(q)] * fh.dot(normal);
    }
  }
  return phi;
}

/// The body's slip made compatible with incompressibility on its mesh: returns
/// u_s(r) - c n(r), n = r / |r|, with c such that the discrete flux of the new slip through the
/// body's polygonal surface (facets tagged body.tag in `mesh`, at the body's initial place) is
/// zero. Why: with Dirichlet walls all round, the discrete continuity equations sum to "net
/// flux through the boundary = 0". A rigid velocity satisfies that exactly (its interpolant is
/// exact and V + w x r is divergence-free), a slip tangent to the *sphere* does not: through
/// the flat facets its interpolant leaks a flux of O(h^2) (cancelling only by symmetry, e.g.
/// for a slip on the whole sphere on a symmetric mesh), which the pinned pressure DOF then
/// absorbs as a point source, polluting the body's velocity (measured on a mirror-symmetric
/// mesh with the hemisphere slip of paper 6.1, h = R / 3: V_y = 6e-5 instead of 0). The
/// correction is a uniform normal velocity of O(h^2), which exerts no force or torque on a
/// sphere (surface_flux gives the discrete flux). AleFlow applies the same correction itself in
/// a closed domain, on every mesh it runs on (after each remesh too: BodySystem::remove_slip_flux);
/// this function is for a slip used on a fixed mesh outside a flow, or to see the leak.
///
///     squirmer.slip = tangential_slip(Vec<3>(-1, 0, 0), Vec<3>(1, 0, 0));
///     squirmer.slip = flux_free_slip(squirmer, mesh);   // before flow.add_body(squirmer)
inline std::function<Vec<3>(const Vec<3>&)> flux_free_slip(const RigidBody3D& body, const Mesh<3>& mesh,
                                                           int velocity_degree = 2, Real* removed = nullptr) {
  ALEFSI_CHECK_ARG(body.slip != nullptr, "body.slip", "the body has no slip");
  ALEFSI_CHECK_ARG(velocity_degree == 1 || velocity_degree == 2, "velocity_degree", "must be 1 or 2, got ",
                   velocity_degree);
  const auto slip = body.slip;
  std::vector<std::array<Vec<3>, 3>> facets;  // body frame
  for (Index k : mesh.boundary_facets()) {
    if (mesh.facet_tag(k) != body.tag) continue;
    std::array<Vec<3>, 3> x;
    for (int i = 0; i < 3; ++i) x[i] = body.orientation.conjugate() * (mesh.node(mesh.facet(k)[i]) - body.centre);
    facets.push_back(x);
  }
  ALEFSI_CHECK_ARG(!facets.empty(), "body.tag", "no boundary facet of the mesh has tag ", body.tag);
  const Real c = surface_flux<3>(facets, slip, velocity_degree) /
                 surface_flux<3>(facets, [](const Vec<3>& r) { return Vec<3>(r.normalized()); }, velocity_degree);
  if (removed) *removed = c;
  return [slip, c](const Vec<3>& r) { return Vec<3>(slip(r) - c * r.normalized()); };
}

/// [v]_x, the matrix of v x (.).
inline Mat<3> skew(const Vec<3>& v) {
  Mat<3> s;
  s << 0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0;
  return s;
}

/// Rows of H(x) = [I | -[r]_x] for a point at offset r = x - x_g: u_c = H(c, :) Z.
inline std::array<Vec<6>, 3> rigid_rows(const Vec<3>& r) {
  Vec<6> h0, h1, h2;
  h0 << 1, 0, 0, 0, r[2], -r[1];
  h1 << 0, 1, 0, -r[2], 0, r[0];
  h2 << 0, 0, 1, r[1], -r[0], 0;
  return {h0, h1, h2};
}

/// Rigid velocity V + w x r (3D).
inline Vec<3> rigid_velocity(const Vec<6>& Z, const Vec<3>& r) {
  return Z.head<3>() + Vec<3>(Z.tail<3>()).cross(r);
}

/// Rotation by the vector phi (angle |phi| about phi / |phi|) as a unit quaternion.
inline Eigen::Quaternion<Real> rotation_quaternion(const Vec<3>& phi) {
  const Real a = phi.norm();
  if (a == 0) return Eigen::Quaternion<Real>::Identity();
  return Eigen::Quaternion<Real>(Eigen::AngleAxis<Real>(a, phi / a));
}
/// The rotation vector of a unit quaternion (angle in [0, pi]).
inline Vec<3> rotation_vector(const Eigen::Quaternion<Real>& q) {
  const Eigen::AngleAxis<Real> aa(q);
  return aa.angle() * aa.axis();
}
/// J_l(phi)^{-1}, the inverse left Jacobian of SO(3): if R(t) = exp([phi(t)]) R_0 turns at the
/// angular velocity w (world axes, R' R^T = [w]_x), then phi' = J_l(phi)^{-1} w.
inline Mat<3> so3_left_jacobian_inverse(const Vec<3>& phi) {
  const Real a = phi.norm();
  const Real c = a < 1e-4 ? 1.0 / 12 + a * a / 720 : 1 / (a * a) - (1 + std::cos(a)) / (2 * a * std::sin(a));
  const Mat<3> P = skew(phi);
  return Mat<3>::Identity() - 0.5 * P + c * P * P;
}

/// What differs between 2D and 3D rigid bodies: the rigid-body models of the flow
/// (sim/body_system.hpp reads a body only through these). A model is a traits type: the body
/// description `Body`, the number of rigid DOFs, H, the orientation and its update, the inertia
/// term and its Jacobian, and the accessors of every body property the coupling reads; see the
/// concept `RigidBodyModel` below.
template <int D>
struct RigidBodyTraits;

/// The accessors both built-in models share (a model may define them differently).
template <class Body, class Velocity>
struct RigidBodyAccessors {
  static int tag(const Body& b) { return b.tag; }
  static bool is_free(const Body& b) { return b.free(); }
  static void validate(const Body& b, std::size_t index) { b.validate(index); }
  static auto initial_centre(const Body& b) { return b.centre; }
  /// Z at t0: the given motion's at t0 for a driven body, else `velocity`.
  static Velocity initial_velocity(const Body& b, Real t0) { return b.prescribed ? b.prescribed(t0) : b.velocity; }
  /// Z(t) of a driven body.
  static Velocity prescribed_velocity(const Body& b, Real t) { return b.prescribed(t); }
  static bool has_slip(const Body& b) { return bool(b.slip); }
  /// u_s at the body-frame offset r.
  template <class V>
  static V slip(const Body& b, const V& r) {
    return b.slip(r);
  }
  static Real mass(const Body& b) { return b.mass; }
  /// Constant external force and torque on a free body (besides gravity).
  static Velocity external_load(const Body& b) { return b.external_load; }
  /// > 0: a disk / sphere of this radius (exact surface for the remesher, exact contact distances).
  static Real radius(const Body& b) { return b.radius; }
  /// > 0: the exact area / volume (exact buoyancy of a body that is not a disk / sphere).
  static Real volume(const Body& b) { return b.volume; }
};

template <>
struct RigidBodyTraits<2> : RigidBodyAccessors<RigidBody2D, Vec<3>> {
  static constexpr const char* name = "rigid body 2D (3 DOF)";
  using Body = RigidBody2D;
  static constexpr int dim = 2;
  static constexpr int n_dof = 3;
  using Velocity = Vec<3>;
  using Orientation = Real;  ///< the angle theta
  /// Names of the CSV columns of the orientation, the velocity Z and the load (run()).
  static constexpr std::array<const char*, 1> orientation_columns{"angle"};
  static constexpr std::array<const char*, 3> velocity_columns{"vx", "vy", "omega"};
  static constexpr std::array<const char*, 3> load_columns{"fx", "fy", "torque"};
  static std::array<Real, 1> orientation_values(Orientation th) { return {th}; }
  static Orientation initial_orientation(const Body& b) { return b.angle; }
  /// A surface offset at t0 as stored (world axes at the initial angle).
  static Vec<2> initial_offset(const Vec<2>& r, const Body&) { return r; }
  static Vec<2> to_world(const Vec<2>& r0, Orientation th, const Body& b) { return rotate(r0, th - b.angle); }
  /// The body's convex shape (if any) in the axes of its surface offsets: turned by `angle`.
  static convex::Support<2> shape(const Body& b) {
    if (!b.shape) return {};
    Mat<2> Q;
    Q.col(0) = rotate(Vec<2>::UnitX(), b.angle), Q.col(1) = rotate(Vec<2>::UnitY(), b.angle);
    return convex::placed<2>(b.shape, Vec<2>::Zero(), Q);
  }
  static Vec<2> to_body(const Vec<2>& r, Orientation th, const Body& b) { return rotate(r, -(th - b.angle)); }
  static std::array<Velocity, 2> rows(const Vec<2>& r) { return rigid_rows(r); }
  static Vec<2> velocity(const Velocity& Z, const Vec<2>& r) { return rigid_velocity(Z, r); }
  /// theta^{n-1} = theta^n - dt w (the first MR/AB step).
  static Orientation step_back(Orientation th, const Velocity& Z, Real dt) { return th - dt * Z[2]; }
  /// The position formula sum_{k=0}^{l} b_k theta^{n+1-k} = dt w^ (past levels th[k - 1]).
  static Orientation advance(const std::array<Orientation, 3>& th, const Velocity& Zhat, const std::array<Real, 4>& b,
                             int l, Real dt) {
    Real ts = dt * Zhat[2];
    for (int k = 1; k <= l; ++k) ts -= b[k] * th[k - 1];
    return ts / b[0];
  }
  /// Richardson extrapolation 2 a - b of two approximations a (error e) and b (error ~2 e).
  static Orientation extrapolate(Orientation a, Orientation b) { return 2 * a - b; }
  /// M dZ / dt with M = diag(m, m, I33); dZ = delta_l Z (BDF combination, a0 Z + history).
  static Velocity inertia(const Body& b, Orientation, const Velocity&, const Velocity& dZ, Real dt) {
    return Vec<3>(b.mass, b.mass, b.inertia).cwiseProduct(dZ) / dt;
  }
  /// d inertia / d Z (dZ = a0 Z + history).
  static Mat<3> inertia_jacobian(const Body& b, Orientation, const Velocity&, Real a0, Real dt) {
    const Vec<3> m(b.mass, b.mass, b.inertia);
    Mat<3> J = Mat<3>::Zero();
    for (int C = 0; C < 3; ++C) J(C, C) = m[C] * a0 / dt;
    return J;
  }
};

template <>
struct RigidBodyTraits<3> : RigidBodyAccessors<RigidBody3D, Vec<6>> {
  static constexpr const char* name = "rigid body 3D (6 DOF)";
  using Body = RigidBody3D;
  static constexpr int dim = 3;
  static constexpr int n_dof = 6;
  using Velocity = Vec<6>;
  using Orientation = Eigen::Quaternion<Real>;  ///< unit, body frame -> world
  static constexpr std::array<const char*, 4> orientation_columns{"qw", "qx", "qy", "qz"};
  static constexpr std::array<const char*, 6> velocity_columns{"vx", "vy", "vz", "wx", "wy", "wz"};
  static constexpr std::array<const char*, 6> load_columns{"fx", "fy", "fz", "tx", "ty", "tz"};
  static std::array<Real, 4> orientation_values(const Orientation& q) { return {q.w(), q.x(), q.y(), q.z()}; }
  static Orientation initial_orientation(const Body& b) { return b.orientation; }
  /// A surface offset at t0, stored in the body frame.
  static Vec<3> initial_offset(const Vec<3>& r, const Body& b) { return b.orientation.conjugate() * r; }
  static Vec<3> to_world(const Vec<3>& rb, const Orientation& q, const Body&) { return q * rb; }
  /// The body's convex shape (if any) in the axes of its surface offsets: the body frame.
  static convex::Support<3> shape(const Body& b) { return b.shape; }
  static Vec<3> to_body(const Vec<3>& r, const Orientation& q, const Body&) { return q.conjugate() * r; }
  static std::array<Velocity, 3> rows(const Vec<3>& r) { return rigid_rows(r); }
  static Vec<3> velocity(const Velocity& Z, const Vec<3>& r) { return rigid_velocity(Z, r); }
  /// q^{n-1} = exp(-dt w) q^n (the first MR/AB step).
  static Orientation step_back(const Orientation& q, const Velocity& Z, Real dt) {
    return (rotation_quaternion(-dt * Vec<3>(Z.tail<3>())) * q).normalized();
  }
  /// The position formula applied to the rotation vector relative to q^n: with
  /// q^{n+1-k} = exp(phi_k) q^n (phi_1 = 0), sum_k b_k phi_k = dt phi'(t^{n+1}) where
  /// phi' = J_l(phi)^{-1} w^ (so3_left_jacobian_inverse); solved for phi_0 by fixed-point
  /// iteration (contraction factor O(dt |w|)), then q^{n+1} = exp(phi_0) q^n, normalised.
  /// This is the BDF formula of the centre in exponential coordinates, so the orientation has
  /// the order of the scheme's position formula.
  static Orientation advance(const std::array<Orientation, 3>& q, const Velocity& Zhat, const std::array<Real, 4>& b,
                             int l, Real dt) {
    const Vec<3> w = Zhat.tail<3>();
    Vec<3> hist = Vec<3>::Zero();  // sum_{k >= 2} b_k phi_k
    for (int k = 2; k <= l; ++k) hist += b[k] * rotation_vector(q[k - 1] * q[0].conjugate());
    Vec<3> phi = (dt * w - hist) / b[0];
    for (int it = 0; it < 50; ++it) {
      const Vec<3> next = (dt * (so3_left_jacobian_inverse(phi) * w) - hist) / b[0];
      const Real change = (next - phi).norm();
      phi = next;
      if (change <= 1e-15 * (1 + phi.norm())) break;
    }
    return (rotation_quaternion(phi) * q[0]).normalized();
  }
  /// Richardson extrapolation on the rotation group: a (b^-1 a), since
  /// a exp(e_a) exp(e_a - e_b) = exp(2 e_a - e_b) to O(e^2).
  static Orientation extrapolate(const Orientation& a, const Orientation& b) {
    return Orientation(a * (b.inverse() * a)).normalized();
  }
  /// (m dV / dt, I_w dw / dt + w x (I_w w)) with I_w = R(q) I_body R(q)^T at orientation q;
  /// dZ = delta_l Z (BDF combination, a0 Z + history), Z = (V, w) the new velocity.
  static Velocity inertia(const Body& b, const Orientation& q, const Velocity& Z, const Velocity& dZ, Real dt) {
    const Mat<3> R = q.toRotationMatrix();
    const Mat<3> Iw = R * b.inertia * R.transpose();
    const Vec<3> w = Z.tail<3>();
    Velocity out;
    out.head<3>() = b.mass * dZ.head<3>() / dt;
    out.tail<3>() = Iw * dZ.tail<3>() / dt + w.cross(Iw * w);
    return out;
  }
  /// d inertia / d Z: diag(m a0 / dt) and I_w a0 / dt + [w]_x I_w - [I_w w]_x.
  static Mat<6> inertia_jacobian(const Body& b, const Orientation& q, const Velocity& Z, Real a0, Real dt) {
    const Mat<3> R = q.toRotationMatrix();
    const Mat<3> Iw = R * b.inertia * R.transpose();
    const Vec<3> w = Z.tail<3>();
    Mat<6> J = Mat<6>::Zero();
    for (int C = 0; C < 3; ++C) J(C, C) = b.mass * a0 / dt;
    J.bottomRightCorner<3, 3>() = Iw * a0 / dt + skew(w) * Iw - skew(Iw * w);
    return J;
  }
};

/// A rigid-body model: everything the flow (sim/body_system.hpp, sim/flow_state.hpp, run())
/// asks of a body of dimension D, and nothing else. `Body` is the run-time description (tag,
/// mass and inertia, initial state, slip, optional prescribed motion Z(t)); free and prescribed
/// bodies share it because a scene mixes them (a driven cylinder beside free particles).
/// Models: RigidBodyTraits<2> (3 DOF), RigidBodyTraits<3> (6 DOF). A new model (e.g. a body
/// constrained to a plane in 3D, or one with a shape of its own) is a traits type with these
/// members, checked by this concept; tests/physics/test_body_system.cpp shows that a type
/// lacking any one of them is rejected.
///
///     static_assert(alefsi::RigidBodyModel<alefsi::RigidBodyTraits<3>>);
template <class T>
concept RigidBodyModel = requires(const typename T::Body& body, const typename T::Velocity& Z,
                                  const typename T::Orientation& th, const std::array<typename T::Orientation, 3>& ths,
                                  const Vec<T::dim>& r, const std::array<Real, 4>& bdf, Real dt, int l, std::size_t index) {
  requires T::dim == 2 || T::dim == 3;
  requires T::n_dof == T::dim * (T::dim + 1) / 2;
  { T::name } -> std::convertible_to<const char*>;  // checkpoints record it
  requires std::tuple_size_v<decltype(T::velocity_columns)> == std::size_t(T::n_dof);
  requires std::tuple_size_v<decltype(T::load_columns)> == std::size_t(T::n_dof);
  // the body's properties
  { T::tag(body) } -> std::convertible_to<int>;
  { T::is_free(body) } -> std::same_as<bool>;
  T::validate(body, index);
  { T::initial_centre(body) } -> std::convertible_to<Vec<T::dim>>;
  { T::initial_velocity(body, dt) } -> std::convertible_to<typename T::Velocity>;
  { T::prescribed_velocity(body, dt) } -> std::convertible_to<typename T::Velocity>;
  { T::has_slip(body) } -> std::same_as<bool>;
  { T::slip(body, r) } -> std::convertible_to<Vec<T::dim>>;
  { T::mass(body) } -> std::convertible_to<Real>;
  { T::external_load(body) } -> std::convertible_to<typename T::Velocity>;
  { T::radius(body) } -> std::convertible_to<Real>;
  // kinematics
  { T::initial_orientation(body) } -> std::convertible_to<typename T::Orientation>;
  { T::initial_offset(r, body) } -> std::convertible_to<Vec<T::dim>>;
  { T::to_world(r, th, body) } -> std::convertible_to<Vec<T::dim>>;
  { T::to_body(r, th, body) } -> std::convertible_to<Vec<T::dim>>;
  { T::rows(r) } -> std::convertible_to<std::array<typename T::Velocity, T::dim>>;
  { T::velocity(Z, r) } -> std::convertible_to<Vec<T::dim>>;
  { T::step_back(th, Z, dt) } -> std::convertible_to<typename T::Orientation>;
  { T::advance(ths, Z, bdf, l, dt) } -> std::convertible_to<typename T::Orientation>;
  { T::extrapolate(th, th) } -> std::convertible_to<typename T::Orientation>;
  // dynamics
  { T::inertia(body, th, Z, Z, dt) } -> std::convertible_to<typename T::Velocity>;
  { T::inertia_jacobian(body, th, Z, dt, dt) } -> std::convertible_to<Eigen::Matrix<Real, T::n_dof, T::n_dof>>;
  // output
  { T::orientation_values(th) }
  -> std::convertible_to<std::array<Real, std::tuple_size_v<decltype(T::orientation_columns)>>>;
};

static_assert(RigidBodyModel<RigidBodyTraits<2>>, "RigidBodyTraits<2> (3-DOF bodies) must model RigidBodyModel");
static_assert(RigidBodyModel<RigidBodyTraits<3>>, "RigidBodyTraits<3> (6-DOF bodies) must model RigidBodyModel");

}  // namespace alefsi
