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
/// `coupling` (optional, la/coupling.hpp): Jacobian entries beside J's pattern, filled by
/// `residual` with J (the contact between two bodies); the update then solves (J + C) du = r.
/// Failure: a non-finite residual, or `max_iterations` updates without meeting the test, throws
/// SolverError (with the iteration and the residuals); `u` is then the last iterate.
///
///     LinearSolve<SparseLu<>> lin;
///     NewtonReport rep = newton_solve([&](const VecX& u, SparseMatrix& J, VecX& r) { ... }, lin, u, {});
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/linear_solve.hpp"
#include "alefsi/la/solvers.hpp"

namespace alefsi {

struct NewtonOptions {
  bool linear = false;           ///< one update and stop (a linear or linearised problem)
  int max_iterations = 25;       ///< >= 1
  Real tolerance = 1e-10;        ///< relative to the first residual's max norm
  Real absolute_tolerance = 1e-13;
  Real scaled_tolerance = 1e-14;  ///< on max_i |r_i| / (sum_j |J_ij| max|u|)
  Real step_tolerance = 1e-12;   ///< on max|du| / max|u|
  /// With J assembled in parts (one per MPI process, la/partition.hpp): sums a vector over the
  /// processes (the row sums of the scaled-residual test). Empty: J is whole. The parts' row
  /// sums of |J_ij| bound the whole matrix's from above (an entry split over two parts may
  /// cancel in the sum), so the scaled residual is at most the whole matrix's and the test may
  /// stop a Newton iteration sooner than a serial run (the residual test is unchanged).
  std::function<void(VecX&)> sum_parts{};
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

namespace detail {
/// max_i |r_i| / (sum_j |J_ij| max|u|) (0 for an empty or zero r).
inline Real scaled_residual(const SparseMatrix& J, const VecX& r, const VecX& u,
                            const std::function<void(VecX&)>& sum_parts = {}) {
  if (r.size() == 0) return 0;
  VecX rows = VecX::Zero(J.rows());
  for (Index c = 0; c < J.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(J, c); it; ++it) rows[it.row()] += std::abs(it.value());
  if (sum_parts) sum_parts(rows);
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
NewtonReport newton_solve(Residual&& residual, LinearSolve<S>& lin, SparseMatrix& J, VecX& u, const NewtonOptions& opt,
                          const BlockCoupling* coupling = nullptr) {
  NewtonReport rep;
  struct Unset {  // the solver forgets the coupling when Newton returns or throws
    LinearSolve<S>& lin;
    ~Unset() { lin.set_coupling(nullptr); }
  } unset{lin};
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
      if (detail::scaled_residual(J, r, u, opt.sum_parts) <= opt.scaled_tolerance) {
        rep.stop = NewtonReport::Stop::scaled_residual;
        break;
      }
    }
    if (!opt.linear && it == opt.max_iterations)
      throw SolverError("Newton did not converge in " + std::to_string(it) + " iterations (residual " + detail::sci(rn) +
                        ", first " + detail::sci(r0) + ")");
    lin.set_coupling(coupling);
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
