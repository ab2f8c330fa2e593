#pragma once
/// \file la/solvers.hpp
/// Linear-solver policies: a solver is a type with `analyze(A)` (symbolic work, once per
/// sparsity pattern), `factorize(A)` (numeric work, per matrix) and `solve(b)`.
///
///   SparseLu<Ordering>: Eigen's supernodal SparseLU. The default ordering,
///       `SaddlePointAmdOrdering` (la/ordering.hpp), is AMD on A + A^T with zero-diagonal
///       (pressure) unknowns placed after a neighbour, factorised in SparseLU's symmetric mode
///       (diagonal pivots unless |a_jj| < pivot_threshold * max_i |a_ij|). Measured on the 2D
///       P2/P1 Stokes matrix, N = 256 (588k unknowns): 154 M entries in L+U and 9.6 s, against
///       630 M and 193 s with `SparseLu<Eigen::COLAMDOrdering<Index>>` (partial pivoting),
///       which stays available. Numbers and commands: docs/solvers.md.
///       `SparseLu<Eigen::AMDOrdering<Index>>` is plain AMD the right way round (Eigen's
///       SparseLU applies AMDOrdering's permutation inverted; la/ordering.hpp explains).
///   BiCgStabIlut:       BiCGSTAB preconditioned by ILUT (drop tolerance, fill factor).
///   SimplicialLlt:      Eigen's simplicial Cholesky (AMD), for SPD matrices.
/// SuiteSparse policies (UMFPACK, CHOLMOD) are in la/suitesparse.hpp.
///
///     alefsi::SparseLu<> lu;
///     lu.analyze(J);  lu.factorize(J);  VecX du = lu.solve(-r);
///
/// `analyze` needs the assembled matrix (values, not only the pattern) for the saddle-point
/// ordering: it tells zero diagonal entries apart. Failures (singular matrix, no convergence,
/// not positive definite) throw `SolverError` with the library's message.
#include <string>
#include <type_traits>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/ordering.hpp"

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wshadow"
#endif
#include <Eigen/SparseCholesky>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace alefsi {

/// What the rest of the library calls on a linear solver.
template <class S>
concept LinearSolver = requires(S s, const SparseMatrix& A, const VecX& b) {
  s.analyze(A);
  s.factorize(A);
  { s.solve(b) } -> std::convertible_to<VecX>;
  { S::name } -> std::convertible_to<const char*>;
};

/// A solver whose factors solve its matrix exactly (to rounding), marked by `direct = true`,
/// so that they can precondition later matrices (factorisation reuse, sim/newton.hpp).
template <class S>
concept DirectSolver = LinearSolver<S> && requires { requires S::direct; };

namespace detail {
/// How SparseLu uses an ordering: the functor SparseLU calls, whether the ordering is
/// symmetric (then SparseLU runs in symmetric mode with diagonal pivoting) and its name.
template <class Ordering>
struct SparseLuOrdering {
  using type = Ordering;
  static constexpr bool symmetric = false;
  static constexpr const char* name = "custom";
};
template <class I>
struct SparseLuOrdering<Eigen::COLAMDOrdering<I>> {
  using type = Eigen::COLAMDOrdering<I>;
  static constexpr bool symmetric = false;
  static constexpr const char* name = "COLAMD";
};
template <class I>
struct SparseLuOrdering<Eigen::NaturalOrdering<I>> {
  using type = Eigen::NaturalOrdering<I>;
  static constexpr bool symmetric = false;
  static constexpr const char* name = "natural";
};
template <class I>
struct SparseLuOrdering<Eigen::AMDOrdering<I>> {  // Eigen's AMD, applied the right way round
  using type = SymmetricAmdOrdering<I>;
  static constexpr bool symmetric = true;
  static constexpr const char* name = "AMD";
};
template <class I>
struct SparseLuOrdering<SymmetricAmdOrdering<I>> : SparseLuOrdering<Eigen::AMDOrdering<I>> {};
template <class I>
struct SparseLuOrdering<SaddlePointAmdOrdering<I>> {
  using type = SaddlePointAmdOrdering<I>;
  static constexpr bool symmetric = true;
  static constexpr const char* name = "saddle-point AMD";
};
}  // namespace detail

/// Eigen's SparseLU with a column ordering. Symmetric orderings (AMD, saddle-point AMD) run
/// SparseLU in symmetric mode with a small diagonal pivot threshold, so the rows follow the
/// columns; other orderings (COLAMD) use partial pivoting (threshold 1).
template <class Ordering = SaddlePointAmdOrdering<Index>>
class SparseLu {
  using Traits = detail::SparseLuOrdering<Ordering>;

 public:
  static constexpr const char* name = "SparseLU";
  static constexpr bool direct = true;
  static constexpr const char* ordering_name = Traits::name;
  static constexpr bool symmetric_mode = Traits::symmetric;
  /// Default diagonal pivot threshold: a diagonal pivot is kept unless it is smaller than
  /// this times the largest entry of its column. In symmetric mode it must sit below the
  /// ratio |b|/|a| of the pressure coupling to the velocity diagonal (about h in 2D Stokes
  /// with mu = 1), or SparseLU leaves the ordering: 1e-3 already does at N = 128.
  static constexpr Real default_pivot_threshold = symmetric_mode ? 1e-6 : 1.0;

  SparseLu() : SparseLu(default_pivot_threshold) {}
  explicit SparseLu(Real pivot_threshold) {
    ALEFSI_CHECK_ARG(pivot_threshold >= 0 && pivot_threshold <= 1, "pivot_threshold", "must be in [0, 1], got ",
                     pivot_threshold);
    lu_.isSymmetric(symmetric_mode);
    lu_.setPivotThreshold(pivot_threshold);
  }
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
  Eigen::SparseLU<SparseMatrix, typename Traits::type> lu_;
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

/// Eigen's simplicial Cholesky (LL^T, AMD ordering) for symmetric positive definite matrices;
/// reads the lower triangle.
class SimplicialLlt {
 public:
  static constexpr const char* name = "SimplicialLLT";
  static constexpr bool direct = true;
  void analyze(const SparseMatrix& A) {
    llt_.analyzePattern(A);
    analyzed_ = true;
  }
  void factorize(const SparseMatrix& A) {
    if (!analyzed_) analyze(A);
    llt_.factorize(A);
    if (llt_.info() != Eigen::Success) throw SolverError("SimplicialLLT: the matrix is not positive definite");
  }
  VecX solve(const VecX& b) { return llt_.solve(b); }
  /// Nonzeros in L.
  Index factor_nonzeros() const { return Index(llt_.matrixL().nestedExpression().nonZeros()); }

 private:
  Eigen::SimplicialLLT<SparseMatrix> llt_;
  bool analyzed_ = false;
};

static_assert(LinearSolver<SparseLu<>>, "SparseLu must model LinearSolver");
static_assert(LinearSolver<BiCgStabIlut>, "BiCgStabIlut must model LinearSolver");
static_assert(LinearSolver<SimplicialLlt>, "SimplicialLlt must model LinearSolver");

}  // namespace alefsi
