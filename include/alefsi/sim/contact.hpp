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
///     current Newton iterate. For each contact, `visit(body, F, dF, arm, other)` is called on
///     each free or driven body it acts on with the force F on that body, dF = dF/dV of that
///     body's own translational velocity, `arm`, from the body's centre to the point where F
///     acts (0: through the centre), and `other`, the body on the contact's other side (-1: a
///     wall). F depends on the velocities through V_body - V_other only, so dF/dV_other = -dF.
///     The flow subtracts the force and its moment arm x F from the body's rows, their
///     derivatives from its Jacobian block, and the coupling to the other body's velocity
///     through a dense block beside the assembled pattern (la/coupling.hpp, sim/body_system.hpp).
///
/// Models: `NoContact<D>` (no forces, no gaps, no overlap checks) and `CollisionContact<D>`
/// (sim/collision_contact.hpp, 2D and 3D: the paper's eq. (24) made repulsive, the spring
/// safeguard, exact disk and sphere distances). Adding a model: derive from ContactModel<D>,
/// implement the five functions, and hand it to `AleFlow::set_contact_model`
/// (docs/architecture.md, "How to add a contact model").
#include <array>
#include <functional>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/physics/convex.hpp"

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
  /// radius == 0 and there is no `convex` shape.
  std::vector<std::array<Vec<D>, D>> surface;
  /// The body's exact convex shape in world coordinates, if it has one (physics/convex.hpp).
  alefsi::convex::Support<D> convex;
};

/// Two bodies whose surfaces overlap (gap <= 0).
struct ContactOverlap {
  int k = -1, j = -1;
  Real gap = 0;
};

template <int D>
class ContactModel {
 public:
  using Visit =
      std::function<void(int body, const Vec<D>& force, const Mat<D>& dforce, const Vec<D>& arm, int other)>;
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

/// Another model with the coupling between two bodies hidden: each force is visited as if its
/// other side were a wall, so the flow lags dF/dV_other (Newton then converges linearly while
/// two bodies touch, to the same solution). For measuring what the coupling buys (the
/// collision tests, bench/contact_newton.cpp); the forces are the model's.
template <int D>
class LaggedPairCoupling final : public ContactModel<D> {
 public:
  explicit LaggedPairCoupling(std::unique_ptr<ContactModel<D>> model) : model_(std::move(model)) {
    ALEFSI_CHECK_ARG(model_ != nullptr, "model", "is empty");
  }
  void set_walls(const Mesh<D>& mesh, const std::vector<int>& body_tags) override { model_->set_walls(mesh, body_tags); }
  std::vector<ContactOverlap> overlaps(const std::vector<ContactBody<D>>& b) const override { return model_->overlaps(b); }
  std::vector<Real> gaps(const std::vector<ContactBody<D>>& b) const override { return model_->gaps(b); }
  std::vector<Real> times_to_contact(const std::vector<ContactBody<D>>& b) const override {
    return model_->times_to_contact(b);
  }
  int find(const std::vector<ContactBody<D>>& b, Real mu) override { return model_->find(b, mu); }
  void forces(const std::vector<Vec<D>>& v, const typename ContactModel<D>::Visit& visit) const override {
    model_->forces(v, [&](int b, const Vec<D>& F, const Mat<D>& dF, const Vec<D>& arm, int) { visit(b, F, dF, arm, -1); });
  }

 private:
  std::unique_ptr<ContactModel<D>> model_;
};

/// The contact models a flow of dimension D starts with: `geometry()` (no forces; gaps and
/// overlap checks where the dimension has them) and, where the dimension has one,
/// `collisions(CollisionOptions)` (what `AleFlow::set_collisions` installs); 2D and 3D:
/// sim/collision_contact.hpp.
template <int D>
struct DefaultContact;

}  // namespace alefsi
