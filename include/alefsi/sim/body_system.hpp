#pragma once
/// \file sim/body_system.hpp
/// The rigid bodies of a flow and their coupling to it (section 3 of the paper), through a
/// rigid-body model M (physics/rigid_body.hpp, concept RigidBodyModel): the flow reads a body
/// only through M, so a new model changes nothing here.
///
/// What it does, per body k, with Z^k its rigid velocity ((V1, V2, w) in 2D, (V, w) in 3D):
///   - topology (after each mesh rebuild): the surface nodes (facets tagged with the body's
///     tag), the surface velocity DOFs, and for a free body `n_dof` extra unknowns and the
///     links u = H(x) Z + u_s of its surface DOFs (`attach`, `constrain`);
///   - the step's prediction: the extrapolated state that drives the mesh-velocity problem
///     (`mesh_velocity_data`: the rigid velocity of each surface node), the centre and
///     orientation at t^{n+1} by the scheme's position formula, and the surface nodes at
///     t^{n+1} by the exact rigid map (`advance`);
///   - the flow system: the surface velocities at t^{n+1} (Dirichlet data of a driven body,
///     link weights and offsets of a free one: at X^{n+theta} for its test functions, see
///     `set_surface_velocities`), the body rows M delta_l Z / dt (+ w x I_w w) - M g - F_ext
///     - F_contact and their exact Jacobian (`add_rows`), and after the solve Z^{n+1} and the
///     hydrodynamic load (`finish`);
///   - the hydrodynamic load of a driven body from the residual of the rows it would have if it
///     were free (`driven_loads`);
///   - views for the contact model and the remesher, and the reset of the surface after a
///     remesh (`reset_surface`, `reset_surface_velocities`).
/// The histories (centre, orientation, Z per level, loads, surface offsets) live in the flow
/// state (sim/flow_state.hpp); this class holds the bodies' descriptions, their topology and
/// the step's prediction.
///
///     BodySystem<2, RigidBodyTraits<2>> bodies;
///     bodies.add(disk_body(5, {1, 4.5}, 0.125, 1.5), mesh, t0, state.bodies);
#include <algorithm>
#include <array>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/geometry.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/coupling.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/physics/collision.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/sim/contact.hpp"
#include "alefsi/sim/flow_state.hpp"
#include "alefsi/sim/mesh_velocity.hpp"
#include "alefsi/sim/remesher.hpp"
#include "alefsi/time/stepper.hpp"

namespace alefsi {

template <int D, RigidBodyModel M>
class BodySystem {
  static_assert(M::dim == D, "the rigid-body model's dimension must be the flow's");

 public:
  using Model = M;
  using Body = typename M::Body;
  using Velocity = typename M::Velocity;
  using Orientation = typename M::Orientation;
  using State = BodyState<D, M>;
  static constexpr int n_dof = M::n_dof;

  // ---- registry -------------------------------------------------------------------------

  /// Registers `body` (validated, its surface = the boundary facets of `mesh` tagged with its
  /// tag) and appends its initial state at time t to `states`; returns its index.
  std::size_t add(const Body& body, const Mesh<D>& mesh, Real t, std::vector<State>& states) {
    const std::size_t k = entries_.size();
    M::validate(body, k);
    const int tag = M::tag(body);
    ALEFSI_CHECK_ARG(!mesh.boundary_nodes(tag).empty(), "body.tag", "bodies[", k, "]: no boundary facet has its tag ", tag);
    for (const auto& e : entries_)
      ALEFSI_CHECK_ARG(M::tag(e.data) != tag, "body.tag", "bodies[", k, "] has the tag ", tag, " of an earlier body");
    Entry e;
    e.data = body;
    e.nodes = mesh.boundary_nodes(tag);
    State s;
    s.centre.fill(M::initial_centre(body));
    s.orientation.fill(M::initial_orientation(body));
    s.velocity.fill(M::initial_velocity(body, t));
    for (Index v : e.nodes) s.surface.push_back(M::initial_offset(mesh.node(v) - M::initial_centre(body), body));
    entries_.push_back(std::move(e));
    states.push_back(std::move(s));
    return k;
  }
  std::size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  const Body& body(std::size_t k) const { return entries_.at(k).data; }
  std::vector<int> tags() const {
    std::vector<int> t;
    for (const auto& e : entries_) t.push_back(M::tag(e.data));
    return t;
  }
  bool has_tag(int tag) const {
    for (const auto& e : entries_)
      if (M::tag(e.data) == tag) return true;
    return false;
  }
  /// The index of the body with tag `tag`, or -1.
  int index_of(int tag) const {
    for (std::size_t k = 0; k < entries_.size(); ++k)
      if (M::tag(entries_[k].data) == tag) return int(k);
    return -1;
  }
  /// A world point x in body k's model frame (the frame of its surface offsets) when the body
  /// is at `centre` and `orientation`, and back (`from_model`).
  Vec<D> to_model(std::size_t k, const Vec<D>& x, const Vec<D>& centre, const Orientation& orientation) const {
    return M::to_body(x - centre, orientation, entries_.at(k).data);
  }
  Vec<D> from_model(std::size_t k, const Vec<D>& r, const Vec<D>& centre, const Orientation& orientation) const {
    return centre + M::to_world(r, orientation, entries_.at(k).data);
  }
  /// Surface mesh nodes of body k (sorted).
  const std::vector<Index>& surface_nodes(std::size_t k) const { return entries_.at(k).nodes; }

  // ---- topology ---------------------------------------------------------------------------

  /// Surface nodes and facets on a (new) mesh topology.
  void attach(const Mesh<D>& mesh) {
    for (auto& e : entries_) {
      e.nodes = mesh.boundary_nodes(M::tag(e.data));
      e.facets.clear();
      e.facet_ids.clear();
      for (Index f : mesh.boundary_facets())
        if (mesh.facet_tag(f) == M::tag(e.data)) {
          e.facets.push_back(mesh.facet(f));
          e.facet_ids.push_back(f);
        }
    }
  }

  /// The constraint structure of the surface velocity DOFs: fixed (driven bodies) or linked to
  /// n_dof new extra unknowns (free bodies). `taken` marks velocity DOFs already constrained
  /// (Dirichlet walls); a body surface touching one, or another body, is refused.
  template <class Space>
  void constrain(const Space& space, DofConstraints& cons, std::vector<char>& taken) {
    for (auto& e : entries_) {
      e.dofs.clear();
      e.cells.clear();
      const bool free = M::is_free(e.data);
      if (free) e.extra = cons.add_unknowns(n_dof);
      for (Index i : space.velocity().boundary_dofs(M::tag(e.data))) {
        ALEFSI_CHECK_ARG(!taken[i], "body.tag", "body surface (tag ", M::tag(e.data),
                         ") touches a Dirichlet wall or another body");
        taken[i] = 1;
        e.dofs.push_back(i);
        for (int k = 0; k < D; ++k) {
          const Index f = space.velocity_field(i, k);
          if (free) {
            std::array<Index, n_dof> ex;
            for (int C = 0; C < n_dof; ++C) ex[C] = e.extra + C;
            const std::array<Real, n_dof> w{};
            cons.link(f, ex, w, 0.0);
          } else {
            cons.fix(f, 0.0);
          }
        }
      }
    }
    // the cells around driven bodies, whose element residuals give those bodies' loads
    std::vector<int> owner(std::size_t(space.velocity().n_dofs()), -1);
    bool any = false;
    for (std::size_t k = 0; k < entries_.size(); ++k)
      if (!M::is_free(entries_[k].data)) {
        any = true;
        for (Index i : entries_[k].dofs) owner[i] = int(k);
      }
    if (!any) return;
    for (auto& e : entries_) e.dofs_sorted = e.dofs, std::sort(e.dofs_sorted.begin(), e.dofs_sorted.end());
    const auto& mesh = space.mesh();
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      int last = -1;
      for (Index i : space.velocity().cell_dofs(c))
        if (owner[i] >= 0 && owner[i] != last) {
          auto& cells = entries_[std::size_t(owner[i])].cells;
          if (cells.empty() || cells.back() != c) cells.push_back(c);
          last = owner[i];
        }
    }
  }

  /// Exact buoyancy (AleFlow::set_gravity with Buoyancy::exact): each body's weight becomes
  /// (m - rho_f V) g, V its exact area (disk: pi r^2) or volume (sphere: 4/3 pi r^3; any other
  /// body: the `volume` it was given), acting at its centre; rho_f = 0 restores m g. A body that
  /// is neither a disk / sphere nor has a volume is refused by name. Massless (force-free)
  /// bodies keep rows without gravity.
  void set_displaced_density(Real rho_f) {
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      auto& e = entries_[k];
      if (M::mass(e.data) == 0) continue;
      const Real r = M::radius(e.data);
      const Real V = r > 0 ? (D == 2 ? std::numbers::pi * r * r : 4.0 / 3.0 * std::numbers::pi * r * r * r)
                           : M::volume(e.data);
      ALEFSI_CHECK_ARG(rho_f == 0 || V > 0, "gravity", "exact buoyancy needs the displaced volume: bodies[", k,
                       "] (tag ", M::tag(e.data), ") is not a ", D == 2 ? "disk" : "sphere", " and has no volume");
      e.displaced = rho_f * V;
    }
  }

  /// Disks and spheres (M::radius > 0): every surface node at the radius from the centre.
  void check_radii(const Mesh<D>& mesh, const std::vector<State>& states) const {
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const auto& e = entries_[k];
      const Real radius = M::radius(e.data);
      if (radius <= 0) continue;
      for (Index v : e.nodes)
        ALEFSI_CHECK_ARG(std::abs((mesh.node(v) - states[k].centre[0]).norm() - radius) <= 1e-6 * radius,
                         "body.radius", "bodies[", k, "] (tag ", M::tag(e.data), "): surface node ", v, " is at distance ",
                         (mesh.node(v) - states[k].centre[0]).norm(), " from the centre, not the radius ", radius);
    }
  }

  /// Bodies with a convex shape (not disks / spheres): the shape must be the meshed surface. No
  /// surface node may lie outside the shape (by 1e-6 r_out), and the shape may not reach beyond
  /// a node, along the node's normal (the mean of its facets'), by more than half the node's
  /// longest facet edge: on a smooth surface the sag of the facets is far less, while a shape
  /// turned the wrong way, too small or too large is refused, naming the body and the node.
  void check_shapes(const std::vector<State>& states) const {
    if constexpr (requires(const Body& b) { M::shape(b); }) {
      for (std::size_t k = 0; k < entries_.size(); ++k) {
        const auto& e = entries_[k];
        const auto shape = M::shape(e.data);
        if (!shape || M::radius(e.data) > 0) continue;
        const auto& r0 = states[k].surface;  // offsets, in the shape's axes
        const Real r_out = reach(states[k]);
        std::vector<Vec<D>> normal(r0.size(), Vec<D>::Zero());
        std::vector<Real> edge(r0.size(), 0);
        for (const auto& f : e.facets) {
          std::array<std::size_t, D> j;
          for (int i = 0; i < D; ++i)
            j[i] = std::size_t(std::lower_bound(e.nodes.begin(), e.nodes.end(), f[i]) - e.nodes.begin());
          Vec<D> n, mid = Vec<D>::Zero();
          Real longest = 0;
          if constexpr (D == 2) {
            const Vec<2> t = r0[j[1]] - r0[j[0]];
            n = Vec<2>(t[1], -t[0]), longest = t.norm();
          } else {
            n = (r0[j[1]] - r0[j[0]]).cross(r0[j[2]] - r0[j[0]]);
            for (int i = 0; i < 3; ++i) longest = std::max(longest, (r0[j[(i + 1) % 3]] - r0[j[i]]).norm());
          }
          for (int i = 0; i < D; ++i) mid += r0[j[i]] / D;
          if (n.dot(mid) < 0) n = -n;  // outward: the surface is star-shaped about the centre
          for (int i = 0; i < D; ++i) normal[j[i]] += n.normalized(), edge[j[i]] = std::max(edge[j[i]], longest);
        }
        for (std::size_t j = 0; j < r0.size(); ++j) {
          const convex::Support<D> node{[p = r0[j]](const Vec<D>&) { return p; }, 0};
          const Real outside = convex::distance<D>(node, shape).distance;
          ALEFSI_CHECK_ARG(outside <= 1e-6 * r_out, "body.shape", "bodies[", k, "] (tag ", M::tag(e.data),
                           "): surface node ", e.nodes[j], " lies ", outside,
                           " outside the shape: the shape is not the meshed surface (too small, or turned?)");
          if (normal[j].squaredNorm() == 0) continue;
          const Vec<D> n = normal[j].normalized();
          const Real beyond = n.dot(shape.support(n)) + shape.margin() - n.dot(r0[j]);
          ALEFSI_CHECK_ARG(beyond <= 0.5 * edge[j], "body.shape", "bodies[", k, "] (tag ", M::tag(e.data),
                           "): the shape reaches ", beyond, " beyond surface node ", e.nodes[j],
                           " along its normal (more than half its facets' edge ", edge[j],
                           "): the shape is not the meshed surface (too large, or turned?)");
        }
      }
    }
  }

  /// Disks and spheres with a slip: the slip at every surface node is finite and tangential
  /// (its normal part at most 1 % of the body's largest slip; flux_free_slip's correction is
  /// far smaller). A slip with a normal part would make the body a source or a sink.
  void check_slip(const Mesh<D>& mesh, const std::vector<State>& states) const {
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const auto& e = entries_[k];
      if (!M::has_slip(e.data) || M::radius(e.data) <= 0) continue;
      Real largest = 0, normal = 0;
      Index worst = -1;
      for (Index v : e.nodes) {
        const Vec<D> r = M::to_body(mesh.node(v) - states[k].centre[0], states[k].orientation[0], e.data);
        const Vec<D> us = slip(e, r);
        ALEFSI_CHECK_ARG(us.allFinite(), "body.slip", "bodies[", k, "] (tag ", M::tag(e.data),
                         "): the slip is not finite at surface node ", v);
        largest = std::max(largest, us.norm());
        const Real un = std::abs(us.dot(r.normalized()));
        if (un > normal) normal = un, worst = v;
      }
      ALEFSI_CHECK_ARG(normal <= 1e-2 * largest, "body.slip", "bodies[", k, "] (tag ", M::tag(e.data),
                       "): the slip is not tangential: its normal part is ", normal, " at surface node ", worst,
                       ", the largest slip ", largest);
    }
  }

  /// In a closed domain (`closed`: every boundary velocity given) the discrete continuity
  /// equations sum to "no net flux through the boundary", which the interpolant of a rigid
  /// velocity meets exactly and that of a slip tangent to the exact surface does not: through
  /// the flat facets it leaks an O(h^2) flux, through curved ones (`geometry`) a smaller one
  /// that does not vanish either, which a pinned pressure DOF would absorb as a point source
  /// (and which leaves an unpinned system without a solution). So each body's slip is applied
  /// less c n, n = r / |r|, c = Phi[u_s] / Phi[n] with Phi the discrete flux through its facets
  /// on this mesh (surface_flux, or curved_surface_flux through the facets' edge points; in the
  /// body frame of its surface offsets): the same c while the mesh moves (the surface and its
  /// edge points move rigidly), recomputed after each remesh. Elsewhere c = 0. Call after
  /// `attach`, with the surface offsets of `states` on this mesh and its geometry if curved.
  void remove_slip_flux(const std::vector<State>& states, int velocity_degree, bool closed,
                        const QuadraticGeometry<D>* geometry = nullptr) {
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      auto& e = entries_[k];
      e.slip_flux = 0;
      if (!closed || !M::has_slip(e.data)) continue;
      auto radial = [](const Vec<D>& r) { return Vec<D>(r.normalized()); };
      auto given = [&](const Vec<D>& r) { return Vec<D>(M::slip(e.data, r)); };
      auto corner = [&](Index v) {
        const auto j = std::lower_bound(e.nodes.begin(), e.nodes.end(), v) - e.nodes.begin();
        return states[k].surface[std::size_t(j)];
      };
      if (geometry) {
        ALEFSI_CHECK_ARG(velocity_degree == 2, "velocity_degree", "curved cells carry P2 velocities, got degree ",
                         velocity_degree);
        std::vector<std::array<Vec<D>, D*(D + 1) / 2>> facets;
        facets.reserve(e.facet_ids.size());
        for (Index f : e.facet_ids) {
          auto x = geometry->facet_nodes(f);
          for (auto& p : x) p = M::to_body(p - states[k].centre[0], states[k].orientation[0], e.data);
          facets.push_back(x);
        }
        e.slip_flux = curved_surface_flux<D>(facets, given) / curved_surface_flux<D>(facets, radial);
        continue;
      }
      std::vector<std::array<Vec<D>, D>> facets;
      facets.reserve(e.facets.size());
      for (const auto& f : e.facets) {
        std::array<Vec<D>, D> x;
        for (int i = 0; i < D; ++i) x[std::size_t(i)] = corner(f[std::size_t(i)]);
        facets.push_back(x);
      }
      e.slip_flux = surface_flux<D>(facets, given, velocity_degree) / surface_flux<D>(facets, radial, velocity_degree);
    }
  }
  /// The uniform normal speed c removed from body k's slip on this mesh (remove_slip_flux).
  Real slip_flux_removed(std::size_t k) const { return entries_.at(k).slip_flux; }

  // ---- one step ---------------------------------------------------------------------------

  /// The rigid velocities of the surface nodes on geometry x for the mesh-velocity problem,
  /// from the bodies' state extrapolated with weights w (levels n, n-1, n-2), or the driven
  /// bodies' motion at t. Records the extrapolated velocity as the step's prediction.
  void mesh_velocity_data(const std::vector<State>& states, const std::vector<Vec<D>>& x, const std::array<Real, 3>& w,
                          Real t, NodeVelocities<D>& out) {
    if (entries_.empty()) return;
    out.value.assign(x.size(), Vec<D>::Zero());
    out.given.assign(x.size(), 0);
    for (std::size_t b = 0; b < entries_.size(); ++b) {
      auto& e = entries_[b];
      const State& s = states[b];
      Vec<D> xg = Vec<D>::Zero();
      Velocity Z = Velocity::Zero();
      for (int k = 0; k < 3; ++k) xg += w[k] * s.centre[k], Z += w[k] * s.velocity[k];
      if (!M::is_free(e.data)) Z = M::prescribed_velocity(e.data, t);
      e.Zhat = Z;
      for (Index v : e.nodes) {
        out.value[v] = M::velocity(Z, x[v] - xg);
        out.given[v] = 1;
      }
    }
  }

  /// Centre and orientation at t^{n+1} by the scheme's position formula with the predicted
  /// velocity; the surface nodes of `Xn1` by the exact rigid map.
  void advance(const std::vector<State>& states, const StepCoefficients& c, std::vector<Vec<D>>& Xn1) {
    const auto& b = c.position_bdf;
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      auto& e = entries_[k];
      const State& s = states[k];
      Vec<D> xs = c.dt * e.Zhat.template head<D>();
      for (int l = 1; l <= c.position_order; ++l) xs -= b[l] * s.centre[l - 1];
      e.xg_next = xs / b[0];
      // the position formula reads at most levels n .. n-2
      const std::array<Orientation, 3> th{s.orientation[0], s.orientation[1], s.orientation[2]};
      e.th_next = M::advance(th, e.Zhat, b, c.position_order, c.dt);
      for (std::size_t j = 0; j < e.nodes.size(); ++j)
        Xn1[e.nodes[j]] = e.xg_next + M::to_world(s.surface[j], e.th_next, e.data);
    }
  }

  /// The surface velocities at t^{n+1} = t1, u = H(r^{n+1}) Z + u_s on X^{n+1}: Dirichlet values
  /// of a driven body; a free body's link. A free body's link is also its rows' test function,
  /// which must live where the flow is integrated, X^{n+theta} (else the torque row is off by
  /// (r^{n+1} - r^{n+theta}) x F = O(dt) when theta < 1: the sum of r . F over the surface
  /// carries the pressure level). So the link takes H(r^{n+theta}) and the offset the rest,
  /// (H(r^{n+1}) - H(r^{n+theta})) Z*, Z* extrapolated to t^{n+1}: the velocity is off by
  /// O(dt^3) only. For theta = 1 both are H(r^{n+1}). `Xn` is X^n.
  template <class Space>
  void set_surface_velocities(const Space& space, DofConstraints& cons, const std::vector<State>& states,
                              const StepCoefficients& c, const std::vector<Vec<D>>& Xn1, const std::vector<Vec<D>>& Xth,
                              Real t1) const {
    const auto& vel = space.velocity();
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const auto& e = entries_[k];
      const State& s = states[k];
      const bool free = M::is_free(e.data);
      const Velocity Zp = free ? Velocity::Zero() : Velocity(M::prescribed_velocity(e.data, t1));
      const Vec<D> xg_th = c.theta * e.xg_next + (1 - c.theta) * s.centre[0];
      Velocity Zx = c.body_velocity[0] * s.velocity[0] + c.body_velocity[1] * s.velocity[1];
      if (c.body_velocity[2] != 0) Zx += c.body_velocity[2] * s.velocity[2];
      for (Index i : e.dofs) {
        const Vec<D> r = vel.point(i, Xn1) - e.xg_next;
        Vec<D> us = M::has_slip(e.data) ? M::to_world(slip(e, M::to_body(r, e.th_next, e.data)), e.th_next, e.data)
                                        : Vec<D>::Zero();
        const auto H = M::rows(r);
        if (!free) {
          for (int d = 0; d < D; ++d) cons.set_fixed_value(space.velocity_field(i, d), H[d].dot(Zp) + us[d]);
          continue;
        }
        if (c.theta < 1) {
          const auto Hth = M::rows(Vec<D>(vel.point(i, Xth) - xg_th));
          for (int d = 0; d < D; ++d) {
            us[d] += (H[d] - Hth[d]).dot(Zx);
            cons.set_link(space.velocity_field(i, d), {Hth[d].data(), std::size_t(n_dof)}, us[d]);
          }
        } else {
          for (int d = 0; d < D; ++d) cons.set_link(space.velocity_field(i, d), {H[d].data(), std::size_t(n_dof)}, us[d]);
        }
      }
    }
  }

  /// The free bodies' unknowns in `u` set to Z^n (Newton's initial guess).
  void initial_guess(const DofConstraints& cons, const std::vector<State>& states, VecX& u) const {
    for (std::size_t k = 0; k < entries_.size(); ++k)
      if (M::is_free(entries_[k].data))
        u.template segment<n_dof>(cons.extra_unknown(entries_[k].extra)) = states[k].velocity[0];
  }

  /// The body rows of the free bodies (eq. 11) added to r: M delta_l Z / dt (+ w x I_w w in
  /// 3D) - M g - external load - contact force, and their Jacobian (exact, gyroscopic term
  /// included) on each body's diagonal block of J. The contact forces come from `contact` at
  /// the bodies' velocities at t^{n+1} = t1 (the unknowns of free bodies, the given motion of
  /// driven ones); each body's total is recorded in its state. With `jacobian_here` (J
  /// assembled in parts, one per MPI process: la/partition.hpp), body k's terms enter J only
  /// where jacobian_here[k] is set (one process; r is whole and takes them everywhere).
  /// `coupling` (optional): the derivatives of a body's rows in the velocity of the free body it
  /// touches, which J's pattern lacks (la/coupling.hpp), are put there; without it they are
  /// left out (lagged: Newton then converges linearly while two bodies touch).
  void add_rows(std::vector<State>& states, const StepCoefficients& c, const DofConstraints& cons, const VecX& u, VecX& r,
                SparseMatrix& J, const Vec<D>& gravity, const ContactModel<D>& contact, Real t1,
                const std::vector<char>* jacobian_here = nullptr, BlockCoupling* coupling = nullptr) const {
    auto here = [&](std::size_t k) { return !jacobian_here || (*jacobian_here)[k]; };
    const Real a0 = c.flow_bdf[0];
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const auto& e = entries_[k];
      State& s = states[k];
      s.contact = Velocity::Zero();
      if (!M::is_free(e.data)) continue;
      const Index row = cons.extra_unknown(e.extra);
      const Velocity Z = u.template segment<n_dof>(row);
      r.template segment<n_dof>(row) += inertia(e, s, c, Z) - weight(e, gravity) - M::external_load(e.data);
      if (!here(k)) continue;
      const auto Jb = M::inertia_jacobian(e.data, e.th_next, Z, a0, c.dt);
      for (int i = 0; i < n_dof; ++i)
        for (int j = 0; j < n_dof; ++j)
          if (Jb(i, j) != 0) J.coeffRef(row + i, row + j) += Jb(i, j);  // structural zeros stay untouched
    }
    std::vector<Vec<D>> v(entries_.size());
    for (std::size_t k = 0; k < entries_.size(); ++k)
      v[k] = M::is_free(entries_[k].data)
                 ? Vec<D>(u.template segment<D>(cons.extra_unknown(entries_[k].extra)))
                 : Vec<D>(M::prescribed_velocity(entries_[k].data, t1).template head<D>());
    // d r_b / d V_other = H(arm)^T dF per (b, other) pair of free bodies, summed over contacts
    std::vector<std::pair<std::array<int, 2>, Eigen::Matrix<Real, n_dof, D>>> pairs;
    // a force F at `arm` from the centre is the load H(arm)^T F (force and moment arm x F)
    contact.forces(v, [&](int b, const Vec<D>& F, const Mat<D>& dF, const Vec<D>& arm, int other) {
      const bool moment = arm.squaredNorm() > 0;  // else G = (F, 0) exactly
      const auto H = M::rows(arm);
      Velocity G = Velocity::Zero();
      for (int d = 0; d < D; ++d) G += F[d] * H[d];
      states[b].contact += G;
      if (!M::is_free(entries_[b].data)) return;
      const Index row = cons.extra_unknown(entries_[b].extra);
      r.template segment<n_dof>(row) -= G;
      if (!here(std::size_t(b))) return;
      Eigen::Matrix<Real, n_dof, D> dG = Eigen::Matrix<Real, n_dof, D>::Zero();  // d G / d V_b
      for (int i = 0; i < (moment ? n_dof : D); ++i)
        for (int j = 0; j < D; ++j) {
          for (int d = 0; d < D; ++d) dG(i, j) += H[d][i] * dF(d, j);
          J.coeffRef(row + i, row + j) -= dG(i, j);
        }
      // G depends on V_b - V_other: d r_b / d V_other = +dG
      if (!coupling || other < 0 || !M::is_free(entries_[std::size_t(other)].data)) return;
      const std::array<int, 2> key{b, other};
      auto it = std::find_if(pairs.begin(), pairs.end(), [&](const auto& p) { return p.first == key; });
      if (it == pairs.end()) pairs.emplace_back(key, dG);
      else it->second += dG;
    });
    if (coupling) couple(pairs, cons, *coupling);
  }

  // The coupling's block: the unknowns of the bodies in `pairs` (ascending), and per (b, other)
  // the n_dof x D derivative of b's rows in other's translational velocity.
  template <class Pairs>
  void couple(const Pairs& pairs, const DofConstraints& cons, BlockCoupling& C) const {
    C.clear();
    if (pairs.empty()) return;
    std::vector<std::pair<Index, int>> first;  // (a body's first unknown, the body), ascending
    for (const auto& [key, dG] : pairs)
      for (int b : key) first.emplace_back(cons.extra_unknown(entries_[std::size_t(b)].extra), b);
    std::sort(first.begin(), first.end());
    first.erase(std::unique(first.begin(), first.end()), first.end());
    for (const auto& [f, b] : first)  // a body's n_dof unknowns are consecutive
      for (int i = 0; i < n_dof; ++i) C.index.push_back(f + i);
    C.block = MatX::Zero(C.size(), C.size());
    auto at = [&](int b) {
      const auto it = std::find_if(first.begin(), first.end(), [b](const auto& p) { return p.second == b; });
      return n_dof * Index(it - first.begin());
    };
    for (const auto& [key, dG] : pairs) C.block.block(at(key[0]), at(key[1]), n_dof, D) += dG;
  }

  /// The first of the n_dof unknowns of body k (-1: a driven body has none).
  Index first_unknown(std::size_t k, const DofConstraints& cons) const {
    const auto& e = entries_.at(k);
    return M::is_free(e.data) ? cons.extra_unknown(e.extra) : Index(-1);
  }
  /// Whether body k is free (its velocity solved for) rather than driven.
  bool is_free(std::size_t k) const { return M::is_free(entries_.at(k).data); }
  /// Z^{n+1} of body k after the solve (`u` the unknowns at t1): its unknowns if it is free,
  /// its prescribed velocity at t1 if it is driven.
  Velocity next_velocity(std::size_t k, const DofConstraints& cons, const VecX& u, Real t1) const {
    const auto& e = entries_.at(k);
    return M::is_free(e.data) ? Velocity(u.template segment<n_dof>(cons.extra_unknown(e.extra)))
                              : Velocity(M::prescribed_velocity(e.data, t1));
  }

  /// After the solve (`u` the unknowns at t^{n+1} = t1): Z^{n+1} of every body, the hydrodynamic
  /// load of the free ones from their momentum balance (M delta_l Z / dt (+ w x I_w w) - M g -
  /// external load - contact force), and the new level of each body's history.
  void finish(std::vector<State>& states, const StepCoefficients& c, const DofConstraints& cons, const VecX& u, Real t1,
              const Vec<D>& gravity) const {
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const auto& e = entries_[k];
      State& s = states[k];
      const bool free = M::is_free(e.data);
      const Velocity Zn1 = next_velocity(k, cons, u, t1);
      if (free) {
        s.load = inertia(e, s, c, Zn1) - weight(e, gravity) - M::external_load(e.data);
        s.load -= s.contact;
      }
      s.velocity.push(Zn1);
      s.centre.push(e.xg_next);
      s.orientation.push(e.th_next);
    }
  }

  /// The hydrodynamic load of each driven body, from the residual of the rows its velocity
  /// would have if it were free: F = -sum_i H(r_i)^T r_i over its surface DOFs i, r the element
  /// residuals of the flow (`kernel`, set for the step) at `field` on the cells around the body,
  /// H at X^{n+theta} (where the flow is integrated; the test functions of a free body's rows
  /// too). For a free body this equals its momentum balance (`finish`) at convergence; this is
  /// the consistent force, more accurate than integrating the stress over the surface. `Xth`:
  /// the node positions at n+theta.
  template <class Space, class Kernel>
  void driven_loads(std::vector<State>& states, const Space& space, const Kernel& kernel, const VecX& field,
                    const StepCoefficients& c, const std::vector<Vec<D>>& Xth) const {
    using LocalVec = typename Kernel::LocalVec;
    using LocalMat = typename Kernel::LocalMat;
    constexpr int nv = Space::n_velocity_local;
    LocalVec u, r;
    LocalMat A;
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const auto& e = entries_[k];
      if (M::is_free(e.data)) continue;
      const Vec<D> xg = c.theta * e.xg_next + (1 - c.theta) * states[k].centre[0];
      Velocity F = Velocity::Zero();
      for (Index cell : e.cells) {
        const auto fd = space.cell_field_dofs(cell);
        for (int l = 0; l < Space::n_local; ++l) u[l] = field[fd[l]];
        kernel.cell(cell, u, A, r);
        const auto& vd = space.velocity().cell_dofs(cell);
        for (int a = 0; a < nv; ++a) {
          if (!std::binary_search(e.dofs_sorted.begin(), e.dofs_sorted.end(), vd[a])) continue;
          const auto H = M::rows(Vec<D>(space.velocity().point(vd[a], Xth) - xg));
          for (int d = 0; d < D; ++d) F -= r[D * a + d] * H[d];
        }
      }
      states[k].load = F;
    }
  }

  // ---- views and resets -------------------------------------------------------------------

  /// The bodies for a contact model at history level `level` (0: t^n), or at t^{n+1}
  /// (level = -1: the positions and velocities predicted for the step being solved).
  std::vector<ContactBody<D>> contact_bodies(const std::vector<State>& states, int level) const {
    std::vector<ContactBody<D>> out;
    out.reserve(entries_.size());
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const auto& e = entries_[k];
      const State& s = states[k];
      ContactBody<D> c;
      c.centre = level < 0 ? e.xg_next : s.centre[level];
      c.velocity = (level < 0 ? e.Zhat : s.velocity[level]).template head<D>();
      c.radius = M::radius(e.data);
      const Orientation& th = level < 0 ? e.th_next : s.orientation[level];
      auto at = [&](Index v) {
        const auto it = std::lower_bound(e.nodes.begin(), e.nodes.end(), v);
        return Vec<D>(c.centre + M::to_world(s.surface[std::size_t(it - e.nodes.begin())], th, e.data));
      };
      if constexpr (requires { M::shape(e.data); }) {
        if (const auto shape = M::shape(e.data); shape && c.radius == 0) {  // in the offsets' axes
          Mat<D> Q;
          for (int i = 0; i < D; ++i) Q.col(i) = M::to_world(Vec<D>::Unit(i), th, e.data);
          c.convex = convex::placed<D>(shape, c.centre, Q);
        }
      }
      c.r_in = std::numeric_limits<Real>::infinity();
      c.r_out = reach(s);
      for (const auto& f : e.facets) {
        std::array<Vec<D>, D> x;
        for (int i = 0; i < D; ++i) x[i] = at(f[i]);
        c.r_in = std::min(c.r_in, (detail::closest_on_facet(c.centre, x) - c.centre).norm());
        if (c.radius == 0 && !c.convex) c.surface.push_back(x);
      }
      if (c.radius > 0) c.r_in = c.r_out = c.radius;
      out.push_back(std::move(c));
    }
    return out;
  }

  /// The bodies for a remesher, at t^n.
  std::vector<RemeshBody<D>> remesh_bodies(const std::vector<State>& states) const {
    std::vector<RemeshBody<D>> out;
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const Real radius = M::radius(entries_[k].data);
      out.push_back({M::tag(entries_[k].data), states[k].centre[0], radius, radius > 0 ? radius : reach(states[k])});
    }
    return out;
  }

  /// Surface nodes of body k in X (the positions of level `level`) from the exact rigid map.
  void place_surface(const State& s, std::size_t k, int level, std::vector<Vec<D>>& X) const {
    const auto& e = entries_[k];
    for (std::size_t j = 0; j < e.nodes.size(); ++j)
      X[e.nodes[j]] = s.centre[level] + M::to_world(s.surface[j], s.orientation[level], e.data);
  }

  /// After a remesh (`attach` done on `mesh`, the levels of `X` transferred): each body's
  /// surface offsets from the new mesh's nodes (at t^n), and its surface nodes at the past
  /// levels from its exact rigid motion.
  void reset_surface(const Mesh<D>& mesh, std::vector<State>& states, Levels<std::vector<Vec<D>>>& X) const {
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const auto& e = entries_[k];
      State& s = states[k];
      s.surface.clear();
      for (Index v : e.nodes) s.surface.push_back(M::to_body(mesh.node(v) - s.centre[0], s.orientation[0], e.data));
      for (int l = 1; l < X.size(); ++l)
        if (!X[l].empty()) place_surface(s, k, l, X[l]);
    }
  }

  /// After a remesh (`constrain` done): the surface velocity DOFs of every level of U set from
  /// the rigid velocity (+ slip) of that level on that level's positions.
  template <class Space>
  void reset_surface_velocities(const Space& space, const std::vector<State>& states,
                                const Levels<std::vector<Vec<D>>>& X, Levels<VecX>& U) const {
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const auto& e = entries_[k];
      const State& s = states[k];
      for (int l = 0; l < U.size(); ++l) {
        if (U[l].size() == 0 || X[l].empty()) continue;
        for (Index i : e.dofs) {
          const Vec<D> r = space.velocity().point(i, X[l]) - s.centre[l];
          const Vec<D> v =
              M::velocity(s.velocity[l], r) +
              (M::has_slip(e.data)
                   ? Vec<D>(M::to_world(slip(e, M::to_body(r, s.orientation[l], e.data)), s.orientation[l], e.data))
                   : Vec<D>(Vec<D>::Zero()));
          for (int d = 0; d < D; ++d) U[l][space.velocity_field(i, d)] = v[d];
        }
      }
    }
  }

 private:
  // The largest distance from the centre to a surface node.
  static Real reach(const State& s) {
    Real r = 0;
    for (const auto& r0 : s.surface) r = std::max(r, r0.norm());
    return r;
  }

  struct Entry {
    Body data;
    Index extra = -1;                               // first of its n_dof extra unknowns (free bodies)
    std::vector<Index> nodes;                       // surface mesh nodes (sorted)
    std::vector<Index> dofs;                        // surface velocity DOFs
    std::vector<Index> dofs_sorted;                 // the same, sorted (driven bodies)
    std::vector<Index> cells;                       // cells with a surface velocity DOF (driven bodies)
    std::vector<typename Mesh<D>::Facet> facets;    // surface facets
    std::vector<Index> facet_ids;                   // ... their indices in the mesh
    Real displaced = 0;                             // fluid mass of its exact volume (exact buoyancy), else 0
    Real slip_flux = 0;                             // normal speed removed from the slip (remove_slip_flux)
    // the step's prediction
    Velocity Zhat = Velocity::Zero();               // extrapolated (or given) velocity
    Vec<D> xg_next = Vec<D>::Zero();                // centre at t^{n+1}
    Orientation th_next{};                          // orientation at t^{n+1}
  };
  // The slip applied at body-frame offset r: the body's, less the flux correction.
  static Vec<D> slip(const Entry& e, const Vec<D>& r) { return M::slip(e.data, r) - e.slip_flux * r.normalized(); }
  // M delta_l Z^{n+1} / dt (+ w x I_w w in 3D), at the orientation for t^{n+1}.
  static Velocity inertia(const Entry& e, const State& s, const StepCoefficients& c, const Velocity& Zn1) {
    const auto& a = c.flow_bdf;
    Velocity dZ = a[0] * Zn1;
    for (int k = 1; k <= c.flow_order; ++k) dZ += a[k] * s.velocity[k - 1];
    return M::inertia(e.data, e.th_next, Zn1, dZ, c.dt);
  }
  static Velocity weight(const Entry& e, const Vec<D>& gravity) {
    Velocity w = Velocity::Zero();
    w.template head<D>() = (M::mass(e.data) - e.displaced) * gravity;
    return w;
  }

  std::vector<Entry> entries_;
};

}  // namespace alefsi
