#pragma once
/// \file scenes/oscillating_cylinder.hpp
/// A circular cylinder oscillating in-line in a fluid at rest: the case of Dütsch, Durst, Becker &
/// Lienhart (1998, J. Fluid Mech. 360, 249-271), Re = Um D / nu = 100, KC = Um / (f D) = 5.
/// The cylinder (tag 5, diameter D, centred at the origin at t = 0) is a driven body moving as
/// x(t) = -A sin(2 pi f t), u(t) = -Um cos(2 pi f t), A = Um / (2 pi f); the fluid fills the box
/// [-L, L]^2 with no-slip walls (tag 1), far enough (L = 15 D by default) to stand for the
/// unbounded fluid; rho = 1. The in-line force F(t) on the cylinder is summarised by the
/// coefficients of Morison's equation, F = -1/2 rho D C_D u|u| - rho (pi D^2 / 4) C_I du/dt,
/// fitted over one period (`morison`).
///
///     scenes::OscillatingCylinder scene;
///     AleFlow<FlowConfig<2, TaylorHood, BDF2_BDF2E>> flow(scene.mesh(0.04, 1.0), scene.options());
///     scene.configure(flow);
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/sim/config.hpp"

namespace alefsi::scenes {

struct OscillatingCylinder {
  static constexpr int wall = 1, cylinder = 5;
  Real reynolds = 100;    ///< Um D / nu
  Real kc = 5;            ///< Keulegan-Carpenter number Um / (f D)
  Real diameter = 1;      ///< D
  Real max_speed = 1;     ///< Um
  Real half_width = 15;   ///< L: the box is [-L, L]^2

  Real nu() const { return max_speed * diameter / reynolds; }
  Real frequency() const { return max_speed / (kc * diameter); }
  Real period() const { return 1 / frequency(); }
  Real omega() const { return 2 * std::numbers::pi * frequency(); }
  Real amplitude() const { return max_speed / omega(); }
  /// The cylinder's in-line position, velocity and acceleration at t.
  Real position(Real t) const { return -amplitude() * std::sin(omega() * t); }
  Real velocity(Real t) const { return -max_speed * std::cos(omega() * t); }
  Real acceleration(Real t) const { return max_speed * omega() * std::sin(omega() * t); }

  FlowOptions options() const {
    FlowOptions o;
    o.rho = 1;
    o.mu = nu();
    o.damped_start = 4;  // the start is impulsive: u(0) = -Um in a fluid at rest
    return o;
  }

  /// Graded from h_body at the cylinder (growing by `grading` per unit distance) to h_far.
  Mesh<2> mesh(Real h_body, Real h_far, Real grading = 0.12) const {
    ALEFSI_CHECK_ARG(h_body > 0 && h_far >= h_body, "h_body, h_far", "need 0 < h_body <= h_far, got ", h_body, ", ",
                     h_far);
    ALEFSI_CHECK_ARG(half_width > diameter + amplitude(), "half_width", "the box must hold the cylinder's path, got ",
                     half_width);
    const Real L = half_width, R = diameter / 2;
    Domain2D dom;
    dom.outer = Polyline{{Vec<2>(-L, -L), Vec<2>(L, -L), Vec<2>(L, L), Vec<2>(-L, L)}, wall};
    dom.holes.emplace_back(Circle{Vec<2>::Zero(), R, cylinder});
    const auto size = [=](const Vec<2>& x) { return std::min(h_far, h_body + grading * std::max(0.0, x.norm() - R)); };
    return generate_mesh(dom, MesherOptions{size});
  }

  /// No-slip walls and the cylinder driven along x; returns the body's index.
  template <class Flow>
  std::size_t configure(Flow& flow) const {
    flow.set_velocity(wall, [](const Vec<2>&, Real) { return Vec<2>(0, 0); });
    const OscillatingCylinder s = *this;
    RigidBody2D body;
    body.tag = cylinder;
    body.centre = Vec<2>::Zero();
    body.radius = diameter / 2;
    body.prescribed = [s](Real t) { return Vec<3>(s.velocity(t), 0, 0); };
    return flow.add_body(body);
  }

  struct Morison {
    Real drag;     ///< C_D
    Real inertia;  ///< C_I
  };
  /// Morison's coefficients of the in-line force samples F(t_k) over [t0, t0 + T] (T the
  /// period; the samples sorted by time and covering that window): projections of F on the
  /// velocity's and the acceleration's harmonics, C_D = 3 / (4 rho D Um^2) int F cos(wt) d(wt)
  /// and C_I = -4 / (pi^2 rho D^2 Um w) int F sin(wt) d(wt) for u = -Um cos(wt) (rho = 1),
  /// by the trapezoidal rule.
  Morison morison(const std::vector<Real>& t, const std::vector<Real>& F, Real t0) const {
    ALEFSI_CHECK_ARG(t.size() == F.size() && t.size() >= 3, "t, F", "need as many times as forces, at least 3");
    const Real t1 = t0 + period(), w = omega();
    ALEFSI_CHECK_ARG(t.front() <= t0 + 1e-9 * period() && t.back() >= t1 - 1e-9 * period(), "t0",
                     "the samples must cover [t0, t0 + T]");
    Real c = 0, s = 0;
    for (std::size_t k = 1; k < t.size(); ++k) {
      const Real a = std::max(t[k - 1], t0), b = std::min(t[k], t1);
      if (b <= a) continue;
      auto f = [&](Real x) { return F[k - 1] + (F[k] - F[k - 1]) * (x - t[k - 1]) / (t[k] - t[k - 1]); };
      c += 0.5 * (b - a) * (f(a) * std::cos(w * a) + f(b) * std::cos(w * b));
      s += 0.5 * (b - a) * (f(a) * std::sin(w * a) + f(b) * std::sin(w * b));
    }
    c *= w, s *= w;  // d(wt) = w dt
    const Real D = diameter, Um = max_speed;
    return {3 * c / (4 * D * Um * Um), -4 * s / (std::numbers::pi * std::numbers::pi * D * D * Um * w)};
  }
};

}  // namespace alefsi::scenes
