#pragma once
/// \file la/amg.hpp
/// Smoothed-aggregation algebraic multigrid (Vaněk, Mandel, Brezina 1996), used as one V-cycle
/// preconditioner for the velocity block of the flow systems (la/krylov.hpp) and for scalar
/// pressure operators.
///
/// Systems of PDEs are handled the "unknown-based" way: each unknown carries a component label
/// (0..D-1 for interleaved velocity components; all 0 for a scalar problem), the strength graph
/// only joins unknowns of the same component, so every aggregate holds one component and the
/// near-null space is the constant per component (the rigid translations). The coarse operators
/// are Galerkin products R A P of the full matrix, cross-component couplings included.
///
/// Per level: strength |a_ij| >= theta sqrt(|a_ii a_jj|) (same component, i != j); greedy
/// aggregation in three passes (roots whose strong neighbours are all free; free unknowns join
/// the aggregate of their strongest aggregated neighbour; what is left forms new aggregates);
/// unknowns without strong neighbours get no coarse unknown (the smoother handles them); the
/// tentative prolongator is piecewise constant, smoothed once by damped Jacobi on the filtered
/// matrix A_F (diagonal and strong entries), damping (4/3) / lambda_max(D^-1 A_F)
/// with lambda_max from power iterations. Smoother: Gauss–Seidel, forward before the coarse
/// correction, backward after (a symmetric V-cycle for a symmetric matrix). Coarsest level
/// (<= coarse_size unknowns, or max_levels): dense LU.
///
/// The V-cycle is a fixed linear operator (no inner Krylov), so it can precondition GMRES or CG.
///
///     alefsi::SmoothedAggregationAmg amg;
///     amg.compute(A_rowmajor, components);      // hierarchy for this matrix (values read)
///     VecX x = amg.apply(b);                    // one V-cycle from x = 0
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"

namespace alefsi {

/// Row-major sparse matrix (row access for Gauss–Seidel and the strength graph).
using RowSparseMatrix = Eigen::SparseMatrix<Real, Eigen::RowMajor, Index>;

struct AmgOptions {
  Real strength = 0.08;       ///< theta of the strength test (0.08: usual for 3D problems)
  Index coarse_size = 600;    ///< a level with at most this many unknowns is solved by dense LU
  int max_levels = 12;
  Real jacobi_weight = 4.0 / 3.0;  ///< prolongator smoothing: omega = jacobi_weight / lambda_max
  int sweeps = 1;             ///< Gauss–Seidel sweeps before and after the coarse correction
};

namespace detail {

/// Strong-neighbour graph in CSR form with the entries' magnitudes.
struct StrengthGraph {
  std::vector<Index> start, nbr;
  std::vector<Real> mag;
};

inline StrengthGraph strength_graph(const RowSparseMatrix& A, const std::vector<int>& comp, Real theta) {
  const Index n = A.rows();
  const VecX d = A.diagonal();
  StrengthGraph g;
  g.start.assign(std::size_t(n) + 1, 0);
  g.nbr.reserve(std::size_t(A.nonZeros() / 3));
  g.mag.reserve(std::size_t(A.nonZeros() / 3));
  for (Index i = 0; i < n; ++i) {
    for (RowSparseMatrix::InnerIterator it(A, i); it; ++it) {
      const Index j = it.col();
      if (j == i || comp[i] != comp[j]) continue;
      const Real a = std::abs(it.value());
      if (a > 0 && a >= theta * std::sqrt(std::abs(d[i] * d[j]))) {
        g.nbr.push_back(j);
        g.mag.push_back(a);
      }
    }
    g.start[i + 1] = Index(g.nbr.size());
  }
  return g;
}

/// Aggregate of each unknown (-1: none), and the number of aggregates.
inline std::vector<Index> aggregate(const StrengthGraph& g, Index n, Index& n_agg) {
  std::vector<Index> agg(n, -1);
  n_agg = 0;
  constexpr Index isolated = -2;
  // pass 1: roots whose strong neighbours are all unaggregated
  for (Index i = 0; i < n; ++i) {
    if (agg[i] != -1) continue;
    if (g.start[i] == g.start[i + 1]) {
      agg[i] = isolated;
      continue;
    }
    bool free = true;
    for (Index k = g.start[i]; k < g.start[i + 1] && free; ++k) free = agg[g.nbr[k]] == -1;
    if (!free) continue;
    agg[i] = n_agg;
    for (Index k = g.start[i]; k < g.start[i + 1]; ++k) agg[g.nbr[k]] = n_agg;
    ++n_agg;
  }
  // pass 2: join the aggregate of the strongest aggregated neighbour (as left by pass 1)
  std::vector<Index> joined = agg;
  for (Index i = 0; i < n; ++i) {
    if (agg[i] != -1) continue;
    Real best = -1;
    for (Index k = g.start[i]; k < g.start[i + 1]; ++k)
      if (agg[g.nbr[k]] >= 0 && g.mag[k] > best) best = g.mag[k], joined[i] = agg[g.nbr[k]];
  }
  agg.swap(joined);
  // pass 3: the rest with their free strong neighbours
  for (Index i = 0; i < n; ++i) {
    if (agg[i] != -1) continue;
    agg[i] = n_agg;
    for (Index k = g.start[i]; k < g.start[i + 1]; ++k)
      if (agg[g.nbr[k]] == -1) agg[g.nbr[k]] = n_agg;
    ++n_agg;
  }
  for (Index& a : agg)
    if (a == isolated) a = -1;
  return agg;
}

}  // namespace detail

class SmoothedAggregationAmg {
 public:
  explicit SmoothedAggregationAmg(AmgOptions opt = {}) : opt_(opt) {
    ALEFSI_CHECK_ARG(opt.strength >= 0 && opt.strength < 1, "strength", "must be in [0, 1), got ", opt.strength);
    ALEFSI_CHECK_ARG(opt.coarse_size >= 1, "coarse_size", "must be positive");
    ALEFSI_CHECK_ARG(opt.max_levels >= 1, "max_levels", "must be positive");
    ALEFSI_CHECK_ARG(opt.sweeps >= 1, "sweeps", "must be positive");
  }

  /// Builds the hierarchy for A (square, nonzero diagonal). `component[i]` labels unknown i
  /// (empty: all 0, a scalar problem).
  void compute(RowSparseMatrix A, std::vector<int> component = {}) {
    ALEFSI_CHECK_ARG(A.rows() == A.cols(), "A", "must be square");
    if (component.empty()) component.assign(std::size_t(A.rows()), 0);
    ALEFSI_CHECK_ARG(Index(component.size()) == A.rows(), "component", "needs one label per unknown");
    levels_.clear();
    levels_.emplace_back();
    levels_.back().A = std::move(A);
    levels_.back().comp = std::move(component);
    for (;;) {
      Level& L = levels_.back();
      L.A.makeCompressed();
      prepare_smoother(L);
      const Index n = L.A.rows();
      if (n <= opt_.coarse_size || int(levels_.size()) == opt_.max_levels) break;
      const auto g = detail::strength_graph(L.A, L.comp, opt_.strength);
      Index n_agg = 0;
      const std::vector<Index> agg = detail::aggregate(g, n, n_agg);
      if (n_agg == 0 || n_agg >= n) break;  // no coarsening possible
      std::vector<int> coarse_comp(std::size_t(n_agg), 0);
      std::vector<Eigen::Triplet<Real, Index>> t;
      t.reserve(std::size_t(n));
      for (Index i = 0; i < n; ++i)
        if (agg[i] >= 0) t.emplace_back(i, agg[i], 1.0), coarse_comp[agg[i]] = L.comp[i];
      RowSparseMatrix Pt(n, n_agg);
      Pt.setFromTriplets(t.begin(), t.end());
      // filtered matrix scaled by the diagonal: S = D^-1 A_F, A_F = the diagonal and the strong
      // same-component entries (P2 couplings of both signs make lumping the weak ones unsafe)
      RowSparseMatrix S(n, n);
      {
        std::vector<Eigen::Triplet<Real, Index>> s;
        s.reserve(g.nbr.size() + std::size_t(n));
        for (Index i = 0; i < n; ++i) {
          s.emplace_back(i, i, 1.0);
          for (RowSparseMatrix::InnerIterator it(L.A, i); it; ++it) {
            const Index j = it.col();
            if (j == i || L.comp[j] != L.comp[i]) continue;
            if (std::binary_search(g.nbr.begin() + g.start[i], g.nbr.begin() + g.start[i + 1], j))
              s.emplace_back(i, j, it.value() * L.inv_diag[i]);
          }
        }
        S.setFromTriplets(s.begin(), s.end());
      }
      const Real lambda = spectral_radius(S);
      const Real omega = opt_.jacobi_weight / lambda;
      RowSparseMatrix P = Pt;
      P -= omega * RowSparseMatrix(S * Pt);
      P.prune(Real(0));
      RowSparseMatrix R = P.transpose();
      const RowSparseMatrix AP = L.A * P;
      RowSparseMatrix Ac = R * AP;
      L.P = std::move(P);
      L.R = std::move(R);
      Level next;
      next.A = std::move(Ac);
      next.comp = std::move(coarse_comp);
      levels_.push_back(std::move(next));
    }
    Level& C = levels_.back();
    coarse_lu_.compute(MatX(C.A));
    work_.assign(levels_.size(), {});
  }

  /// One V-cycle for A x = b from x = 0.
  VecX apply(const VecX& b) const {
    ALEFSI_ASSERT(!levels_.empty() && b.size() == levels_[0].A.rows());
    VecX x = VecX::Zero(b.size());
    cycle(0, b, x);
    return x;
  }

  int n_levels() const { return int(levels_.size()); }
  /// The finest-level matrix (the one given to `compute`).
  const RowSparseMatrix& matrix() const { return levels_.front().A; }
  Index level_size(int l) const { return levels_[std::size_t(l)].A.rows(); }
  /// Sum of nonzeros over all levels / nonzeros of the finest.
  Real operator_complexity() const {
    double s = 0;
    for (const auto& L : levels_) s += double(L.A.nonZeros());
    return levels_.empty() ? 0 : Real(s / double(levels_[0].A.nonZeros()));
  }
  /// Nonzeros held by the hierarchy (matrices and transfer operators).
  std::int64_t stored_nonzeros() const {
    std::int64_t s = 0;
    for (const auto& L : levels_) s += L.A.nonZeros() + L.P.nonZeros() + L.R.nonZeros();
    return s;
  }

 private:
  struct Level {
    RowSparseMatrix A, P, R;  // P, R: to and from the next coarser level
    VecX inv_diag;
    std::vector<int> comp;
  };
  struct Work {
    VecX r, bc, xc;
  };

  static void prepare_smoother(Level& L) {
    L.inv_diag = L.A.diagonal();
    for (Index i = 0; i < L.inv_diag.size(); ++i) {
      if (!(std::abs(L.inv_diag[i]) > 0)) throw SolverError("AMG: zero diagonal entry at unknown " + std::to_string(i));
      L.inv_diag[i] = 1 / L.inv_diag[i];
    }
  }

  // lambda_max of S (power iterations; S = D^-1 A with real, positive spectrum for SPD A)
  static Real spectral_radius(const RowSparseMatrix& S) {
    const Index n = S.rows();
    VecX v(n);
    for (Index i = 0; i < n; ++i) v[i] = 1.0 + 0.5 * std::sin(Real(7 * i + 1));  // deterministic start
    v.normalize();
    Real lambda = 1;
    for (int k = 0; k < 12; ++k) {
      const VecX w = S * v;
      const Real nw = w.norm();
      if (!(nw > 0)) break;
      lambda = nw;
      v = w / nw;
    }
    return std::max(lambda, Real(1e-12));
  }

  static void gauss_seidel(const RowSparseMatrix& A, const VecX& inv_diag, const VecX& b, VecX& x, bool forward) {
    const Index n = A.rows();
    const Real* val = A.valuePtr();
    const Index* col = A.innerIndexPtr();
    const Index* start = A.outerIndexPtr();
    auto relax = [&](Index i) {
      Real s = b[i];
      for (Index k = start[i]; k < start[i + 1]; ++k) s -= val[k] * x[col[k]];
      x[i] += s * inv_diag[i];
    };
    if (forward)
      for (Index i = 0; i < n; ++i) relax(i);
    else
      for (Index i = n - 1; i >= 0; --i) relax(i);
  }

  void cycle(std::size_t l, const VecX& b, VecX& x) const {
    const Level& L = levels_[l];
    if (l + 1 == levels_.size()) {
      x = coarse_lu_.solve(b);
      return;
    }
    Work& w = work_[l];
    for (int s = 0; s < opt_.sweeps; ++s) gauss_seidel(L.A, L.inv_diag, b, x, true);
    w.r.noalias() = b - L.A * x;
    w.bc.noalias() = L.R * w.r;
    w.xc.setZero(w.bc.size());
    cycle(l + 1, w.bc, w.xc);
    x.noalias() += L.P * w.xc;
    for (int s = 0; s < opt_.sweeps; ++s) gauss_seidel(L.A, L.inv_diag, b, x, false);
  }

  AmgOptions opt_;
  std::vector<Level> levels_;
  Eigen::PartialPivLU<MatX> coarse_lu_;
  mutable std::vector<Work> work_;
};

}  // namespace alefsi
