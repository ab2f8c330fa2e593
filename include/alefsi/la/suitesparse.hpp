#pragma once
/// \file la/suitesparse.hpp
/// SuiteSparse solver policies through Eigen's wrappers, compiled in when CMake found
/// SuiteSparse (option ALEFSI_WITH_SUITESPARSE, compile definition ALEFSI_HAVE_SUITESPARSE on
/// alefsi::alefsi). Without it this header declares only the aliases below.
///
///   UmfPackLu:  UMFPACK's multifrontal LU. Strategy `symmetric` (the default here: AMD on
///               A + A^T, diagonal pivots preferred) suits the symmetric-pattern flow
///               matrices; `automatic` is UMFPACK's own choice, `unsymmetric` COLAMD.
///   CholmodLlt: CHOLMOD's supernodal Cholesky LL^T (AMD or METIS ordering, CHOLMOD's
///               choice), for symmetric positive definite matrices (reads the lower triangle).
///               Supernodal, not CHOLMOD's automatic choice: a small matrix would get a
///               simplicial LDL^T, which factorises indefinite matrices without complaint.
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
/// Lifetime: UMFPACK's solve does iterative refinement with the matrix given to `factorize`,
/// and Eigen's wrapper keeps a reference to it: that matrix must stay alive and unchanged
/// until the last `solve` (CHOLMOD has no such requirement).
#include <memory>
#include <string>
#include <type_traits>

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
#include <Eigen/UmfPackSupport>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
#endif

namespace alefsi {

#ifdef ALEFSI_HAVE_SUITESPARSE

namespace detail {
/// Eigen's UmfPackLU with read access to UMFPACK's statistics (Info array).
struct UmfPackLuWithInfo : Eigen::UmfPackLU<SparseMatrix> {
  double statistic(int i) const { return m_umfpackInfo[i]; }
};
}  // namespace detail

class UmfPackLu {
 public:
  static constexpr const char* name = "UMFPACK";
  static constexpr bool direct = true;
  enum class Strategy { automatic, symmetric, unsymmetric };

  explicit UmfPackLu(Strategy strategy = Strategy::symmetric) : lu_(std::make_unique<detail::UmfPackLuWithInfo>()) {
    auto& control = lu_->umfpackControl();
    switch (strategy) {
      case Strategy::automatic: control[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_AUTO; break;
      case Strategy::symmetric: control[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_SYMMETRIC; break;
      case Strategy::unsymmetric: control[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_UNSYMMETRIC; break;
    }
  }
  void analyze(const SparseMatrix& A) {
    lu_->analyzePattern(A);
    if (lu_->info() != Eigen::Success) throw SolverError("UMFPACK symbolic analysis failed: " + status());
    analyzed_ = true;
  }
  void factorize(const SparseMatrix& A) {
    if (!analyzed_) analyze(A);
    lu_->factorize(A);
    if (lu_->info() != Eigen::Success) throw SolverError("UMFPACK factorisation failed: " + status());
  }
  VecX solve(const VecX& b) {
    VecX x = lu_->solve(b);
    if (lu_->info() != Eigen::Success) throw SolverError("UMFPACK solve failed");
    return x;
  }
  /// Entries in L (without its unit diagonal) and U, from the last factorisation.
  Index factor_nonzeros() const { return Index(lu_->statistic(UMFPACK_LNZ) + lu_->statistic(UMFPACK_UNZ)); }

 private:
  std::string status() const {
    const double s = lu_->statistic(UMFPACK_STATUS);
    if (s == UMFPACK_WARNING_singular_matrix) return "singular matrix";
    if (s == UMFPACK_ERROR_out_of_memory) return "out of memory";
    return "UMFPACK status " + std::to_string(int(s));
  }
  std::unique_ptr<detail::UmfPackLuWithInfo> lu_;
  bool analyzed_ = false;
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
