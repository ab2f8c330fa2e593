#pragma once
/// \file sim/contact2d.hpp
/// Today's 2D contact model behind the `ContactModel<2>` seam (sim/contact.hpp): the repulsive
/// short-range force of the paper's eq. (24) and the optional spring safeguard
/// (physics/collision.hpp, `CollisionModel2D`), exact distances between disks and from a disk
/// to the walls, segment distances for other shapes.
///
/// Without forces (`CollisionContact2D()`) the model still measures: the flow refuses a scene
/// whose bodies overlap at t0, rejects a step whose positions would overlap, and reports the
/// gaps. Overlaps are between bodies only (a body crossing a wall is caught by the mesh: its
/// cells would invert).
///
///     flow.set_collisions({.range = 0.1, .spring_range = 0.04, .spring_force = 50 * weight});
///     // = flow.set_contact_model(std::make_unique<CollisionContact2D>(options))
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "alefsi/physics/collision.hpp"
#include "alefsi/sim/contact.hpp"

namespace alefsi {

class CollisionContact2D final : public ContactModel<2> {
 public:
  /// Geometry only: gaps and overlap checks, no forces.
  CollisionContact2D() = default;
  /// With the forces of `options` (validated).
  explicit CollisionContact2D(const CollisionOptions& options) : model_(std::in_place, options) {}

  void set_walls(const Mesh<2>& mesh, const std::vector<int>& body_tags) override {
    walls_.clear();
    for (Index f : mesh.boundary_facets()) {
      bool body = false;
      for (int tag : body_tags) body |= tag == mesh.facet_tag(f);
      if (!body) walls_.push_back({mesh.node(mesh.facet(f)[0]), mesh.node(mesh.facet(f)[1])});
    }
    if (model_) model_->set_walls(walls_);
  }

  std::vector<ContactOverlap> overlaps(const std::vector<ContactBody<2>>& bodies) const override {
    std::vector<ContactOverlap> out;
    if (bodies.size() < 2) return out;
    const CollisionModel2D probe(CollisionOptions{.range = 1e-9, .walls = false});
    for (const auto& c : probe.contacts(convert(bodies), 1.0))
      if (c.gap <= 0) out.push_back({c.k, c.j, c.gap});
    return out;
  }

  std::vector<Real> gaps(const std::vector<ContactBody<2>>& bodies) const override {
    CollisionModel2D model(CollisionOptions{.range = 1e6});
    model.set_walls(model_ ? model_->walls() : walls_);
    std::vector<Real> g(bodies.size(), std::numeric_limits<Real>::infinity());
    for (const auto& c : model.contacts(convert(bodies), 1.0)) {
      g[c.k] = std::min(g[c.k], c.gap);
      if (c.j >= 0) g[c.j] = std::min(g[c.j], c.gap);
    }
    return g;
  }

  std::vector<Real> times_to_contact(const std::vector<ContactBody<2>>& bodies) const override {
    std::vector<Real> t(bodies.size(), std::numeric_limits<Real>::infinity());
    auto take = [&](std::size_t k, Real gap, Real closing) {
      if (closing > 0) t[k] = std::min(t[k], std::max(gap, Real(0)) / closing);
    };
    // bodies: the normal points from j to k, the gap closes at -(V_k - V_j) . n
    CollisionModel2D model(CollisionOptions{.range = 1e6, .walls = false});
    for (const auto& c : model.contacts(convert(bodies), 1.0))
      if (c.j >= 0) {
        const std::size_t k = std::size_t(c.k), j = std::size_t(c.j);
        take(k, c.gap, -(bodies[k].velocity - bodies[j].velocity).dot(c.normal));
        t[j] = std::min(t[j], t[k]);
      }
    // every wall segment, not only the nearest (a disk sliding along a side wall still falls
    // toward the floor); a body without radius by its outer radius
    const auto& walls = model_ ? model_->walls() : walls_;
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      const Real r = bodies[k].radius > 0 ? bodies[k].radius : bodies[k].r_out;
      for (const auto& w : walls) {
        const Vec<2> d = bodies[k].centre - detail::closest_on_segment(bodies[k].centre, w);
        const Real dist = d.norm();
        if (dist > 0) take(k, dist - r, -bodies[k].velocity.dot(d / dist));
      }
    }
    return t;
  }

  int find(const std::vector<ContactBody<2>>& bodies, Real mu) override {
    contacts_.clear();
    bodies_.clear();
    if (!model_ || bodies.empty()) return 0;
    bodies_ = convert(bodies);
    contacts_ = model_->contacts(bodies_, mu);
    return int(contacts_.size());
  }

  void forces(const std::vector<Vec<2>>& v, const Visit& visit) const override {
    if (contacts_.empty()) return;
    auto cb = bodies_;
    for (std::size_t k = 0; k < cb.size(); ++k) cb[k].velocity = v[k];
    for (const auto& c : contacts_) {
      const Vec<2> F = CollisionModel2D::force(c, cb);
      const Mat<2> dF = CollisionModel2D::dforce_dvk(c, cb);
      visit(c.k, F, dF);  // dF_j / dV_j = -dF_k / dV_j = dF_k / dV_k
      if (c.j >= 0) visit(c.j, Vec<2>(-F), dF);
    }
  }

  /// The contacts found by the last `find`.
  const std::vector<Contact2D>& contacts() const { return contacts_; }

 private:
  static std::vector<CollisionBody2D> convert(const std::vector<ContactBody<2>>& bodies) {
    std::vector<CollisionBody2D> out(bodies.size());
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      const auto& b = bodies[k];
      out[k] = {b.centre, b.velocity, b.radius, b.r_in, b.r_out, b.surface};
    }
    return out;
  }

  std::optional<CollisionModel2D> model_;
  std::vector<Segment2D> walls_;
  std::vector<CollisionBody2D> bodies_;
  std::vector<Contact2D> contacts_;
};

/// 2D: the geometry-only model, and eq. (24) + spring for `set_collisions`.
template <>
struct DefaultContact<2> {
  static std::unique_ptr<ContactModel<2>> geometry() { return std::make_unique<CollisionContact2D>(); }
  static std::unique_ptr<ContactModel<2>> collisions(const CollisionOptions& opt) {
    return std::make_unique<CollisionContact2D>(opt);
  }
};

}  // namespace alefsi
