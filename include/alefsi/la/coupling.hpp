#pragma once
/// \file la/coupling.hpp
/// Entries of a linear system that its sparse matrix's pattern lacks: a small dense block B at a
/// few unknowns, C = E B E^T (E: the identity's columns at `index`). The flow's contact forces
/// couple two bodies' rows this way (sim/body_system.hpp): the assembled pattern is fixed per
/// mesh, and which bodies touch changes from step to step. `LinearSolve` (la/linear_solve.hpp)
/// solves (J + C) x = r when it is given one: by GMRES on J + C preconditioned by the factors of
/// J (direct solvers: I + C J^-1 differs from the identity by rank(C), so GMRES needs at most
/// rank(C) + 1 iterations), or, for `SaddlePointGmres`, with C in its operator and in its exact
/// elimination of the extra unknowns. `CoupledMatrix{J, C}` is the operator J + C for gmres.
///
///     BlockCoupling C;
///     C.index = {10, 11, 13};  C.block = MatX::Zero(3, 3);  C.block(0, 2) = 0.5;
///     VecX y = CoupledMatrix<SparseMatrix>{J, C} * x;   // J x + C x
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

struct BlockCoupling {
  std::vector<Index> index;  ///< ascending, distinct unknowns
  MatX block;                ///< index.size() x index.size()

  bool empty() const { return index.empty(); }
  Index size() const { return Index(index.size()); }
  void clear() {
    index.clear();
    block.resize(0, 0);
  }
  /// y += C x.
  template <class X, class Y>
  void add_product(const Eigen::MatrixBase<X>& x, Eigen::MatrixBase<Y>& y) const {
    const Index m = size();
    if (m == 0) return;
    VecX xs(m);
    for (Index i = 0; i < m; ++i) xs[i] = x.derived().coeff(index[std::size_t(i)]);
    const VecX ys = block * xs;
    for (Index i = 0; i < m; ++i) y.derived().coeffRef(index[std::size_t(i)]) += ys[i];
  }
};

/// The operator J + C (any J with J * VecX), for gmres (la/gmres.hpp).
template <class Matrix>
struct CoupledMatrix {
  const Matrix& matrix;
  const BlockCoupling& coupling;

  template <class X>
  VecX operator*(const Eigen::MatrixBase<X>& x) const {
    VecX y = matrix * x;
    coupling.add_product(x, y);
    return y;
  }
};

}  // namespace alefsi
