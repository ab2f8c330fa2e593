#pragma once
/// \file scenes/annulus.hpp
/// The paper's annulus (section 6.3), built once for the examples, tests and benchmarks: fluid
/// between an outer cylinder of radius r2 (boundary tag tags::outer = 2) turning at omega(t) and
/// a free inner cylinder of radius r1 (tag tags::inner = 1) of density rho_s, driven by the
/// fluid. The outer wall's mesh velocity stays 0 (only the fluid velocity is driven there: a
/// tangential mesh velocity would move its nodes off the circle); the inner cylinder's surface
/// follows its exact rigid motion. Reference solution: reference/annulus.hpp.
///
///     scenes::Annulus scene{.rho_s = 1.25};
///     AleFlow<FlowConfig<2, TaylorHood, MR_AB>> flow(scene.mesh(0.04), {.rho = 1, .mu = 0.01});
///     scene.configure(flow);                  // the wall velocity and the inner body
///     scene.start_with_moving_wall(flow);     // u^0 = the wall's speed on its DOFs (impulsive start)
#include <algorithm>
#include <functional>
#include <numbers>
#include <set>
#include <utility>

#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/rigid_body.hpp"

namespace alefsi::scenes {

struct Annulus {
  Real r1 = 0.25, r2 = 1.0;  ///< inner and outer radius
  Real rho_s = 1.25;         ///< density of the inner cylinder
  /// Angular velocity of the outer wall at t (default: 1 from t = 0+, the impulsive start).
  std::function<Real(Real)> omega = [](Real) { return 1.0; };
  Vec<3> initial_velocity = Vec<3>::Zero();  ///< Z of the inner cylinder at t0
  Vec<3> external_load = Vec<3>::Zero();     ///< (F1, F2, T) on the inner cylinder

  /// The inner cylinder: a free disk (m = rho_s pi r1^2, I = m r1^2 / 2).
  RigidBody2D inner_body() const {
    RigidBody2D b = disk_body(tags::inner, Vec<2>::Zero(), r1, rho_s);
    b.velocity = initial_velocity;
    b.external_load = external_load;
    return b;
  }
  /// The outer wall's velocity omega(t) e_z x x.
  Vec<2> wall_velocity(const Vec<2>& x, Real t) const { return omega(t) * Vec<2>(-x[1], x[0]); }
  /// I^ = I / (2 pi rho r1^2 r2^2), the paper's nondimensional inertia (Figure 7; rho_s / 64 for
  /// the default radii), for fluid density rho.
  Real inertia_ratio(Real rho) const { return inner_body().inertia / (2 * std::numbers::pi * rho * r1 * r1 * r2 * r2); }

  /// An unstructured mesh of size h, graded towards the outer wall to h_wall when 0 < h_wall:
  /// h(x) = min(h, h_wall + (r2 - |x|) / 4).
  Mesh<2> mesh(Real h, Real h_wall = 0) const {
    if (h_wall <= 0) return annulus_unstructured(r1, r2, h);
    const Domain2D dom{Circle{Vec<2>::Zero(), r2, tags::outer}, {Circle{Vec<2>::Zero(), r1, tags::inner}}};
    const Real R2 = r2;
    return generate_mesh(dom, MesherOptions{[h, h_wall, R2](const Vec<2>& x) { return std::min(h, h_wall + 0.25 * (R2 - x.norm())); }});
  }

  /// The outer wall's velocity and the free inner cylinder; returns the body's index.
  template <class Flow>
  std::size_t configure(Flow& flow) const {
    flow.set_velocity(tags::outer, [s = *this](const Vec<2>& x, Real t) { return s.wall_velocity(x, t); });
    return flow.add_body(inner_body());
  }
  /// The consistent impulsive start: u^0 = the wall's velocity at t0 on the outer wall's
  /// velocity DOFs, 0 elsewhere (the jump lies inside the first cell layer).
  template <class Flow>
  void start_with_moving_wall(Flow& flow, Real t0 = 0) const {
    std::set<std::pair<Real, Real>> wall;  // positions of the outer wall's velocity DOFs
    const auto& vel = flow.space().velocity();
    for (Index i : vel.boundary_dofs(tags::outer)) wall.emplace(vel.point(i)[0], vel.point(i)[1]);
    flow.set_initial_velocity(
        [&](const Vec<2>& x) { return wall.count({x[0], x[1]}) ? wall_velocity(x, t0) : Vec<2>(Vec<2>::Zero()); }, t0);
  }
};

}  // namespace alefsi::scenes
