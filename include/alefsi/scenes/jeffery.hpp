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
#include <type_traits>
#include <utility>

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
  /// `follow_orbit`: remesh (sim/remesher2d.hpp, this scene's size function, the container's
  /// circle as the wall) when the worst cell quality falls below this; 0: never.
  Real remesh_quality = 0;

  using Flow = AleFlow<FlowConfig<2, TaylorHood, BDF2_BDF2E, UnsteadyStokes>>;

  void validate() const {
    ALEFSI_CHECK_ARG(a > 0 && b > 0 && std::isfinite(a) && std::isfinite(b), "a, b",
                     "semi-axes must be positive and finite, got ", a, ", ", b);
    ALEFSI_CHECK_ARG(container > 2 * std::max(a, b), "container", "must exceed twice the larger semi-axis, got ",
                     container);
    ALEFSI_CHECK_ARG(h_body > 0 && h_far >= h_body && grading > 0, "h_body, h_far, grading",
                     "need 0 < h_body <= h_far and grading > 0");
    ALEFSI_CHECK_ARG(remesh_quality >= 0 && remesh_quality < 1, "remesh_quality", "must be in [0, 1), got ",
                     remesh_quality);
  }

  /// The ellipse at orientation phi (tag 1).
  Ellipse ellipse(Real phi) const { return Ellipse{Vec<2>::Zero(), a, b, phi, 1}; }

  /// The container with the ellipse at orientation phi.
  Mesh<2> mesh(Real phi) const {
    validate();
    MesherOptions opt;
    opt.size = size();
    return generate_mesh(Domain2D{Circle{Vec<2>::Zero(), container, 2}, {ellipse(phi)}}, opt);
  }
  /// The mesh size: h_body within the circle of radius max(a, b), growing by `grading` per unit
  /// distance up to h_far.
  SizeFunction size() const {
    return [s = *this](const Vec<2>& x) {
      return std::min(s.h_far, s.h_body + s.grading * std::max(Real(0), x.norm() - std::max(s.a, s.b)));
    };
  }

  /// The ellipse's quasi-static spin at orientation phi: Stokes flow (unsteady Stokes with
  /// rho = 1e-18, one step of 1e-6 from rest: the rest mass term rho / dt = 1e-12 is far below
  /// the solution's accuracy), the body massless and free. `nodes`: the mesh's node count.
  Real spin(Real phi, Index* nodes = nullptr) const {
    Flow flow(mesh(phi), FlowOptions{1e-18, mu});
    if (nodes) *nodes = flow.mesh().n_nodes();
    set_up(flow, phi, 0);
    flow.step(1e-6);
    return flow.body_velocity(0)[2];
  }

  /// The ellipse followed in time on a moving mesh: a quasi-static flow (rho = 1e-18), from the
  /// orientation phi0, round(t_end / dt) steps of dt, the body free and massless, the mesh moved by
  /// elasticity, the curved edge points carried rigidly with the body. The start is consistent:
  /// the body spins at once at spin(phi0) (from rest, the first explicit position update would
  /// lag the orbit by dt w). `visit(t, phi, worst_quality)` after every step. Without remeshing
  /// a quarter turn keeps the cells above quality 0.28 (b / a = 1/2, h_body 0.1); a half turn
  /// brings them to 0.09. With `remesh_quality` > 0 the mesh is adapted when its worst cell
  /// falls below it (the curved edge points placed anew on the ellipse where the body is then).
  /// `visit` may take the flow as a fourth argument. Returns the number of remeshes.
  template <class Visit>
  Index follow_orbit(Real phi0, Real dt, Real t_end, Visit&& visit) const {
    validate();
    ALEFSI_CHECK_ARG(dt > 0 && t_end >= dt && std::isfinite(t_end), "dt, t_end", "need 0 < dt <= t_end, got ", dt,
                     ", ", t_end);
    const Real w0 = spin(phi0);
    Flow flow(mesh(phi0), FlowOptions{1e-18, mu});
    set_up(flow, phi0, w0);
    if (remesh_quality > 0) set_remeshing(flow);
    const long n = std::lround(t_end / dt);
    for (long i = 0; i < n; ++i) {
      flow.step(dt);
      if constexpr (std::is_invocable_v<Visit&, Real, Real, Real, const Flow&>)
        visit(flow.time(), flow.body_angle(0), flow.worst_quality(), std::as_const(flow));
      else
        visit(flow.time(), flow.body_angle(0), flow.worst_quality());
    }
    return flow.stats().remeshes;
  }

  /// The orbit of d phi / dt = w0 cos^2 phi + w1 sin^2 phi (w0, w1 < 0: the spins at phi = 0
  /// and pi / 2) from phi(0) = phi0, continuous in t. In a circular container the spin has this
  /// form exactly; the discrete spins, each on its own mesh, follow it to 5e-7 (w(pi / 4),
  /// w(pi / 8): docs/results.md), so with w0 = spin(0), w1 = spin(pi / 2) it is the discrete
  /// problem's own orbit to that accuracy (Jeffery's with w0 = -b^2 / (a^2 + b^2),
  /// w1 = -a^2 / (a^2 + b^2)):
  ///     tan phi = (B / A)^{1/2} tan theta,  theta = theta0 - (A B)^{1/2} t,  A = -w1, B = -w0.
  static Real orbit_angle(Real t, Real phi0, Real w0, Real w1) {
    ALEFSI_CHECK_ARG(w0 < 0 && w1 < 0, "w0, w1", "the spins must be negative (shear along +x), got ", w0, ", ", w1);
    const Real A = -w1, B = -w0, two_pi = 2 * std::numbers::pi;
    // the maps between phi and theta keep the quadrant, so each is the identity plus a bounded,
    // 2 pi-periodic part: continuous for any phi0 and t
    const auto turn = [two_pi](Real x, Real cx, Real cy) {  // atan2(cy sin x, cx cos x), continuous in x
      return x + std::remainder(std::atan2(cy * std::sin(x), cx * std::cos(x)) - x, two_pi);
    };
    const Real theta = turn(phi0, std::sqrt(B), std::sqrt(A)) - std::sqrt(A * B) * t;
    return turn(theta, std::sqrt(A), std::sqrt(B));
  }

  /// The scene on `flow` (a mesh of `mesh(phi)`): the container's wall in the shear, the free,
  /// massless ellipse at orientation phi spinning at `spin0`, the curved boundaries.
  void set_up(Flow& flow, Real phi, Real spin0) const {
    flow.set_velocity(2, [g = gamma](const Vec<2>& x, Real) { return Vec<2>(g * x[1], 0); });
    RigidBody2D body;
    body.tag = 1;
    body.angle = phi;
    body.velocity = Vec<3>(0, 0, spin0);
    flow.add_body(body);
    if (curved) {
      flow.curve_boundary(1, [e = ellipse(phi)](const Vec<2>& x) { return e.radial_projection(x); });
      flow.curve_boundary(2, onto_sphere<2>(Vec<2>::Zero(), container));
    }
  }

  /// Remeshing on `flow` (a mesh of `mesh(phi)`) when the worst cell quality falls below
  /// `remesh_quality` (> 0): this scene's size function, the container's circle as the wall.
  void set_remeshing(Flow& flow) const {
    ALEFSI_CHECK_ARG(remesh_quality > 0 && remesh_quality < 1, "remesh_quality", "must be in (0, 1), got ",
                     remesh_quality);
    flow.set_remeshing({.trigger_quality = remesh_quality,
                        .walls = {Circle{Vec<2>::Zero(), container, 2}},
                        .size = [h = size()](const auto&) { return h; },
                        .adapt = {}});
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
