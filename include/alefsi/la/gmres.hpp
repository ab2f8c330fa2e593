#pragma once
/// \file la/gmres.hpp
/// Restarted GMRES(m) with right preconditioning (Saad & Schultz 1986; Saad, Iterative Methods
/// for Sparse Linear Systems, 2nd ed., Algorithm 9.5), the one Krylov loop of the library: it
/// solves A P^-1 y = b, x = P^-1 y, from x = 0, with modified Gram–Schmidt Arnoldi and Givens
/// rotations, and stops when the true residual ||b - A x||_2 <= tolerance ||b||_2 (checked at
/// each restart; within a cycle the rotated residual decides) or after max_iterations
/// applications of A. It does not throw: the caller decides what a miss means
/// (`SaddlePointGmres` throws SolverError; `LinearSolve` refactorises, sim/newton.hpp).
///
///     GmresWork work;
///     GmresResult res = gmres(A, b, [&](const VecX& v) { return lu.solve(v); }, {.tolerance = 1e-12}, x, work);
#include <algorithm>
#include <cmath>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

struct GmresOptions {
  Real tolerance = 1e-8;      ///< on ||b - A x||_2 / ||b||_2
  int max_iterations = 1000;  ///< applications of A (and of the preconditioner)
  int restart = 60;           ///< Krylov vectors kept (memory: restart + 1 vectors)
};

struct GmresResult {
  int iterations = 0;     ///< applications of A
  Real residual = 0;      ///< ||b - A x|| / ||b|| at the end (0 for b = 0)
  bool converged = false;
};

/// The Krylov basis, kept between calls so that repeated solves do not reallocate it.
struct GmresWork {
  MatX V;
};

/// x = the GMRES iterate for A x = b (A: any matrix with A * VecX, e.g. SparseMatrix),
/// preconditioned on the right by `precondition` (a callable VecX(const VecX&) applying P^-1).
template <class Matrix, class Precondition>
GmresResult gmres(const Matrix& A, const VecX& b, Precondition&& precondition, const GmresOptions& opt, VecX& x,
                  GmresWork& work) {
  const Index n = b.size();
  const int m = std::max(1, opt.restart);
  GmresResult res;
  x = VecX::Zero(n);
  const Real bnorm = b.norm();
  if (bnorm == 0) {
    res.converged = true;
    return res;
  }
  const Real target = opt.tolerance * bnorm;
  MatX& V = work.V;
  if (V.cols() != m + 1 || V.rows() != n) V.resize(n, m + 1);
  MatX H = MatX::Zero(m + 1, m);
  VecX g(m + 1), cs(m), sn(m), w(n);
  VecX r = b;
  Real rnorm = bnorm;
  while (rnorm > target && res.iterations < opt.max_iterations) {
    V.col(0) = r / rnorm;
    g.setZero();
    g[0] = rnorm;
    H.setZero();
    int k = 0;
    while (k < m && res.iterations < opt.max_iterations) {
      w.noalias() = A * precondition(VecX(V.col(k)));
      for (int i = 0; i <= k; ++i) {  // modified Gram–Schmidt
        H(i, k) = w.dot(V.col(i));
        w.noalias() -= H(i, k) * V.col(i);
      }
      H(k + 1, k) = w.norm();
      if (H(k + 1, k) > 0) V.col(k + 1) = w / H(k + 1, k);
      for (int i = 0; i < k; ++i) {  // earlier rotations
        const Real t = cs[i] * H(i, k) + sn[i] * H(i + 1, k);
        H(i + 1, k) = -sn[i] * H(i, k) + cs[i] * H(i + 1, k);
        H(i, k) = t;
      }
      const Real h = std::hypot(H(k, k), H(k + 1, k));
      cs[k] = H(k, k) / h;
      sn[k] = H(k + 1, k) / h;
      H(k, k) = h;
      H(k + 1, k) = 0;
      g[k + 1] = -sn[k] * g[k];
      g[k] = cs[k] * g[k];
      ++k;
      ++res.iterations;
      if (std::abs(g[k]) <= target) break;
    }
    const VecX y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    x.noalias() += precondition(VecX(V.leftCols(k) * y));
    r.noalias() = b - A * x;
    rnorm = r.norm();
  }
  res.residual = rnorm / bnorm;
  res.converged = rnorm <= target;
  return res;
}

}  // namespace alefsi
