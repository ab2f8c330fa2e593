#pragma once
/// \file sim/config.hpp
/// A flow's choices: the compile-time ones in one named configuration type (`FlowConfig`), the
/// run-time ones in `FlowOptions`.
///
/// `FlowConfig<D, Pair, Scheme>` names the dimension, the element pair, the time scheme, and
/// with defaults the equations (Navier–Stokes; `UnsteadyStokes` drops convection at compile
/// time), the linear solver of the flow system (`SparseLu<>`, the same in every build) and the
/// rigid-body model (`RigidBodyTraits<D>`). Change one choice by name:
///
///     using Cfg = FlowConfig<2, P1P1Gls, BDF2_BDF2E>;                  // the DKT scene
///     using Squirmer = FlowConfig<3, TaylorHood, BSS, UnsteadyStokes>::with_solver<SaddlePointGmres<3>>;
///     AleFlow<Cfg> flow(mesh, {.rho = 1, .mu = 0.01});
///
/// The concept `FlowConfiguration` checks a configuration where it is used, so a wrong choice is
/// reported as the choice that is wrong.
#include <cmath>
#include <concepts>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/element_pair.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/physics/navier_stokes.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/time/schemes.hpp"
#include "alefsi/time/stepper.hpp"

namespace alefsi {

/// The incompressible Navier–Stokes equations (convection on).
struct NavierStokes {
  static constexpr bool convection = true;
  static constexpr const char* name = "Navier-Stokes";
};
/// The unsteady Stokes equations: every convective term dropped at compile time.
struct UnsteadyStokes {
  static constexpr bool convection = false;
  static constexpr const char* name = "unsteady Stokes";
};
template <class E>
concept FlowEquations = requires {
  { E::convection } -> std::convertible_to<bool>;
  { E::name } -> std::convertible_to<const char*>;
};

template <int D, ElementPair PairT, TimeScheme SchemeT, FlowEquations EquationsT = NavierStokes,
          LinearSolver SolverT = SparseLu<>, RigidBodyModel BodyModelT = RigidBodyTraits<D>>
struct FlowConfig {
  static_assert(D == 2 || D == 3, "FlowConfig: the dimension must be 2 or 3");
  static_assert(BodyModelT::dim == D, "FlowConfig: the rigid-body model must have the flow's dimension");
  static constexpr int dim = D;
  using Pair = PairT;
  using Scheme = SchemeT;
  using Equations = EquationsT;
  using Solver = SolverT;
  using BodyModel = BodyModelT;

  template <ElementPair P>
  using with_pair = FlowConfig<D, P, SchemeT, EquationsT, SolverT, BodyModelT>;
  template <TimeScheme S>
  using with_scheme = FlowConfig<D, PairT, S, EquationsT, SolverT, BodyModelT>;
  template <FlowEquations E>
  using with_equations = FlowConfig<D, PairT, SchemeT, E, SolverT, BodyModelT>;
  template <LinearSolver S>
  using with_solver = FlowConfig<D, PairT, SchemeT, EquationsT, S, BodyModelT>;
  template <RigidBodyModel B>
  using with_body_model = FlowConfig<D, PairT, SchemeT, EquationsT, SolverT, B>;
};

/// What AleFlow reads from a configuration.
template <class C>
concept FlowConfiguration = requires {
  { C::dim } -> std::convertible_to<int>;
  typename C::Pair;
  typename C::Scheme;
  typename C::Equations;
  typename C::Solver;
  typename C::BodyModel;
} && (C::dim == 2 || C::dim == 3) && ElementPair<typename C::Pair> && TimeScheme<typename C::Scheme> &&
                            FlowEquations<typename C::Equations> && LinearSolver<typename C::Solver> &&
                            RigidBodyModel<typename C::BodyModel> && C::BodyModel::dim == C::dim;

static_assert(FlowConfiguration<FlowConfig<2, TaylorHood, BDF2_BDF2E>>);

/// The run-time choices of a flow.
/// Where the buoyancy of bodies under gravity comes from (AleFlow::set_gravity): the fluid's
/// hydrostatic pressure on their discrete surfaces, or their exact volume (the hydrostatic
/// pressure taken out of the pressure; closed domains).
enum class Buoyancy { pressure, exact };

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
  /// Variable steps (default): a step of another dt than the last keeps the history and uses
  /// the variable-step formulas (time/stepper.hpp), unless it grows by more than the scheme's
  /// step-ratio bound (2 for BDF2, 1.5 for BDF3: max_step_ratio), which restarts it; adaptive
  /// runs (RunOptions::tolerance) need it. false: every change of dt restarts the history
  /// (start-up formulas), the paper's constant-step procedure. With equal steps both are the
  /// same, bit for bit.
  bool variable_steps = true;
  /// Threads of the flow system's assembly (Assembler::set_threads; default 1). Results are
  /// bit-identical for every count. With more than one, the user's force callback
  /// (set_force) is called concurrently and must be safe to call so (a pure function is).
  int threads = 1;
  /// Stabilised pairs (P1/P1-GLS): the step in tau_K's transient term (2 rho / dt)^2. 0
  /// (default): each step's dt, as the paper. The stabilised operator then changes with dt
  /// (as dt -> 0, tau -> dt / (2 rho)), so a change of dt moves the discrete solution by a
  /// spatial, not a temporal, amount that the error estimate of adaptive runs reads as a
  /// step error; adaptive runs (RunOptions::tolerance) of a stabilised pair need a fixed value
  /// here, e.g. the nominal step (run() refuses them otherwise). Ignored by stable pairs.
  Real tau_dt = 0;
  /// Factorisation reuse (direct solvers; sim/newton.hpp, FactorisationReuse): a step's linear
  /// solve is GMRES preconditioned by the factors of an earlier matrix, to a relative residual
  /// of 1e-13, and the matrix is factorised afresh when that takes more than 16 iterations (the
  /// next one when it took more than 8) and after every remesh; the mesh-velocity (elasticity)
  /// solve likewise (physics/mesh_motion.hpp). The choice is automatic;
  /// false: every solve factorises (the results differ at the 1e-13 level). Checkpoints keep the
  /// factorised matrix, so a continued run is bit for bit the uninterrupted one either way.
  /// An iterative solver with `ReusableSetUp` (SaddlePointGmres) sets up its preconditioner at
  /// a step's first Newton iteration and keeps it for the step's others (afresh when a solve
  /// needed more than twice the iterations of the set-up's first); false: at every iteration.
  bool reuse_factorisation = true;
  /// The start-up steps' formulas (time/stepper.hpp), taken while the history is shorter than
  /// the scheme reads (after the damped start, if any): MR/AB's (default, the paper's), or for
  /// the BDF schemes (theta = 1) BSS then BDF2/BDF2E (`StartUp::bdf`), which are L-stable and
  /// damp what an impulsive start leaves; their lower order costs nothing when the first steps
  /// are small (an adaptive run from a small dt, or a graded start: time/step_sequence.hpp).
  StartUp start_up = StartUp::midpoint;

  void validate() const {
    ALEFSI_CHECK_ARG(rho >= 0 && std::isfinite(rho), "rho", "fluid density must be >= 0 and finite, got ", rho);
    ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "viscosity must be positive and finite, got ", mu);
    ALEFSI_CHECK_ARG(max_newton >= 1, "max_newton", "must be >= 1");
    ALEFSI_CHECK_ARG(threads >= 1, "threads", "must be at least 1, got ", threads);
    ALEFSI_CHECK_ARG(tau_dt >= 0 && std::isfinite(tau_dt), "tau_dt", "must be >= 0 (0: each step's dt), got ", tau_dt);
    ALEFSI_CHECK_ARG(damped_start == 0 || (damped_start >= 2 && damped_start <= 64 && damped_start % 2 == 0),
                     "damped_start", "must be 0 (off) or an even number of substeps in 2..64, got ", damped_start);
  }
};

}  // namespace alefsi
