#pragma once
/// \file physics/mass_properties.hpp
/// Mass, centre of mass and moment of inertia of a body of uniform density, from its shape:
/// what RigidBody2D / RigidBody3D need, computed rather than typed in.
///
///   * 2D (per unit length): a Circle, an Ellipse or a closed Polyline (a simple polygon, either
///     orientation; exact by the shoelace formulas). `inertia` is I_33 about the centre of mass.
///   * 3D: a sphere, and an ellipsoid with semi-axes (a, b, c) along its body axes; `inertia` is
///     the tensor about the centre of mass in the body frame, as RigidBody3D takes it (diagonal
///     for these shapes: the body axes are the principal axes).
///
/// Bad input (a non-positive size or density, a polygon with fewer than 3 points or no area)
/// throws InvalidArgument naming the parameter.
///
///     const auto p = alefsi::mass_properties(alefsi::Ellipse{{0, 0}, 0.2, 0.1, 0.3, 5}, 1.5);
///     alefsi::RigidBody2D body = alefsi::free_body(5, p);   // m = rho pi a b, I = m (a^2 + b^2) / 4
#include <cmath>
#include <numbers>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/physics/rigid_body.hpp"

namespace alefsi {

struct MassProperties2D {
  Real mass = 0;                    ///< per unit length
  Vec<2> centre = Vec<2>::Zero();   ///< centre of mass
  Real inertia = 0;                 ///< I_33 about the centre of mass, per unit length
};

struct MassProperties3D {
  Real mass = 0;
  Vec<3> centre = Vec<3>::Zero();
  Mat<3> inertia = Mat<3>::Zero();  ///< about the centre of mass, body frame
};

namespace detail {
inline void check_density(Real density) {
  ALEFSI_CHECK_ARG(density > 0 && std::isfinite(density), "density", "must be positive and finite, got ", density);
}
inline void check_length(Real x, const char* name) {
  ALEFSI_CHECK_ARG(x > 0 && std::isfinite(x), name, "must be positive and finite, got ", x);
}
}  // namespace detail

/// A disk: m = rho pi r^2, I = m r^2 / 2 (disk_body's).
inline MassProperties2D mass_properties(const Circle& c, Real density) {
  const RigidBody2D b = disk_body(c.tag, c.centre, c.radius, density);
  return {b.mass, b.centre, b.inertia};
}

/// An elliptic disk: m = rho pi a b, I = m (a^2 + b^2) / 4 (independent of its angle).
inline MassProperties2D mass_properties(const Ellipse& e, Real density) {
  detail::check_density(density), detail::check_length(e.a, "a"), detail::check_length(e.b, "b");
  const Real m = density * std::numbers::pi * e.a * e.b;
  return {m, e.centre, 0.25 * m * (e.a * e.a + e.b * e.b)};
}

/// A simple polygon (the polyline closed): area, centroid and polar moment by the shoelace
/// sums over its edges, taken about the first vertex to keep round-off small far from the origin.
inline MassProperties2D mass_properties(const Polyline& p, Real density) {
  detail::check_density(density);
  const std::size_t n = p.points.size();
  ALEFSI_CHECK_ARG(n >= 3, "points", "a polygon needs at least 3 points, got ", n);
  const Vec<2> o = p.points[0];
  Real a2 = 0, jo = 0;  // twice the signed area; 12 x the polar moment about o (signed)
  Vec<2> s = Vec<2>::Zero();  // 6 x the first moment about o (signed)
  for (std::size_t i = 0; i < n; ++i) {
    const Vec<2> x = p.points[i] - o, y = p.points[(i + 1) % n] - o;
    const Real cross = x[0] * y[1] - y[0] * x[1];
    a2 += cross;
    s += cross * (x + y);
    jo += cross * (x.squaredNorm() + x.dot(y) + y.squaredNorm());
  }
  const Real area = 0.5 * a2;
  ALEFSI_CHECK_ARG(std::abs(area) > 0 && std::isfinite(area), "points", "the polygon encloses no area");
  const Vec<2> g = s / (3 * a2);            // centroid relative to o
  const Real j = jo / 12 / area;            // polar moment per unit area about o (sign cancels)
  const Real m = density * std::abs(area);
  return {m, o + g, m * (j - g.squaredNorm())};  // parallel axes: about the centroid
}

/// A ball: m = rho 4/3 pi r^3, I = 2/5 m r^2 times the identity (sphere_body's).
inline MassProperties3D sphere_mass_properties(const Vec<3>& centre, Real radius, Real density) {
  const RigidBody3D b = sphere_body(0, centre, radius, density);
  return {b.mass, b.centre, b.inertia};
}

/// An ellipsoid with semi-axes (a, b, c) along the body's x, y, z axes: m = rho 4/3 pi a b c,
/// I = m / 5 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2).
inline MassProperties3D ellipsoid_mass_properties(const Vec<3>& centre, const Vec<3>& semi_axes, Real density) {
  detail::check_density(density);
  detail::check_length(semi_axes[0], "semi_axes[0]"), detail::check_length(semi_axes[1], "semi_axes[1]"),
      detail::check_length(semi_axes[2], "semi_axes[2]");
  const Real a = semi_axes[0], b = semi_axes[1], c = semi_axes[2];
  const Real m = density * 4.0 / 3.0 * std::numbers::pi * a * b * c;
  const Vec<3> d(b * b + c * c, a * a + c * c, a * a + b * b);
  return {m, centre, Mat<3>(d.asDiagonal()) * (m / 5)};
}

/// A free body with these properties (the other fields at their defaults). A disk is better made
/// by disk_body, which also sets its radius (exact contact distances and surface on remeshing).
inline RigidBody2D free_body(int tag, const MassProperties2D& p) {
  RigidBody2D b;
  b.tag = tag, b.mass = p.mass, b.inertia = p.inertia, b.centre = p.centre;
  return b;
}
inline RigidBody3D free_body(int tag, const MassProperties3D& p) {
  RigidBody3D b;
  b.tag = tag, b.mass = p.mass, b.inertia = p.inertia, b.centre = p.centre;
  return b;
}

}  // namespace alefsi
