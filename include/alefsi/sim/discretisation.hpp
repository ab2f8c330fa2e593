#pragma once
/// \file sim/discretisation.hpp
/// Everything of a flow that is tied to the mesh topology: the velocity/pressure space, the
/// element kernel, the mesh-motion operator, the constraints of the flow system (Dirichlet
/// walls, body links, a pinned pressure), the assembler's sparsity pattern, the system matrix
/// and the linear solver's analysis. `rebuild(mesh)` after a topology change drops them all;
/// `constrain(dirichlet, bodies)` then builds the constraints and the pattern.
///
/// The space, the kernel and the motion operator keep a pointer to the mesh given to
/// `rebuild`: it must outlive them (AleFlow owns both).
///
/// A solver that accepts the saddle-point blocks of the space (`set_blocks`, e.g.
/// SaddlePointGmres) gets them here: the pressure mass matrix and, for a time step, the lumped
/// velocity mass with gamma = rho a_0 / (theta dt), refreshed when the pattern or gamma
/// changes (`prepare_solver`).
///
/// Assembly in parts: with a solver that takes each process's part of the matrix
/// (SummedPartsSolver, la/partition.hpp: PetscKrylov and PetscDirect under MPI) on more than one
/// process, each process assembles the Jacobian of its own cells only (the solver's partition of
/// the cells when it has one, `partition(mesh)`: PT-Scotch through PETSc; else a Morton part,
/// `partition_cells`), with the pattern of those cells; the residual is summed over the
/// processes, so that it is whole everywhere. Factorisation reuse is off then (it would need
/// products with the whole matrix).
///
///     Discretisation<Cfg> disc(mesh, options);            // or (mesh, options, solver options)
///     disc.constrain(dirichlet, bodies);
///     disc.assemble(field, &disc.jacobian(), &r);  // (in parts: this process's cells)
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/partition.hpp"
#include "alefsi/la/saddle_point_blocks.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/physics/mesh_motion.hpp"
#include "alefsi/physics/navier_stokes.hpp"
#include "alefsi/sim/config.hpp"
#include "alefsi/sim/newton.hpp"
#include "alefsi/time/history.hpp"
#include "alefsi/time/stepper.hpp"

namespace alefsi {

/// A solver that takes the space's saddle-point blocks (la/saddle_point_blocks.hpp), e.g.
/// SaddlePointGmres (la/krylov.hpp).
template <class S>
concept TakesSaddlePointBlocks = requires(S s, SaddlePointBlocks b) { s.set_blocks(std::move(b)); };

template <FlowConfiguration Cfg>
class Discretisation {
 public:
  static constexpr int D = Cfg::dim;
  using Space = MixedSpace<D, typename Cfg::Pair>;
  using Kernel = AleNavierStokesKernel<D, typename Cfg::Pair, Cfg::Equations::convection>;
  using Motion = ElasticMeshMotion<D>;
  using Solver = typename Cfg::Solver;
  using FlowAssembler = Assembler<Space::n_local>;

  /// `solver_args`: the arguments of the solver's constructor (e.g. its options).
  template <class... SolverArgs>
  Discretisation(const Mesh<D>& mesh, const FlowOptions& opt, SolverArgs&&... solver_args)
      : opt_(opt), solve_(std::forward<SolverArgs>(solver_args)...) {
    solve_.set_reuse({.enabled = opt_.reuse_factorisation});
    rebuild(mesh);
  }
  Discretisation(const Discretisation&) = delete;  // the parts point into each other
  Discretisation& operator=(const Discretisation&) = delete;

  /// A new mesh topology: new space, kernel and motion operator; no constraints or pattern
  /// until `constrain`; the solver analyses the next matrix afresh.
  void rebuild(const Mesh<D>& mesh) {
    geometry_ = nullptr;
    space_ = std::make_unique<Space>(mesh);
    kernel_ = std::make_unique<Kernel>(*space_, opt_.rho, opt_.mu, opt_.linearisation);
    motion_ = std::make_unique<Motion>(mesh);
    motion_->set_reuse({.enabled = opt_.reuse_factorisation});
    cons_.reset();
    asmb_.reset();
    J_ = SparseMatrix();  // the assembler keeps a matrix whose size matches: a flip keeps the size
    solve_.reset();
    gamma_ = -1;
  }

  /// The constraints of the flow system: velocity DOFs on the tags of `dirichlet` (a map
  /// keyed by tag) fixed, the bodies' surface DOFs fixed or linked (BodySystem::constrain),
  /// pressure DOF 0 pinned when every boundary velocity is prescribed (unless the solver takes
  /// the constant pressure as a null space instead: `pressure_null_space()`); then the pattern.
  template <class Dirichlet, class Bodies>
  void constrain(const Dirichlet& dirichlet, Bodies& bodies) {
    cons_ = std::make_unique<DofConstraints>(space_->n_field());
    std::vector<char> taken(std::size_t(space_->velocity().n_dofs()), 0);
    dirichlet_dofs_ = fix_velocity_on_tags(*space_, dirichlet, *cons_, taken);
    bodies.constrain(*space_, *cons_, taken);
    // every boundary velocity prescribed (walls or bodies): p is defined up to a constant
    closed_ = whole_boundary_prescribed(space_->mesh(),
                                        [&](int tag) { return bodies.has_tag(tag) || dirichlet.count(tag) > 0; });
    null_space_ = constrain_pressure_constant(solve_.solver(), closed_, *cons_, space_->pressure_field(0));
    cons_->finalize();
    if (null_space_)  // the pressure unknowns: all free, contiguous after the velocities
      for (Index k = 0; k < space_->pressure().n_dofs(); ++k)
        ALEFSI_ASSERT(cons_->kind(space_->pressure_field(k)) == DofConstraints::Kind::free &&
                      cons_->indices(space_->pressure_field(k))[0] == cons_->indices(space_->pressure_field(0))[0] + k);
    in_parts_ = false;
    if constexpr (SummedPartsSolver<Solver>) {
      Solver& s = solve_.solver();
      in_parts_ = s.parts() > 1;
      s.set_summed(in_parts_);
      if (in_parts_) solve_.set_reuse({.enabled = false});
    }
    if (in_parts_) {
      std::vector<int> cell_part;  // the solver's partitioner (PETSc: PT-Scotch), else the Morton curve
      if constexpr (requires { solve_.solver().partition(space_->mesh()); })
        cell_part = solve_.solver().partition(space_->mesh());
      if (cell_part.empty()) cell_part = partition_cells(space_->mesh(), parts());
      own_cells_ = cells_of_part(cell_part, part());
      asmb_ = std::make_unique<FlowAssembler>(
          Index(own_cells_.size()), [&](Index i) { return space_->cell_field_dofs(own_cells_[std::size_t(i)]); },
          *cons_, AssembledCells::part);
      touched_.assign(std::size_t(cons_->n_unknowns()), 0);
      for (Index c : own_cells_)
        for (Index f : space_->cell_field_dofs(c))
          for (Index u : cons_->indices(f)) touched_[std::size_t(u)] = 1;
    } else {
      own_cells_.clear(), touched_.clear();
      asmb_ = std::make_unique<FlowAssembler>(
          space_->mesh().n_cells(), [&](Index c) { return space_->cell_field_dofs(c); }, *cons_);
    }
    asmb_->set_threads(opt_.threads);
    gamma_ = -1;
  }
  bool constrained() const { return cons_ != nullptr; }

  /// The Jacobian (of this process's cells, in parts) into J and the residual (whole) into r, at
  /// `field`; either may be null. With a pressure null space the residual's continuity rows
  /// lose their sum: the mass defect of the boundary data (round-off when they conserve mass),
  /// which no update reaches and which a pin would put into one pressure DOF's cell.
  void assemble(const VecX& field, SparseMatrix* J, VecX* r) {
    if (!in_parts_) {
      asmb_->assemble(*kernel_, field, J, r);
      if (r && null_space_) {
        auto rp = r->segment(cons_->indices(space_->pressure_field(0))[0], space_->pressure().n_dofs());
        rp.array() -= rp.mean();
      }
      return;
    }
    asmb_->assemble(PartKernel<Kernel>{kernel_.get(), &own_cells_}, field, J, r);
    if (r) sum_parts(*r);
  }
  /// Whether each process assembles its part (class comment); the parts, this process's part.
  bool in_parts() const { return in_parts_; }
  int parts() const {
    if constexpr (SummedPartsSolver<Solver>) return solve_.solver().parts();
    return 1;
  }
  int part() const {
    if constexpr (SummedPartsSolver<Solver>) return solve_.solver().part();
    return 0;
  }
  /// Sums v over the processes (in parts; nothing otherwise).
  void sum_parts(VecX& v) const {
    if constexpr (SummedPartsSolver<Solver>)
      if (in_parts_) solve_.solver().sum(v);
  }
  /// The elementwise minimum of w over the processes (in parts; nothing otherwise).
  void min_parts(std::vector<int>& w) const {
    if constexpr (SummedPartsSolver<Solver>)
      if (in_parts_) solve_.solver().min(w);
  }
  /// In parts: this process's cells, increasing (empty otherwise).
  const std::vector<Index>& own_cells() const { return own_cells_; }
  /// Cells this process assembles.
  Index assembled_cells() const { return in_parts_ ? Index(own_cells_.size()) : space_->mesh().n_cells(); }
  /// Whether this process's cells touch unknown u (always, unless in parts).
  bool touches(Index u) const { return !in_parts_ || touched_[std::size_t(u)]; }

  /// Isoparametric P2 (Taylor–Hood): the kernel integrates the curved cells of `g` and the
  /// velocity's edge DOFs sit at its points; the kernel gets the edge points' velocities each
  /// step. Null: straight cells. A rebuild drops it (the geometry is on the old mesh).
  void set_geometry(const QuadraticGeometry<D>* g)
    requires(Space::VelocityElement::degree == 2)
  {
    space_->set_geometry(g);
    kernel_->set_geometry(g);
    geometry_ = g;
  }
  const QuadraticGeometry<D>* geometry() const { return geometry_; }

  /// The kernel's inputs for the step with coefficients c: the BDF history of the time
  /// derivative sum_{k>=1} a_k U^{n+1-k}, the extrapolated (convecting) velocity u*, U^n, the
  /// mesh velocity the flow sees (per node) and the body force. `U` and `Vflow` are read
  /// during the step's assembly: they must live until it is done.
  void set_step(const StepCoefficients& c, const Levels<VecX>& U, const std::vector<Vec<D>>& Vflow,
                VectorFunction<D> force) {
    hist_ = VecX::Zero(U[0].size());
    ustar_ = VecX::Zero(U[0].size());
    for (int k = 1; k <= c.flow_order; ++k) hist_ += c.flow_bdf[k] * U[k - 1];
    for (int k = 0; k < 3; ++k)
      if (c.convection[k] != 0) ustar_ += c.convection[k] * U[k];
    StepInputs<D> in;
    in.dt = c.dt, in.theta = c.theta, in.a0 = c.flow_bdf[0], in.tau_dt = opt_.tau_dt;
    in.history = &hist_, in.previous = &U[0], in.extrapolated = &ustar_, in.mesh_velocity = &Vflow;
    if (geometry_) {  // the edge points' velocities, at the mesh's current (the step's flow) nodes
      edge_velocity_ = geometry_->edge_velocities(Vflow);
      in.edge_velocity = &edge_velocity_;
    }
    in.force = std::move(force);
    kernel_->set_step(in);
  }

  /// Gives a block-aware solver the blocks for a velocity block holding gamma M_u (gamma =
  /// rho a_0 / (theta dt)); nothing for other solvers.
  void prepare_solver(Real gamma) {
    // an iterative solver's preconditioner is set up once per step, at its first Newton
    // iteration, and serves the others (LinearSolve, ReusableSetUp)
    if constexpr (ReusableSetUp<Solver>) solve_.drop();
    if constexpr (TakesSaddlePointBlocks<Solver>) {
      if (gamma == gamma_) return;
      solve_.solver().set_blocks(saddle_point_blocks(*space_, *cons_, opt_.mu, gamma));
      gamma_ = gamma;
    }
  }

  const Space& space() const { return *space_; }
  Kernel& kernel() { return *kernel_; }
  Motion& motion() { return *motion_; }
  const Motion& motion() const { return *motion_; }
  DofConstraints& constraints() { return *cons_; }
  const DofConstraints& constraints() const { return *cons_; }
  /// The assembler of this process's cells: all of them, or its part (in_parts()).
  const FlowAssembler& assembler() const { return *asmb_; }
  SparseMatrix& jacobian() { return J_; }
  LinearSolve<Solver>& linear_solve() { return solve_; }
  const LinearSolve<Solver>& linear_solve() const { return solve_; }
  /// (scalar velocity DOF, tag) of the Dirichlet DOFs.
  const std::vector<std::pair<Index, int>>& dirichlet_dofs() const { return dirichlet_dofs_; }
  /// Every boundary velocity is prescribed: the pressure is defined up to a constant (pressure
  /// DOF 0 pinned, or the solver's null space), shifted to zero mean after each solve.
  bool closed_domain() const { return closed_; }
  /// The solver takes the closed domain's system unpinned (SolvesPressureNullSpace).
  bool pressure_null_space() const { return null_space_; }

 private:
  FlowOptions opt_;
  std::unique_ptr<Space> space_;
  std::unique_ptr<Kernel> kernel_;
  std::unique_ptr<Motion> motion_;
  std::unique_ptr<DofConstraints> cons_;
  std::unique_ptr<FlowAssembler> asmb_;
  SparseMatrix J_;
  LinearSolve<Solver> solve_;
  std::vector<std::pair<Index, int>> dirichlet_dofs_;
  bool closed_ = false, null_space_ = false;
  Real gamma_ = -1;
  VecX hist_, ustar_;  // the step's kernel inputs
  const QuadraticGeometry<D>* geometry_ = nullptr;
  std::vector<Vec<D>> edge_velocity_;  // the step's edge-point velocities (curved geometry)
  bool in_parts_ = false;
  std::vector<Index> own_cells_;  // in parts: this process's cells
  std::vector<char> touched_;     // in parts: the unknowns its cells touch
};

}  // namespace alefsi
