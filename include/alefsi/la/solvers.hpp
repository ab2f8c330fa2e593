#pragma once
/// \file la/solvers.hpp
/// Linear-solver policies: a solver is a type with `analyze(A)` (symbolic work, once per
/// sparsity pattern), `factorize(A)` (numeric work, per matrix) and `solve(b)`.
///
///   SparseLu<Ordering>: Eigen's supernodal SparseLU with a column ordering (default COLAMD).
///       Measured on the 2D P2/P1 Stokes matrix, N = 32 (9.5k unknowns): COLAMD gives 3.0 M
///       entries in L+U and factorises in 0.25 s; AMD on A + A^T gives 56 M and 34 s, because
///       SparseLU's partial pivoting then has to leave the ordering on the zero pressure block.
///       Better orderings for saddle-point matrices are the subject of docs/performance.md.
///   BiCgStabIlut:       BiCGSTAB preconditioned by ILUT (drop tolerance, fill factor).
///
///     alefsi::SparseLu<> lu;
///     lu.analyze(J);  lu.factorize(J);  VecX du = lu.solve(-r);
///
/// Failures (singular matrix, no convergence) throw `SolverError` with Eigen's message.
#include <string>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/la/assembler.hpp"

namespace alefsi {

/// What the rest of the library calls on a linear solver.
template <class S>
concept LinearSolver = requires(S s, const SparseMatrix& A, const VecX& b) {
  s.analyze(A);
  s.factorize(A);
  { s.solve(b) } -> std::convertible_to<VecX>;
  { S::name } -> std::convertible_to<const char*>;
};

template <class Ordering = Eigen::COLAMDOrdering<Index>>
class SparseLu {
 public:
  static constexpr const char* name = "SparseLU";
  void analyze(const SparseMatrix& A) {
    lu_.analyzePattern(A);
    analyzed_ = true;
  }
  void factorize(const SparseMatrix& A) {
    if (!analyzed_) analyze(A);
    lu_.factorize(A);
    if (lu_.info() != Eigen::Success) throw SolverError("SparseLU factorisation failed: " + lu_.lastErrorMessage());
  }
  VecX solve(const VecX& b) {
    VecX x = lu_.solve(b);
    if (lu_.info() != Eigen::Success) throw SolverError("SparseLU solve failed: " + lu_.lastErrorMessage());
    return x;
  }
  /// Nonzeros in the L and U factors (fill).
  Index factor_nonzeros() { return Index(lu_.nnzL() + lu_.nnzU()); }

 private:
  Eigen::SparseLU<SparseMatrix, Ordering> lu_;
  bool analyzed_ = false;
};

class BiCgStabIlut {
 public:
  static constexpr const char* name = "BiCGSTAB+ILUT";
  explicit BiCgStabIlut(Real tolerance = 1e-10, int max_iterations = 2000, Real drop_tolerance = 1e-4,
                        int fill_factor = 20) {
    ALEFSI_CHECK_ARG(tolerance > 0, "tolerance", "must be positive");
    solver_.setTolerance(tolerance);
    solver_.setMaxIterations(max_iterations);
    solver_.preconditioner().setDroptol(drop_tolerance);
    solver_.preconditioner().setFillfactor(fill_factor);
  }
  void analyze(const SparseMatrix&) {}
  void factorize(const SparseMatrix& A) {
    solver_.compute(A);
    if (solver_.info() != Eigen::Success) throw SolverError("ILUT preconditioner failed");
  }
  VecX solve(const VecX& b) {
    VecX x = solver_.solve(b);
    if (solver_.info() != Eigen::Success)
      throw SolverError("BiCGSTAB did not converge: " + std::to_string(solver_.iterations()) + " iterations, error " +
                        std::to_string(solver_.error()));
    return x;
  }
  int iterations() const { return int(solver_.iterations()); }

 private:
  Eigen::BiCGSTAB<SparseMatrix, Eigen::IncompleteLUT<Real, Index>> solver_;
};

static_assert(LinearSolver<SparseLu<>>, "SparseLu must model LinearSolver");
static_assert(LinearSolver<BiCgStabIlut>, "BiCgStabIlut must model LinearSolver");

}  // namespace alefsi
