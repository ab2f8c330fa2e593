#pragma once
/// \file scenes/settling.hpp
/// Disks settling in a closed 2D channel (the paper's section 6.2, drafting, kissing and
/// tumbling, and its variants), built once for the examples, tests and benchmarks: the channel
/// [0, width] x [0, height] with no-slip walls (tags bottom 1, right 2, top 3, left 4), free
/// disks of density rho_s (tags as given), gravity; remeshing around the disks and the collision
/// model (eq. 24 + spring) with a fixed spring range.
///
///     auto scene = scenes::SettlingDisks::dkt(0.001);        // the paper's pair
///     AleFlow<FlowConfig<2, P1P1Gls, BDF2_BDF2E>> flow(scene.mesh(0.02, 0.15), {.rho = 1, .mu = 0.01});
///     scene.configure(flow, 0.02, 0.15);
#include <numbers>
#include <vector>

#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/physics/collision.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/sim/remesher2d.hpp"

namespace alefsi::scenes {

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
    return {.enabled = remeshing,
            .walls = {channel_outline(width, height)},
            .size = [=](const std::vector<Circle>& now) { return graded_size(now, h_body, h_far); },
            .adapt = {}};
  }
  /// eq. (24) with delta = R/10, plus the Glowinski spring (collision.hpp).
  CollisionOptions collision_options() const {
    return {.range = 0.1, .spring_range = spring_range, .spring_force = spring_weights * net_weight()};
  }
  /// No-slip walls, the free disks, gravity, collisions and remeshing (for sizes h_body, h_far).
  template <class Flow>
  void configure(Flow& flow, Real h_body, Real h_far) const {
    for (int tag : {tags::bottom, tags::right, tags::top, tags::left})
      flow.set_velocity(tag, [](const Vec<2>&, Real) { return Vec<2>(0, 0); });
    for (const Circle& c : disks) flow.add_body(disk_body(c.tag, c.centre, c.radius, rho_s));
    flow.set_gravity(gravity);
    if (collisions) flow.set_collisions(collision_options());
    flow.set_remeshing(remesh_options(h_body, h_far));
  }
};

}  // namespace alefsi::scenes
