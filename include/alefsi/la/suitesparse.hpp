#pragma once
/// \file la/suitesparse.hpp
/// SuiteSparse solver policies, compiled in when CMake found SuiteSparse (option
/// ALEFSI_WITH_SUITESPARSE, compile definition ALEFSI_HAVE_SUITESPARSE on alefsi::alefsi).
/// Without it this header declares only the aliases below.
///
///   UmfPackLu:  UMFPACK's multifrontal LU through its 64-bit-index interface (umfpack_dl_*),
///               called directly. Strategy `symmetric` (the default here: AMD on A + A^T,
///               diagonal pivots preferred) suits the symmetric-pattern flow matrices;
///               `automatic` is UMFPACK's own choice, `unsymmetric` COLAMD. The 32-bit
///               interface (umfpack_di_*, the one Eigen's UmfPackLU calls for int indices)
///               counts its workspace in int and reported "out of memory" with most of the
///               machine free from about 1e5 unknowns in 3D (docs/solvers.md).
///   CholmodLlt: CHOLMOD's supernodal Cholesky LL^T through Eigen's wrapper (AMD or METIS
///               ordering, CHOLMOD's choice), for symmetric positive definite matrices (reads
///               the lower triangle). Supernodal, not CHOLMOD's automatic choice: a small
///               matrix would get a simplicial LDL^T, which factorises indefinite matrices
///               without complaint.
///   DefaultSpdSolver: CholmodLlt when SuiteSparse is there, else SimplicialLlt; the
///               mesh-velocity problem (physics/mesh_motion.hpp) uses it in 3D
///               (`DefaultSpdSolverFor<D>`: SimplicialLlt in 2D).
///   DefaultDirectSolver: UmfPackLu when SuiteSparse is there, else SparseLu<> (saddle-point
///               AMD): the direct solver for flow systems of 1e4-1e6 unknowns where UMFPACK is
///               the faster (docs/solvers.md). Not FlowConfig's default, which is SparseLu<> in
///               every build so that a scene's numbers do not depend on what CMake found.
/// Both use the BLAS that the SuiteSparse libraries load (Debian: libblas.so.3, OpenBLAS when
/// libopenblas is installed; with OPENBLAS_NUM_THREADS unset it uses every core).
///
///     #ifdef ALEFSI_HAVE_SUITESPARSE
///     alefsi::UmfPackLu lu;               // move-only (owns UMFPACK's handles)
///     lu.analyze(J);  lu.factorize(J);  VecX du = lu.solve(-r);
///     #endif
///
/// UmfPackLu keeps its own copy of the factorised matrix (64-bit indices and the values; 16
/// bytes per nonzero), which its solve's iterative refinement multiplies by: the caller's
/// matrix may change or go away after `factorize`. A `factorize` whose matrix has another
/// pattern than the last analysis analyses it again. `solve_refined_against(A, b)` refines
/// against a later matrix of the same pattern instead (factorisation reuse, la/linear_solve.hpp).
#include <array>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/solvers.hpp"

#ifdef ALEFSI_HAVE_SUITESPARSE
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wshadow"
#endif
#include <Eigen/CholmodSupport>
#include <umfpack.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
#endif

namespace alefsi {

#ifdef ALEFSI_HAVE_SUITESPARSE

class UmfPackLu {
 public:
  static constexpr const char* name = "UMFPACK";
  static constexpr bool direct = true;
  enum class Strategy { automatic, symmetric, unsymmetric };
  using Long = SuiteSparse_long;

  explicit UmfPackLu(Strategy strategy = Strategy::symmetric) {
    umfpack_dl_defaults(control_.data());
    switch (strategy) {
      case Strategy::automatic: control_[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_AUTO; break;
      case Strategy::symmetric: control_[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_SYMMETRIC; break;
      case Strategy::unsymmetric: control_[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_UNSYMMETRIC; break;
    }
  }
  UmfPackLu(const UmfPackLu&) = delete;
  UmfPackLu& operator=(const UmfPackLu&) = delete;
  UmfPackLu(UmfPackLu&& o) noexcept {  // o is left empty, with UMFPACK's default controls
    umfpack_dl_defaults(control_.data());
    swap(o);
  }
  UmfPackLu& operator=(UmfPackLu&& o) noexcept {
    if (this != &o) {
      release();
      swap(o);
    }
    return *this;
  }
  ~UmfPackLu() { release(); }

  /// The symbolic analysis (ordering) of A's pattern; a later `factorize` of the same pattern
  /// reuses it.
  void analyze(const SparseMatrix& A) {
    release();
    copy(A);
    const Long status = umfpack_dl_symbolic(n_, n_, ap_.data(), ai_.data(), ax_.data(), &symbolic_, control_.data(),
                                            info_.data());
    if (status != UMFPACK_OK) throw SolverError("UMFPACK symbolic analysis failed: " + message(status));
  }
  void factorize(const SparseMatrix& A) {
    if (!symbolic_ || !same_pattern(A)) {
      analyze(A);
    } else {
      std::copy(A.valuePtr(), A.valuePtr() + A.nonZeros(), ax_.begin());
    }
    if (numeric_) umfpack_dl_free_numeric(&numeric_);
    const Long status =
        umfpack_dl_numeric(ap_.data(), ai_.data(), ax_.data(), symbolic_, &numeric_, control_.data(), info_.data());
    if (status != UMFPACK_OK) {  // the singular-matrix warning included: its solve would divide by zero
      if (numeric_) umfpack_dl_free_numeric(&numeric_);
      throw SolverError("UMFPACK factorisation failed: " + message(status));
    }
    factor_nonzeros_ = Index(info_[UMFPACK_LNZ] + info_[UMFPACK_UNZ]);
  }
  VecX solve(const VecX& b) {
    if (numeric_ && b.size() != n_)
      throw SolverError("UMFPACK solve: right-hand side of size " + std::to_string(b.size()) + " for a matrix of " +
                        std::to_string(n_) + " rows");
    return refined_solve(ax_.data(), b);
  }
  /// The factors at hand applied to b, with UMFPACK's iterative refinement against A instead of
  /// the factorised matrix: A is a later matrix of the analysed pattern (Newton iterations,
  /// time steps), and the refinement brings the result nearer A^-1 b than the factors alone.
  /// `LinearSolve` preconditions its GMRES on a reused factorisation with it (la/linear_solve.hpp;
  /// docs/solvers.md, "UMFPACK's index width": 1.6x fewer CPU seconds on the annulus).
  VecX solve_refined_against(const SparseMatrix& A, const VecX& b) {
    if (numeric_ && (A.rows() != n_ || A.cols() != n_ || Long(A.nonZeros()) != Long(ai_.size()) || b.size() != n_))
      throw SolverError("UMFPACK refinement: a matrix of " + std::to_string(A.rows()) + " rows and " +
                        std::to_string(A.nonZeros()) + " entries and a right-hand side of " +
                        std::to_string(b.size()) + " for factors of " + std::to_string(n_) + " rows and " +
                        std::to_string(ai_.size()) + " entries");
    return refined_solve(A.valuePtr(), b);
  }
  /// Entries in L (without its unit diagonal) and U, from the last factorisation.
  Index factor_nonzeros() const { return factor_nonzeros_; }

 private:
  static std::string message(Long status) {
    if (status == UMFPACK_WARNING_singular_matrix) return "singular matrix";
    if (status == UMFPACK_ERROR_out_of_memory) return "out of memory";
    if (status == UMFPACK_ERROR_invalid_matrix) return "invalid matrix (unsorted or duplicate row indices)";
    if (status == UMFPACK_ERROR_n_nonpositive) return "empty matrix";
    return "UMFPACK status " + std::to_string(status);
  }
  // the factors applied to b (sizes checked by the caller), refined against the matrix of the
  // analysed pattern with these values
  VecX refined_solve(const Real* values, const VecX& b) {
    if (!numeric_) throw SolverError("UMFPACK solve before a successful factorize");
    VecX x(n_);
    const Long status = umfpack_dl_solve(UMFPACK_A, ap_.data(), ai_.data(), values, x.data(), b.data(), numeric_,
                                         control_.data(), info_.data());
    if (status != UMFPACK_OK) throw SolverError("UMFPACK solve failed: " + message(status));
    return x;
  }
  // the matrix in UMFPACK's compressed-column form with 64-bit indices (A: column-major)
  void copy(const SparseMatrix& A) {
    if (A.rows() != A.cols())
      throw SolverError("UMFPACK: the matrix is " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                        ", not square");
    if (!A.isCompressed()) throw SolverError("UMFPACK: the matrix is not compressed (call makeCompressed())");
    n_ = A.rows();
    ap_.assign(A.outerIndexPtr(), A.outerIndexPtr() + n_ + 1);
    ai_.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    ax_.assign(A.valuePtr(), A.valuePtr() + A.nonZeros());
  }
  bool same_pattern(const SparseMatrix& A) const {
    if (A.rows() != n_ || A.cols() != n_ || !A.isCompressed() || Long(A.nonZeros()) != Long(ai_.size())) return false;
    return std::equal(ap_.begin(), ap_.end(), A.outerIndexPtr()) &&
           std::equal(ai_.begin(), ai_.end(), A.innerIndexPtr());
  }
  void release() {
    if (numeric_) umfpack_dl_free_numeric(&numeric_);
    if (symbolic_) umfpack_dl_free_symbolic(&symbolic_);
  }
  void swap(UmfPackLu& o) noexcept {
    std::swap(control_, o.control_);
    std::swap(info_, o.info_);
    std::swap(symbolic_, o.symbolic_);
    std::swap(numeric_, o.numeric_);
    std::swap(n_, o.n_);
    ap_.swap(o.ap_);
    ai_.swap(o.ai_);
    ax_.swap(o.ax_);
    std::swap(factor_nonzeros_, o.factor_nonzeros_);
  }
  std::array<double, UMFPACK_CONTROL> control_{};
  std::array<double, UMFPACK_INFO> info_{};
  void* symbolic_ = nullptr;
  void* numeric_ = nullptr;
  Index n_ = 0;
  std::vector<Long> ap_, ai_;
  std::vector<Real> ax_;
  Index factor_nonzeros_ = 0;
};

class CholmodLlt {
 public:
  static constexpr const char* name = "CHOLMOD";
  static constexpr bool direct = true;
  CholmodLlt() : llt_(std::make_unique<Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower>>()) {
    llt_->setMode(Eigen::CholmodSupernodalLLt);
  }
  void analyze(const SparseMatrix& A) {
    llt_->analyzePattern(A);
    if (llt_->info() != Eigen::Success) throw SolverError("CHOLMOD symbolic analysis failed");
    analyzed_ = true;
  }
  void factorize(const SparseMatrix& A) {
    if (!analyzed_) analyze(A);
    llt_->factorize(A);
    if (llt_->info() != Eigen::Success) throw SolverError("CHOLMOD: the matrix is not positive definite");
  }
  VecX solve(const VecX& b) {
    VecX x = llt_->solve(b);
    if (llt_->info() != Eigen::Success) throw SolverError("CHOLMOD solve failed");
    return x;
  }
  /// Nonzeros in L as predicted by the last analysis (CHOLMOD's Common->lnz).
  Index factor_nonzeros() { return Index(llt_->cholmod().lnz); }

 private:
  std::unique_ptr<Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower>> llt_;
  bool analyzed_ = false;
};

static_assert(LinearSolver<UmfPackLu>, "UmfPackLu must model LinearSolver");
static_assert(LinearSolver<CholmodLlt>, "CholmodLlt must model LinearSolver");

using DefaultSpdSolver = CholmodLlt;
using DefaultDirectSolver = UmfPackLu;

#else

using DefaultSpdSolver = SimplicialLlt;
using DefaultDirectSolver = SparseLu<>;

#endif

/// The mesh-velocity solver per dimension: in 2D the SPD matrices are small and narrow-banded,
/// and SimplicialLLT beats CHOLMOD's supernodal BLAS kernels there (DKT scene, 2,239 nodes:
/// 0.31 s against 0.69 s for 30 solves, and OpenBLAS threads oversubscribe a loaded 2-core
/// machine: 40 s against 1 s for 175 solves at load 9); in 3D DefaultSpdSolver.
template <int D>
using DefaultSpdSolverFor = std::conditional_t<D == 3, DefaultSpdSolver, SimplicialLlt>;

}  // namespace alefsi
