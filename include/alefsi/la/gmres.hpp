#pragma once
/// \file la/gmres.hpp
/// Restarted GMRES(m) with right preconditioning (Saad & Schultz 1986; Saad, Iterative Methods
/// for Sparse Linear Systems, 2nd ed., Algorithm 9.5), the one Krylov loop of the library: it
/// solves A P^-1 y = b, x = P^-1 y (or flexibly, below), from x = 0, with modified Gram–Schmidt
/// Arnoldi and Givens rotations, and stops when the true residual ||b - A x||_2 <= tolerance
/// ||b||_2 (checked at each restart; within a cycle the rotated residual decides) or after
/// max_iterations Krylov steps. It does not throw: the caller decides what a miss means
/// (`SaddlePointGmres` throws SolverError; `LinearSolve` refactorises, sim/newton.hpp).
///
/// Breakdown: a step whose A P^-1 v_k adds no new direction to the residual's least-squares
/// problem (the new column of its triangular factor is below round-off, 0 or not finite: a
/// preconditioner that returns zero or NaN, or one singular on the Krylov space) is dropped and
/// ends the cycle, which then updates x from the steps before it; a cycle that breaks down at
/// its first step ends the solve, not converged, with `breakdown` set and x the previous
/// cycles' iterate (it does not spin to max_iterations, and no rotation divides by zero).
///
/// With `augment = k > 0` it is LGMRES(m, k) (Baker, Jessup & Manteuffel, SIAM J. Matrix Anal.
/// Appl. 26 (2005) 962): each cycle's search space is the m Krylov directions plus the k latest
/// cycle corrections z_j = x_j - x_{j-1}. A restart otherwise forgets the slow error components
/// that earlier cycles had found, and the residual then falls by a constant factor per cycle
/// (it did for a free sphere on a graded mesh, docs/solvers.md); the corrections keep them. Cost:
/// 2k more vectors, k products with A per cycle, no more preconditioner applications.
///
/// With `flexible = true` it is FGMRES (Saad, SIAM J. Sci. Comput. 14 (1993) 461; Algorithm 9.6
/// of the book): each preconditioned direction z_k = P^-1 v_k is kept and the iterate is formed
/// as x = Z y. The plain form's x = P^-1 (V y) assumes that P^-1 is the same linear map at
/// every application; a preconditioner that is not (single-precision factors, an inner
/// iteration) then loses what its rounding or its variation adds, cycle after cycle. Flexible
/// GMRES minimises the true residual over the directions it applied, whatever they were, and
/// saves the one extra application per cycle. Cost: `restart` more vectors.
///
///     GmresWork work;
///     GmresResult res = gmres(A, b, [&](const VecX& v) { return lu.solve(v); }, {.tolerance = 1e-12}, x, work);
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

struct GmresOptions {
  Real tolerance = 1e-8;      ///< on ||b - A x||_2 / ||b||_2
  int max_iterations = 1000;  ///< Krylov steps (each one application of P^-1 and of A)
  int restart = 60;           ///< Krylov vectors per cycle (memory: restart + 1 vectors)
  int augment = 0;            ///< LGMRES: earlier cycle corrections kept (memory: 2 augment vectors more)
  bool flexible = false;      ///< FGMRES: keep z_k = P^-1 v_k, x = Z y (memory: restart vectors more)
};

struct GmresResult {
  int iterations = 0;     ///< Krylov steps (P^-1 applied once per step, once more per cycle unless flexible)
  Real residual = 0;      ///< ||b - A x|| / ||b|| at the end (0 for b = 0)
  bool converged = false;
  bool breakdown = false;  ///< a cycle could not take its first step (see the file comment)
};

/// The Krylov basis, the LGMRES corrections and FGMRES's preconditioned directions, kept
/// between calls so that repeated solves do not reallocate them.
struct GmresWork {
  MatX V, Z, F;
};

/// x = the GMRES iterate for A x = b (A: any matrix with A * VecX, e.g. SparseMatrix),
/// preconditioned on the right by `precondition` (a callable VecX(const VecX&) applying P^-1).
template <class Matrix, class Precondition>
GmresResult gmres(const Matrix& A, const VecX& b, Precondition&& precondition, const GmresOptions& opt, VecX& x,
                  GmresWork& work) {
  const Index n = b.size();
  const int m = std::max(1, opt.restart), k_aug = std::max(0, opt.augment);
  GmresResult res;
  x = VecX::Zero(n);
  const Real bnorm = b.norm();
  if (bnorm == 0) {
    res.converged = true;
    return res;
  }
  const Real target = opt.tolerance * bnorm;
  MatX& V = work.V;
  MatX& Z = work.Z;  // unit corrections of the latest cycles, newest first
  // grown, never shrunk: callers alternate between restart lengths (LinearSolve's coupled solves)
  if (V.cols() < m + k_aug + 1 || V.rows() != n) V.resize(n, m + k_aug + 1);
  if (Z.cols() < k_aug || Z.rows() != n) Z.resize(n, k_aug);
  MatX& F = work.F;  // flexible: F.col(k) = P^-1 V.col(k) as applied
  if (opt.flexible && (F.cols() < m || F.rows() != n)) F.resize(n, m);
  int n_z = 0;  // corrections stored so far (< k_aug in the first cycles)
  MatX H = MatX::Zero(m + k_aug + 1, m + k_aug);
  VecX g(m + k_aug + 1), cs(m + k_aug), sn(m + k_aug), w(n);
  VecX r = b;
  Real rnorm = bnorm;
  while (rnorm > target && res.iterations < opt.max_iterations) {
    V.col(0) = r / rnorm;
    g.setZero();
    g[0] = rnorm;
    H.setZero();
    int k = 0;
    bool broke = false;  // this cycle's latest Krylov step added nothing: the cycle ends
    // one Arnoldi step on the new direction w = A q (q: P^-1 v_k or a stored correction);
    // `optional`: a correction (nearly) in the space already is left out, not added
    auto arnoldi = [&](bool optional) {
      const Real wnorm = w.norm();
      for (int i = 0; i <= k; ++i) {  // modified Gram–Schmidt
        H(i, k) = w.dot(V.col(i));
        w.noalias() -= H(i, k) * V.col(i);
      }
      H(k + 1, k) = w.norm();
      if (optional && !(H(k + 1, k) > 1e-10 * wnorm)) {
        H.col(k).setZero();
        return false;
      }
      if (H(k + 1, k) > 0) V.col(k + 1) = w / H(k + 1, k);
      for (int i = 0; i < k; ++i) {  // earlier rotations
        const Real t = cs[i] * H(i, k) + sn[i] * H(i + 1, k);
        H(i + 1, k) = -sn[i] * H(i, k) + cs[i] * H(i + 1, k);
        H(i, k) = t;
      }
      const Real h = std::hypot(H(k, k), H(k + 1, k));
      if (!(h > std::numeric_limits<Real>::epsilon() * wnorm)) {  // breakdown (also h or wnorm NaN)
        H.col(k).setZero();
        broke = !optional;
        return false;
      }
      cs[k] = H(k, k) / h;
      sn[k] = H(k + 1, k) / h;
      H(k, k) = h;
      H(k + 1, k) = 0;
      g[k + 1] = -sn[k] * g[k];
      g[k] = cs[k] * g[k];
      ++k;
      return std::abs(g[k]) <= target;
    };
    bool done = false;
    while (!done && !broke && k < m && res.iterations < opt.max_iterations) {
      if (opt.flexible) {
        F.col(k) = precondition(VecX(V.col(k)));
        w.noalias() = A * F.col(k);
      } else {
        w.noalias() = A * precondition(VecX(V.col(k)));
      }
      ++res.iterations;
      done = arnoldi(false);
    }
    const int n_krylov = k;
    if (broke && n_krylov == 0) {
      res.breakdown = true;
      break;
    }
    std::vector<int> used;  // the corrections added, in the order of their columns
    if (n_krylov == m)  // a full cycle: add the stored corrections to the search space
      for (int j = 0; j < n_z && !done; ++j) {
        w.noalias() = A * Z.col(j);
        const int k0 = k;
        done = arnoldi(true);
        if (k > k0) used.push_back(j);
      }
    const VecX y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    VecX dx = opt.flexible ? VecX(F.leftCols(n_krylov) * y.head(n_krylov))
                           : VecX(precondition(VecX(V.leftCols(n_krylov) * y.head(n_krylov))));
    for (std::size_t j = 0; j < used.size(); ++j) dx.noalias() += y[n_krylov + Index(j)] * Z.col(used[j]);
    x += dx;
    if (k_aug > 0) {  // newest correction first, the oldest dropped
      const Real dnorm = dx.norm();
      if (dnorm > 0) {
        for (int j = std::min(n_z, k_aug - 1); j > 0; --j) Z.col(j) = Z.col(j - 1);
        Z.col(0) = dx / dnorm;
        n_z = std::min(n_z + 1, k_aug);
      }
    }
    r.noalias() = b - A * x;
    rnorm = r.norm();
  }
  res.residual = rnorm / bnorm;
  res.converged = rnorm <= target;
  return res;
}

}  // namespace alefsi
