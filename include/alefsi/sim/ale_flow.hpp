#pragma once
/// \file sim/ale_flow.hpp
/// Incompressible flow on a moving mesh, advanced by one of the five ALE schemes.
///
/// `AleFlow<D, Pair, Scheme, Convection>` owns the mesh and the time histories (positions X,
/// velocities U, the mesh velocity V^n) and advances them, one `step(dt)` at a time, exactly as
/// section 4 of the paper prescribes (see time/schemes.hpp for the table):
///   1. X^ = sum_k e_k X^{n-k}, U^ likewise (the scheme's extrapolation);
///   2. the mesh velocity at the scheme's level, on X^: from the elasticity problem with the
///      boundary mesh velocities (`set_mesh_velocity`, default 0), or from an analytic field
///      (`set_prescribed_mesh_velocity`, for verification);
///   3. X^{n+1} from delta_lg X^{n+1} = dt V;
///   4. the flow at n+theta on X^{n+theta} (physics/navier_stokes.hpp): Newton with the exact
///      Jacobian until the residual drops below the tolerance, or one semi-implicit linear solve.
/// Dirichlet velocities (`set_velocity`) are imposed at t^{n+1} on the DOF positions of X^{n+1}.
/// When every boundary facet has a Dirichlet velocity, pressure DOF 0 is pinned and the pressure
/// shifted to zero mean after each step (as in physics/stokes.hpp).
///
/// Time step changes: the schemes are constant-step multistep formulas, so a step with a dt
/// different from the previous one restarts the history from the current state (as at t0:
/// MR/AB start-up steps); a rejected step (exception) leaves the state at t^n untouched.
///
/// Rigid bodies (`add_body`): 2D (RigidBody2D, 3 DOF) and 3D (RigidBody3D, 6 DOF, orientation a
/// unit quaternion), coupled monolithically: a free body's velocities are extra unknowns, its
/// surface velocity DOFs are linked to them through H (at X^{n+theta}, see step_with), its rows
/// are the Newton-Euler equations (3D: with the gyroscopic term w x I_w w and its exact
/// Jacobian).
/// Centre and orientation advance by the scheme's position formula with the extrapolated body
/// velocity (3D: on the rotation vector relative to q^n, see RigidBodyTraits<3>::advance);
/// surface nodes follow the exact rigid map. What differs between 2D and 3D is
/// RigidBodyTraits<D> (physics/rigid_body.hpp).
///
/// Remeshing (2D, `set_remeshing`): after each step, if the worst cell quality is below the
/// trigger or an edge leaves the size band, the mesh is adapted (mesh/adapt/adapt2d.hpp;
/// disks stay on their exact circles, other bodies' surfaces are kept), every history level
/// (positions X, velocities and pressures U, mesh velocity V^n) is interpolated to the new
/// mesh in the current configuration, body nodes and body DOF values are set from the exact
/// rigid motion of each level, and the DOF maps, patterns, factorisation analysis and
/// mesh-motion operator are rebuilt.
///
/// Collisions (2D, `set_collisions`): the repulsive short-range force of physics/collision.hpp
/// (eq. 24), with gaps and directions from the bodies' positions at t^{n+1} (known before the
/// flow solve) and the relative velocity at t^{n+1} (implicit; its derivative enters the
/// Jacobian's diagonal body blocks, the coupling between two bodies' rows is lagged).
///
/// Start-up: a scheme that reads past levels the history does not have yet takes MR/AB steps
/// (self-starting, local error O(dt^3), so BDF3 keeps its order); the very first MR/AB step
/// takes X^{-1} = X^0 - dt V^0 with V^0 solved on X^0, and U^{-1} = U^0. With
/// `FlowOptions::damped_start` = m the first step is instead taken by m backward-Euler
/// substeps (extrapolated for order >= 3; see damped_start_step), which damp the stiff modes
/// of a non-smooth start (MR/AB = Crank-Nicolson does not); the scheme's own formulas, and its
/// MR/AB start-up steps if it needs a third level, follow.
///
///     AleFlow<2, TaylorHood, BDF3_BDF3E> flow(mesh, {.rho = 1, .mu = 0.01});
///     flow.set_velocity(tags::top, [](const Vec<2>& x, Real t) { ... });
///     flow.set_initial_velocity(u0);
///     for (int n = 0; n < 100; ++n) flow.step(0.01);
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/mesh/adapt/adapt2d.hpp"
#include "alefsi/mesh/adapt/transfer.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/physics/collision.hpp"
#include "alefsi/physics/mesh_motion.hpp"
#include "alefsi/physics/navier_stokes.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/sim/checkpoint.hpp"
#include "alefsi/time/schemes.hpp"

namespace alefsi {

struct FlowOptions {
  Real rho = 1, mu = 1;
  Linearisation linearisation = Linearisation::newton;
  int max_newton = 25;
  Real newton_tolerance = 1e-10;  ///< on the residual's max norm, relative to its first value (+ absolute 1e-13)
  /// Damped start (Rannacher's, after Luskin & Rannacher 1982) for a start that is not smooth,
  /// e.g. an impulsive one. 0 (default): the multistep start-up (MR/AB steps, see AleFlow).
  /// m (even, 2..64): the first step from t0, and the first after each history restart, is
  /// taken as m backward-Euler (BSS) substeps of dt/m, which damp the stiff modes that
  /// Crank-Nicolson (MR/AB) keeps (|R(z)| = (1 + z/m)^-m against 1); for a scheme of design
  /// order >= 3 it is Richardson-extrapolated, 2 [m substeps of dt/m] - [m/2 substeps of 2dt/m],
  /// so its local error is O(dt^3) instead of O(dt^2) and BDF3 keeps its order
  /// (|R(z)| ~ (m/2)^(m/2) / z^(m/2) for large z). The history is then left at t^n and
  /// t^n + dt (equal spacing dt); a scheme that needs more levels continues with its MR/AB
  /// start-up steps.
  int damped_start = 0;
  /// Threads of the flow system's assembly (Assembler::set_threads; default 1). Results are
  /// bit-identical for every count. With more than one, the user's force callback
  /// (set_force) is called concurrently and must be safe to call so (a pure function is).
  int threads = 1;
};

/// Remeshing in the time loop (2D). Trigger: worst cell quality (Mesh::quality) below
/// `trigger_quality`, or (with a size function) an edge with |L - h| / h > adapt.tolerance.
struct RemeshOptions {
  bool enabled = true;
  Real trigger_quality = 0.35;  ///< in [0, 1)
  /// The fixed outer boundary (walls) as curves, at their place (mesh/generate/mesher2d.hpp).
  std::vector<BoundaryCurve> walls;
  /// Target edge length for the bodies' current circles (disk bodies, radius > 0), e.g.
  /// `[](const auto& disks) { return graded_size(disks, 0.02, 0.2); }`. Empty: the paper's
  /// comparative value (adapt2d.hpp) and the quality trigger only.
  std::function<SizeFunction(const std::vector<Circle>& disks)> size;
  AdaptOptions adapt;  ///< tolerance T, min_quality, smoothing (adapt.size is set from `size`)
};

/// What the flow did so far (for logs).
struct FlowStats {
  int steps = 0, remeshes = 0, history_restarts = 0;
  int contacts = 0;              ///< active collision contacts in the last step
  AdaptReport last_adapt;        ///< of the last remesh
};

struct StepReport {
  int newton_iterations = 0;
  std::vector<Real> residuals;  ///< max-norm residual before each Newton update
  bool startup = false;
  bool remeshed = false;  ///< the mesh was adapted after the step
  /// Wall time (s) of the step's phases: mesh-velocity solve, assembly (all Newton
  /// iterations), numeric factorisation (incl. the one-off symbolic analysis), triangular
  /// solves, adaptation + transfer + rebuild.
  Real t_mesh_velocity = 0, t_assembly = 0, t_factorize = 0, t_solve = 0, t_remesh = 0;
};

template <int D>
void detail_write_mesh(CheckpointWriter& w, const Mesh<D>& m) {
  w.section("mesh");
  std::vector<Real> x(D * std::size_t(m.n_nodes()));
  for (Index i = 0; i < m.n_nodes(); ++i)
    for (int c = 0; c < D; ++c) x[D * std::size_t(i) + c] = m.node(i)[c];
  w.put_vector(x);
  w.put_vector(m.cells());
  w.put_vector(m.cell_tags());
  std::vector<typename Mesh<D>::Facet> facets;
  std::vector<int> tags;
  for (Index f : m.boundary_facets()) facets.push_back(m.facet(f)), tags.push_back(m.facet_tag(f));
  w.put_vector(facets);
  w.put_vector(tags);
}

template <int D>
Mesh<D> detail_read_mesh(CheckpointReader& r) {
  r.section("mesh");
  const auto x = r.get_vector<Real>("node coordinates");
  std::vector<Vec<D>> nodes(x.size() / D);
  for (std::size_t i = 0; i < nodes.size(); ++i)
    for (int c = 0; c < D; ++c) nodes[i][c] = x[D * i + c];
  auto cells = r.get_vector<typename Mesh<D>::Cell>("cells");
  auto cell_tags = r.get_vector<int>("cell tags");
  const auto facets = r.get_vector<typename Mesh<D>::Facet>("boundary facets");
  const auto tags = r.get_vector<int>("boundary tags");
  try {
    return Mesh<D>(std::move(nodes), std::move(cells), facets, tags, std::move(cell_tags));
  } catch (const MeshError& e) {
    r.fail(std::string("invalid mesh: ") + e.what());
  }
}

/// The mesh stored in a checkpoint written by AleFlow::save_checkpoint (to build the flow
/// that `load_checkpoint` restores).
template <int D>
Mesh<D> read_checkpoint_mesh(const std::filesystem::path& file) {
  CheckpointReader r(file);
  r.section("config");
  if (r.get<std::int32_t>("dimension") != D) r.fail("written by a flow of another dimension");
  r.get_string("element pair");
  r.get_string("scheme");
  return detail_read_mesh<D>(r);
}

template <int D, ElementPair Pair, TimeScheme Scheme, bool Convection = true, LinearSolver Solver = SparseLu<>>
class AleFlow {
 public:
  using Space = MixedSpace<D, Pair>;
  using Kernel = AleNavierStokesKernel<D, Pair, Convection>;
  using TimeFunction = std::function<Vec<D>(const Vec<D>&, Real)>;
  /// What differs between 2D and 3D bodies (physics/rigid_body.hpp).
  using BodyTraits = RigidBodyTraits<D>;
  static_assert(RigidBodyModel<BodyTraits> && BodyTraits::dim == D);
  using BodyData = typename BodyTraits::Body;                 ///< RigidBody2D / RigidBody3D
  using BodyVelocity = typename BodyTraits::Velocity;         ///< Z: Vec<3> (2D) / Vec<6> (3D)
  using BodyOrientation = typename BodyTraits::Orientation;  ///< angle (2D) / unit quaternion (3D)
  static constexpr int body_dofs = BodyTraits::n_dof;

  AleFlow(Mesh<D> mesh, FlowOptions opt) : mesh_(std::move(mesh)), opt_(opt) {
    ALEFSI_CHECK_ARG(opt.rho >= 0 && std::isfinite(opt.rho), "rho", "fluid density must be >= 0 and finite, got ", opt.rho);
    ALEFSI_CHECK_ARG(opt.mu > 0 && std::isfinite(opt.mu), "mu", "viscosity must be positive and finite, got ", opt.mu);
    ALEFSI_CHECK_ARG(opt.max_newton >= 1, "max_newton", "must be >= 1");
    ALEFSI_CHECK_ARG(opt.threads >= 1, "threads", "must be at least 1, got ", opt.threads);
    ALEFSI_CHECK_ARG(opt.damped_start == 0 || (opt.damped_start >= 2 && opt.damped_start <= 64 && opt.damped_start % 2 == 0),
                     "damped_start", "must be 0 (off) or an even number of substeps in 2..64, got ", opt.damped_start);
    rebuild_discretisation();
    X_[0] = mesh_.coordinates();
    U_[0] = VecX::Zero(space_->n_field());
  }

  AleFlow(const AleFlow&) = delete;  // the space and kernels point into the owned mesh
  AleFlow& operator=(const AleFlow&) = delete;

  const Mesh<D>& mesh() const { return mesh_; }
  const Space& space() const { return *space_; }
  const FlowStats& stats() const { return stats_; }
  std::size_t n_bodies() const { return bodies_.size(); }
  Real time() const { return t_; }
  /// u^n and p^n (p at the scheme's level n - 1 + theta) as a field vector.
  const VecX& field() const { return U_[0]; }
  /// Mesh velocity at level n (per node).
  const std::vector<Vec<D>>& mesh_velocity() const { return Vn_; }

  void set_velocity(int tag, TimeFunction g) {
    require_not_started("set_velocity");
    ALEFSI_CHECK_ARG(g != nullptr, "g", "boundary velocity function is empty");
    ALEFSI_CHECK_ARG(!space_->velocity().boundary_dofs(tag).empty(), "tag", "no boundary facet has tag ", tag);
    dirichlet_[tag] = std::move(g);
  }
  void set_mesh_velocity(int tag, TimeFunction g) {
    ALEFSI_CHECK_ARG(!mesh_.boundary_nodes(tag).empty(), "tag", "no boundary facet has tag ", tag);
    mesh_bc_[tag] = std::move(g);
  }
  void set_prescribed_mesh_velocity(TimeFunction v) { prescribed_ = std::move(v); }
  /// Gravity: body force rho_f g on the fluid and M g on every free body.
  void set_gravity(const Vec<D>& g) { gravity_ = g; }
  /// Adds a rigid body (2D: 3 DOF). Its surface facets carry `body.tag`; returns its index.
  std::size_t add_body(const RigidBody2D& body)
    requires(D == 2)
  {
    return add_body_impl(body);
  }
  /// Adds a rigid body (3D: 6 DOF, orientation a unit quaternion). Its surface facets carry
  /// `body.tag`; returns its index.
  std::size_t add_body(const RigidBody3D& body)
    requires(D == 3)
  {
    return add_body_impl(body);
  }
  /// Body k's centre of mass and velocity Z at t^n: (V1, V2, w3) in 2D, (V, w) in 3D.
  Vec<D> body_centre(std::size_t k) const { return bodies_.at(k).xg[0]; }
  BodyVelocity body_velocity(std::size_t k) const { return bodies_.at(k).Z[0]; }
  /// Body k's angle at t^n (2D).
  Real body_angle(std::size_t k) const
    requires(D == 2)
  {
    return bodies_.at(k).th[0];
  }
  /// Body k's orientation at t^n (3D): the unit quaternion mapping body axes to world axes.
  Eigen::Quaternion<Real> body_orientation(std::size_t k) const
    requires(D == 3)
  {
    return bodies_.at(k).th[0];
  }
  /// Surface node positions of body k at t^n (from the exact rigid map).
  std::vector<Vec<D>> body_surface(std::size_t k) const {
    std::vector<Vec<D>> x;
    for (Index v : bodies_.at(k).nodes) x.push_back(X_[0][v]);
    return x;
  }
  /// Hydrodynamic force and torque on free body k over the last step, (F1, F2, T3) in 2D,
  /// (F, T) in 3D (torque about the centre of mass, world axes), from its momentum balance:
  /// M delta_l Z / dt (+ w x I_w w in 3D) - M g - external load - collision force.
  BodyVelocity body_hydrodynamic_load(std::size_t k) const { return bodies_.at(k).load; }
  void set_force(TimeFunction f) { force_ = std::move(f); }
  void set_initial_velocity(const std::function<Vec<D>(const Vec<D>&)>& u0, Real t0 = 0) {
    require_not_started("set_initial_velocity");
    t_ = t0;
    for (Index i = 0; i < space_->velocity().n_dofs(); ++i) {
      const Vec<D> val = u0(space_->velocity().point(i));
      for (int k = 0; k < D; ++k) U_[0][space_->velocity_field(i, k)] = val[k];
    }
  }

  /// Advances from t^n to t^n + dt.
  StepReport step(Real dt) {
    ALEFSI_CHECK_ARG(dt > 0 && std::isfinite(dt), "dt", "time step must be positive and finite, got ", dt);
    if (!cons_) setup();
    if (levels_ > 0 && dt != last_dt_) {  // constant-step formulas: restart from the current state
      levels_ = 0;
      ++stats_.history_restarts;
    }
    const bool damped = levels_ == 0 && opt_.damped_start > 0;
    if (levels_ == 0 && !damped) {
      set_body_mesh_velocity(X_[0], {1.0, 0.0, 0.0}, t_);
      Vn_ = solve_mesh_velocity(X_[0], U_[0], t_);
    }
    StepReport rep;
    if (damped) {
      rep = damped_start_step(dt);
    } else if (levels_ < history_levels<Scheme>()) {
      rep = step_with<MR_AB>(dt);
      rep.startup = true;
    } else {
      rep = step_with<Scheme>(dt);
    }
    last_dt_ = dt;
    ++stats_.steps;
    if constexpr (D == 2)
      if (remesh_ && remesh_->enabled) {
        const auto t0 = std::chrono::steady_clock::now();
        if (remesh_needed()) rep.remeshed = remesh();
        rep.t_remesh = std::chrono::duration<Real>(std::chrono::steady_clock::now() - t0).count();
      }
    return rep;
  }

  /// Remeshing in the time loop (2D); see RemeshOptions. May be called before or between steps.
  void set_remeshing(RemeshOptions opt)
    requires(D == 2)
  {
    ALEFSI_CHECK_ARG(opt.trigger_quality >= 0 && opt.trigger_quality < 1, "remesh.trigger_quality",
                     "must be in [0, 1), got ", opt.trigger_quality);
    remesh_ = std::move(opt);
  }
  /// Short-range repulsive collision forces (eq. 24) between bodies and against the walls
  /// (every boundary facet that is not a body surface); see physics/collision.hpp.
  void set_collisions(CollisionOptions opt)
    requires(D == 2)
  {
    collision_.emplace(opt);
    update_collision_walls();
  }
  /// Collision force on body k in the last step (F1, F2).
  Vec<D> body_collision_force(std::size_t k) const { return bodies_.at(k).contact; }
  /// Per body, the gap between its surface and the nearest other body or wall, at t^n (disk
  /// bodies exactly; others from their surface facets). One search for all bodies.
  std::vector<Real> body_gaps() const
    requires(D == 2)
  {
    CollisionModel2D model(CollisionOptions{.range = 1e6});
    model.set_walls(collision_ ? collision_->walls() : wall_segments());
    std::vector<Real> g(bodies_.size(), std::numeric_limits<Real>::infinity());
    for (const auto& c : model.contacts(collision_bodies(0), opt_.mu)) {
      g[c.k] = std::min(g[c.k], c.gap);
      if (c.j >= 0) g[c.j] = std::min(g[c.j], c.gap);
    }
    return g;
  }

  /// Adapts the mesh now (2D; needs `set_remeshing` for the walls, size and options) and
  /// transfers the state. Returns whether the mesh changed.
  bool remesh()
    requires(D == 2)
  {
    ALEFSI_CHECK_ARG(remesh_.has_value(), "remesh", "call set_remeshing first");
    std::vector<BoundaryCurve> curves = remesh_->walls;
    const std::vector<Circle> disks = current_disks();
    curves.insert(curves.end(), disks.begin(), disks.end());
    AdaptOptions ao = remesh_->adapt;
    if (remesh_->size) ao.size = remesh_->size(disks);
    AdaptReport ar;
    Mesh<2> m2 = adapt(mesh_, curves, ao, &ar);
    stats_.last_adapt = ar;
    if (!ar.changed) return false;
    // every history level, interpolated in the current configuration
    const FieldTransfer2D t1(mesh_, m2, 1);
    const FieldTransfer2D tu(mesh_, m2, Pair::template Velocity<D>::degree);
    auto move_points = [&](std::vector<Vec<2>>& x) {
      if (x.empty()) return;
      std::vector<Real> flat(2 * x.size());
      for (std::size_t i = 0; i < x.size(); ++i) flat[2 * i] = x[i][0], flat[2 * i + 1] = x[i][1];
      flat = t1.apply(flat, 2);
      x.resize(flat.size() / 2);
      for (std::size_t i = 0; i < x.size(); ++i) x[i] = Vec<2>(flat[2 * i], flat[2 * i + 1]);
    };
    const Index nv_old = space_->velocity().n_dofs();
    auto move_field = [&](VecX& u) {
      if (u.size() == 0) return;
      const std::vector<Real> vel(u.data(), u.data() + 2 * nv_old), pre(u.data() + 2 * nv_old, u.data() + u.size());
      const auto v2 = tu.apply(vel, 2), p2 = t1.apply(pre, 1);
      u.resize(Index(v2.size() + p2.size()));
      std::copy(v2.begin(), v2.end(), u.data());
      std::copy(p2.begin(), p2.end(), u.data() + v2.size());
    };
    for (int k = 1; k < 3; ++k) move_points(X_[k]);
    move_points(Vn_);
    for (auto& u : U_) move_field(u);
    X_[0] = m2.coordinates();
    mesh_ = std::move(m2);
    rebuild_discretisation();
    // bodies: surface nodes and their past positions from the exact rigid motion
    for (auto& b : bodies_) {
      b.nodes = mesh_.boundary_nodes(b.data.tag);
      b.r0.clear();
      for (Index v : b.nodes) b.r0.push_back(rotate(mesh_.node(v) - b.xg[0], -(b.th[0] - b.data.angle)));
      for (int k = 1; k < 3; ++k)
        if (!X_[k].empty())
          for (std::size_t j = 0; j < b.nodes.size(); ++j)
            X_[k][b.nodes[j]] = b.xg[k] + rotate(b.r0[j], b.th[k] - b.data.angle);
    }
    setup();
    // body DOF values of every level: rigid velocity (+ slip) of that level
    for (const auto& b : bodies_)
      for (int k = 0; k < 3; ++k) {
        if (U_[k].size() == 0 || X_[k].empty()) continue;
        const Real rot = b.th[k] - b.data.angle;
        for (Index i : b.dofs) {
          const Vec<2> r = dof_point(i, X_[k]) - b.xg[k];
          const Vec<2> v = rigid_velocity(b.Z[k], r) + (b.data.slip ? rotate(b.data.slip(rotate(r, -rot)), rot) : Vec<2>::Zero());
          for (int c = 0; c < 2; ++c) U_[k][space_->velocity_field(i, c)] = v[c];
        }
      }
    ++stats_.remeshes;
    after_remesh_ = mesh_badness();
    return true;
  }

  /// Writes the whole state at t^n (mesh, every history level, bodies, counters) to `file`,
  /// atomically (sim/checkpoint.hpp). A flow built on `read_checkpoint_mesh<D>(file)`, given
  /// the same configuration (options, boundary data, bodies, remeshing, collisions) and then
  /// `load_checkpoint(file)`, continues bit for bit.
  void save_checkpoint(const std::filesystem::path& file) const {
    CheckpointWriter w(file);
    w.section("config");
    w.put(std::int32_t(D));
    w.put_string(Pair::name);
    w.put_string(Scheme::name);
    detail_write_mesh(w, mesh_);
    w.section("state");
    w.put(t_);
    w.put(last_dt_);
    w.put(std::int32_t(levels_));
    w.put(std::int32_t(stats_.steps));
    w.put(std::int32_t(stats_.remeshes));
    w.put(std::int32_t(stats_.history_restarts));
    w.put(after_remesh_.first);
    w.put(after_remesh_.second);
    for (int k = 1; k < 3; ++k) w.put_vector(flatten(X_[k]));
    for (int k = 0; k < 3; ++k) w.put_vector(U_[k]);
    w.put_vector(flatten(Vn_));
    w.section("bodies");
    w.put(std::uint64_t(bodies_.size()));
    for (const auto& b : bodies_) {
      w.put(std::int32_t(b.data.tag));
      for (int k = 0; k < 3; ++k) {
        w.put_vector(std::vector<Real>(b.xg[k].data(), b.xg[k].data() + D));
        put_orientation(w, b.th[k]);
        w.put_vector(std::vector<Real>(b.Z[k].data(), b.Z[k].data() + body_dofs));
      }
      w.put_vector(std::vector<Real>(b.load.data(), b.load.data() + body_dofs));
      w.put_vector(std::vector<Real>(b.contact.data(), b.contact.data() + D));
      w.put_vector(flatten(b.r0));
    }
    w.section("end");
    w.commit();
  }

  /// Restores the state written by `save_checkpoint` into a flow that has not stepped yet and
  /// was built on the checkpoint's mesh (`read_checkpoint_mesh`) with the same configuration.
  void load_checkpoint(const std::filesystem::path& file) {
    require_not_started("load_checkpoint");
    CheckpointReader r(file);
    r.section("config");
    if (r.get<std::int32_t>("dimension") != D) r.fail("written by a flow of another dimension");
    if (r.get_string("element pair") != Pair::name) r.fail("written with another element pair");
    if (r.get_string("scheme") != Scheme::name) r.fail("written with another time scheme");
    const Mesh<D> m = detail_read_mesh<D>(r);
    if (m.n_nodes() != mesh_.n_nodes() || m.n_cells() != mesh_.n_cells() || m.cells() != mesh_.cells() ||
        m.coordinates() != mesh_.coordinates())
      r.fail("the flow's mesh is not the checkpoint's (build it with read_checkpoint_mesh)");
    r.section("state");
    t_ = r.get<Real>("t");
    last_dt_ = r.get<Real>("dt");
    levels_ = r.get<std::int32_t>("levels");
    stats_.steps = r.get<std::int32_t>("steps");
    stats_.remeshes = r.get<std::int32_t>("remeshes");
    stats_.history_restarts = r.get<std::int32_t>("history restarts");
    after_remesh_.first = r.get<Real>("remesh state");
    after_remesh_.second = r.get<Real>("remesh state");
    X_[0] = mesh_.coordinates();
    for (int k = 1; k < 3; ++k) X_[k] = unflatten(r.get_vector<Real>("positions"));
    for (int k = 0; k < 3; ++k) U_[k] = r.get_vecx("field");
    Vn_ = unflatten(r.get_vector<Real>("mesh velocity"));
    if (U_[0].size() != space_->n_field()) r.fail("field size does not match the mesh");
    r.section("bodies");
    if (r.get<std::uint64_t>("body count") != bodies_.size()) r.fail("another number of bodies than this flow's");
    for (auto& b : bodies_) {
      if (r.get<std::int32_t>("body tag") != b.data.tag) r.fail("body tags differ from this flow's");
      for (int k = 0; k < 3; ++k) {
        const auto xg = r.get_vector<Real>("body centre");
        const BodyOrientation th = get_orientation(r);
        const auto Z = r.get_vector<Real>("body velocity");
        if (xg.size() != std::size_t(D) || Z.size() != std::size_t(body_dofs)) r.fail("bad body record");
        for (int c = 0; c < D; ++c) b.xg[k][c] = xg[c];
        b.th[k] = th;
        for (int c = 0; c < body_dofs; ++c) b.Z[k][c] = Z[c];
      }
      const auto load = r.get_vector<Real>("body load");
      const auto contact = r.get_vector<Real>("body contact");
      b.r0 = unflatten(r.get_vector<Real>("body surface"));
      if (load.size() != std::size_t(body_dofs) || contact.size() != std::size_t(D) || b.r0.size() != b.nodes.size())
        r.fail("bad body record");
      for (int c = 0; c < body_dofs; ++c) b.load[c] = load[c];
      for (int c = 0; c < D; ++c) b.contact[c] = contact[c];
    }
    r.section("end");
    r.finish();
    setup();
  }

  /// Smallest Mesh::quality over the cells.
  Real worst_quality() const {
    Real q = 1;
    for (Index c = 0; c < mesh_.n_cells(); ++c) q = std::min(q, mesh_.quality(c));
    return q;
  }

 private:
  // A body's orientation in a checkpoint: the angle (2D), the quaternion (x, y, z, w) (3D).
  static void put_orientation(CheckpointWriter& w, const BodyOrientation& th) {
    if constexpr (D == 2) w.put(th);
    else w.put_vector(std::vector<Real>(th.coeffs().data(), th.coeffs().data() + 4));
  }
  static BodyOrientation get_orientation(CheckpointReader& r) {
    if constexpr (D == 2) {
      return r.get<Real>("body angle");
    } else {
      const auto q = r.get_vector<Real>("body orientation");
      if (q.size() != 4) r.fail("bad body record");
      return Eigen::Quaternion<Real>(q[3], q[0], q[1], q[2]);
    }
  }

  std::size_t add_body_impl(const BodyData& body) {
    require_not_started("add_body");
    body.validate(bodies_.size());
    ALEFSI_CHECK_ARG(!mesh_.boundary_nodes(body.tag).empty(), "body.tag", "no boundary facet has tag ", body.tag);
    ALEFSI_CHECK_ARG(!dirichlet_.count(body.tag), "body.tag", "tag ", body.tag, " already has a Dirichlet velocity");
    Body b;
    b.data = body;
    b.xg.fill(body.centre);
    b.th.fill(BodyTraits::initial_orientation(body));
    b.Z.fill(body.prescribed ? body.prescribed(t_) : body.velocity);
    b.nodes = mesh_.boundary_nodes(body.tag);
    for (Index v : b.nodes) b.r0.push_back(BodyTraits::initial_offset(mesh_.node(v) - body.centre, body));
    bodies_.push_back(std::move(b));
    return bodies_.size() - 1;
  }

  void require_not_started(const char* what) const {
    if (cons_) throw Error(std::string("AleFlow::") + what + " after the first step");
  }

  void setup() {
    cons_ = std::make_unique<DofConstraints>(space_->n_field());
    const auto& vel = space_->velocity();
    std::vector<char> done(vel.n_dofs(), 0);
    dirichlet_dofs_ = fix_velocity_on_tags(*space_, dirichlet_, *cons_, done);
    for (auto& b : bodies_) {
      b.dofs.clear();
      if (b.data.free()) b.extra = cons_->add_unknowns(body_dofs);
      for (Index i : vel.boundary_dofs(b.data.tag)) {
        ALEFSI_CHECK_ARG(!done[i], "body.tag", "body surface (tag ", b.data.tag, ") touches a Dirichlet wall or another body");
        done[i] = 1;
        b.dofs.push_back(i);
        for (int k = 0; k < D; ++k) {
          const Index f = space_->velocity_field(i, k);
          if (b.data.free()) {
            std::array<Index, body_dofs> ex;
            for (int C = 0; C < body_dofs; ++C) ex[C] = b.extra + C;
            const std::array<Real, body_dofs> w{};
            cons_->link(f, ex, w, 0.0);
          } else {
            cons_->fix(f, 0.0);
          }
        }
      }
    }
    // every boundary velocity prescribed (walls or bodies): p is defined up to a constant
    pinned_ = whole_boundary_prescribed(mesh_, [&](int tag) {
      bool body = false;
      for (const auto& b : bodies_) body |= b.data.tag == tag;
      return body || dirichlet_.count(tag) > 0;
    });
    if (pinned_) cons_->fix(space_->pressure_field(0), 0.0);
    cons_->finalize();
    asmb_ = std::make_unique<Assembler<Space::n_local>>(
        mesh_.n_cells(), [&](Index c) { return space_->cell_field_dofs(c); }, *cons_);
    asmb_->set_threads(opt_.threads);
    for (const auto& b : bodies_)  // disks and spheres: their surface is on the given radius
      if (b.data.radius > 0)
        for (Index v : b.nodes)
          ALEFSI_CHECK_ARG(std::abs((mesh_.node(v) - b.xg[0]).norm() - b.data.radius) <= 1e-6 * b.data.radius,
                           "body.radius", "body with tag ", b.data.tag, ": surface node ", v, " is at distance ",
                           (mesh_.node(v) - b.xg[0]).norm(), " from the centre, not the radius ", b.data.radius);
    if constexpr (D == 2) {
      for (auto& b : bodies_) {
        b.facets.clear();
        for (Index f : mesh_.boundary_facets())
          if (mesh_.facet_tag(f) == b.data.tag) b.facets.push_back({mesh_.facet(f)[0], mesh_.facet(f)[1]});
      }
      update_collision_walls();
      // a scene with overlapping bodies is refused before the first step (the mesh cannot
      // show that: two holes share no node, but a user's centre or radius can be wrong)
      if (stats_.steps == 0)
        for (const auto& c : overlaps(0))
          throw InvalidArgument("bodies", "bodies[" + std::to_string(c.k) + "] and bodies[" + std::to_string(c.j) +
                                              "] overlap (gap " + std::to_string(c.gap) + ")");
    }
  }

  // Pairs of bodies whose surfaces overlap (gap <= 0) at level k (-1: t^{n+1}).
  std::vector<Contact2D> overlaps(int k) const
    requires(D == 2)
  {
    std::vector<Contact2D> out;
    CollisionModel2D probe(CollisionOptions{.range = 1e-9, .walls = false});
    for (const auto& c : probe.contacts(collision_bodies(k), opt_.mu))
      if (c.gap <= 0) out.push_back(c);
    return out;
  }

  // Boundary facets that are not body surfaces, as segments at the current positions.
  std::vector<Segment2D> wall_segments() const
    requires(D == 2)
  {
    std::vector<Segment2D> w;
    for (Index f : mesh_.boundary_facets()) {
      bool body = false;
      for (const auto& b : bodies_) body |= b.data.tag == mesh_.facet_tag(f);
      if (!body) w.push_back({mesh_.node(mesh_.facet(f)[0]), mesh_.node(mesh_.facet(f)[1])});
    }
    return w;
  }
  void update_collision_walls() {
    if constexpr (D == 2)
      if (collision_) collision_->set_walls(wall_segments());
  }
  // The bodies for the collision model at history level k (0: t^n), or at t^{n+1} (k = -1:
  // the positions placed for the step being solved), with their velocities Z[k] / Zhat.
  std::vector<CollisionBody2D> collision_bodies(int k) const
    requires(D == 2)
  {
    std::vector<CollisionBody2D> out;
    for (const auto& b : bodies_) {
      CollisionBody2D c;
      c.centre = k < 0 ? b.xg_next : b.xg[k];
      c.velocity = (k < 0 ? b.Zhat : b.Z[k]).template head<2>();
      c.radius = b.data.radius;
      const Real rot = (k < 0 ? b.th_next : b.th[k]) - b.data.angle;
      auto at = [&](Index v) {
        const auto it = std::lower_bound(b.nodes.begin(), b.nodes.end(), v);
        return Vec<2>(c.centre + rotate(b.r0[std::size_t(it - b.nodes.begin())], rot));
      };
      c.r_in = std::numeric_limits<Real>::infinity();
      for (std::size_t j = 0; j < b.r0.size(); ++j) c.r_out = std::max(c.r_out, b.r0[j].norm());
      for (const auto& f : b.facets) {
        const Segment2D seg{at(f[0]), at(f[1])};
        c.r_in = std::min(c.r_in, (detail::closest_on_segment(c.centre, seg) - c.centre).norm());
        if (c.radius == 0) c.surface.push_back(seg);
      }
      if (c.radius > 0) c.r_in = c.r_out = c.radius;
      out.push_back(std::move(c));
    }
    return out;
  }

  // The disk bodies (radius > 0) as circles at their place at t^n.
  std::vector<Circle> current_disks() const
    requires(D == 2)
  {
    std::vector<Circle> disks;
    for (const auto& b : bodies_)
      if (b.data.radius > 0) disks.push_back(Circle{b.xg[0], b.data.radius, b.data.tag});
    return disks;
  }

  // (worst quality, worst relative size deviation |L - h| / h) of the current mesh
  std::pair<Real, Real> mesh_badness() const
    requires(D == 2)
  {
    Real dev = 0;
    if (remesh_->size) {
      const SizeFunction h = remesh_->size(current_disks());
      for (const auto& e : mesh_.edges()) {
        const Vec<2> a = mesh_.node(e[0]), c = mesh_.node(e[1]);
        const Real E = h(0.5 * (a + c));
        dev = std::max(dev, std::abs((a - c).norm() - E) / E);
      }
    }
    return {worst_quality(), dev};
  }
  // The trigger, with hysteresis: what the last adaptation could not bring inside the band
  // (e.g. the cells in a gap narrower than h) triggers again only once it got worse by 10 %.
  bool remesh_needed() const
    requires(D == 2)
  {
    const auto [q, dev] = mesh_badness();
    const Real q_lim = std::min(remesh_->trigger_quality, 0.9 * after_remesh_.first);
    const Real dev_lim = std::max(remesh_->adapt.tolerance, 1.1 * after_remesh_.second);
    return q < q_lim || (remesh_->size && dev > dev_lim);
  }

  // DOF position of scalar velocity DOF i on geometry x.
  Vec<D> dof_point(Index i, const std::vector<Vec<D>>& x) const {
    if (i < mesh_.n_nodes()) return x[i];
    const auto& e = mesh_.edge(i - mesh_.n_nodes());
    return 0.5 * (x[e[0]] + x[e[1]]);
  }

  std::vector<Vec<D>> solve_mesh_velocity(const std::vector<Vec<D>>& x, const VecX& /*u_hat*/, Real t) {
    if (prescribed_) {
      std::vector<Vec<D>> v(x.size());
      for (std::size_t i = 0; i < x.size(); ++i) v[i] = prescribed_(x[i], t);
      return v;
    }
    // boundary data: a body's rigid velocity, else the tag's function, else 0
    std::vector<const TimeFunction*> node_fn(mesh_.n_nodes(), nullptr);
    for (const auto& [tag, g] : mesh_bc_)
      for (Index v : mesh_.boundary_nodes(tag)) node_fn[v] = &g;
    return motion_->solve(x, [&](Index v, const Vec<D>& xv) {
      if (!body_v_.empty() && body_has_v_[v]) return body_v_[v];
      return node_fn[v] ? (*node_fn[v])(xv, t) : Vec<D>(Vec<D>::Zero());
    });
  }

  // Rigid velocities of the body nodes on geometry x for the mesh-velocity problem: the bodies'
  // extrapolated state (weights w over levels n, n-1, n-2), or the prescribed motion at t.
  void set_body_mesh_velocity(const std::vector<Vec<D>>& x, const std::array<Real, 3>& w, Real t) {
    if (bodies_.empty()) return;
    body_v_.assign(mesh_.n_nodes(), Vec<D>::Zero());
    body_has_v_.assign(mesh_.n_nodes(), 0);
    for (auto& b : bodies_) {
      Vec<D> xg = Vec<D>::Zero();
      BodyVelocity Z = BodyVelocity::Zero();
      for (int k = 0; k < 3; ++k) xg += w[k] * b.xg[k], Z += w[k] * b.Z[k];
      if (!b.data.free()) Z = b.data.prescribed(t);
      b.Zhat = Z;
      for (Index v : b.nodes) {
        body_v_[v] = BodyTraits::velocity(Z, x[v] - xg);
        body_has_v_[v] = 1;
      }
    }
  }


  template <TimeScheme S>
  StepReport step_with(Real dt) {
    // the first MR/AB step: X^{-1} = X^0 - dt V^0, U^{-1} = U^0
    if (levels_ == 0 && history_levels<S>() > 0) {
      X_[1] = X_[0];
      for (std::size_t i = 0; i < X_[1].size(); ++i) X_[1][i] -= dt * Vn_[i];
      U_[1] = U_[0];
      for (auto& b : bodies_) {
        b.xg[1] = b.xg[0] - dt * b.Z[0].template head<D>();
        b.th[1] = BodyTraits::step_back(b.th[0], b.Z[0], dt);
        b.Z[1] = b.Z[0];
      }
    }
    // 1. extrapolated geometry and flow
    std::vector<Vec<D>> Xh(X_[0].size(), Vec<D>::Zero());
    VecX Uh = VecX::Zero(U_[0].size());
    for (int k = 0; k < 3; ++k)
      if (S::extrapolation[k] != 0) {
        for (std::size_t i = 0; i < Xh.size(); ++i) Xh[i] += S::extrapolation[k] * X_[k][i];
        Uh += S::extrapolation[k] * U_[k];
      }
    // 2. mesh velocity
    const Real tV = S::velocity_level == VelocityLevel::n ? t_ : S::velocity_level == VelocityLevel::n_half ? t_ + dt / 2 : t_ + dt;
    StepReport rep;
    auto clock = std::chrono::steady_clock::now();
    auto lap = [&clock](Real& acc) {
      const auto now = std::chrono::steady_clock::now();
      acc += std::chrono::duration<Real>(now - clock).count();
      clock = now;
    };
    set_body_mesh_velocity(Xh, S::extrapolation, tV);
    const std::vector<Vec<D>> Vs = solve_mesh_velocity(Xh, Uh, tV);
    lap(rep.t_mesh_velocity);
    // 3. positions
    const auto b = bdf_coefficients(S::position_bdf);
    std::vector<Vec<D>> Xn1(X_[0].size());
    for (std::size_t i = 0; i < Xn1.size(); ++i) {
      Vec<D> s = dt * Vs[i];
      for (int k = 1; k <= S::position_bdf; ++k) s -= b[k] * X_[k - 1][i];
      Xn1[i] = s / b[0];
    }
    // bodies: centre and orientation by the same formula with the extrapolated rigid velocity
    // (3D: on the rotation vector, RigidBodyTraits<3>::advance); their surface nodes are
    // placed by the exact rigid motion
    for (auto& body : bodies_) {
      Vec<D> xs = dt * body.Zhat.template head<D>();
      for (int k = 1; k <= S::position_bdf; ++k) xs -= b[k] * body.xg[k - 1];
      body.xg_next = xs / b[0];
      body.th_next = BodyTraits::advance(body.th, body.Zhat, b, S::position_bdf, dt);
      for (std::size_t j = 0; j < body.nodes.size(); ++j)
        Xn1[body.nodes[j]] = body.xg_next + BodyTraits::to_world(body.r0[j], body.th_next, body.data);
    }
    // mesh velocity the flow sees, and V^{n+1} for the next step
    std::vector<Vec<D>> Vflow = Vs, Vnext = Vs;
    if (S::velocity_level == VelocityLevel::n_half)
      for (std::size_t i = 0; i < Vs.size(); ++i) Vnext[i] = 2 * Vs[i] - Vn_[i];
    if (S::flow_velocity == FlowMeshVelocity::ab2) Vflow = Vnext;
    // 4. flow geometry X^{n+theta}
    std::vector<Vec<D>> Xth(Xn1.size());
    for (std::size_t i = 0; i < Xth.size(); ++i) Xth[i] = S::theta * Xn1[i] + (1 - S::theta) * X_[0][i];
    mesh_.set_coordinates(Xth);
    // Dirichlet values at t^{n+1} on X^{n+1}
    const Real t1 = t_ + dt;
    for (const auto& [i, tag] : dirichlet_dofs_) {
      const Vec<D> val = dirichlet_.at(tag)(dof_point(i, Xn1), t1);
      for (int k = 0; k < D; ++k) cons_->set_fixed_value(space_->velocity_field(i, k), val[k]);
    }
    // body surface velocities at t^{n+1} on X^{n+1}: u = H(r^{n+1}) Z + u_s. A free body's link
    // is also its rows' test function, which must live where the flow is integrated, X^{n+theta}
    // (else the torque row is off by (r^{n+1} - r^{n+theta}) x F = O(dt) when theta < 1: the
    // sum of r . F over the surface carries the pressure level). So the link takes
    // H(r^{n+theta}) and the offset the rest, H(r^{n+1}) - H(r^{n+theta}), times the
    // Z extrapolated to t^{n+1}: the velocity is off by O(dt^3) only. For theta = 1 both are
    // H(r^{n+1}).
    for (auto& body : bodies_) {
      const BodyVelocity Zp = body.data.free() ? BodyVelocity::Zero() : BodyVelocity(body.data.prescribed(t1));
      const Vec<D> xg_th = S::theta * body.xg_next + (1 - S::theta) * body.xg[0];
      const BodyVelocity Zx = 2 * body.Z[0] - body.Z[1];
      for (Index i : body.dofs) {
        const Vec<D> r = dof_point(i, Xn1) - body.xg_next;
        Vec<D> us = body.data.slip ? BodyTraits::to_world(body.data.slip(BodyTraits::to_body(r, body.th_next, body.data)),
                                                          body.th_next, body.data)
                                   : Vec<D>::Zero();
        const auto H = BodyTraits::rows(r);
        if (!body.data.free()) {
          for (int k = 0; k < D; ++k) cons_->set_fixed_value(space_->velocity_field(i, k), H[k].dot(Zp) + us[k]);
          continue;
        }
        if constexpr (S::theta < 1) {
          const auto Hth = BodyTraits::rows(Vec<D>(dof_point(i, Xth) - xg_th));
          for (int k = 0; k < D; ++k) {
            us[k] += (H[k] - Hth[k]).dot(Zx);
            cons_->set_link(space_->velocity_field(i, k), {Hth[k].data(), std::size_t(body_dofs)}, us[k]);
          }
        } else {
          for (int k = 0; k < D; ++k) cons_->set_link(space_->velocity_field(i, k), {H[k].data(), std::size_t(body_dofs)}, us[k]);
        }
      }
    }
    // history of the BDF time derivative and the extrapolated convecting velocity
    const auto a = bdf_coefficients(S::flow_bdf);
    VecX hist = VecX::Zero(U_[0].size());
    for (int k = 1; k <= S::flow_bdf; ++k) hist += a[k] * U_[k - 1];
    const auto ew = extrapolation_weights(S::theta < 1 ? 2 : S::flow_bdf, S::theta < 1);
    VecX ustar = VecX::Zero(U_[0].size());
    for (int k = 0; k < 3; ++k)
      if (ew[k] != 0) ustar += ew[k] * U_[k];
    StepInputs<D> in;
    in.dt = dt;
    in.theta = S::theta;
    in.a0 = a[0];
    in.history = &hist;
    in.previous = &U_[0];
    in.extrapolated = &ustar;
    in.mesh_velocity = &Vflow;
    const Real tf = t_ + S::theta * dt;
    if (force_ || gravity_.squaredNorm() > 0)
      in.force = [this, tf](const Vec<D>& x) {
        Vec<D> f = opt_.rho * gravity_;
        if (force_) f += force_(x, tf);
        return f;
      };
    kernel_->set_step(in);
    if constexpr (D == 2) {
      contacts_.clear();
      if (collision_ && !bodies_.empty()) contacts_ = collision_->contacts(collision_bodies(-1), opt_.mu);
      stats_.contacts = int(contacts_.size());
      if (bodies_.size() > 1)
        for (const auto& c : overlaps(-1)) {  // reject the step: the caller may retry with a smaller dt
          mesh_.set_coordinates(X_[0]);
          throw SolverError("bodies[" + std::to_string(c.k) + "] and bodies[" + std::to_string(c.j) +
                            "] would overlap at t = " + std::to_string(t1) + " (gap " + std::to_string(c.gap) + ")");
        }
    }
    // 5. Newton (or one semi-implicit solve)
    clock = std::chrono::steady_clock::now();
    VecX u = cons_->restrict_free(U_[0]);
    for (const auto& body : bodies_)
      if (body.data.free()) u.template segment<body_dofs>(cons_->extra_unknown(body.extra)) = body.Z[0];
    VecX field = cons_->expand(u);
    VecX r;
    Real r0 = -1;
    const bool newton = opt_.linearisation == Linearisation::newton;
    try {
      for (int it = 0;; ++it) {
        asmb_->assemble(*kernel_, field, &J_, &r);
        add_body_rows<S>(dt, u, r);
        lap(rep.t_assembly);
        const Real rn = r.size() ? r.lpNorm<Eigen::Infinity>() : 0.0;
        rep.residuals.push_back(rn);
        if (!std::isfinite(rn)) throw SolverError("non-finite residual at Newton iteration " + std::to_string(it));
        if (r0 < 0) r0 = rn;
        if (newton && it > 0 && rn <= opt_.newton_tolerance * r0 + 1e-13) break;
        if (newton && it == opt_.max_newton)
          throw SolverError("Newton did not converge in " + std::to_string(it) + " iterations (residual " +
                            std::to_string(rn) + ", first " + std::to_string(r0) + ")");
        if (!analysed_) {
          solver_->analyze(J_);
          analysed_ = true;
        }
        solver_->factorize(J_);
        lap(rep.t_factorize);
        u -= solver_->solve(r);
        lap(rep.t_solve);
        field = cons_->expand(u);
        ++rep.newton_iterations;
        if (!newton) break;
      }
    } catch (...) {
      mesh_.set_coordinates(X_[0]);  // the step is rejected: the state stays at t^n
      throw;
    }
    if (pinned_) shift_pressure_to_zero_mean(*space_, field);
    for (auto& body : bodies_) {
      const BodyVelocity Zn1 = body.data.free() ? BodyVelocity(u.template segment<body_dofs>(cons_->extra_unknown(body.extra)))
                                                : BodyVelocity(body.data.prescribed(t1));
      if (body.data.free()) {
        body.load = body_inertia<S>(body, Zn1, dt) - body_weight(body) - body.data_external();
        body.load.template head<D>() -= body.contact;
      }
      body.Z[2] = body.Z[1], body.Z[1] = body.Z[0], body.Z[0] = Zn1;
      body.xg[2] = body.xg[1], body.xg[1] = body.xg[0], body.xg[0] = body.xg_next;
      body.th[2] = body.th[1], body.th[1] = body.th[0], body.th[0] = body.th_next;
    }
    // 6. shift histories
    U_[2] = U_[1];
    U_[1] = U_[0];
    U_[0] = field;
    X_[2] = X_[1];
    X_[1] = X_[0];
    X_[0] = Xn1;
    Vn_ = Vnext;
    mesh_.set_coordinates(Xn1);
    t_ = t1;
    ++levels_;
    return rep;
  }

  struct Body {
    BodyData data;
    std::array<Vec<D>, 3> xg;
    std::array<BodyOrientation, 3> th{};  // angle (2D) / quaternion (3D) per level
    std::array<BodyVelocity, 3> Z;
    BodyVelocity Zhat = BodyVelocity::Zero(), load = BodyVelocity::Zero();
    Vec<D> xg_next = Vec<D>::Zero();
    BodyOrientation th_next{};
    Index extra = -1;           // first of its body_dofs extra unknowns (free bodies)
    std::vector<Index> nodes;   // surface mesh nodes
    std::vector<Vec<D>> r0;     // their offsets from the centre at t0 (3D: in body axes)
    std::vector<Index> dofs;    // surface velocity DOFs
    std::vector<std::array<Index, 2>> facets;  // surface facets (2D)
    Vec<D> contact = Vec<D>::Zero();           // collision force in the last step
    BodyVelocity data_external() const { return data.external_load; }
  };

  // ---- the damped start (FlowOptions::damped_start) ----
  // The whole state a step changes, to take a damped start twice (extrapolation) and to leave
  // the flow at t^n when a substep throws.
  struct Snapshot {
    Real t = 0;
    int levels = 0;
    std::array<std::vector<Vec<D>>, 3> X;
    std::array<VecX, 3> U;
    std::vector<Vec<D>> Vn;
    std::vector<Body> bodies;
  };
  Snapshot snapshot() const { return {t_, levels_, X_, U_, Vn_, bodies_}; }
  void restore(const Snapshot& s) {
    t_ = s.t, levels_ = s.levels, X_ = s.X, U_ = s.U, Vn_ = s.Vn, bodies_ = s.bodies;
    mesh_.set_coordinates(X_[0]);
  }
  static void add_report(StepReport& acc, const StepReport& r) {
    acc.newton_iterations += r.newton_iterations;
    acc.residuals.insert(acc.residuals.end(), r.residuals.begin(), r.residuals.end());
    acc.t_mesh_velocity += r.t_mesh_velocity, acc.t_assembly += r.t_assembly, acc.t_factorize += r.t_factorize;
    acc.t_solve += r.t_solve;
  }
  // Orientation extrapolated from two approximations a (error e) and b (error ~2e): 2a - b on
  // the angle (2D); a (b^-1 a) on the rotation group (3D: a exp(e_a) exp(e_a - e_b) = exp(2 e_a - e_b) to O(e^2)).
  static BodyOrientation extrapolate_orientation(const BodyOrientation& a, const BodyOrientation& b) {
    if constexpr (D == 2) return 2 * a - b;
    else return BodyOrientation(a * (b.inverse() * a)).normalized();
  }

  // The first step from t^n (levels_ == 0) by m = opt_.damped_start backward-Euler substeps of
  // dt/m: BSS, the only L-stable scheme of the five (|R(inf)| = 0, where Crank-Nicolson keeps
  // |R(inf)| = 1), so the stiff modes of a non-smooth start are damped before the multistep
  // formulas take over. Local error O(dt^2) (m substeps of O((dt/m)^2)): enough for design
  // order <= 2. For order >= 3 the result is Richardson-extrapolated with m/2 substeps of
  // 2 dt/m, 2 u_{dt/m} - u_{2dt/m}, local error O(dt^3) (the O(dt^2) terms of the two cancel:
  // BE's error is c dt_sub + O(dt_sub^2) per unit time); the extrapolation of the stability
  // functions, 2 (1 + z/m)^-m - (1 + 2z/m)^-(m/2), still vanishes at z -> inf. Positions and
  // field are extrapolated node by node, the bodies' centre, velocity and orientation likewise
  // and their surface nodes placed by the exact rigid map. The history is then set to levels
  // t^n (the state before the step) and t^n + dt, V^n is solved at t^n + dt on X^{n+1} (as at a
  // history restart) and levels_ = 1: a scheme that reads two past levels (BDF3) takes one
  // MR/AB start-up step next. A substep that throws leaves the flow at t^n.
  StepReport damped_start_step(Real dt) {
    const int m = opt_.damped_start;
    const Snapshot s0 = snapshot();
    StepReport rep;
    rep.startup = true;
    auto substeps = [&](int count) {
      for (int j = 0; j < count; ++j) add_report(rep, step_with<BSS>(dt / count));
    };
    try {
      substeps(m);
      if constexpr (Scheme::order >= 3) {
        const Snapshot fine = snapshot();
        restore(s0);
        substeps(m / 2);
        for (std::size_t i = 0; i < X_[0].size(); ++i) X_[0][i] = 2 * fine.X[0][i] - X_[0][i];
        U_[0] = 2 * fine.U[0] - U_[0];
        for (std::size_t k = 0; k < bodies_.size(); ++k) {
          Body& b = bodies_[k];
          const Body& f = fine.bodies[k];
          b.xg[0] = 2 * f.xg[0] - b.xg[0];
          b.Z[0] = 2 * f.Z[0] - b.Z[0];
          b.th[0] = extrapolate_orientation(f.th[0], b.th[0]);
          b.load = f.load, b.contact = f.contact;
          for (std::size_t j = 0; j < b.nodes.size(); ++j)
            X_[0][b.nodes[j]] = b.xg[0] + BodyTraits::to_world(b.r0[j], b.th[0], b.data);
        }
      }
      // the history at t^n and t^n + dt (level 2 is not read with levels_ = 1; it holds t^n too)
      for (int k = 1; k < 3; ++k) X_[k] = s0.X[0], U_[k] = s0.U[0];
      for (std::size_t i = 0; i < bodies_.size(); ++i)
        for (int k = 1; k < 3; ++k) {
          bodies_[i].xg[k] = s0.bodies[i].xg[0];
          bodies_[i].th[k] = s0.bodies[i].th[0];
          bodies_[i].Z[k] = s0.bodies[i].Z[0];
        }
      t_ = s0.t + dt;
      levels_ = 1;
      mesh_.set_coordinates(X_[0]);
      set_body_mesh_velocity(X_[0], {1.0, 0.0, 0.0}, t_);
      Vn_ = solve_mesh_velocity(X_[0], U_[0], t_);
    } catch (...) {
      restore(s0);
      throw;
    }
    return rep;
  }

  // M delta_l Z^{n+1} / dt (+ w x I_w w in 3D) for body b, at its orientation for t^{n+1}.
  template <TimeScheme S>
  static BodyVelocity body_inertia(const Body& b, const BodyVelocity& Zn1, Real dt) {
    const auto a = bdf_coefficients(S::flow_bdf);
    BodyVelocity dZ = a[0] * Zn1;
    for (int k = 1; k <= S::flow_bdf; ++k) dZ += a[k] * b.Z[k - 1];
    return BodyTraits::inertia(b.data, b.th_next, Zn1, dZ, dt);
  }
  BodyVelocity body_weight(const Body& b) const {
    BodyVelocity w = BodyVelocity::Zero();
    w.template head<D>() = b.data.mass * gravity_;
    return w;
  }
  // Body rows (eq. 11): M delta_l Z / dt (+ w x I_w w) - M g - external load, added to the
  // fluid terms; their Jacobian (exact, gyroscopic term included) on the body's block.
  template <TimeScheme S>
  void add_body_rows(Real dt, const VecX& u, VecX& r) {
    const Real a0 = bdf_coefficients(S::flow_bdf)[0];
    for (auto& body : bodies_) {
      body.contact = Vec<D>::Zero();
      if (!body.data.free()) continue;
      const Index e = cons_->extra_unknown(body.extra);
      const BodyVelocity Z = u.template segment<body_dofs>(e);
      r.template segment<body_dofs>(e) += body_inertia<S>(body, Z, dt) - body_weight(body) - body.data_external();
      const auto Jb = BodyTraits::inertia_jacobian(body.data, body.th_next, Z, a0, dt);
      for (int i = 0; i < body_dofs; ++i)
        for (int j = 0; j < body_dofs; ++j)
          if (Jb(i, j) != 0) J_.coeffRef(e + i, e + j) += Jb(i, j);  // structural zeros stay untouched
    }
    if constexpr (D == 2) {
      if (contacts_.empty()) return;
      // velocities at t^{n+1}: the unknowns of free bodies, the given motion of driven ones
      auto cb = collision_bodies(-1);
      for (std::size_t k = 0; k < bodies_.size(); ++k)
        cb[k].velocity = bodies_[k].data.free()
                             ? Vec<2>(u.template segment<2>(cons_->extra_unknown(bodies_[k].extra)))
                             : Vec<2>(bodies_[k].data.prescribed(t_ + dt).template head<2>());
      for (const auto& c : contacts_) {
        const Vec<2> F = CollisionModel2D::force(c, cb);
        const Eigen::Matrix<Real, 2, 2> dF = CollisionModel2D::dforce_dvk(c, cb);
        bodies_[c.k].contact += F;
        if (c.j >= 0) bodies_[c.j].contact -= F;
        // rows: r_K -= F_K, r_J += F_K; the diagonal blocks' derivatives (the K-J coupling is lagged)
        auto add = [&](int b, Real sign) {
          if (!bodies_[b].data.free()) return;
          const Index e = cons_->extra_unknown(bodies_[b].extra);
          r.template segment<2>(e) -= sign * F;
          for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) J_.coeffRef(e + i, e + j) -= dF(i, j);
        };
        add(c.k, 1);
        if (c.j >= 0) add(c.j, -1);
      }
    }
  }

  static std::vector<Real> flatten(const std::vector<Vec<D>>& x) {
    std::vector<Real> out(D * x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
      for (int c = 0; c < D; ++c) out[D * i + c] = x[i][c];
    return out;
  }
  static std::vector<Vec<D>> unflatten(const std::vector<Real>& v) {
    std::vector<Vec<D>> out(v.size() / D);
    for (std::size_t i = 0; i < out.size(); ++i)
      for (int c = 0; c < D; ++c) out[i][c] = v[D * i + c];
    return out;
  }

  // (re)built for each mesh topology: the space and kernels point into mesh_
  void rebuild_discretisation() {
    space_ = std::make_unique<Space>(mesh_);
    kernel_ = std::make_unique<Kernel>(*space_, opt_.rho, opt_.mu, opt_.linearisation);
    motion_ = std::make_unique<ElasticMeshMotion<D>>(mesh_);
    cons_.reset();
    asmb_.reset();
    J_ = SparseMatrix();  // the assembler keeps a matrix whose size matches: a flip keeps the size
    solver_.emplace();
    analysed_ = false;
  }

  Mesh<D> mesh_;
  FlowOptions opt_;
  std::unique_ptr<Space> space_;
  std::unique_ptr<Kernel> kernel_;
  std::unique_ptr<ElasticMeshMotion<D>> motion_;
  std::map<int, TimeFunction> dirichlet_, mesh_bc_;
  TimeFunction prescribed_, force_;
  Vec<D> gravity_ = Vec<D>::Zero();
  std::vector<Body> bodies_;
  std::vector<Vec<D>> body_v_;
  std::vector<char> body_has_v_;
  std::vector<std::pair<Index, int>> dirichlet_dofs_;
  std::unique_ptr<DofConstraints> cons_;
  std::unique_ptr<Assembler<Space::n_local>> asmb_;
  SparseMatrix J_;
  std::optional<Solver> solver_;
  bool analysed_ = false, pinned_ = false;
  Real t_ = 0, last_dt_ = 0;
  int levels_ = 0;
  std::optional<RemeshOptions> remesh_;
  std::pair<Real, Real> after_remesh_{1.0, 0.0};  // mesh_badness() after the last remesh
  std::optional<CollisionModel2D> collision_;
  std::vector<Contact2D> contacts_;
  FlowStats stats_;  // steps taken (history levels available)
  std::array<std::vector<Vec<D>>, 3> X_;
  std::array<VecX, 3> U_;
  std::vector<Vec<D>> Vn_;
};

}  // namespace alefsi
