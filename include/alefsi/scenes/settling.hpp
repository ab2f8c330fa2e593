#pragma once
/// \file scenes/settling.hpp
/// Bodies settling in a 2D channel [0, width] x [0, height] (tags bottom 1, right 2, top 3,
/// left 4), built once for the examples, tests and benchmarks:
///   - `SettlingDisks`: free disks in the closed channel (the paper's section 6.2, drafting,
///     kissing and tumbling, and its variants);
///   - `SettlingEllipse`: one free ellipse in the closed channel, with exact buoyancy.
/// Both: no-slip walls, bodies of density rho_s, gravity, remeshing around the bodies, and the
/// collision model (eq. 24 + spring) with a fixed spring range.
///
///     auto scene = scenes::SettlingDisks::dkt(0.001);        // the paper's pair
///     AleFlow<FlowConfig<2, P1P1Gls, BDF2_BDF2E>> flow(scene.mesh(0.02, 0.15), {.rho = 1, .mu = 0.01});
///     scene.configure(flow, 0.02, 0.15);
#include <cmath>
#include <numbers>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/fem/geometry.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/physics/collision.hpp"
#include "alefsi/physics/convex.hpp"
#include "alefsi/physics/mass_properties.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/sim/config.hpp"
#include "alefsi/sim/remesher2d.hpp"

namespace alefsi::scenes {

namespace detail {
/// Remeshing of the channel [0, width] x [0, height], the size graded from h_body at the
/// bodies' current circles (a non-disk body's bounding circle) to h_far.
inline RemeshOptions channel_remeshing(Real width, Real height, bool enabled, Real h_body, Real h_far) {
  return {.enabled = enabled,
          .walls = {channel_outline(width, height)},
          .size = [=](const std::vector<Circle>& now) { return graded_size(now, h_body, h_far); },
          .adapt = {}};
}
/// No-slip on the channel's four walls.
template <class Flow>
void no_slip_channel(Flow& flow) {
  for (int tag : {tags::bottom, tags::right, tags::top, tags::left})
    flow.set_velocity(tag, [](const Vec<2>&, Real) { return Vec<2>(0, 0); });
}
}  // namespace detail

struct SettlingDisks {
  Real width = 2, height = 6;  ///< the channel (cm)
  std::vector<Circle> disks;   ///< centres, radii and tags at t0
  Real rho_s = 1.5;            ///< density of the disks (g/cm^3)
  Real rho_f = 1;              ///< density of the fluid (for the net weight)
  Vec<2> gravity = Vec<2>(0, -980);
  bool collisions = true;
  Real spring_range = 0.04;    ///< the spring's range (a model parameter, the same on every mesh)
  Real spring_weights = 50;    ///< the spring's force at contact, in net weights of the first disk
  bool remeshing = true;

  /// The paper's pair: disks of radius 0.125 at (1 - offset, 5) (tag 5) and (1, 4.5) (tag 6).
  static SettlingDisks dkt(Real offset = 0.001) {
    SettlingDisks s;
    s.disks = {{Vec<2>(1 - offset, 5), 0.125, 5}, {Vec<2>(1, 4.5), 0.125, 6}};
    return s;
  }
  /// The net weight (rho_s - rho_f) pi R^2 |g| of disk k.
  Real net_weight(std::size_t k = 0) const {
    const Real R = disks.at(k).radius;
    return (rho_s - rho_f) * std::numbers::pi * R * R * gravity.norm();
  }
  Mesh<2> mesh(Real h_body, Real h_far) const { return channel_with_disks(width, height, disks, h_body, h_far); }
  /// Remeshing with the size graded from h_body at the disks' current places to h_far.
  RemeshOptions remesh_options(Real h_body, Real h_far) const {
    return detail::channel_remeshing(width, height, remeshing, h_body, h_far);
  }
  /// eq. (24) with delta = R/10, plus the Glowinski spring (collision.hpp).
  CollisionOptions collision_options() const {
    return {.range = 0.1, .spring_range = spring_range, .spring_force = spring_weights * net_weight()};
  }
  /// No-slip walls, the free disks, gravity, collisions and remeshing (for sizes h_body, h_far).
  template <class Flow>
  void configure(Flow& flow, Real h_body, Real h_far) const {
    detail::no_slip_channel(flow);
    for (const Circle& c : disks) flow.add_body(disk_body(c.tag, c.centre, c.radius, rho_s));
    flow.set_gravity(gravity);
    if (collisions) flow.set_collisions(collision_options());
    flow.set_remeshing(remesh_options(h_body, h_far));
  }
};

/// One free ellipse settling in a vertical channel. Defaults: the set-up of Xia et al. (2009,
/// J. Fluid Mech. 625, 249) as the Feel++ ALE benchmark states it (Berti et al., hal-03835136;
/// its ellipsoid_2d case): channel 0.4 x 2.8 cm, ellipse semi-axes 0.05 and 0.025 cm (aspect
/// ratio 2, blockage 2a / width = 0.25), centre (0.2, 2.4) on the centreline, major axis at 45
/// degrees, rho_s = 1.1, fluid rho_f = 1 (mu = 0.01 g / (cm s) is the flow's), g = 981 cm/s^2.
/// The top here is a no-slip wall (Feel++'s is an outlet): with every boundary velocity given,
/// the buoyancy is exact (Buoyancy::exact), not the pressure on the polygon, whose O(h^2) area
/// error the density ratio amplifies tenfold in the net weight. No net flux crosses the top in
/// either set-up (the rest of the boundary is closed).
struct SettlingEllipse {
  Real width = 0.4, height = 2.8;  ///< the channel (cm)
  Ellipse ellipse{Vec<2>(0.2, 2.4), 0.05, 0.025, std::numbers::pi / 4, 5};  ///< at t0 (angle: major axis from x)
  Real rho_s = 1.1;
  Real rho_f = 1;
  Vec<2> gravity = Vec<2>(0, -981);
  bool collisions = true;
  Real spring_range = 0.005;   ///< the spring's range (cm)
  Real spring_weights = 50;    ///< the spring's force at contact, in net weights
  bool remeshing = true;
  bool curved = false;         ///< isoparametric P2 cells on the ellipse (Taylor–Hood only)

  void validate() const {
    ALEFSI_CHECK_ARG(width > 0 && height > 0 && std::isfinite(width) && std::isfinite(height), "width, height",
                     "must be positive and finite, got ", width, ", ", height);
    ALEFSI_CHECK_ARG(ellipse.a >= ellipse.b && ellipse.b > 0 && std::isfinite(ellipse.a), "ellipse",
                     "needs semi-axes a >= b > 0, got ", ellipse.a, ", ", ellipse.b);
    const Vec<2>& c = ellipse.centre;
    ALEFSI_CHECK_ARG(c[0] - ellipse.a > 0 && c[0] + ellipse.a < width && c[1] - ellipse.a > 0 &&
                         c[1] + ellipse.a < height,
                     "ellipse.centre", "the ellipse's bounding circle must lie inside the channel, centre (", c[0],
                     ", ", c[1], ")");
    ALEFSI_CHECK_ARG(rho_s > 0 && rho_f > 0 && std::isfinite(rho_s) && std::isfinite(rho_f), "rho_s, rho_f",
                     "must be positive and finite");
  }
  /// The net weight (rho_s - rho_f) pi a b |g|.
  Real net_weight() const { return (rho_s - rho_f) * std::numbers::pi * ellipse.a * ellipse.b * gravity.norm(); }
  /// Graded from h_body within the ellipse's bounding circle (radius a) to h_far.
  Mesh<2> mesh(Real h_body, Real h_far) const {
    validate();
    MesherOptions opt;
    opt.size = graded_size({bounding_circle()}, h_body, h_far);
    return generate_mesh(Domain2D{channel_outline(width, height), {ellipse}}, opt);
  }
  /// The free body: mass, inertia and area of the elliptic disk, its exact shape for contact.
  RigidBody2D body() const {
    const MassProperties2D m = mass_properties(ellipse, rho_s);
    RigidBody2D b;
    b.tag = ellipse.tag, b.mass = m.mass, b.inertia = m.inertia, b.centre = m.centre, b.angle = ellipse.angle;
    b.shape = convex::support_of<2>(convex::Ellipsoid<2>{Vec<2>(ellipse.a, ellipse.b)});
    b.volume = std::numbers::pi * ellipse.a * ellipse.b;  // exact buoyancy
    return b;
  }
  RemeshOptions remesh_options(Real h_body, Real h_far) const {
    return detail::channel_remeshing(width, height, remeshing, h_body, h_far);
  }
  /// eq. (24) with delta = 0.1 R-bar, plus the spring.
  CollisionOptions collision_options() const {
    return {.range = 0.1, .spring_range = spring_range, .spring_force = spring_weights * net_weight()};
  }
  template <class Flow>
  void configure(Flow& flow, Real h_body, Real h_far) const {
    validate();
    if constexpr (Flow::Space::VelocityElement::degree != 2)  // refused before the flow is touched
      if (curved) throw InvalidArgument("curved", "isoparametric cells need P2 velocities (Taylor–Hood)");
    detail::no_slip_channel(flow);
    flow.add_body(body());
    flow.set_gravity(gravity, Buoyancy::exact);
    if (collisions) flow.set_collisions(collision_options());
    flow.set_remeshing(remesh_options(h_body, h_far));
    if constexpr (Flow::Space::VelocityElement::degree == 2)
      if (curved) flow.curve_boundary(ellipse.tag, projection());
  }
  /// The nearest point on the ellipse at t0: its edge points' projection on curved cells.
  auto projection() const {
    return onto_ellipsoid<2>(ellipse.centre, Vec<2>(ellipse.a, ellipse.b),
                             Eigen::Rotation2D<Real>(ellipse.angle).toRotationMatrix());
  }

 private:
  Circle bounding_circle() const { return Circle{ellipse.centre, ellipse.a, ellipse.tag}; }
};

}  // namespace alefsi::scenes
