#pragma once
/// \file sim/ale_flow.hpp
/// Incompressible flow with rigid bodies on a moving mesh, advanced by one of the five ALE
/// schemes: the front that composes the parts of sim/ (docs/architecture.md).
///
/// `AleFlow<Cfg>` (Cfg a FlowConfig: dimension, element pair, scheme, equations, solver,
/// rigid-body model) owns the mesh and the flow state and advances them, one `step(dt)` at a
/// time, as section 4 of the paper prescribes (the coefficients: time/stepper.hpp):
///   1. X^ = sum_k e_k X^{n-k} (the scheme's extrapolation);
///   2. the mesh velocity at the scheme's level, on X^ (sim/mesh_velocity.hpp: bodies' rigid
///      velocities, `set_mesh_velocity` data, else 0 on the boundary; elasticity inside);
///   3. X^{n+1} from delta_lg X^{n+1} = dt V; bodies' centres and orientations by the same
///      formula, their surface nodes by the exact rigid map (sim/body_system.hpp);
///   4. the flow at n+theta on X^{n+theta} (physics/navier_stokes.hpp) with the bodies' rows
///      and the contact forces: Newton (sim/newton.hpp) with the exact Jacobian, or one
///      semi-implicit solve. Dirichlet velocities (`set_velocity`) are imposed at t^{n+1} on
///      X^{n+1}; when every boundary velocity is prescribed, pressure DOF 0 is pinned (or, for
///      a solver that takes it, the constant pressure is the system's null space) and the
///      pressure shifted to zero mean;
///   5. the new level enters the state (sim/flow_state.hpp); then, if the remesher asks for
///      it, the mesh is adapted and the state transferred (sim/remesher.hpp).
/// A step that fails (Newton, a non-finite value, an inverted cell, overlapping bodies) throws
/// and leaves the flow at t^n.
///
/// Start-up and dt changes (time/stepper.hpp): the formulas are constant-step, so a step with
/// another dt restarts the history from the current state; while the history is short the
/// step is an MR/AB start-up step (the first back-fills X^{n-1} = X^n - dt V^n); with
/// `FlowOptions::damped_start` = m the first step is m backward-Euler substeps instead
/// (Richardson-extrapolated for order >= 3).
///
///     AleFlow<FlowConfig<2, TaylorHood, BDF3_BDF3E>> flow(mesh, {.rho = 1, .mu = 0.01});
///     flow.set_velocity(tags::top, [](const Vec<2>& x, Real t) { ... });
///     flow.add_body(disk_body(5, {0.5, 0.5}, 0.1, 1.5));
///     for (int n = 0; n < 100; ++n) flow.step(0.01);
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/sim/body_system.hpp"
#include "alefsi/sim/checkpoint.hpp"
#include "alefsi/sim/config.hpp"
#include "alefsi/sim/contact.hpp"
#include "alefsi/sim/collision_contact.hpp"
#include "alefsi/sim/discretisation.hpp"
#include "alefsi/sim/flow_state.hpp"
#include "alefsi/sim/kinematics.hpp"
#include "alefsi/sim/mesh_velocity.hpp"
#include "alefsi/sim/newton.hpp"
#include "alefsi/sim/remesher.hpp"
#include "alefsi/sim/remesher2d.hpp"
#include "alefsi/time/error_estimate.hpp"
#include "alefsi/time/stepper.hpp"

namespace alefsi {

struct StepReport {
  int newton_iterations = 0;
  std::vector<Real> residuals;  ///< max-norm residual before each Newton update
  bool startup = false;   ///< a start-up step (MR/AB, or a damped start)
  bool remeshed = false;  ///< the mesh was adapted after the step
  /// The local error estimate of a regular step (time/error_estimate.hpp); none for start-up
  /// steps.
  ErrorEstimate error;
  /// Wall time (s) of the step's phases: mesh-velocity solve, assembly (all Newton
  /// iterations), numeric factorisation (incl. the one-off symbolic analysis), triangular
  /// solves, adaptation + transfer + rebuild.
  Real t_mesh_velocity = 0, t_assembly = 0, t_factorize = 0, t_solve = 0, t_remesh = 0;
  /// The flow system's linear solves: factorisations, solves reusing an earlier factorisation
  /// (FlowOptions::reuse_factorisation) and their GMRES iterations.
  LinearSolveCounts linear;

  void add(const StepReport& r) {
    newton_iterations += r.newton_iterations;
    residuals.insert(residuals.end(), r.residuals.begin(), r.residuals.end());
    t_mesh_velocity += r.t_mesh_velocity, t_assembly += r.t_assembly, t_factorize += r.t_factorize;
    t_solve += r.t_solve, t_remesh += r.t_remesh;
    linear += r.linear;
  }
};

template <FlowConfiguration Cfg>
class AleFlow {
 public:
  static constexpr int D = Cfg::dim;
  using Config = Cfg;
  using Scheme = typename Cfg::Scheme;
  using BodyModel = typename Cfg::BodyModel;
  using Solver = typename Cfg::Solver;
  using Space = typename Discretisation<Cfg>::Space;
  using State = FlowState<D, BodyModel>;
  using TimeFunction = std::function<Vec<D>(const Vec<D>&, Real)>;
  using BodyData = typename BodyModel::Body;                 ///< RigidBody2D / RigidBody3D
  using BodyVelocity = typename BodyModel::Velocity;         ///< Z: Vec<3> (2D) / Vec<6> (3D)
  using BodyOrientation = typename BodyModel::Orientation;  ///< angle (2D) / unit quaternion (3D)
  static constexpr int body_dofs = BodyModel::n_dof;

  /// The flow on `mesh` (owned), with the run-time options; `solver_args` are passed to the
  /// constructor of the flow system's solver (e.g. `KrylovOptions{.tolerance = 1e-10}`), which
  /// `solver()` gives access to afterwards.
  template <class... SolverArgs>
  AleFlow(Mesh<D> mesh, FlowOptions opt, SolverArgs&&... solver_args)
      : mesh_(std::move(mesh)),
        opt_((opt.validate(), opt)),
        stepper_(opt.damped_start, opt.variable_steps, opt.start_up),
        disc_(mesh_, opt_, std::forward<SolverArgs>(solver_args)...), contact_(DefaultContact<D>::geometry()) {
    state_.X[0] = mesh_.coordinates();
    state_.U[0] = VecX::Zero(disc_.space().n_field());
  }
  AleFlow(const AleFlow&) = delete;  // the space and kernels point into the owned mesh
  AleFlow& operator=(const AleFlow&) = delete;

  const Mesh<D>& mesh() const { return mesh_; }
  const Space& space() const { return disc_.space(); }
  /// The flow system's linear solver (its analysis is redone after every topology change).
  Solver& solver() { return disc_.linear_solve().solver(); }
  const Solver& solver() const { return disc_.linear_solve().solver(); }
  /// Every boundary velocity is prescribed: the pressure is defined up to a constant (and
  /// reported with zero mean).
  bool closed_domain() const { return disc_.closed_domain(); }
  /// ... and the solver takes the system unpinned, the constant pressure as its null space
  /// (SolvesPressureNullSpace, la/saddle_point_blocks.hpp) rather than pressure DOF 0 pinned.
  bool pressure_null_space() const { return disc_.pressure_null_space(); }
  const State& state() const { return state_; }
  const FlowStats& stats() const { return state_.stats; }
  /// Whether a change of dt keeps the history (FlowOptions::variable_steps).
  bool variable_steps() const { return stepper_.variable_steps(); }
  /// What the time loop's step-size controller remembers: the next step and the last scaled
  /// error; kept in checkpoints (sim/driver.hpp).
  void set_step_control(Real next_dt, Real last_error) {
    state_.control.next_dt = next_dt, state_.control.last_error = last_error;
  }
  const FlowOptions& options() const { return opt_; }
  std::size_t n_bodies() const { return bodies_.size(); }
  Real time() const { return state_.time.now(); }
  /// u^n and p^n (p at the scheme's level n - 1 + theta) as a field vector (MixedSpace layout).
  const VecX& field() const { return state_.U[0]; }
  /// Mesh velocity at level n (per node).
  const std::vector<Vec<D>>& mesh_velocity() const { return state_.V; }
  /// The cells whose matrix this process assembles: all, or its part under MPI with a solver
  /// that sums the parts (sim/discretisation.hpp).
  Index assembled_cells() const { return disc_.assembled_cells(); }
  /// Whether each process assembles a part of the cells (MPI; sim/discretisation.hpp), and then
  /// its part, the number of parts and its cells (increasing), e.g. for output in pieces.
  bool in_parts() const { return disc_.in_parts(); }
  int part() const { return disc_.part(); }
  int parts() const { return disc_.parts(); }
  const std::vector<Index>& own_cells() const { return disc_.own_cells(); }
  /// Whether `ok` holds on every process: a collective call in parts (every process must make
  /// it), `ok` itself otherwise.
  bool all_parts(bool ok) const {
    std::vector<int> w{ok ? 1 : 0};
    disc_.min_parts(w);
    return w[0] == 1;
  }
  /// The elementwise minimum of w over the processes: a collective call in parts, nothing otherwise.
  void min_parts(std::vector<int>& w) const { disc_.min_parts(w); }
  /// Smallest Mesh::quality over the cells.
  Real worst_quality() const { return alefsi::worst_quality(mesh_); }

  // ---- the scene (before the first step) ----------------------------------------------------
  void set_velocity(int tag, TimeFunction g) {
    require_not_started("set_velocity");
    ALEFSI_CHECK_ARG(g != nullptr, "g", "boundary velocity function is empty");
    ALEFSI_CHECK_ARG(!space().velocity().boundary_dofs(tag).empty(), "tag", "no boundary facet has tag ", tag);
    ALEFSI_CHECK_ARG(!bodies_.has_tag(tag), "tag", "tag ", tag, " is a body's surface");
    dirichlet_[tag] = std::move(g);
  }
  void set_mesh_velocity(int tag, TimeFunction g) { mesh_velocity_.set_boundary(mesh_, tag, std::move(g)); }
  void set_prescribed_mesh_velocity(TimeFunction v) { mesh_velocity_.set_prescribed(std::move(v)); }
  /// Gravity g, with the buoyancy (Buoyancy, sim/config.hpp):
  ///  * Buoyancy::pressure (default): body force rho_f g on the fluid and M g on every free
  ///    body; the fluid's pressure carries the hydrostatic part and the buoyancy is that
  ///    pressure on the bodies' discrete surfaces, rho_f V_h g with V_h the volume inside their
  ///    facets (a polyhedron inscribed in a sphere: V_h < V by O(h^2)).
  ///  * Buoyancy::exact: the hydrostatic pressure rho_f g.x is taken out of the pressure (the
  ///    pressure solved and written is p - rho_f g.x, the loads are the hydrodynamic loads
  ///    without buoyancy) and every free body weighs (M - rho_f V) g with its exact V. The two
  ///    are the same problem when every boundary has its velocity given (walls, bodies): a
  ///    natural (traction) boundary is refused, naming its tag. For bodies whose density is near
  ///    the fluid's this matters: the error rho_f (V - V_h) |g| is amplified by
  ///    rho_f / (rho_s - rho_f) in the net weight (ten Cate's spheres: 6 times).
  void set_gravity(const Vec<D>& g, Buoyancy buoyancy = Buoyancy::pressure) {
    ALEFSI_CHECK_ARG(g.allFinite(), "gravity", "must be finite, got (", g.transpose(), ")");
    require_not_started("set_gravity");
    gravity_ = g;
    buoyancy_ = buoyancy;
  }
  /// Body force per unit volume f(x, t) on the fluid (besides gravity).
  void set_force(TimeFunction f) { force_ = std::move(f); }
  /// Adds a rigid body whose surface facets carry its tag; returns its index.
  std::size_t add_body(const BodyData& body) {
    require_not_started("add_body");
    ALEFSI_CHECK_ARG(!dirichlet_.count(BodyModel::tag(body)), "body.tag", "tag ", BodyModel::tag(body),
                     " already has a Dirichlet velocity");
    for (const auto& c : curved_)  // its projection must be known in the body's frame
      ALEFSI_CHECK_ARG(c.tag != BodyModel::tag(body), "body.tag", "curve_boundary(", c.tag,
                       ") was called before add_body: add the body first");
    return bodies_.add(body, mesh_, time(), state_.bodies);
  }
  void set_initial_velocity(const std::function<Vec<D>(const Vec<D>&)>& u0, Real t0 = 0) {
    require_not_started("set_initial_velocity");
    state_.time.assign(t0, 0, {});
    for (Index i = 0; i < space().velocity().n_dofs(); ++i) {
      const Vec<D> val = u0(space().velocity().point(i));
      for (int k = 0; k < D; ++k) state_.U[0][space().velocity_field(i, k)] = val[k];
    }
  }
  /// Isoparametric P2 cells on the boundary with tag `tag` (Taylor–Hood): the point of each of
  /// its edges is placed at onto(midpoint) now (e.g. `onto_sphere<D>(centre, radius)` for a
  /// disk or sphere, a body's or a wall's) and then follows the edge's nodes (fem/geometry.hpp):
  /// a body's surface moves it rigidly with the body, a fixed wall keeps it. The kernel
  /// integrates the curved cells through their quadratic map, boundary data and the bodies'
  /// rigid link u = H(x) Z are taken at the edge points (so is an initial field set after it).
  /// Before the first step, and after `add_body` for a body's surface: `onto` is the projection
  /// at the body's pose as added, and a remesh applies it to the new mesh's edges at the body's
  /// pose then (moved by the body's rigid map; the state is transferred through the curved
  /// cells). A checkpoint keeps the points: a flow that loads it is given the same
  /// `curve_boundary` calls (refused otherwise) and takes the points from the checkpoint. A tag
  /// with no boundary facet is refused here; a cell the points fold (MeshError) when the flow
  /// is prepared (`prepare`, the first step), so that a restart's mesh, curved here at the
  /// pose as added, is judged only on the checkpoint's points.
  template <class Onto>
  void curve_boundary(int tag, Onto&& onto)
    requires(Space::VelocityElement::degree == 2)
  {
    require_not_started("curve_boundary");
    ALEFSI_CHECK_ARG(!mesh_.boundary_edges(tag).empty(), "tag", "no boundary facet has tag ", tag);
    for (const auto& c : curved_) ALEFSI_CHECK_ARG(c.tag != tag, "tag", "tag ", tag, " is curved already");
    CurvedBoundary c{tag, std::function<Vec<D>(const Vec<D>&)>(std::forward<Onto>(onto))};
    if (const int k = bodies_.index_of(tag); k >= 0) {
      c.body = k;
      c.centre = state_.bodies[std::size_t(k)].centre[0];
      c.orientation = state_.bodies[std::size_t(k)].orientation[0];
    }
    if (!geometry_) {
      geometry_ = std::make_unique<QuadraticGeometry<D>>(mesh_);
      disc_.set_geometry(geometry_.get());
    }
    project_boundary_edges(*geometry_, tag, c.onto, false);
    geometry_checked_ = false;
    curved_.push_back(std::move(c));
  }
  /// The curved geometry (null: straight cells).
  const QuadraticGeometry<D>* geometry() const { return geometry_.get(); }

  /// Remeshing in the time loop by `remesher` (sim/remesher.hpp); may be set between steps.
  void set_remesher(std::unique_ptr<Remesher<D>> remesher) {
    remesher_ = std::move(remesher);
  }
  /// 2D remeshing (sim/remesher2d.hpp).
  void set_remeshing(RemeshOptions opt)
    requires(D == 2)
  {
    set_remesher(std::make_unique<Remesher2D>(std::move(opt)));
  }
  /// The contact model (sim/contact.hpp); default: DefaultContact<D>::geometry().
  void set_contact_model(std::unique_ptr<ContactModel<D>> model) {
    ALEFSI_CHECK_ARG(model != nullptr, "model", "is empty");
    contact_ = std::move(model);
    contact_->set_walls(mesh_, bodies_.tags());
  }
  /// Short-range repulsive collision forces (eq. 24 + spring) between bodies and against the
  /// walls (every boundary facet that is not a body surface); see physics/collision.hpp.
  void set_collisions(const CollisionOptions& opt)
    requires requires(const CollisionOptions& o) { DefaultContact<D>::collisions(o); }
  {
    set_contact_model(DefaultContact<D>::collisions(opt));
  }

  // ---- the bodies at t^n ---------------------------------------------------------------------
  Vec<D> body_centre(std::size_t k) const { return state_.bodies.at(k).centre[0]; }
  /// Z: (V1, V2, w3) in 2D, (V, w) in 3D.
  BodyVelocity body_velocity(std::size_t k) const { return state_.bodies.at(k).velocity[0]; }
  /// The uniform normal speed removed from body k's slip on the current mesh so that its
  /// discrete flux vanishes (closed domains only, else 0; BodySystem::remove_slip_flux).
  Real slip_flux_removed(std::size_t k) const { return bodies_.slip_flux_removed(k); }
  /// The angle (2D) or the unit quaternion mapping body axes to world axes (3D).
  BodyOrientation body_orientation(std::size_t k) const { return state_.bodies.at(k).orientation[0]; }
  Real body_angle(std::size_t k) const
    requires std::same_as<BodyOrientation, Real>
  {
    return body_orientation(k);
  }
  /// Surface node positions of body k (from the exact rigid map).
  std::vector<Vec<D>> body_surface(std::size_t k) const {
    std::vector<Vec<D>> x;
    for (Index v : bodies_.surface_nodes(k)) x.push_back(state_.X[0][v]);
    return x;
  }
  /// Hydrodynamic force and torque on body k over the last step ((F1, F2, T3) in 2D, (F, T) in
  /// 3D, torque about the centre of mass, world axes): a free body's from its momentum balance,
  /// a driven body's from the residual of the rows it would have if it were free (the same
  /// quantity; BodySystem::driven_loads).
  BodyVelocity body_hydrodynamic_load(std::size_t k) const { return state_.bodies.at(k).load; }
  /// Contact force on body k in the last step.
  Vec<D> body_collision_force(std::size_t k) const { return state_.bodies.at(k).contact.template head<D>(); }
  /// The contact force and its moment about the centre (2D: F1, F2, M3; 3D: F, M) in the last step.
  BodyVelocity body_collision_load(std::size_t k) const { return state_.bodies.at(k).contact; }
  /// Per body, the gap to the nearest other body or wall at t^n (the contact model's).
  std::vector<Real> body_gaps() const { return contact_->gaps(bodies_.contact_bodies(state_.bodies, 0)); }
  /// Per body, the smallest gap / closing speed to a body or wall it approaches (infinity: none).
  std::vector<Real> body_times_to_contact() const {
    return contact_->times_to_contact(bodies_.contact_bodies(state_.bodies, 0));
  }

  // ---- stepping ------------------------------------------------------------------------------
  /// Checks the scene and builds what the first step needs (constraints, contact walls). A
  /// scene that cannot be run is refused here with an `InvalidArgument` naming the body:
  /// overlapping bodies, a surface node off its body's circle or sphere, a slip with a normal
  /// part. The first step calls it; `run()` calls it before it writes any output.
  void prepare() {
    if (disc_.constrained()) return;
    if (geometry_ && !geometry_checked_) {  // the points curve_boundary placed
      geometry_->check_all();
      geometry_checked_ = true;
    }
    setup();
  }
  /// Advances from t^n to t^n + dt. With `control.tolerance` > 0, a regular step whose error
  /// estimate exceeds it is rejected before anything changes: `StepRejected` is thrown and the
  /// flow stays at t^n.
  StepReport step(Real dt, const ErrorControl& control = {}) {
    ALEFSI_CHECK_ARG(dt > 0 && std::isfinite(dt), "dt", "time step must be positive and finite, got ", dt);
    prepare();
    if (stepper_.restarts(state_.time, dt)) {
      state_.time.restart();
      ++state_.stats.history_restarts;
    }
    const StepPlan plan = stepper_.plan(state_.time, dt);
    if (state_.time.levels() == 0 && plan.kind != StepKind::damped_start) start_mesh_velocity();
    StepReport rep = plan.kind == StepKind::damped_start ? damped_start(plan, dt)
                     : plan.kind == StepKind::startup  ? advance(plan.coefficients)
                                                       : advance(plan.coefficients, &control);
    rep.startup = plan.kind != StepKind::regular;
    ++state_.stats.steps;
    if (state_.control.steps_since_remesh >= 0) ++state_.control.steps_since_remesh;
    if (remesher_ && remesher_->enabled()) {
      const auto t0 = std::chrono::steady_clock::now();
      if (remesher_->needed(mesh_, bodies_.remesh_bodies(state_.bodies), state_.remesh) || curved_due())
        rep.remeshed = remesh();
      rep.t_remesh = std::chrono::duration<Real>(std::chrono::steady_clock::now() - t0).count();
    }
    return rep;
  }

  /// Adapts the mesh now (needs a remesher) and transfers the state; returns whether the mesh
  /// changed.
  bool remesh() {
    ALEFSI_CHECK_ARG(remesher_ != nullptr, "remesh", "call set_remeshing (or set_remesher) first");
    auto out = remesher_->adapt(mesh_, bodies_.remesh_bodies(state_.bodies), Space::VelocityElement::degree);
    if (!out) {  // nothing changed: the curved trigger waits until the cells are 10 % worse
      if (geometry_) state_.remesh.curved = geometry_->worst_ratio();
      return false;
    }
    // curved boundaries: the new mesh's edge points first, then the transfer through the old
    // and new curved cells. A cell the points would bring within curved_trigger of folding
    // keeps its edges straight (`straighten_below`): where the new mesh is too coarse for a
    // thin gap beside a curve (a body near a wall), the chord instead of a folded map.
    std::unique_ptr<MeshTransfer<D>> curved_transfer;
    std::optional<QuadraticGeometry<D>> g;
    if (geometry_) {
      g.emplace(out->mesh);
      curve(*g, state_.bodies, false);
      state_.stats.straightened += g->straighten_below(curved_trigger);
      curved_transfer = std::make_unique<LagrangeTransfer<D>>(mesh_, out->mesh, Space::VelocityElement::degree,
                                                              geometry_->edge_points(), g->edge_points());
    }
    transfer_levels(state_, space(), curved_transfer ? *curved_transfer : *out->transfer, out->mesh.coordinates());
    state_.X[0] = out->mesh.coordinates();
    mesh_ = std::move(out->mesh);
    disc_.rebuild(mesh_);
    if constexpr (Space::VelocityElement::degree == 2)  // (curved cells are Taylor–Hood's)
      if (geometry_) {  // g's points, on the moved mesh (the same nodes)
        geometry_ = std::make_unique<QuadraticGeometry<D>>(mesh_);
        for (Index e = 0; e < mesh_.n_edges(); ++e)
          if (g->point_set(e)) geometry_->set_frame_coefficients(e, g->frame_coefficients(e));
        disc_.set_geometry(geometry_.get());
      }
    bodies_.attach(mesh_);
    bodies_.reset_surface(mesh_, state_.bodies, state_.X);
    setup();
    bodies_.reset_surface_velocities(space(), state_.bodies, state_.X, state_.U);
    ++state_.stats.remeshes;
    state_.control.steps_since_remesh = 0;
    state_.remesh = remesher_->measure(mesh_, bodies_.remesh_bodies(state_.bodies));
    if (geometry_) state_.remesh.curved = geometry_->worst_ratio();
    return true;
  }
  /// With remeshing, a curved cell whose map has come this near to folding (smallest
  /// det J / det J_affine, `QuadraticGeometry::jacobian_ratio`) triggers a remesh, as a cell's
  /// quality triggers the remesher: the motion flattens the cells between a curved surface and
  /// another boundary (a body landing on a wall) while their edge points stay on the curve. Like
  /// the quality, with hysteresis: once the last remesh left the ratio lower, when it is 10 %
  /// lower again. The new mesh's cells below this ratio keep their edges straight
  /// (`FlowStats::straightened` counts them). A step that folds a curved cell (ratio 0.1,
  /// `QuadraticGeometry::check`) is rejected with a MeshError naming the cell.
  static constexpr Real curved_trigger = 0.3;

  // ---- checkpoints ---------------------------------------------------------------------------
  /// Writes the whole state at t^n (configuration, mesh, flow state) to `file`, atomically;
  /// the checkpoint it replaces is kept as `<file>.prev` (sim/checkpoint.hpp). A flow built on
  /// `read_checkpoint_mesh<D>(file)`, given the same configuration (options, boundary data,
  /// bodies, remeshing, contacts) and then `load_checkpoint(file)`, continues bit for bit.
  void save_checkpoint(const std::filesystem::path& file) const {
    CheckpointWriter w(file);
    write_config(w);
    write_mesh(w, mesh_);
    write_state(w, state_, bodies_.tags());
    // the curved boundaries' tags and their points
    w.section("curved");
    w.put_vector(curved_tags());
    std::vector<Index> edges;
    std::vector<Real> coef;
    if (geometry_)
      for (Index e = 0; e < mesh_.n_edges(); ++e)
        if (geometry_->point_set(e)) {
          edges.push_back(e);
          for (int i = 0; i < D; ++i) coef.push_back(geometry_->frame_coefficients(e)[i]);
        }
    w.put_vector(edges);
    w.put_vector(coef);
    // the factorisations a reused solve would precondition with (empty: none)
    auto put_solver = [&w](const char* name, const auto& lin) {
      w.section(name);
      w.put_vector(lin.analysed_values());
      w.put_vector(lin.factored_values());
      w.put(std::int32_t(lin.refactor_next()));
    };
    put_solver("solver", disc_.linear_solve());
    put_solver("mesh-velocity solver", disc_.motion().linear_solve());
    w.commit(true);
  }
  /// Restores what `save_checkpoint` wrote into a flow that has not stepped yet and was built
  /// on the checkpoint's mesh with the same configuration; a file written by another
  /// configuration, or not exactly as written, is refused (IoError naming the file and what
  /// differs) and the flow is left as it was.
  void load_checkpoint(const std::filesystem::path& file) {
    require_not_started("load_checkpoint");
    CheckpointReader r(file);
    check_config(r);
    const Mesh<D> m = read_mesh<D>(r);
    if (m.n_nodes() != mesh_.n_nodes() || m.cells() != mesh_.cells() || m.coordinates() != mesh_.coordinates())
      r.fail("the flow's mesh is not the checkpoint's (build it with read_checkpoint_mesh)");
    State s = state_;
    read_state(r, s, bodies_.tags(), space().n_field());
    r.section("curved");
    if (const auto tags = r.get_vector<int>("curved tags"); tags != curved_tags())
      r.fail("written with curved boundaries on " + std::to_string(tags.size()) +
             " tags, this flow has other curve_boundary calls (" + std::to_string(curved_.size()) + ")");
    const auto edges = r.get_vector<Index>("curved edges");
    const auto coef = r.get_vector<Real>("frame coefficients");
    if (coef.size() != edges.size() * std::size_t(D)) r.fail("the curved edges and their coefficients differ in size");
    for (Index e : edges)
      if (e < 0 || e >= mesh_.n_edges()) r.fail("a curved edge is out of the mesh's range");
    const KeptFactors flow_factors = read_kept_factors(r, "solver");
    const KeptFactors motion_factors = read_kept_factors(r, "mesh-velocity solver");
    r.finish();
    s.X[0] = mesh_.coordinates();
    // the points as written, bit for bit (curve_boundary placed them at the bodies' poses as
    // added, not at the checkpoint's)
    std::unique_ptr<QuadraticGeometry<D>> g;
    if (!curved_.empty()) {
      g = std::make_unique<QuadraticGeometry<D>>(mesh_);
      for (std::size_t i = 0; i < edges.size(); ++i)
        g->set_frame_coefficients(edges[i], Eigen::Map<const Vec<D>>(coef.data() + D * i));
      g->check_all();
    }
    state_ = std::move(s);
    if constexpr (Space::VelocityElement::degree == 2)
      if (g) {
        geometry_ = std::move(g);
        disc_.set_geometry(geometry_.get());
        geometry_checked_ = true;
      }
    setup();
    // in parts (MPI) the flow's factors are not reused, and a whole matrix's kept factors would
    // not fit a part's pattern: the first solve factorises afresh
    if (!disc_.in_parts()) {
      if (!flow_factors.factored.empty()) disc_.assembler().take_pattern(disc_.jacobian());
      restore_factors(file, "flow", flow_factors, disc_.jacobian(), disc_.linear_solve());
    }
    restore_factors(file, "mesh-velocity", motion_factors, disc_.motion().matrix(), disc_.motion().linear_solve());
  }

 private:
  // A curved boundary as `curve_boundary` was given it: the projection, and for a body's
  // surface the body's pose then.
  struct CurvedBoundary {
    int tag = 0;
    std::function<Vec<D>(const Vec<D>&)> onto;
    int body = -1;  // the body with this tag (-1: a wall)
    Vec<D> centre = Vec<D>::Zero();
    BodyOrientation orientation{};
  };
  // Every curved boundary's edge points on g's mesh (at its nodes now), a body's projection
  // carried from its pose when given to its pose at t^n in `states` (as given at that pose).
  // With `check`, a cell the points fold is refused (MeshError).
  void curve(QuadraticGeometry<D>& g, const std::vector<typename BodySystem<D, BodyModel>::State>& states,
             bool check = true) const {
    for (const auto& c : curved_) {
      const std::size_t k = std::size_t(std::max(c.body, 0));
      if (c.body < 0 || same_pose(states[k], c)) {
        project_boundary_edges(g, c.tag, c.onto, check);
        continue;
      }
      const Vec<D> centre = states[k].centre[0];
      const BodyOrientation q = states[k].orientation[0];
      project_boundary_edges(
          g, c.tag,
          [&](const Vec<D>& x) -> Vec<D> {
            const Vec<D> x0 = bodies_.from_model(k, bodies_.to_model(k, x, centre, q), c.centre, c.orientation);
            return bodies_.from_model(k, bodies_.to_model(k, c.onto(x0), c.centre, c.orientation), centre, q);
          },
          check);
    }
  }

  template <class S>
  static bool same_pose(const S& s, const CurvedBoundary& c) {
    if (s.centre[0] != c.centre) return false;
    if constexpr (std::same_as<BodyOrientation, Real>)
      return s.orientation[0] == c.orientation;
    else
      return s.orientation[0].coeffs() == c.orientation.coeffs();
  }
  // The curved cells' remesh trigger (curved_trigger).
  bool curved_due() const {
    return geometry_ && geometry_->worst_ratio() < std::min(curved_trigger, 0.9 * state_.remesh.curved);
  }
  std::vector<int> curved_tags() const {
    std::vector<int> t;
    for (const auto& c : curved_) t.push_back(c.tag);
    return t;
  }

  // The matrices a solver analysed and factorised last, as a checkpoint keeps them.
  struct KeptFactors {
    std::vector<Real> analysed, factored;
    bool refactor_next = false;
  };
  static KeptFactors read_kept_factors(CheckpointReader& r, const char* section) {
    r.section(section);
    KeptFactors k;
    k.analysed = r.get_vector<Real>("analysed matrix");
    k.factored = r.get_vector<Real>("factorised matrix");
    k.refactor_next = r.get<std::int32_t>("refactorisation flag") != 0;
    if (k.analysed.size() != k.factored.size()) r.fail(std::string(section) + ": the kept matrices differ in size");
    return k;
  }
  // Analyses and factorises the kept matrices in `lin` (nothing when none were kept); `J` has
  // the solver's pattern.
  template <class Lin>
  static void restore_factors(const std::filesystem::path& file, const char* what, const KeptFactors& k, SparseMatrix& J,
                              Lin& lin) {
    if (k.factored.empty()) return;
    if (std::size_t(J.nonZeros()) != k.factored.size())
      throw IoError("checkpoint '" + file.string() + "': the kept " + what + " matrices have " +
                    std::to_string(k.factored.size()) + " entries, the " + what + " pattern " +
                    std::to_string(J.nonZeros()));
    lin.restore(J, Eigen::Map<const VecX>(k.analysed.data(), Index(k.analysed.size())),
                Eigen::Map<const VecX>(k.factored.data(), Index(k.factored.size())), k.refactor_next);
  }

  // The configuration a checkpoint was written with, checked on reading (what differs named).
  void write_config(CheckpointWriter& w) const {
    w.section("config");
    w.put(std::int32_t(D));
    for (const char* n : {Cfg::Pair::name, Scheme::name, Cfg::Equations::name, BodyModel::name}) w.put_string(n);
    w.put_vector(bodies_.tags());
  }
  void check_config(CheckpointReader& r) const {
    r.section("config");
    if (const int d = r.get<std::int32_t>("dimension"); d != D)
      r.fail("written by a " + std::to_string(d) + "D flow, this flow is " + std::to_string(D) + "D");
    const char* what[] = {"element pair", "time scheme", "equations", "rigid-body model"};
    const char* mine[] = {Cfg::Pair::name, Scheme::name, Cfg::Equations::name, BodyModel::name};
    for (int i = 0; i < 4; ++i)
      if (const std::string got = r.get_string(what[i]); got != mine[i])
        r.fail(std::string("written with the ") + what[i] + " '" + got + "', this flow has '" + mine[i] + "'");
    const auto tags = r.get_vector<int>("body tags");
    if (tags.size() != bodies_.size())
      r.fail("written with " + std::to_string(tags.size()) + " bodies, this flow has " + std::to_string(bodies_.size()));
    if (tags != bodies_.tags()) r.fail("the bodies' tags differ from this flow's");
  }

  // Every boundary facet has its velocity given (a wall's or a body's): no traction boundary.
  void check_closed(const char* what) const {
    for (Index f : mesh_.boundary_facets()) {
      const int tag = mesh_.facet_tag(f);
      ALEFSI_CHECK_ARG(dirichlet_.count(tag) || bodies_.has_tag(tag), "gravity", what,
                       " needs the velocity given on every boundary: facets with tag ", tag,
                       " have a natural (traction) condition");
    }
  }

  void require_not_started(const char* what) const {
    if (disc_.constrained()) throw Error(std::string("AleFlow::") + what + " after the first step");
  }

  // The constraints and pattern of the current topology, the contact walls; a scene whose
  // bodies overlap is refused before the first step.
  void setup() {
    // refusals that hold whatever the mesh, before anything is built (a refused scene stays refused)
    if (buoyancy_ == Buoyancy::exact) check_closed("Buoyancy::exact");
    bodies_.set_displaced_density(buoyancy_ == Buoyancy::exact ? opt_.rho : 0);
    bodies_.attach(mesh_);
    disc_.constrain(dirichlet_, bodies_);
    if (disc_.in_parts()) {  // a free body's own terms enter the part of the lowest process touching it
      std::vector<int> first(bodies_.size(), std::numeric_limits<int>::max());
      for (std::size_t k = 0; k < bodies_.size(); ++k)
        if (const Index z = bodies_.first_unknown(k, disc_.constraints()); z >= 0 && disc_.touches(z))
          first[k] = disc_.part();
      disc_.min_parts(first);
      body_jacobian_here_.assign(bodies_.size(), 0);
      for (std::size_t k = 0; k < bodies_.size(); ++k) body_jacobian_here_[k] = first[k] == disc_.part();
    }
    // a closed domain needs each slip discretely flux-free on this mesh, through its curved
    // facets if it has them
    bodies_.remove_slip_flux(state_.bodies, Space::VelocityElement::degree, disc_.closed_domain(), geometry_.get());
    bodies_.check_radii(mesh_, state_.bodies);
    bodies_.check_shapes(state_.bodies);
    if (state_.stats.steps == 0) bodies_.check_slip(mesh_, state_.bodies);
    contact_->set_walls(mesh_, bodies_.tags());
    if (state_.stats.steps == 0)
      for (const auto& o : contact_->overlaps(bodies_.contact_bodies(state_.bodies, 0)))
        throw InvalidArgument("bodies", "bodies[" + std::to_string(o.k) + "] and bodies[" + std::to_string(o.j) +
                                            "] overlap (gap " + detail::sci(o.gap) + ")");
  }

  // V^n at t^n on X^n (at t0 and at each history restart).
  void start_mesh_velocity() {
    bodies_.mesh_velocity_data(state_.bodies, state_.X[0], {1.0, 0.0, 0.0}, time(), body_nodes_);
    state_.V = mesh_velocity_.solve(disc_.motion(), mesh_, state_.X[0], time(), body_nodes_);
  }

  // One step with the coefficients c (steps 1-5 of the file comment); with `control` (regular
  // steps) the error is estimated, and the step rejected if it exceeds the tolerance.
  StepReport advance(const StepCoefficients& c, const ErrorControl* control = nullptr) {
    State& s = state_;
    const Real t = s.time.now(), t1 = t + c.dt;
    if (c.backfill) backfill(s, c.dt);
    // 1.-2. the mesh velocity at t_V on the extrapolated geometry
    const std::vector<Vec<D>> Xh = extrapolate(s.X, c.extrapolation);
    StepReport rep;
    const auto clock = std::chrono::steady_clock::now();
    const Real tV = c.velocity_time(t);
    bodies_.mesh_velocity_data(s.bodies, Xh, c.extrapolation, tV, body_nodes_);
    const std::vector<Vec<D>> Vs = mesh_velocity_.solve(disc_.motion(), mesh_, Xh, tV, body_nodes_);
    rep.t_mesh_velocity = std::chrono::duration<Real>(std::chrono::steady_clock::now() - clock).count();
    // 3. positions (bodies by their rigid map), the flow geometry X^{n+theta}
    StepNodes<D> g = advance_nodes(s.X, s.V, Vs, c);
    bodies_.advance(s.bodies, c, g.Xn1);
    const std::vector<Vec<D>> Xth = flow_geometry(g.Xn1, s.X[0], c.theta);
    mesh_.set_coordinates(Xth);
    try {
      if (geometry_) geometry_->check_all();  // curved cells the motion folded (MeshError)
      // 4. the flow at n+theta
      const VecX u = solve_flow(c, t1, g, Xth, rep);
      VecX field = disc_.constraints().expand(u);
      bodies_.driven_loads(s.bodies, space(), disc_.kernel(), field, c, Xth);
      if (disc_.closed_domain()) shift_pressure_to_zero_mean(space(), field);
      if (control) {
        rep.error = estimate_error(c.dt, field, u, t1);
        if (const Real e = rep.error.scaled(*control); e > 1)
          throw StepRejected("local error " + detail::sci(e) + " times the tolerance in the step from t = " +
                                 detail::sci(t) + " with dt = " + detail::sci(c.dt),
                             e);
      }
      mesh_.set_coordinates(g.Xn1);
      if (geometry_ && c.theta != 1) geometry_->check_all();
      // 5. the new level
      bodies_.finish(s.bodies, c, disc_.constraints(), u, t1, gravity_);
      s.U.push(std::move(field));
      s.X.push(std::move(g.Xn1));
      s.V = std::move(g.Vnext);
      s.time.advance(c.dt);
    } catch (...) {
      mesh_.set_coordinates(s.X[0]);  // the step is rejected: the state stays at t^n
      throw;
    }
    return rep;
  }

  // The error estimate of the step from t^n to t1 = t^n + dt whose new field is `field` (`u` its
  // unknowns), before the state takes it (time/error_estimate.hpp).
  ErrorEstimate estimate_error(Real dt, const VecX& field, const VecX& u, Real t1) const {
    const State& s = state_;
    const ErrorWeights w = error_weights<Scheme>(dt, s.time);
    ErrorEstimate est;
    if (!w.available()) return est;
    // the levels read must be computed on this mesh, not interpolated by a remesh
    if (s.control.steps_since_remesh >= 0 && s.control.steps_since_remesh < w.points) return est;
    for (int k = 0; k < w.points; ++k)
      if (s.U[k].size() != field.size()) return est;  // a level not taken yet
    est.available = true;
    const auto& vel = space().velocity();
    const DofConstraints& cons = disc_.constraints();
    for (Index i = 0; i < vel.n_dofs(); ++i)
      for (int d = 0; d < D; ++d) {
        const Index j = space().velocity_field(i, d);
        est.scale = std::max(est.scale, std::abs(field[j]));
        // the free DOFs only: prescribed values (a wall's data) and a body's surface (its Z,
        // estimated below) are not the scheme's error
        if (cons.kind(j) != DofConstraints::Kind::free) continue;
        Real p = 0;
        for (int k = 0; k < w.points; ++k) p += w.predictor[std::size_t(k)] * s.U[k][j];
        est.velocity = std::max(est.velocity, std::abs(w.constant * (field[j] - p)));
      }
    for (std::size_t b = 0; b < s.bodies.size(); ++b) {
      if (!bodies_.is_free(b)) continue;
      const auto& body = s.bodies[b];
      Real L = 0;
      for (const Vec<D>& r : body.surface) L = std::max(L, r.norm());
      const BodyVelocity Z = bodies_.next_velocity(b, cons, u, t1);
      BodyVelocity P = BodyVelocity::Zero();
      for (int k = 0; k < w.points; ++k) P += w.predictor[std::size_t(k)] * body.velocity[k];
      const BodyVelocity e = w.constant * (Z - P);
      constexpr int nw = body_dofs - D;
      est.body = std::max(est.body, e.template head<D>().norm() + L * e.template tail<nw>().norm());
      est.scale = std::max(est.scale, Z.template head<D>().norm() + L * Z.template tail<nw>().norm());
    }
    return est;
  }

  // Step 4: Dirichlet data and body links at t1, the kernel's inputs, the contacts, Newton;
  // returns the unknowns.
  VecX solve_flow(const StepCoefficients& c, Real t1, const StepNodes<D>& g, const std::vector<Vec<D>>& Xth,
                  StepReport& rep) {
    State& s = state_;
    DofConstraints& cons = disc_.constraints();
    for (const auto& [i, tag] : disc_.dirichlet_dofs()) {
      const Vec<D> val = dirichlet_.at(tag)(space().velocity().point(i, g.Xn1), t1);
      for (int k = 0; k < D; ++k) cons.set_fixed_value(space().velocity_field(i, k), val[k]);
    }
    bodies_.set_surface_velocities(space(), cons, s.bodies, c, g.Xn1, Xth, t1);
    VectorFunction<D> force;
    const bool weighed = gravity_.squaredNorm() > 0 && buoyancy_ == Buoyancy::pressure;
    if (force_ || weighed)
      force = [this, weighed, tf = s.time.now() + c.theta * c.dt](const Vec<D>& x) {
        Vec<D> f = weighed ? Vec<D>(opt_.rho * gravity_) : Vec<D>::Zero();
        if (force_) f += force_(x, tf);
        return f;
      };
    disc_.set_step(c, s.U, g.Vflow, std::move(force));
    // contacts from the bodies placed at t^{n+1}; positions that overlap reject the step
    const auto placed = bodies_.contact_bodies(s.bodies, -1);
    s.stats.contacts = contact_->find(placed, opt_.mu);
    for (const auto& o : contact_->overlaps(placed))
      throw SolverError("bodies[" + std::to_string(o.k) + "] and bodies[" + std::to_string(o.j) +
                        "] would overlap at t = " + detail::sci(t1) + " (gap " + detail::sci(o.gap) + ")");
    // Newton (or one semi-implicit solve) from u^n, Z^n
    disc_.prepare_solver(opt_.rho * c.flow_bdf[0] / (c.theta * c.dt));
    VecX u = cons.restrict_free(s.U[0]);
    bodies_.initial_guess(cons, s.bodies, u);
    // in parts (MPI) the contact coupling between two bodies stays lagged; add_rows refills it
    BlockCoupling* coupling = disc_.in_parts() ? nullptr : &coupling_;
    const auto residual = [&](const VecX& uu, SparseMatrix& J, VecX& r) {
      disc_.assemble(cons.expand(uu), &J, &r);
      bodies_.add_rows(s.bodies, c, cons, uu, r, J, gravity_, *contact_, t1,
                       disc_.in_parts() ? &body_jacobian_here_ : nullptr, coupling);
    };
    NewtonOptions no{.linear = opt_.linearisation != Linearisation::newton,
                     .max_iterations = opt_.max_newton,
                     .tolerance = opt_.newton_tolerance};
    if (disc_.in_parts()) no.sum_parts = [this](VecX& v) { disc_.sum_parts(v); };
    const NewtonReport nr = newton_solve(residual, disc_.linear_solve(), disc_.jacobian(), u, no, coupling);
    rep.newton_iterations = nr.iterations, rep.residuals = nr.residuals;
    rep.t_assembly = nr.t_assembly, rep.t_factorize = nr.t_factorize, rep.t_solve = nr.t_solve;
    rep.linear = nr.linear;
    return u;
  }

  // The first step from t^n by plan.substeps backward-Euler substeps (FlowOptions::
  // damped_start), Richardson-extrapolated (2 u_{dt/m} - u_{2dt/m}) when plan.richardson, the
  // bodies' surface nodes then placed by their exact rigid map; the history is then t^n and
  // t^n + dt and V^n is solved at t^n + dt on X^{n+1}. A substep that throws leaves the flow
  // at t^n.
  StepReport damped_start(const StepPlan& plan, Real dt) {
    const State s0 = state_;
    StepReport rep;
    auto substeps = [&](int count) {
      for (int j = 0; j < count; ++j) rep.add(advance(Stepper<Scheme>::substep(dt / count, state_.time)));
    };
    auto restore = [&](const State& s) {
      state_ = s;
      mesh_.set_coordinates(state_.X[0]);
    };
    try {
      substeps(plan.substeps);
      if (plan.richardson) {
        const State fine = state_;
        restore(s0);
        substeps(plan.substeps / 2);
        richardson(state_, fine);
        for (std::size_t k = 0; k < state_.bodies.size(); ++k) bodies_.place_surface(state_.bodies[k], k, 0, state_.X[0]);
      }
      start_history(state_, s0, dt);
      mesh_.set_coordinates(state_.X[0]);
      start_mesh_velocity();
    } catch (...) {
      restore(s0);
      throw;
    }
    return rep;
  }

  Mesh<D> mesh_;
  FlowOptions opt_;
  Stepper<Scheme> stepper_;
  Discretisation<Cfg> disc_;
  BodySystem<D, BodyModel> bodies_;
  State state_;
  std::map<int, TimeFunction> dirichlet_;
  MeshVelocityData<D> mesh_velocity_;
  TimeFunction force_;
  Vec<D> gravity_ = Vec<D>::Zero();
  Buoyancy buoyancy_ = Buoyancy::pressure;
  std::unique_ptr<ContactModel<D>> contact_;
  std::unique_ptr<Remesher<D>> remesher_;
  std::unique_ptr<QuadraticGeometry<D>> geometry_;  // curved boundaries (null: straight cells)
  std::vector<CurvedBoundary> curved_;               // what curves them, for each new mesh
  bool geometry_checked_ = true;                     // curve_boundary's points checked (prepare)
  NodeVelocities<D> body_nodes_;  // the step's surface node velocities (scratch)
  std::vector<char> body_jacobian_here_;  // in parts: the bodies whose own Jacobian terms this process adds
  BlockCoupling coupling_;  // the contact Jacobian between two bodies, beside the pattern (Newton's)
};

/// The mesh stored in a checkpoint written by AleFlow::save_checkpoint (to build the flow that
/// `load_checkpoint` restores).
template <int D>
Mesh<D> read_checkpoint_mesh(const std::filesystem::path& file) {
  CheckpointReader r(file);
  r.section("config");
  if (const int d = r.get<std::int32_t>("dimension"); d != D)
    r.fail("written by a " + std::to_string(d) + "D flow, not a " + std::to_string(D) + "D one");
  for (const char* what : {"element pair", "time scheme", "equations", "rigid-body model"}) r.get_string(what);
  r.get_vector<int>("body tags");
  return read_mesh<D>(r);
}

}  // namespace alefsi
