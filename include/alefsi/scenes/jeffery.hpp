#pragma once
/// \file scenes/jeffery.hpp
/// A free ellipse in simple shear (Jeffery 1922): a massless, force- and torque-free ellipse
/// with semi-axes a and b (a along its orientation phi) at the centre of a circular container of
/// radius L (tag 2), whose wall moves with the simple shear u = (gamma y, 0); the ellipse's
/// surface is tag 1. In Stokes flow its spin depends on phi alone, and Jeffery's law for the
/// unbounded flow, in 2D,
///     w(phi) = -gamma (a^2 sin^2 phi + b^2 cos^2 phi) / (a^2 + b^2),
///     T = 2 pi (a^2 + b^2) / (gamma a b),   tan phi(t) = -(b / a) tan(gamma a b t / (a^2 + b^2)),
/// is reached as L -> infinity at O((a / L)^2) (the wall reflects the body's stresslet).
/// `spin(phi)` solves the quasi-static mobility problem on a mesh of the built-in mesher
/// (Taylor–Hood, curved cells on the ellipse and the container unless `curved` is false).
///
///     scenes::Jeffery scene{.b = 0.5, .container = 32};
///     const Real w = scene.spin(0.3);           // the ellipse's spin at phi = 0.3
///     const Real T = scene.jeffery_period();
#include <algorithm>
#include <cmath>
#include <numbers>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/fem/geometry.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/sim/ale_flow.hpp"

namespace alefsi::scenes {

struct Jeffery {
  Real a = 1, b = 0.5;        ///< semi-axes
  Real gamma = 1;             ///< shear rate
  Real mu = 1;                ///< viscosity
  Real container = 32;        ///< radius L of the circular container
  Real h_body = 0.05;         ///< mesh size at the ellipse
  Real h_far = 1;             ///< largest mesh size
  Real grading = 0.25;        ///< growth of the size with the distance from the circle of radius a
  bool curved = true;         ///< isoparametric P2 cells on the ellipse and the container

  void validate() const {
    ALEFSI_CHECK_ARG(a > 0 && b > 0 && std::isfinite(a) && std::isfinite(b), "a, b",
                     "semi-axes must be positive and finite, got ", a, ", ", b);
    ALEFSI_CHECK_ARG(container > 2 * std::max(a, b), "container", "must exceed twice the larger semi-axis, got ",
                     container);
    ALEFSI_CHECK_ARG(h_body > 0 && h_far >= h_body && grading > 0, "h_body, h_far, grading",
                     "need 0 < h_body <= h_far and grading > 0");
  }

  /// The ellipse at orientation phi (tag 1).
  Ellipse ellipse(Real phi) const { return Ellipse{Vec<2>::Zero(), a, b, phi, 1}; }

  /// The container with the ellipse at orientation phi.
  Mesh<2> mesh(Real phi) const {
    validate();
    MesherOptions opt;
    opt.size = [s = *this](const Vec<2>& x) {
      return std::min(s.h_far, s.h_body + s.grading * std::max(Real(0), x.norm() - std::max(s.a, s.b)));
    };
    return generate_mesh(Domain2D{Circle{Vec<2>::Zero(), container, 2}, {ellipse(phi)}}, opt);
  }

  /// The ellipse's quasi-static spin at orientation phi: Stokes flow (unsteady Stokes with
  /// rho = 1e-18, one step of 1e-6 from rest: the rest mass term rho / dt = 1e-12 is far below
  /// the solution's accuracy), the body massless and free. `nodes`: the mesh's node count.
  Real spin(Real phi, Index* nodes = nullptr) const {
    AleFlow<FlowConfig<2, TaylorHood, BDF2_BDF2E, UnsteadyStokes>> flow(mesh(phi), FlowOptions{1e-18, mu});
    if (nodes) *nodes = flow.mesh().n_nodes();
    flow.set_velocity(2, [g = gamma](const Vec<2>& x, Real) { return Vec<2>(g * x[1], 0); });
    RigidBody2D body;
    body.tag = 1;
    body.angle = phi;
    flow.add_body(body);
    if (curved) {
      flow.curve_boundary(1, [e = ellipse(phi)](const Vec<2>& x) { return e.radial_projection(x); });
      flow.curve_boundary(2, onto_sphere<2>(Vec<2>::Zero(), container));
    }
    flow.step(1e-6);
    return flow.body_velocity(0)[2];
  }

  /// Jeffery's spin at orientation phi (unbounded flow).
  Real jeffery_spin(Real phi) const {
    const Real s = std::sin(phi), c = std::cos(phi);
    return -gamma * (a * a * s * s + b * b * c * c) / (a * a + b * b);
  }
  /// Jeffery's period of a full turn.
  Real jeffery_period() const { return 2 * std::numbers::pi * (a * a + b * b) / (gamma * a * b); }
  /// Jeffery's orientation at time t from phi(0) = 0 (continuous: -pi per half period).
  Real jeffery_angle(Real t) const {
    const Real theta = gamma * a * b * t / (a * a + b * b);
    const Real turns = std::floor(theta / std::numbers::pi + 0.5);  // whole half-turns of theta
    return -(std::atan((b / a) * std::tan(theta - turns * std::numbers::pi)) + turns * std::numbers::pi);
  }
};

}  // namespace alefsi::scenes
