#pragma once
/// \file physics/rigid_body.hpp
/// Rigid bodies in 2D: state, the rigid-velocity operator H of eq. (8)-(9), and the body's
/// place in the monolithic system.
///
/// A body is a hole of the fluid mesh whose surface facets carry `tag`. Its velocity is
/// Z = (V1, V2, w3): the velocity of a surface point x is H(x) Z + u_s(x) with
///     H(x) = [[1, 0, -(y - yg)], [0, 1, (x - xg)]]
/// and u_s the slip velocity (zero unless given). Body surface nodes follow the exact rigid
/// motion x = x_g + R(theta - theta_0) (x_0 - x_g0), so a body keeps its shape.
/// A *free* body's Z are unknowns of the flow system: its rows are eq. (11),
///     M (delta_l Z) / dt - M g + (fluid terms through the columns of H) = 0,
/// with M = diag(m, m, I). A *prescribed* body moves with Z(t) given by the user; its surface
/// velocities are then Dirichlet data.
///
///     RigidBody2D disk{.tag = 5, .mass = pi * r * r * rho_s, .inertia = 0.5 * mass * r * r,
///                      .centre = {1.0, 4.5}};
///     flow.add_body(disk);
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

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

  bool free() const { return !prescribed; }

  void validate(std::size_t index) const {
    const std::string who = "bodies[" + std::to_string(index) + "]";
    if (free()) {
      ALEFSI_CHECK_ARG(mass > 0 && std::isfinite(mass), who + ".mass", "must be positive and finite, got ", mass);
      ALEFSI_CHECK_ARG(inertia > 0 && std::isfinite(inertia), who + ".inertia", "must be positive and finite, got ",
                       inertia);
    }
    ALEFSI_CHECK_ARG(centre.allFinite() && velocity.allFinite(), who, "non-finite initial state");
    ALEFSI_CHECK_ARG(radius >= 0 && std::isfinite(radius), who + ".radius", "must be >= 0 and finite, got ", radius);
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

/// Slip velocities for RigidBody2D::slip (body frame; n = r / |r|, exact for disks).
///
/// `tangential_slip(Q)`: the tangential projection of a constant field Q, u_s = Q - (Q.n) n
/// (the paper's sections 6.1 and 6.4); with `half` set, only on the half surface r.half > 0
/// (zero elsewhere). On a disk, Q = -B1 e gives the squirmer mode B1 sin(theta) e_theta
/// (theta from e), which swims along +e at B1 / 2 in an unbounded 2D fluid (Blake 1971).
inline std::function<Vec<2>(const Vec<2>&)> tangential_slip(const Vec<2>& Q, const Vec<2>& half = Vec<2>::Zero()) {
  ALEFSI_CHECK_ARG(Q.allFinite() && half.allFinite(), "Q", "must be finite");
  return [Q, half](const Vec<2>& r) -> Vec<2> {
    if (half.squaredNorm() > 0 && r.dot(half) <= 0) return Vec<2>::Zero();
    const Vec<2> n = r.normalized();
    return Q - Q.dot(n) * n;
  };
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

}  // namespace alefsi
