#pragma once
/// \file la/assembler.hpp
/// In-house sparse assembly: the pattern is built once per mesh topology, element matrices
/// scatter through precomputed positions.
///
/// The global matrix is an Eigen column-major `SparseMatrix` (what SparseLU factorises) whose
/// structure is filled once, by the constructor, from the cells' field DOFs and the
/// `DofConstraints` (a cell couples every unknown its field DOFs depend on). For every cell the
/// constructor stores, for each pair of local unknowns, the offset of that entry in the value
/// array, so assembly does no search, no sorting and no allocation.
///
/// Cells whose field DOFs are each free or fixed ("simple" cells: the vast majority) scatter the
/// element matrix directly, skipping fixed rows/columns. Cells with a linked DOF (a rigid body's
/// surface) first form T_e^T A_e T_e on their distinct unknowns, with the link weights current at
/// assembly time.
///
/// The kernel is called as `kernel.cell(c, u_e, A_e, r_e)` with the cell's local field values
/// u_e (constraint offsets included) and must fill the local Jacobian A_e and residual r_e,
/// both of the compile-time size `N` (the space's local field DOFs).
///
///     Assembler<Space::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
///     asmb.assemble(kernel, field, &J, &r);   // J: asmb.matrix() shape, r: n_unknowns
#include <algorithm>
#include <array>
#include <concepts>
#include <cstdint>
#include <numeric>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/fem/constraints.hpp"

namespace alefsi {

using SparseMatrix = Eigen::SparseMatrix<Real, Eigen::ColMajor, Index>;

/// A cell kernel of N local field DOFs: fills the element Jacobian and residual.
template <class K, int N>
concept CellKernel = requires(const K& k, Index c, const Eigen::Matrix<Real, N, 1>& u,
                              Eigen::Matrix<Real, N, N>& A, Eigen::Matrix<Real, N, 1>& r) {
  k.cell(c, u, A, r);
};

template <int N>
class Assembler {
 public:
  static constexpr int n_local = N;
  using LocalVec = Eigen::Matrix<Real, N, 1>;
  using LocalMat = Eigen::Matrix<Real, N, N>;
  using CellDofs = std::array<Index, N>;

  /// `cell_dofs(c)` returns cell c's N field DOFs; `cons` must be finalized.
  template <class CellDofsFn>
  Assembler(Index n_cells, CellDofsFn&& cell_dofs, const DofConstraints& cons) : cons_(&cons) {
    if (!cons.finalized()) throw Error("Assembler: DofConstraints must be finalized first");
    dofs_.resize(n_cells);
    for (Index c = 0; c < n_cells; ++c) dofs_[c] = cell_dofs(c);
    build_local_unknowns();
    build_pattern();
  }

  Index n_unknowns() const { return cons_->n_unknowns(); }
  Index n_cells() const { return static_cast<Index>(dofs_.size()); }
  const CellDofs& cell_dofs(Index c) const { return dofs_[c]; }
  /// The matrix with the assembled pattern (values as left by the last assembly).
  const SparseMatrix& matrix() const { return matrix_; }
  SparseMatrix& matrix() { return matrix_; }
  /// Number of cells that touch a linked DOF.
  Index n_linked_cells() const { return n_general_; }

  /// Gathers cell c's local field values.
  LocalVec gather(Index c, const VecX& field) const {
    LocalVec u;
    for (int i = 0; i < N; ++i) u[i] = field[dofs_[c][i]];
    return u;
  }

  /// Assembles the Jacobian into `J` (if non-null; it takes this assembler's pattern) and the
  /// residual of the unknowns into `r` (if non-null), evaluating the kernel at `field`.
  template <class Kernel>
    requires CellKernel<Kernel, N>
  void assemble(const Kernel& kernel, const VecX& field, SparseMatrix* J, VecX* r) const {
    ALEFSI_CHECK_ARG(field.size() == cons_->n_field(), "field", "has ", field.size(), " entries, expected ",
                     cons_->n_field());
    if (J) {
      if (J->rows() != matrix_.rows() || J->nonZeros() != matrix_.nonZeros()) *J = matrix_;
      std::fill(J->valuePtr(), J->valuePtr() + J->nonZeros(), Real(0));
    }
    if (r) r->setZero(n_unknowns());
    Real* val = J ? J->valuePtr() : nullptr;
    LocalMat A;
    LocalVec re;
    for (Index c = 0; c < n_cells(); ++c) {
      const LocalVec u = gather(c, field);
      kernel.cell(c, u, A, re);
      scatter(c, A, re, val, r);
    }
  }

  /// Scatters one element's Jacobian/residual (exposed for benchmarks and custom loops).
  void scatter(Index c, const LocalMat& A, const LocalVec& re, Real* val, VecX* r) const {
    const Index* red = &red_[red_start_[c]];
    const Index* pos = &pos_[pos_start_[c]];
    if (!general_[c]) {
      if (val)
        for (int i = 0; i < N; ++i) {
          if (red[i] < 0) continue;
          for (int j = 0; j < N; ++j) {
            const Index p = pos[i * N + j];
            if (p >= 0) val[p] += A(i, j);
          }
        }
      if (r)
        for (int i = 0; i < N; ++i)
          if (red[i] >= 0) (*r)[red[i]] += re[i];
      return;
    }
    // linked cell: Ar = T_e^T A T_e on the cell's m distinct unknowns
    const Index m = red_start_[c + 1] - red_start_[c];
    const Index* ent = &ent_[ent_start_[c]];  // per local DOF entry: reduced index
    MatX Ar = MatX::Zero(m, m);
    VecX rr = VecX::Zero(m);
    std::array<Index, N + 1> es;
    es[0] = 0;
    for (int i = 0; i < N; ++i) es[i + 1] = es[i] + Index(cons_->indices(dofs_[c][i]).size());
    for (int i = 0; i < N; ++i) {
      const auto wi = cons_->weights(dofs_[c][i]);
      for (Index a = 0; a < es[i + 1] - es[i]; ++a) {
        const Index ri = ent[es[i] + a];
        rr[ri] += wi[a] * re[i];
        if (!val) continue;
        for (int j = 0; j < N; ++j) {
          const auto wj = cons_->weights(dofs_[c][j]);
          for (Index b = 0; b < es[j + 1] - es[j]; ++b) Ar(ri, ent[es[j] + b]) += wi[a] * wj[b] * A(i, j);
        }
      }
    }
    if (val)
      for (Index i = 0; i < m; ++i)
        for (Index j = 0; j < m; ++j) val[pos[i * m + j]] += Ar(i, j);
    if (r)
      for (Index i = 0; i < m; ++i) (*r)[red[i]] += rr[i];
  }

 private:
  // Per cell: its reduced unknown list. Simple cells: N entries (unknown or -1 for fixed).
  // Linked cells: the distinct unknowns, plus for each local DOF entry its reduced index.
  void build_local_unknowns() {
    const Index nc = n_cells();
    general_.assign(nc, 0);
    red_start_.assign(nc + 1, 0);
    ent_start_.assign(nc + 1, 0);
    for (Index c = 0; c < nc; ++c) {
      bool gen = false;
      for (Index f : dofs_[c]) gen |= cons_->kind(f) == DofConstraints::Kind::linked;
      general_[c] = gen;
      if (!gen) {
        for (Index f : dofs_[c]) red_.push_back(cons_->kind(f) == DofConstraints::Kind::free ? cons_->indices(f)[0] : -1);
      } else {
        ++n_general_;
        std::vector<Index> uniq;
        for (Index f : dofs_[c])
          for (Index u : cons_->indices(f)) uniq.push_back(u);
        std::sort(uniq.begin(), uniq.end());
        uniq.erase(std::unique(uniq.begin(), uniq.end()), uniq.end());
        red_.insert(red_.end(), uniq.begin(), uniq.end());
        for (Index f : dofs_[c])
          for (Index u : cons_->indices(f))
            ent_.push_back(Index(std::lower_bound(uniq.begin(), uniq.end(), u) - uniq.begin()));
      }
      red_start_[c + 1] = static_cast<Index>(red_.size());
      ent_start_[c + 1] = static_cast<Index>(ent_.size());
    }
  }

  // Column-by-column pattern build: for unknown u, the rows are the unknowns of the cells that
  // touch u. A marker array makes it linear in the number of (cell, local pair) couplings.
  void build_pattern() {
    const Index n = n_unknowns(), nc = n_cells();
    // unknown -> (cell, reduced local index) lists
    std::vector<Index> ustart(n + 1, 0);
    for (Index c = 0; c < nc; ++c)
      for (Index k = red_start_[c]; k < red_start_[c + 1]; ++k)
        if (red_[k] >= 0) ++ustart[red_[k] + 1];
    std::partial_sum(ustart.begin(), ustart.end(), ustart.begin());
    std::vector<Index> ucell(ustart[n]), uloc(ustart[n]), fill(ustart.begin(), ustart.end() - 1);
    for (Index c = 0; c < nc; ++c)
      for (Index k = red_start_[c]; k < red_start_[c + 1]; ++k)
        if (red_[k] >= 0) {
          ucell[fill[red_[k]]] = c;
          uloc[fill[red_[k]]++] = k - red_start_[c];
        }
    pos_start_.assign(nc + 1, 0);
    for (Index c = 0; c < nc; ++c) {
      const std::size_t m = std::size_t(red_start_[c + 1] - red_start_[c]);
      pos_start_[c + 1] = pos_start_[c] + std::int64_t(m * m);
    }
    pos_.assign(pos_start_[nc], -1);
    std::vector<Index> outer(n + 1, 0), inner, where(n, -1), rows;
    inner.reserve(std::size_t(ustart[n]) * 8);
    for (Index u = 0; u < n; ++u) {
      rows.clear();
      for (Index k = ustart[u]; k < ustart[u + 1]; ++k) {
        const Index c = ucell[k];
        for (Index q = red_start_[c]; q < red_start_[c + 1]; ++q) {
          const Index v = red_[q];
          if (v >= 0 && where[v] != -2 - u) {
            where[v] = -2 - u;
            rows.push_back(v);
          }
        }
      }
      if (rows.empty()) throw SolverError("unknown " + std::to_string(u) + " is coupled to nothing");
      std::sort(rows.begin(), rows.end());
      const Index base = static_cast<Index>(inner.size());
      for (std::size_t i = 0; i < rows.size(); ++i) where[rows[i]] = base + Index(i);
      inner.insert(inner.end(), rows.begin(), rows.end());
      outer[u + 1] = static_cast<Index>(inner.size());
      for (Index k = ustart[u]; k < ustart[u + 1]; ++k) {
        const Index c = ucell[k], jc = uloc[k];
        const Index m = red_start_[c + 1] - red_start_[c];
        for (Index i = 0; i < m; ++i) {
          const Index v = red_[red_start_[c] + i];
          if (v >= 0) pos_[pos_start_[c] + i * m + jc] = where[v];
        }
      }
      for (Index v : rows) where[v] = -1;
    }
    matrix_.resize(n, n);
    matrix_.resizeNonZeros(static_cast<Index>(inner.size()));
    std::copy(outer.begin(), outer.end(), matrix_.outerIndexPtr());
    std::copy(inner.begin(), inner.end(), matrix_.innerIndexPtr());
    std::fill(matrix_.valuePtr(), matrix_.valuePtr() + inner.size(), Real(0));
  }

  const DofConstraints* cons_;
  std::vector<CellDofs> dofs_;
  std::vector<char> general_;
  Index n_general_ = 0;
  std::vector<Index> red_start_, red_, ent_start_, ent_, pos_;
  std::vector<std::int64_t> pos_start_;  // can exceed 2^31 for big 3D P2 meshes
  SparseMatrix matrix_;
};

}  // namespace alefsi
