#pragma once
/// \file sim/contact.hpp
/// The seam between the flow and a contact (collision) model: `ContactModel<D>`.
///
/// The flow hands a contact model the bodies as `ContactBody<D>` (world coordinates, at one time
/// level) and asks it four things:
///   - `set_walls(mesh, body_tags)`: the fixed walls, once per mesh topology (every boundary
///     facet whose tag is not a body's);
///   - `overlaps(bodies)`: pairs of bodies whose surfaces overlap — a scene is refused at t0
///     and a step is rejected (SolverError) when the positions it would give overlap;
///   - `gaps(bodies)`: per body, the smallest distance to another body or a wall (run()'s CSV),
///     and `times_to_contact(bodies)`: gap over closing speed (the adaptive driver's event);
///   - `find(bodies, mu)` then `forces(velocities, visit)`: the contacts of the step being
///     solved, from the bodies placed at t^{n+1}, and their forces at the velocities of the
///     current Newton iterate. For each contact, `visit(body, F, dF)` is called on each free or
///     driven body it acts on with the force F on that body and dF = dF/dV of that body's own
///     translational velocity (the coupling between two bodies' rows is lagged: it is not in
///     the pattern). The flow adds -F to the body's force rows and -dF to its Jacobian block.
/// The force acts at the centre of mass (no torque) in the models here; a model for non-convex
/// or non-spherical shapes would add the torque of the contact point (issue 16).
///
/// Models: `NoContact<D>` (no forces, no gaps, no overlap checks: what 3D has until a 3D model
/// exists) and `CollisionContact2D` (sim/contact2d.hpp: the paper's eq. (24) made repulsive, the
/// spring safeguard, exact disk distances). Adding a model: derive from ContactModel<D>,
/// implement the five functions, and hand it to `AleFlow::set_contact_model`
/// (docs/architecture.md, "How to add a contact model").
#include <array>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "alefsi/core/types.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

/// A body as a contact model sees it, at one time level.
template <int D>
struct ContactBody {
  Vec<D> centre = Vec<D>::Zero();
  Vec<D> velocity = Vec<D>::Zero();  ///< translational velocity V
  Real radius = 0;                   ///< > 0: a disk / sphere of this radius (exact distances)
  Real r_in = 0;                     ///< smallest distance from the centre to the surface
  Real r_out = 0;                    ///< largest distance from the centre to the surface
  /// The surface facets in world coordinates (2D: segments, 3D: triangles); filled only when
  /// radius == 0.
  std::vector<std::array<Vec<D>, D>> surface;
};

/// Two bodies whose surfaces overlap (gap <= 0).
struct ContactOverlap {
  int k = -1, j = -1;
  Real gap = 0;
};

template <int D>
class ContactModel {
 public:
  using Visit = std::function<void(int body, const Vec<D>& force, const Mat<D>& dforce)>;
  virtual ~ContactModel() = default;
  /// The fixed walls: the boundary facets of `mesh` whose tag is none of `body_tags`.
  virtual void set_walls(const Mesh<D>& mesh, const std::vector<int>& body_tags) = 0;
  /// Pairs of bodies whose surfaces overlap (gap <= 0).
  virtual std::vector<ContactOverlap> overlaps(const std::vector<ContactBody<D>>& bodies) const = 0;
  /// Per body, the smallest gap to another body or a wall (infinity if none is known).
  virtual std::vector<Real> gaps(const std::vector<ContactBody<D>>& bodies) const = 0;
  /// Per body, the smallest time to contact, gap / closing speed, over the bodies and walls it
  /// approaches (infinity if none): the collision event of adaptive runs (sim/driver.hpp). The
  /// default knows no distances.
  virtual std::vector<Real> times_to_contact(const std::vector<ContactBody<D>>& bodies) const {
    return std::vector<Real>(bodies.size(), std::numeric_limits<Real>::infinity());
  }
  /// Finds the contacts of the step (bodies at t^{n+1}) for viscosity mu; returns their number.
  virtual int find(const std::vector<ContactBody<D>>& bodies, Real mu) = 0;
  /// Visits the forces of the contacts found, at the bodies' translational velocities `v`.
  virtual void forces(const std::vector<Vec<D>>& v, const Visit& visit) const = 0;
};

/// No contact: bodies pass through each other and the walls unless the mesh stops them.
template <int D>
class NoContact final : public ContactModel<D> {
 public:
  void set_walls(const Mesh<D>&, const std::vector<int>&) override {}
  std::vector<ContactOverlap> overlaps(const std::vector<ContactBody<D>>&) const override { return {}; }
  std::vector<Real> gaps(const std::vector<ContactBody<D>>& bodies) const override {
    return std::vector<Real>(bodies.size(), std::numeric_limits<Real>::infinity());
  }
  int find(const std::vector<ContactBody<D>>&, Real) override { return 0; }
  void forces(const std::vector<Vec<D>>&, const typename ContactModel<D>::Visit&) const override {}
};

/// The contact models a flow of dimension D starts with: `geometry()` (no forces; gaps and
/// overlap checks where the dimension has them) and, where the dimension has one,
/// `collisions(CollisionOptions)` (what `AleFlow::set_collisions` installs). 2D: sim/contact2d.hpp.
template <int D>
struct DefaultContact;

/// 3D: no contact model yet (issue 15 adds sphere-sphere and sphere-plane).
template <>
struct DefaultContact<3> {
  static std::unique_ptr<ContactModel<3>> geometry() { return std::make_unique<NoContact<3>>(); }
};

}  // namespace alefsi
