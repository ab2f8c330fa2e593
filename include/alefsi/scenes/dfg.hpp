#pragma once
/// \file scenes/dfg.hpp
/// The DFG benchmark "flow around a cylinder" of Schäfer & Turek (1996), 2D: channel
/// [0, 2.2] x [0, 0.41] (walls tags 1 bottom, 3 top; outflow tag 2 on the right, do-nothing;
/// inflow tag 4 on the left, u = 4 U y (0.41 - y) / 0.41^2), a cylinder of diameter 0.1 centred
/// at (0.2, 0.2) (tag 5) held fixed as a driven body (so its drag and lift are the body's load),
/// rho = 1, nu = 1e-3. Case 2D-1: U = 0.3 (Re = 20, steady); 2D-2: U = 1.5 (Re = 100, periodic).
///
///     scenes::DfgCylinder scene{.U = 1.5};
///     AleFlow<FlowConfig<2, TaylorHood, BDF2_BDF2E>> flow(scene.mesh(0.005, 0.04), scene.options());
///     scene.configure(flow);
///     const Vec<2> cd_cl = scene.coefficients(flow.body_hydrodynamic_load(0));
#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

#include "alefsi/core/types.hpp"
#include "alefsi/mesh/adapt/locate.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/physics/rigid_body.hpp"

namespace alefsi::scenes {

struct DfgCylinder {
  static constexpr Real height = 0.41, length = 2.2, diameter = 0.1, nu = 1e-3;
  static constexpr int bottom = 1, outflow = 2, top = 3, inflow = 4, cylinder = 5;
  Real U = 0.3;        ///< the inflow's maximum speed (0.3: 2D-1, 1.5: 2D-2)
  Real ramp_time = 0;  ///< > 0: the inflow ramped up by sin^2 over this time
  Vec<2> centre = Vec<2>(0.2, 0.2);

  Real mean_speed() const { return 2.0 / 3.0 * U; }
  Real reynolds() const { return mean_speed() * diameter / nu; }

  /// Graded from h_body at the cylinder (+ 0.15 per unit distance) to h_far, finer in the wake.
  Mesh<2> mesh(Real h_body, Real h_far) const {
    Domain2D dom;
    dom.outer = Polyline{{Vec<2>(0, 0), Vec<2>(length, 0), Vec<2>(length, height), Vec<2>(0, height)},
                         0,
                         {bottom, outflow, top, inflow}};
    dom.holes.emplace_back(Circle{centre, diameter / 2, cylinder});
    const Vec<2> c = centre;
    const auto size = [=](const Vec<2>& x) {
      Real h = h_body + 0.15 * ((x - c).norm() - diameter / 2);
      if (x[0] > c[0]) h = std::min(h, std::max(h_body, 2 * h_body + 0.05 * std::abs(x[1] - c[1]) + 0.02 * (x[0] - c[0])));
      return std::min(h, h_far);
    };
    return generate_mesh(dom, MesherOptions{size});
  }
  /// The inflow's factor at t (1 after the ramp).
  Real ramp(Real t) const {
    if (ramp_time <= 0 || t >= ramp_time) return 1.0;
    const Real s = std::sin(0.5 * std::numbers::pi * t / ramp_time);
    return s * s;
  }
  /// Inflow, walls, and the cylinder held fixed; returns the body's index.
  template <class Flow>
  std::size_t configure(Flow& flow) const {
    const DfgCylinder s = *this;
    flow.set_velocity(inflow, [s](const Vec<2>& x, Real t) {
      return Vec<2>(s.ramp(t) * 4 * s.U * x[1] * (height - x[1]) / (height * height), 0);
    });
    for (int w : {bottom, top}) flow.set_velocity(w, [](const Vec<2>&, Real) { return Vec<2>(0, 0); });
    RigidBody2D body;
    body.tag = cylinder;
    body.centre = centre;
    body.radius = diameter / 2;
    body.prescribed = [](Real) { return Vec<3>(0, 0, 0); };
    return flow.add_body(body);
  }
  /// (c_D, c_L) = 2 (F_x, F_y) / (rho Um^2 D) of the load (F_x, F_y, T) on the cylinder (rho = 1).
  Vec<2> coefficients(const Vec<3>& load) const {
    const Real scale = 2 / (mean_speed() * mean_speed() * diameter);
    return {scale * load[0], scale * load[1]};
  }
  /// Delta p = p(0.15, 0.2) - p(0.25, 0.2) of the flow (P1 pressure; `loc` on the flow's mesh).
  template <class Flow>
  static Real pressure_difference(const Flow& flow, const PointLocator2D& loc) {
    auto p = [&](const Vec<2>& x) {
      const Location l = loc.find(x);
      const auto& cv = flow.mesh().cell(l.cell);
      const auto& sp = flow.space();
      Real v = 0;
      for (int i = 0; i < 3; ++i) v += l.lambda[i] * flow.field()[sp.pressure_field(sp.pressure().node_dof(cv[i]))];
      return v;
    };
    return p(Vec<2>(0.15, 0.2)) - p(Vec<2>(0.25, 0.2));
  }
};

}  // namespace alefsi::scenes
