#pragma once
/// \file scenes/spheres_settling_in_box.hpp
/// Spheres of one density settling in a closed box of fluid (3D): the scene of ten Cate et al.'s
/// sphere (examples/ten_cate.cpp) and of two spheres drafting, kissing and tumbling
/// (examples/dkt3d.cpp). It holds the physical data and the mesh sizes, checks them, gives the
/// size function of the mesher and the remesher, and configures a flow:
///   - no-slip walls on the box's six faces;
///   - the spheres as free bodies (`sphere_body`, density rho_p), at rest or moving at
///     `velocities`;
///   - gravity along -z with the spheres' exact buoyancy (`Buoyancy::exact`: with rho_p / rho_f
///     near 1 the volume error of the polyhedral holes would enter the net weight
///     rho_f / (rho_p - rho_f) times over);
///   - contact between the spheres and with the walls by eq. (24) on the normal approach speed
///     (`CollisionLaw::lubrication`: the paper's |V| form makes a landing sphere rebound,
///     docs/results.md) and a spring of range h_body / 2 carrying `spring_weights` buoyant
///     weights at contact, so that a sphere rests on the floor at a gap of about h_body / 4.
/// The mesh (gmsh_box_mesh, alefsi::gmsh) and the remesher (Remesher3D) are the caller's, given
/// `box`, `spheres` and `size_rule()`; this header needs only Eigen.
///
///     scenes::SpheresSettlingInBox scene{.box = box, .spheres = {{Vec<3>(0, 0, 0.1275), 0.0075, 7}},
///                                         .rho_f = 960, .mu = 0.058, .rho_p = 1120, .g = 9.81,
///                                         .h_body = 0.0019, .h_far = 0.01};
///     Mesh<3> mesh = gmsh_box_mesh(scene.box, scene.spheres, scene.size_rule()(scene.spheres));
///     Flow flow(std::move(mesh), scene.flow_options());
///     scene.configure(flow);
///     flow.set_remesher(std::make_unique<Remesher3D>(Remesh3DOptions{.box = scene.box, .size = scene.size_rule()}));
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/spheres_in_box.hpp"
#include "alefsi/physics/collision.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/sim/config.hpp"

namespace alefsi::scenes {

struct SpheresSettlingInBox {
  BoxDomain box;
  std::vector<Sphere> spheres;  ///< centres at t = 0, radii, surface tags (distinct from the box's)
  Real rho_f = 1, mu = 1;       ///< the fluid
  Real rho_p = 2;               ///< the spheres' density
  Real g = 1;                   ///< gravity's magnitude, along -z
  Real h_body = 0.1, h_far = 1, grading = 0.25;  ///< mesh sizes: graded_size(spheres, h_body, h_far, grading)
  Real spring_weights = 4;  ///< the spring's force at contact, in buoyant weights of the smallest sphere
  std::vector<Vec<3>> velocities{};  ///< the spheres' velocities at t = 0, one per sphere (empty: at rest)

  void validate() const {
    box.validate();
    ALEFSI_CHECK_ARG(!spheres.empty(), "spheres", "must hold at least one sphere");
    check_spheres_in_box(box, spheres);
    ALEFSI_CHECK_ARG(rho_f > 0 && std::isfinite(rho_f), "rho_f", "must be positive and finite, got ", rho_f);
    ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "must be positive and finite, got ", mu);
    ALEFSI_CHECK_ARG(rho_p > rho_f && std::isfinite(rho_p), "rho_p",
                     "must exceed rho_f = ", rho_f, " (the spheres settle onto the floor) and be finite, got ", rho_p);
    ALEFSI_CHECK_ARG(g > 0 && std::isfinite(g), "g", "must be positive and finite, got ", g);
    ALEFSI_CHECK_ARG(h_body > 0 && std::isfinite(h_body), "h_body", "must be positive and finite, got ", h_body);
    ALEFSI_CHECK_ARG(h_far >= h_body && std::isfinite(h_far), "h_far", "must be finite and >= h_body, got ", h_far);
    ALEFSI_CHECK_ARG(grading > 0 && std::isfinite(grading), "grading", "must be positive and finite, got ", grading);
    ALEFSI_CHECK_ARG(spring_weights > 1 && std::isfinite(spring_weights), "spring_weights",
                     "must exceed 1 (the spring must carry a sphere) and be finite, got ", spring_weights);
    ALEFSI_CHECK_ARG(velocities.empty() || velocities.size() == spheres.size(), "velocities",
                     "must be empty (at rest) or hold one per sphere (", spheres.size(), "), got ", velocities.size());
    for (std::size_t k = 0; k < velocities.size(); ++k)
      ALEFSI_CHECK_ARG(velocities[k].allFinite(), "velocities[" + std::to_string(k) + "]", "must be finite");
  }

  FlowOptions flow_options() const { return {.rho = rho_f, .mu = mu}; }

  /// The mesh size around spheres at the given places (the mesher's and the remesher's).
  std::function<SizeFunction3D(const std::vector<Sphere>&)> size_rule() const {
    return [h_body = h_body, h_far = h_far, grading = grading](const std::vector<Sphere>& s) {
      return graded_size(s, h_body, h_far, grading);
    };
  }

  /// The weight of sphere k less the fluid's on its volume.
  Real buoyant_weight(std::size_t k) const {
    const Real r = spheres.at(k).radius;
    return (rho_p - rho_f) * 4.0 / 3.0 * std::numbers::pi * r * r * r * g;
  }
  /// Eq. (24) on the approach speed with the paper's delta = Rbar / 10, and the spring (file
  /// comment).
  CollisionOptions collisions() const {
    Real lightest = std::numeric_limits<Real>::infinity();
    for (std::size_t k = 0; k < spheres.size(); ++k) lightest = std::min(lightest, buoyant_weight(k));
    return {.range = 0.1,
            .spring_range = 0.5 * h_body,
            .spring_force = spring_weights * lightest,
            .law = CollisionLaw::lubrication};
  }

  /// No-slip walls, the free spheres (moving at `velocities`, if given), gravity with exact
  /// buoyancy, the contacts.
  template <class Flow>
  void configure(Flow& flow) const {
    validate();
    for (int t : box.tags) flow.set_velocity(t, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
    for (std::size_t k = 0; k < spheres.size(); ++k) {
      auto body = sphere_body(spheres[k].tag, spheres[k].centre, spheres[k].radius, rho_p);
      if (!velocities.empty()) body.velocity.template head<3>() = velocities[k];
      flow.add_body(body);
    }
    flow.set_gravity(Vec<3>(0, 0, -g), Buoyancy::exact);
    flow.set_collisions(collisions());
  }
};

}  // namespace alefsi::scenes
