#pragma once
/// \file sim/collision_contact.hpp
/// The contact model behind the `ContactModel<D>` seam (sim/contact.hpp) in 2D and 3D: the
/// repulsive short-range force of the paper's eq. (24) and the optional spring safeguard
/// (physics/collision.hpp, `CollisionModel<D>`), exact distances between disks/spheres and
/// from them to the walls, facet distances (segments, triangles) for other shapes.
///
/// Without forces (`CollisionContact<D>()`) the model still measures: the flow refuses a scene
/// whose bodies overlap at t0, rejects a step whose positions would overlap, and reports the
/// gaps. Overlaps are between bodies only (a body crossing a wall is caught by the mesh: its
/// cells would invert).
///
///     flow.set_collisions({.range = 0.1, .spring_range = 0.04, .spring_force = 50 * weight});
///     // = flow.set_contact_model(std::make_unique<CollisionContact<D>>(options))
#include <limits>
#include <memory>
#include <vector>

#include "alefsi/physics/collision.hpp"
#include "alefsi/sim/contact.hpp"

namespace alefsi {

template <int D>
class CollisionContact final : public ContactModel<D> {
 public:
  using Visit = typename ContactModel<D>::Visit;
  /// Geometry only: gaps and overlap checks, no forces.
  CollisionContact() = default;
  /// With the forces of `options` (validated).
  explicit CollisionContact(const CollisionOptions& options) : model_(options), forces_(true) {}

  void set_walls(const Mesh<D>& mesh, const std::vector<int>& body_tags) override {
    std::vector<Facet<D>> walls;
    for (Index f : mesh.boundary_facets()) {
      bool body = false;
      for (int tag : body_tags) body |= tag == mesh.facet_tag(f);
      if (body) continue;
      Facet<D> x;
      for (int i = 0; i < D; ++i) x[i] = mesh.node(mesh.facet(f)[i]);
      walls.push_back(x);
    }
    model_.set_walls(std::move(walls));
  }

  std::vector<ContactOverlap> overlaps(const std::vector<ContactBody<D>>& bodies) const override {
    std::vector<ContactOverlap> out;
    for (const auto& p : model_.geometry().near(convert(bodies), 0, 0, false)) out.push_back({p.k, p.j, p.gap});
    return out;
  }

  std::vector<Real> gaps(const std::vector<ContactBody<D>>& bodies) const override {
    std::vector<Real> g(bodies.size(), std::numeric_limits<Real>::infinity());
    for (const auto& p : model_.geometry().near(convert(bodies), std::numeric_limits<Real>::infinity(), 0, true)) {
      g[p.k] = std::min(g[p.k], p.gap);
      if (p.j >= 0) g[p.j] = std::min(g[p.j], p.gap);
    }
    return g;
  }

  std::vector<Real> times_to_contact(const std::vector<ContactBody<D>>& bodies) const override {
    return model_.geometry().times_to_contact(convert(bodies));
  }

  int find(const std::vector<ContactBody<D>>& bodies, Real mu) override {
    contacts_.clear();
    bodies_.clear();
    if (!forces_ || bodies.empty()) return 0;
    bodies_ = convert(bodies);
    contacts_ = model_.contacts(bodies_, mu);
    return int(contacts_.size());
  }

  void forces(const std::vector<Vec<D>>& v, const Visit& visit) const override {
    if (contacts_.empty()) return;
    auto cb = bodies_;
    for (std::size_t k = 0; k < cb.size(); ++k) cb[k].velocity = v[k];
    for (const auto& c : contacts_) {
      const Vec<D> F = CollisionModel<D>::force(c, cb);
      const Mat<D> dF = CollisionModel<D>::dforce_dvk(c, cb);
      visit(c.k, F, dF, c.arm_k, c.j);  // dF_j / dV_j = -dF_k / dV_j = dF_k / dV_k
      if (c.j >= 0) visit(c.j, Vec<D>(-F), dF, c.arm_j, c.k);
    }
  }

  /// The contacts found by the last `find`.
  const std::vector<Contact<D>>& contacts() const { return contacts_; }

 private:
  static std::vector<CollisionBody<D>> convert(const std::vector<ContactBody<D>>& bodies) {
    std::vector<CollisionBody<D>> out(bodies.size());
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      const auto& b = bodies[k];
      out[k] = {b.centre, b.velocity, b.radius, b.r_in, b.r_out, b.surface, b.convex};
    }
    return out;
  }

  CollisionModel<D> model_;
  bool forces_ = false;
  std::vector<CollisionBody<D>> bodies_;
  std::vector<Contact<D>> contacts_;
};
using CollisionContact2D = CollisionContact<2>;

/// Both dimensions: the geometry-only model, and eq. (24) + spring for `set_collisions`.
template <int D>
  requires(D == 2 || D == 3)
struct DefaultContact<D> {
  static std::unique_ptr<ContactModel<D>> geometry() { return std::make_unique<CollisionContact<D>>(); }
  static std::unique_ptr<ContactModel<D>> collisions(const CollisionOptions& opt) {
    return std::make_unique<CollisionContact<D>>(opt);
  }
};

}  // namespace alefsi
