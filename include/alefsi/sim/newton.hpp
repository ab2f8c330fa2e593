#pragma once
/// \file sim/newton.hpp
/// Newton's method over a residual / Jacobian callback and a linear solver instance.
///
/// `newton_solve(residual, solve, u, options)` iterates
///     residual(u, J, r);   stop if converged;   u -= J^-1 r
/// where `residual` assembles r(u) and its Jacobian J (any callable
/// `void(const VecX& u, SparseMatrix& J, VecX& r)`), and `solve` is a `LinearSolve` holding the
/// solver policy (la/solvers.hpp) and whether its symbolic analysis was done for the current
/// sparsity pattern (analyse once per pattern, factorise per matrix).
/// Stopping test, at an iteration > 0, any of:
///   - the residual: max|r| <= tolerance * (its first value) + absolute_tolerance;
///   - the scaled residual: max_i |r_i| / (sum_j |J_ij| max|u|) <= scaled_tolerance, each
///     equation's residual against the size of its terms (its backward error). The relative
///     test cannot be met when r is dominated by terms much larger than their difference: a
///     step of 1e-13 s has a mass term rho/dt that leaves the momentum residual at
///     eps rho/dt |u| ~ 1e-5 against a first residual of 0.4, while the pressure, which enters
///     those rows O(h rho/dt) times more weakly, moves by 1e-3 from iteration to iteration
///     (round-off of the velocity equations); the scaled residual is then 1e-16;
///   - the update: after an update du, max|du| <= step_tolerance * max|u| (nothing changes any
///     more; the iterate is the one the residual test would have accepted next).
/// The defaults stop a regular step where the relative test alone did.
/// `linear` (the semi-implicit form): exactly one update, no test.
/// Each update's linear solve goes through `LinearSolve::solve(J, r)`: a factorisation of J, or,
/// with factorisation reuse on (FactorisationReuse), GMRES preconditioned by an earlier one.
/// Failure: a non-finite residual, or `max_iterations` updates without meeting the test, throws
/// SolverError (with the iteration and the residuals); `u` is then the last iterate.
///
///     LinearSolve<SparseLu<>> lin;
///     NewtonReport rep = newton_solve([&](const VecX& u, SparseMatrix& J, VecX& r) { ... }, lin, u, {});
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/gmres.hpp"
#include "alefsi/la/solvers.hpp"

namespace alefsi {

struct NewtonOptions {
  bool linear = false;           ///< one update and stop (a linear or linearised problem)
  int max_iterations = 25;       ///< >= 1
  Real tolerance = 1e-10;        ///< relative to the first residual's max norm
  Real absolute_tolerance = 1e-13;
  Real scaled_tolerance = 1e-14;  ///< on max_i |r_i| / (sum_j |J_ij| max|u|)
  Real step_tolerance = 1e-12;   ///< on max|du| / max|u|
};

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

/// What the linear solves did (per Newton solve; StepReport sums them per step).
struct LinearSolveCounts {
  int factorisations = 0;     ///< numeric factorisations
  int reused = 0;             ///< solves by GMRES on an earlier factorisation
  int krylov_iterations = 0;  ///< their GMRES iterations
  LinearSolveCounts& operator+=(const LinearSolveCounts& o) {
    factorisations += o.factorisations, reused += o.reused, krylov_iterations += o.krylov_iterations;
    return *this;
  }
};

struct NewtonReport {
  int iterations = 0;           ///< updates of u
  std::vector<Real> residuals;  ///< max-norm residual before each update (and the last one, unless
                                ///< the update test stopped the iteration)
  enum class Stop { residual, scaled_residual, update, linear } stop = Stop::residual;
  Real t_assembly = 0, t_factorize = 0, t_solve = 0;  ///< wall time (s) of the phases (a
                                                      ///< reused solve's refactorisation: t_solve)
  LinearSolveCounts linear;  ///< factorisations, reused solves and their GMRES iterations
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
  /// Reuse on or off (always off for iterative solvers).
  void set_reuse(const FactorisationReuse& r) {
    reuse_ = r;
    if constexpr (!DirectSolver<S>) reuse_.enabled = false;
    if (!reuse_.enabled) factored_ = false;
  }
  const FactorisationReuse& reuse() const { return reuse_; }
  /// The sparsity pattern changed: analyse again before the next factorisation.
  void reset() {
    analysed_ = false;
    factored_ = false;
    analysed_values_.resize(0), factored_values_.resize(0);
  }
  void factorize(const SparseMatrix& J) {
    if (!analysed_) {
      solver_.analyze(J);
      analysed_ = true;
      if (reuse_.enabled) analysed_values_ = values(J);
    }
    solver_.factorize(J);
    factored_ = reuse_.enabled, fresh_ = true, refactor_next_ = false;
    if (reuse_.enabled) factored_values_ = values(J);
  }
  /// The next solve of a new matrix can use the factors at hand (no factorisation first).
  bool reusable() const { return reuse_.enabled && factored_ && !refactor_next_; }
  VecX solve(const VecX& r) { return solver_.solve(r); }
  /// Solves J x = r: directly after factorize(J); otherwise by GMRES preconditioned by the
  /// factors at hand, and, when that misses its tolerance in max_iterations, by factorising J.
  VecX solve(const SparseMatrix& J, const VecX& r, LinearSolveCounts& counts) {
    if (fresh_ || !reusable()) {
      if (!fresh_) factorize(J), ++counts.factorisations;
      fresh_ = false;
      return solver_.solve(r);
    }
    VecX x;
    const GmresResult res = gmres(
        J, r, [this](const VecX& v) { return VecX(solver_.solve(v)); },
        {.tolerance = reuse_.tolerance, .max_iterations = reuse_.max_iterations, .restart = reuse_.max_iterations}, x,
        work_);
    counts.krylov_iterations += res.iterations;
    if (res.converged) {
      ++counts.reused;
      refactor_next_ = res.iterations > reuse_.refactor_above;
      return x;
    }
    factorize(J);
    ++counts.factorisations;
    fresh_ = false;
    return solver_.solve(r);
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
  static VecX values(const SparseMatrix& J) { return Eigen::Map<const VecX>(J.valuePtr(), J.nonZeros()); }

  S solver_;
  bool analysed_ = false;
  FactorisationReuse reuse_;
  bool factored_ = false;       // reuse on and factors at hand
  bool fresh_ = false;          // the factors are the matrix's of the coming solve
  bool refactor_next_ = false;  // the last reused solve needed many iterations
  VecX analysed_values_, factored_values_;
  GmresWork work_;
};

namespace detail {
/// max_i |r_i| / (sum_j |J_ij| max|u|) (0 for an empty or zero r).
inline Real scaled_residual(const SparseMatrix& J, const VecX& r, const VecX& u) {
  if (r.size() == 0) return 0;
  VecX rows = VecX::Zero(J.rows());
  for (Index c = 0; c < J.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(J, c); it; ++it) rows[it.row()] += std::abs(it.value());
  const Real un = u.size() ? u.template lpNorm<Eigen::Infinity>() : 0.0;
  Real worst = 0;
  for (Index i = 0; i < r.size(); ++i) {
    const Real scale = rows[i] * un;
    if (r[i] != 0) worst = std::max(worst, scale > 0 ? std::abs(r[i]) / scale : std::numeric_limits<Real>::infinity());
  }
  return worst;
}
}  // namespace detail

template <class Residual, LinearSolver S>
NewtonReport newton_solve(Residual&& residual, LinearSolve<S>& lin, SparseMatrix& J, VecX& u, const NewtonOptions& opt) {
  NewtonReport rep;
  auto clock = std::chrono::steady_clock::now();
  auto lap = [&clock](Real& acc) {
    const auto now = std::chrono::steady_clock::now();
    acc += std::chrono::duration<Real>(now - clock).count();
    clock = now;
  };
  VecX r;
  Real r0 = -1;
  for (int it = 0;; ++it) {
    residual(static_cast<const VecX&>(u), J, r);
    lap(rep.t_assembly);
    const Real rn = r.size() ? r.template lpNorm<Eigen::Infinity>() : 0.0;
    rep.residuals.push_back(rn);
    if (!std::isfinite(rn)) throw SolverError("non-finite residual at Newton iteration " + std::to_string(it));
    if (r0 < 0) r0 = rn;
    if (!opt.linear && it > 0) {
      if (rn <= opt.tolerance * r0 + opt.absolute_tolerance) break;
      if (detail::scaled_residual(J, r, u) <= opt.scaled_tolerance) {
        rep.stop = NewtonReport::Stop::scaled_residual;
        break;
      }
    }
    if (!opt.linear && it == opt.max_iterations)
      throw SolverError("Newton did not converge in " + std::to_string(it) + " iterations (residual " + detail::sci(rn) +
                        ", first " + detail::sci(r0) + ")");
    if (!lin.reusable()) {
      lin.factorize(J);
      ++rep.linear.factorisations;
    }
    lap(rep.t_factorize);
    const VecX du = lin.solve(J, r, rep.linear);
    u -= du;
    lap(rep.t_solve);
    ++rep.iterations;
    if (opt.linear) {
      rep.stop = NewtonReport::Stop::linear;
      break;
    }
    if (du.size() && du.template lpNorm<Eigen::Infinity>() <= opt.step_tolerance * u.template lpNorm<Eigen::Infinity>()) {
      rep.stop = NewtonReport::Stop::update;
      break;
    }
  }
  return rep;
}

}  // namespace alefsi
