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
/// Stopping test: the max norm of r at an iteration > 0 below tolerance * (its first value) +
/// absolute_tolerance. `linear` (the semi-implicit form): exactly one update, no test.
/// Failure: a non-finite residual, or `max_iterations` updates without meeting the test, throws
/// SolverError (with the iteration and the residuals); `u` is then the last iterate.
///
///     LinearSolve<SparseLu<>> lin;
///     NewtonReport rep = newton_solve([&](const VecX& u, SparseMatrix& J, VecX& r) { ... }, lin, u, {});
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/solvers.hpp"

namespace alefsi {

struct NewtonOptions {
  bool linear = false;           ///< one update and stop (a linear or linearised problem)
  int max_iterations = 25;       ///< >= 1
  Real tolerance = 1e-10;        ///< relative to the first residual's max norm
  Real absolute_tolerance = 1e-13;
};

struct NewtonReport {
  int iterations = 0;           ///< updates of u
  std::vector<Real> residuals;  ///< max-norm residual before each update (and the last one)
  Real t_assembly = 0, t_factorize = 0, t_solve = 0;  ///< wall time (s) of the phases
};

/// A linear solver policy (constructed in place: solvers such as SparseLu cannot be moved) and
/// the state of its symbolic analysis.
template <LinearSolver S>
class LinearSolve {
 public:
  template <class... Args>
  explicit LinearSolve(Args&&... args) : solver_(std::forward<Args>(args)...) {}
  /// The sparsity pattern changed: analyse again before the next factorisation.
  void reset() { analysed_ = false; }
  void factorize(const SparseMatrix& J) {
    if (!analysed_) {
      solver_.analyze(J);
      analysed_ = true;
    }
    solver_.factorize(J);
  }
  VecX solve(const VecX& r) { return solver_.solve(r); }
  S& solver() { return solver_; }
  const S& solver() const { return solver_; }

 private:
  S solver_;
  bool analysed_ = false;
};

namespace detail {
inline std::string sci(Real x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", x);
  return buf;
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
    if (!opt.linear && it > 0 && rn <= opt.tolerance * r0 + opt.absolute_tolerance) break;
    if (!opt.linear && it == opt.max_iterations)
      throw SolverError("Newton did not converge in " + std::to_string(it) + " iterations (residual " + detail::sci(rn) +
                        ", first " + detail::sci(r0) + ")");
    lin.factorize(J);
    lap(rep.t_factorize);
    u -= lin.solve(r);
    lap(rep.t_solve);
    ++rep.iterations;
    if (opt.linear) break;
  }
  return rep;
}

}  // namespace alefsi
