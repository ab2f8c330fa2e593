#pragma once
/// \file scenes/settling_sphere.hpp
/// A sphere settling from the centre of a closed spherical container (3D): a free sphere of
/// radius a and density rho_s (surface tag 1) inside a fixed no-slip sphere of radius b (tag 2)
/// filled with a fluid (rho_f, mu), under gravity along -z. The mesh is
/// `spherical_shell_mesh(a, b, layers)` with its layers pulled towards the body,
/// r = a + (b - a) t^grading (t in [0, 1] across the gap), and follows the body by elasticity.
/// With `start` != 0 the sphere starts off centre: each node at radius r moves by
/// (1 - (r - a) / (b - a)) start, so the body's nodes are on the sphere of centre `start`, the
/// container's stay, and no cell inverts (the map's Jacobian determinant is at least
/// 1 - |start| / (b - a) > 0).
///
/// With `collisions()` (eq. 24 + spring, physics/collision.hpp; the container's triangles are
/// the wall) the sphere comes to rest on the bottom, where the spring carries its buoyant
/// weight W' = (m - rho_f V) |g|: the gap is rho (1 - sqrt(W' / F_0)) (`resting_gap`).
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
#include "alefsi/physics/collision.hpp"
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
  Vec<3> start = Vec<3>::Zero();      ///< the sphere's centre at t = 0 (|start| < b - a)
  Real spring_range = 0.05;           ///< collisions(): the spring's range rho (cm)
  Real spring_weights = 4;            ///< collisions(): the spring's force at contact, in buoyant weights
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
    ALEFSI_CHECK_ARG(start.allFinite() && start.norm() < b - a, "start",
                     "must leave the sphere inside the container (|start| < b - a = ", b - a, "), got |start| = ",
                     start.norm());
    ALEFSI_CHECK_ARG(spring_range > 0 && std::isfinite(spring_range), "spring_range",
                     "must be positive and finite, got ", spring_range);
    ALEFSI_CHECK_ARG(spring_weights > 1 && std::isfinite(spring_weights), "spring_weights",
                     "must exceed 1 (the spring must carry the sphere) and be finite, got ", spring_weights);
  }

  FlowOptions flow_options() const { return {.rho = rho_f, .mu = mu}; }

  Mesh<3> mesh() const {
    validate();
    Mesh<3> m = spherical_shell_mesh(a, b, layers);
    std::vector<Vec<3>> x = m.coordinates();
    for (Vec<3>& p : x) {  // every node's radius is in [a, b] (on both spheres exactly)
      const Real r = p.norm(), t = std::clamp((r - a) / (b - a), Real(0), Real(1));
      const Real graded = a + (b - a) * std::pow(t, grading);
      p *= graded / r;
      p += (1 - (graded - a) / (b - a)) * start;  // linear in the radius: J = I - start r^T / (r (b - a))
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

  /// The sphere's weight less the fluid's on volume `volume` (default: the exact sphere's).
  Real buoyant_weight(Real volume = 0) const {
    const Real v = 4.0 / 3.0 * std::numbers::pi * a * a * a;
    return (rho_s * v - rho_f * (volume > 0 ? volume : v)) * gravity.norm();
  }
  /// The collision model: eq. (24) with the paper's delta = a / 10, and the spring of range
  /// `spring_range` and force `spring_weights` buoyant weights at contact (a light sphere rises
  /// and rests against the top).
  CollisionOptions collisions() const {
    return {.range = 0.1, .spring_range = spring_range, .spring_force = spring_weights * std::abs(buoyant_weight())};
  }
  /// The gap at rest on the container's wall: where the spring carries W' (of the sphere of
  /// volume `volume`: the mesh's hole, whose pressure force is the discrete buoyancy).
  Real resting_gap(Real volume = 0) const {
    return spring_range * (1 - std::sqrt(std::abs(buoyant_weight(volume) / (spring_weights * buoyant_weight()))));
  }

  /// No-slip container, the free sphere at `start`, gravity.
  template <class Flow>
  void configure(Flow& flow) const {
    validate();
    flow.set_velocity(wall_tag, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
    flow.add_body(sphere_body(body_tag, start, a, rho_s));
    flow.set_gravity(gravity);
  }
};

}  // namespace alefsi::scenes
