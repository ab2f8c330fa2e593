#pragma once
/// \file scenes/settling_sphere.hpp
/// A sphere settling from the centre of a closed spherical container (3D): a free sphere of
/// radius a and density rho_s (surface tag 1) inside a fixed no-slip sphere of radius b (tag 2)
/// filled with a fluid (rho_f, mu), under gravity along -z. The mesh is
/// `spherical_shell_mesh(a, b, layers)` with its layers pulled towards the body,
/// r = a + (b - a) t^grading (t in [0, 1] across the gap), and follows the body by elasticity.
///
/// The reference for a slow (creeping) settling while the sphere is still near the centre:
/// the concentric-spheres drag (Haberman & Sayre 1958; Happel & Brenner, Low Reynolds Number
/// Hydrodynamics, 1965, eq. 4-22.7),
///     F = 6 pi mu a U K(lambda),  lambda = a / b,
///     K = (1 - lambda^5) / (1 - 9/4 lambda + 5/2 lambda^3 - 9/4 lambda^5 + lambda^6),
/// so the terminal velocity is U = (rho_s - rho_f) |g| (4/3 pi a^3) / (6 pi mu a K).
///
///     scenes::SettlingSphere scene;                    // a = 0.25 cm in b = 2 cm, mu = 10 P
///     AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E>> flow(scene.mesh(), scene.flow_options());
///     scene.configure(flow);
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/sim/config.hpp"

namespace alefsi::scenes {

struct SettlingSphere {
  Real a = 0.25, b = 2;               ///< radii of the sphere and the container (cm)
  Real rho_s = 1.5, rho_f = 1;        ///< densities (g/cm^3)
  Real mu = 10;                       ///< viscosity (P): Re = rho_f U 2a / mu = 0.025 at the terminal velocity
  Vec<3> gravity = Vec<3>(0, 0, -980);
  int layers = 2;                     ///< spherical_shell_mesh's n (336 n^3 tetrahedra)
  Real grading = 2;                   ///< exponent of the layers' pull towards the body (1: none)
  static constexpr int body_tag = tags::inner, wall_tag = tags::outer;

  void validate() const {
    ALEFSI_CHECK_ARG(a > 0 && std::isfinite(a), "a", "must be positive and finite, got ", a);
    ALEFSI_CHECK_ARG(b > a && std::isfinite(b), "b", "must be finite and exceed a = ", a, ", got ", b);
    ALEFSI_CHECK_ARG(rho_s > 0 && std::isfinite(rho_s), "rho_s", "must be positive and finite, got ", rho_s);
    ALEFSI_CHECK_ARG(rho_f > 0 && std::isfinite(rho_f), "rho_f", "must be positive and finite, got ", rho_f);
    ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "must be positive and finite, got ", mu);
    ALEFSI_CHECK_ARG(gravity.allFinite(), "gravity", "must be finite");
    ALEFSI_CHECK_ARG(layers >= 1, "layers", "must be >= 1, got ", layers);
    ALEFSI_CHECK_ARG(grading >= 1 && std::isfinite(grading), "grading", "must be >= 1 and finite, got ", grading);
  }

  FlowOptions flow_options() const { return {.rho = rho_f, .mu = mu}; }

  Mesh<3> mesh() const {
    validate();
    Mesh<3> m = spherical_shell_mesh(a, b, layers);
    std::vector<Vec<3>> x = m.coordinates();
    for (Vec<3>& p : x) {  // every node's radius is in [a, b] (on both spheres exactly)
      const Real r = p.norm(), t = std::clamp((r - a) / (b - a), Real(0), Real(1));
      p *= (a + (b - a) * std::pow(t, grading)) / r;
    }
    m.set_coordinates(std::move(x));
    return m;
  }

  /// The concentric-spheres wall factor K(a / b) (file comment).
  Real wall_factor() const {
    const Real l = a / b;
    return (1 - std::pow(l, 5)) / (1 - 2.25 * l + 2.5 * std::pow(l, 3) - 2.25 * std::pow(l, 5) + std::pow(l, 6));
  }
  /// The creeping-flow terminal speed with the sphere at the centre (file comment).
  Real terminal_speed() const {
    const Real net = (rho_s - rho_f) * gravity.norm() * 4.0 / 3.0 * std::numbers::pi * a * a * a;
    return net / (6 * std::numbers::pi * mu * a * wall_factor());
  }

  /// No-slip container, the free sphere at the centre, gravity.
  template <class Flow>
  void configure(Flow& flow) const {
    validate();
    flow.set_velocity(wall_tag, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
    flow.add_body(sphere_body(body_tag, Vec<3>::Zero(), a, rho_s));
    flow.set_gravity(gravity);
  }
};

}  // namespace alefsi::scenes
