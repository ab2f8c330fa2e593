#pragma once
/// \file la/linear_solve.hpp
/// A linear solver policy (la/solvers.hpp) with the state of its symbolic analysis and, for
/// direct solvers, the reuse of a factorisation across solves of slowly changing matrices
/// (Newton iterations, time steps): `LinearSolve::solve(J, r, counts)` factorises J, or solves
/// it by GMRES (la/gmres.hpp) preconditioned by the factors of an earlier matrix. An iterative
/// solver that can solve with a new matrix on the preconditioner at hand (`solve(A, b)`,
/// `ReusableSetUp`: SaddlePointGmres) keeps its set-up likewise, until `drop()` (the flow drops
/// it at every step: its Schur approximation holds the step's dt). The flow's
/// Newton solve (sim/newton.hpp) and the mesh-velocity problem (physics/mesh_motion.hpp) use it.
/// With a coupling (`set_coupling`, la/coupling.hpp: entries the pattern lacks) it solves
/// (J + C) x = r: direct solvers by GMRES on J + C preconditioned by the factors of J (or of the
/// earlier matrix kept), `SaddlePointGmres` with C in its operator; other iterative solvers
/// solve J x = r (C lagged).
///
///     LinearSolve<SparseLu<>> lin;
///     lin.set_reuse({.enabled = true});
///     if (!lin.reusable()) lin.factorize(J);
///     VecX x = lin.solve(J, r, counts);
#include <concepts>
#include <optional>
#include <utility>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/la/coupling.hpp"
#include "alefsi/la/gmres.hpp"
#include "alefsi/la/solvers.hpp"

namespace alefsi {

/// Reuse of a factorisation across Newton iterations and time steps (direct solvers only): the
/// matrix of a later solve is solved by GMRES (la/gmres.hpp) preconditioned by the factors of
/// an earlier matrix, and factorised afresh when that needs more than `max_iterations`
/// (or, at the next solve, when it needed more than `refactor_above`), or after the pattern
/// changed (a remesh). Measured: docs/performance.md ("Factorisations reused").
struct FactorisationReuse {
  bool enabled = false;
  int max_iterations = 16;  ///< GMRES iterations of a reused solve before J is factorised
  int refactor_above = 8;   ///< a reused solve that needed more: the next one factorises
  Real tolerance = 1e-13;   ///< relative residual ||J x - r|| / ||r|| of a reused solve
};

/// What the linear solves did (a Newton solve's, summed per step in StepReport; a mesh-velocity
/// solver's since it was built).
struct LinearSolveCounts {
  int factorisations = 0;     ///< numeric factorisations (an iterative solver's set-ups)
  int reused = 0;             ///< solves by GMRES on an earlier factorisation
  int krylov_iterations = 0;  ///< their GMRES iterations, and those of solves with a coupling
                              ///< (la/coupling.hpp) on fresh factors
  int iterative_solves = 0;      ///< solves by an iterative solver (one with `iterations()`)
  int iterative_iterations = 0;  ///< their iterations
  LinearSolveCounts& operator+=(const LinearSolveCounts& o) {
    factorisations += o.factorisations, reused += o.reused, krylov_iterations += o.krylov_iterations;
    iterative_solves += o.iterative_solves, iterative_iterations += o.iterative_iterations;
    return *this;
  }
};

/// An iterative solver whose preconditioner, set up by `factorize` for one matrix, can serve a
/// later matrix of the same pattern: `solve(A, b)`.
template <class S>
concept ReusableSetUp = LinearSolver<S> && !DirectSolver<S> && requires(S s, const SparseMatrix& A, const VecX& b) {
  { s.solve(A, b) } -> std::convertible_to<VecX>;
  { s.iterations() } -> std::convertible_to<int>;
};

/// A linear solver policy (constructed in place: solvers such as SparseLu cannot be moved), the
/// state of its symbolic analysis and, with reuse on, of its factorisation: the values of the
/// matrices it analysed and factorised are kept, so that a checkpoint can restore the same
/// factors (`restore`).
template <LinearSolver S>
class LinearSolve {
 public:
  template <class... Args>
  explicit LinearSolve(Args&&... args) : solver_(std::forward<Args>(args)...) {}
  /// Reuse on or off (always off for iterative solvers without `ReusableSetUp`).
  void set_reuse(const FactorisationReuse& r) {
    reuse_ = r;
    if constexpr (!DirectSolver<S> && !ReusableSetUp<S>) reuse_.enabled = false;
    if (!reuse_.enabled) factored_ = false;
  }
  /// The next solve sets up afresh (the factors or preconditioner at hand are not reused).
  void drop() { factored_ = false, factored_values_.resize(0), analysed_values_.resize(0); }
  const FactorisationReuse& reuse() const { return reuse_; }
  /// The sparsity pattern changed: analyse again before the next factorisation.
  void reset() {
    analysed_ = false;
    factored_ = false;
    analysed_values_.resize(0), factored_values_.resize(0);
  }
  /// Entries C beside J's pattern that the coming solves include (null or empty: none): they
  /// solve (J + C) x = r. A direct solver's factors stay J's (GMRES on J + C, at most
  /// FactorisationReuse::max_iterations + C's size iterations on kept factors, C's size + 4 on
  /// fresh ones, to FactorisationReuse::tolerance); an iterative solver that takes one
  /// (`set_coupling`) is handed it. The object must stay alive until it is unset.
  void set_coupling(const BlockCoupling* c) {
    coupling_ = c && !c->empty() ? c : nullptr;
    if constexpr (requires { solver_.set_coupling(c); }) solver_.set_coupling(coupling_);
  }
  void factorize(const SparseMatrix& J) {
    // the matrices' values are kept for checkpoints (direct solvers: an iterative solver's
    // set-up is dropped at every step, so a checkpoint between steps has none)
    constexpr bool keep = DirectSolver<S>;
    if (!analysed_) {
      solver_.analyze(J);
      analysed_ = true;
      if (keep && reuse_.enabled) analysed_values_ = values(J);
    }
    solver_.factorize(J);
    factored_ = reuse_.enabled, fresh_ = true, refactor_next_ = false;
    if (keep && reuse_.enabled) factored_values_ = values(J);
  }
  /// The next solve of a new matrix can use the factors at hand (no factorisation first).
  bool reusable() const { return reuse_.enabled && factored_ && !refactor_next_; }
  VecX solve(const VecX& r) { return solver_.solve(r); }
  /// Solves J x = r (with a coupling: (J + C) x = r, `set_coupling`): directly after
  /// factorize(J); otherwise by GMRES preconditioned by the factors at hand, and, when that
  /// misses its tolerance in max_iterations, by factorising J.
  VecX solve(const SparseMatrix& J, const VecX& r, LinearSolveCounts& counts) {
    if constexpr (DirectSolver<S>)
      if (coupling_) return solve_coupled(J, r, counts);
    if (!fresh_ && reusable())
      if (std::optional<VecX> x = solve_on_kept(J, r, counts)) return std::move(*x);
    // the factors (set-up) of J: the fresh ones, or made now
    if (!fresh_) factorize(J), ++counts.factorisations;
    fresh_ = false;
    VecX x = solver_.solve(r);
    if constexpr (requires { solver_.iterations(); }) {
      ++counts.iterative_solves, counts.iterative_iterations += solver_.iterations();
      fresh_iterations_ = solver_.iterations();
    }
    return x;
  }
  /// The values of the matrices analysed and factorised last (empty: none, or reuse off), and
  /// whether the next solve factorises: what a checkpoint keeps.
  const VecX& analysed_values() const { return analysed_values_; }
  const VecX& factored_values() const { return factored_values_; }
  bool refactor_next() const { return refactor_next_; }
  /// Analyses and factorises the matrices with the pattern of `J` and these values, as
  /// `factorize` did when they were kept; `J`'s values are overwritten.
  void restore(SparseMatrix& J, const VecX& analysed, const VecX& factored, bool refactor_next) {
    reset();
    if (factored.size() == 0) return;
    ALEFSI_CHECK_ARG(analysed.size() == J.nonZeros() && factored.size() == J.nonZeros(), "restore",
                     "the kept matrices have ", factored.size(), " entries, the pattern ", J.nonZeros());
    Eigen::Map<VecX>(J.valuePtr(), J.nonZeros()) = analysed;
    solver_.analyze(J);
    analysed_ = true, analysed_values_ = analysed;
    Eigen::Map<VecX>(J.valuePtr(), J.nonZeros()) = factored;
    factorize(J);
    fresh_ = false, refactor_next_ = refactor_next;
  }
  S& solver() { return solver_; }
  const S& solver() const { return solver_; }

 private:
  // J x = r on the factors (set-up) of an earlier matrix; none when that misses its tolerance
  // (the caller then factorises J). A solve that needed many iterations makes the next one
  // factorise: direct, more than refactor_above GMRES iterations; iterative, more than twice
  // the iterations of the set-up's first solve.
  std::optional<VecX> solve_on_kept(const SparseMatrix& J, const VecX& r, LinearSolveCounts& counts) {
    if constexpr (ReusableSetUp<S>) {
      try {
        VecX x = solver_.solve(J, r);
        ++counts.reused, ++counts.iterative_solves, counts.iterative_iterations += solver_.iterations();
        refactor_next_ = solver_.iterations() > 2 * fresh_iterations_;
        return x;
      } catch (const SolverError&) {
        counts.iterative_iterations += solver_.iterations();
        return std::nullopt;
      }
    } else {
      VecX x;
      const GmresResult res = gmres(
          J, r, [&](const VecX& v) { return apply_kept(J, v); },
          {.tolerance = reuse_.tolerance, .max_iterations = reuse_.max_iterations, .restart = reuse_.max_iterations},
          x, work_);
      counts.krylov_iterations += res.iterations;
      if (!res.converged) return std::nullopt;
      ++counts.reused;
      refactor_next_ = res.iterations > reuse_.refactor_above;
      return x;
    }
  }
  // (J + C) x = r by GMRES on J + C preconditioned by the factors at hand: J's own (made now if
  // need be), at most rank(C) + 1 iterations, or an earlier matrix's (reuse), as many more as
  // the coupling's size. Fresh factors return GMRES's iterate even if round-off keeps it above
  // the tolerance: its residual is no larger than that of J^-1 r, the lagged solve's.
  VecX solve_coupled(const SparseMatrix& J, const VecX& r, LinearSolveCounts& counts) {
    const BlockCoupling& C = *coupling_;
    auto run = [&](int cap, VecX& x) {
      const GmresResult res = gmres(
          CoupledMatrix<SparseMatrix>{J, C}, r, [&](const VecX& v) { return apply_kept(J, v); },
          {.tolerance = reuse_.tolerance, .max_iterations = cap, .restart = cap}, x, work_);
      counts.krylov_iterations += res.iterations;
      return res;
    };
    const int m = int(C.size());
    VecX x;
    if (!fresh_ && reusable()) {
      const GmresResult res = run(reuse_.max_iterations + m, x);
      if (res.converged) {
        ++counts.reused;
        refactor_next_ = res.iterations > reuse_.refactor_above + m;
        return x;
      }
    }
    if (!fresh_) factorize(J), ++counts.factorisations;
    fresh_ = false;
    run(m + 4, x);
    return x;
  }
  // the kept factors applied to v as GMRES's preconditioner for J; a solver that refines its
  // solves (UmfPackLu) refines against J, the matrix being solved, not the one it factorised
  VecX apply_kept(const SparseMatrix& J, const VecX& v) {
    if constexpr (requires { solver_.solve_refined_against(J, v); })
      return solver_.solve_refined_against(J, v);
    else
      return solver_.solve(v);
  }
  static VecX values(const SparseMatrix& J) { return Eigen::Map<const VecX>(J.valuePtr(), J.nonZeros()); }

  S solver_;
  bool analysed_ = false;
  FactorisationReuse reuse_;
  bool factored_ = false;       // reuse on and factors at hand
  bool fresh_ = false;          // the factors are the matrix's of the coming solve
  bool refactor_next_ = false;  // the last reused solve needed many iterations
  int fresh_iterations_ = 0;    // iterative: the iterations of the last solve after a set-up
  const BlockCoupling* coupling_ = nullptr;  // non-empty, or null
  VecX analysed_values_, factored_values_;
  GmresWork work_;
};

}  // namespace alefsi
