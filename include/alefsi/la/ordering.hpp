#pragma once
/// \file la/ordering.hpp
/// Fill-reducing orderings for Eigen's SparseLU on saddle-point matrices.
///
/// Why Eigen's `SparseLU<A, AMDOrdering>` is catastrophic (Eigen 3.4): `AMDOrdering` returns
/// its permutation as "position k holds old index perm[k]" (CSparse's postorder, the
/// convention `SimplicialCholesky` expects: it calls the result P^-1), while
/// `SparseLU::analyzePattern` reads the ordering as "old column i goes to position perm[i]"
/// (the convention `COLAMDOrdering` follows). SparseLU therefore applies the *inverse* of the
/// AMD permutation, a scrambled order: on the 2D P2/P1 Stokes matrix, N = 32, that is 53 M
/// entries in L+U against 1.2 M with the permutation the right way round.
///
/// A symmetric ordering also needs SparseLU to pivot on the diagonal (its "symmetric mode"
/// with a small diagonal pivot threshold): with partial pivoting the row order is again
/// unrelated to the column order. Then a zero diagonal entry (the pressure block of a
/// Taylor–Hood matrix) is a problem only when it is reached before any of its neighbours has
/// been eliminated; `SaddlePointAmdOrdering` moves each such unknown to just after its first
/// eliminated neighbour with a nonzero diagonal, after which its pivot is -b^2/a != 0.
///
///     Eigen::SparseLU<SparseMatrix, SaddlePointAmdOrdering<Index>> lu;
///     lu.isSymmetric(true);  lu.setPivotThreshold(1e-6);
///     lu.compute(A);
/// (`SparseLu<>` in la/solvers.hpp does exactly this.)
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"

namespace alefsi {

namespace detail {

/// Elimination order of AMD on the pattern of A + A^T: order[k] = the unknown eliminated k-th.
template <class StorageIndex, class MatrixType>
std::vector<StorageIndex> amd_elimination_order(const MatrixType& A) {
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, StorageIndex> p;
  Eigen::AMDOrdering<StorageIndex>{}(A, p);  // p.indices()[k] = old index at position k
  return std::vector<StorageIndex>(p.indices().data(), p.indices().data() + p.size());
}

/// Writes an elimination order into SparseLU's convention: perm.indices()[old] = new.
template <class StorageIndex>
void order_to_sparse_lu_permutation(const std::vector<StorageIndex>& order,
                                    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, StorageIndex>& perm) {
  perm.resize(StorageIndex(order.size()));
  for (std::size_t k = 0; k < order.size(); ++k) perm.indices()[order[k]] = StorageIndex(k);
}

}  // namespace detail

/// Plain AMD on A + A^T for SparseLU, in SparseLU's permutation convention (see the file
/// comment: `Eigen::AMDOrdering` used directly in SparseLU applies the inverse).
template <class StorageIndex>
struct SymmetricAmdOrdering {
  using PermutationType = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, StorageIndex>;
  template <class MatrixType>
  void operator()(const MatrixType& A, PermutationType& perm) const {
    detail::order_to_sparse_lu_permutation(detail::amd_elimination_order<StorageIndex>(A), perm);
  }
};

/// AMD on A + A^T, then every unknown with a zero (or absent) diagonal entry is delayed until
/// just after the first of its neighbours (a nonzero A(i,j) or A(j,i)) that has a nonzero
/// diagonal. Unknowns with no such neighbour go last. For a matrix with a nonzero diagonal
/// this is plain AMD. Needs the matrix values, not only its pattern: pass the assembled
/// matrix to `analyzePattern`. Cost: AMD plus O(nnz).
template <class StorageIndex>
struct SaddlePointAmdOrdering {
  using PermutationType = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, StorageIndex>;

  template <class MatrixType>
  void operator()(const MatrixType& A, PermutationType& perm) const {
    detail::order_to_sparse_lu_permutation(order(A), perm);
  }

  /// The elimination order: result[k] = the unknown eliminated k-th.
  template <class MatrixType>
  static std::vector<StorageIndex> order(const MatrixType& A) {
    const std::vector<StorageIndex> amd = detail::amd_elimination_order<StorageIndex>(A);
    const std::size_t n = std::size_t(A.cols());
    // zero-diagonal ("weak") unknowns and the symmetric adjacency of the numerical nonzeros
    std::vector<char> weak(n, 1);
    std::vector<StorageIndex> start(n + 1, 0);
    for (StorageIndex j = 0; j < StorageIndex(n); ++j)
      for (typename MatrixType::InnerIterator it(A, j); it; ++it) {
        if (it.value() == 0) continue;
        if (it.row() == j) {
          weak[j] = 0;
        } else {
          ++start[it.row() + 1];
          ++start[j + 1];
        }
      }
    bool any_weak = false;
    for (char w : weak) any_weak |= w != 0;
    if (!any_weak) return amd;
    for (std::size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    std::vector<StorageIndex> adj(start[n]), fill(start.begin(), start.end() - 1);
    for (StorageIndex j = 0; j < StorageIndex(n); ++j)
      for (typename MatrixType::InnerIterator it(A, j); it; ++it)
        if (it.value() != 0 && it.row() != j) {
          adj[fill[it.row()]++] = j;
          adj[fill[j]++] = StorageIndex(it.row());
        }
    // walk the AMD order; a weak unknown is placed when reached if a strong neighbour is
    // already placed ("ready"), else as soon as one is
    std::vector<char> placed(n, 0), ready(n, 0), pending(n, 0);
    std::vector<StorageIndex> out;
    out.reserve(n);
    for (StorageIndex v : amd) {
      if (weak[v] && !ready[v]) {
        pending[v] = 1;
        continue;
      }
      placed[v] = 1;
      out.push_back(v);
      if (weak[v]) continue;
      for (StorageIndex k = start[v]; k < start[v + 1]; ++k) {
        const StorageIndex w = adj[k];
        if (!weak[w] || placed[w]) continue;
        if (pending[w]) {
          pending[w] = 0;
          placed[w] = 1;
          out.push_back(w);
        } else {
          ready[w] = 1;
        }
      }
    }
    for (StorageIndex v : amd)
      if (!placed[v]) out.push_back(v);
    return out;
  }
};

}  // namespace alefsi
