#pragma once
/// \file la/assembler.hpp
/// In-house sparse assembly: the pattern is built once per mesh topology, element matrices
/// scatter through precomputed positions, optionally on several threads.
///
/// The global matrix is an Eigen column-major `SparseMatrix` (what SparseLU factorises) whose
/// structure is computed once, by the constructor, from the cells' field DOFs and the
/// `DofConstraints` (a cell couples every unknown its field DOFs depend on). The constructor
/// stores the pattern (column starts, row indices) and the scatter positions only; a matrix
/// passed to `assemble` receives that pattern when its shape differs, and `matrix()` builds a
/// zero-valued copy on demand, so no value array is allocated or touched until needed.
///
/// Blocks. A cell's local unknowns are grouped into *blocks*: runs of local DOFs whose unknowns
/// are consecutive and whose columns have the same rows (the free components of one velocity
/// node, interleaved in the field vector; a rigid body's d(d+1)/2 unknowns). Rows of a block
/// are contiguous in every column, and the columns of a block are equally long, so one stored
/// position per (row block, column block) pair addresses the whole D x D sub-matrix: D^2 fewer
/// positions than one per DOF pair (2D P2/P1: 81 instead of 225 per cell), and the pattern
/// build works per node instead of per unknown. Assembly does no search, no sort and no
/// allocation.
///
/// Cells whose field DOFs are each free or fixed ("simple" cells: the vast majority) scatter the
/// element matrix directly, skipping fixed rows/columns. Cells with a linked DOF (a rigid body's
/// surface) first form T_e^T A_e T_e on their distinct unknowns, with the link weights current at
/// assembly time.
///
/// Threads. `set_threads(t)` (default 1) assembles on t std::threads. The simple cells are cut
/// into chunks of `chunk_size` consecutive cells, and the chunks are coloured so that two chunks
/// of one colour share no unknown: chunks of a colour run concurrently, colours one after the
/// other, each chunk in cell order; then the linked cells, in cell order, on one thread. Every
/// matrix/residual entry therefore receives its contributions in the same order whatever the
/// thread count: results are bit-identical for any t (and equal to round-off to a plain loop
/// over the cells). The kernel's `cell` is then called concurrently and must be safe to call so.
///
/// The kernel is called as `kernel.cell(c, u_e, A_e, r_e)` with the cell's local field values
/// u_e (constraint offsets included) and must fill the local Jacobian A_e and residual r_e,
/// both of the compile-time size `N` (the space's local field DOFs).
///
///     Assembler<Space::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
///     asmb.set_threads(2);                    // optional
///     asmb.assemble(kernel, field, &J, &r);   // J: asmb.matrix() shape, r: n_unknowns
#include <algorithm>
#include <array>
#include <atomic>
#include <barrier>
#include <bit>
#include <concepts>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <string>
#include <thread>
#include <utility>
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
  /// Cells per chunk of the thread schedule (fixed: the schedule, hence the summation order,
  /// must not depend on the thread count).
  static constexpr Index chunk_size = 256;
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
    build_schedule();
  }

  Index n_unknowns() const { return cons_->n_unknowns(); }
  Index n_cells() const { return static_cast<Index>(dofs_.size()); }
  const CellDofs& cell_dofs(Index c) const { return dofs_[c]; }
  /// A matrix with the assembled pattern and zero values (built on first call: the constructor
  /// stores the pattern only; not thread-safe against concurrent first calls).
  const SparseMatrix& matrix() const {
    if (!matrix_built_) {
      matrix_built_ = true;
      take_pattern(matrix_);
      std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), Real(0));
    }
    return matrix_;
  }
  SparseMatrix& matrix() { return const_cast<SparseMatrix&>(std::as_const(*this).matrix()); }
  /// Number of stored entries of the pattern.
  Index n_nonzeros() const { return outer_.empty() ? 0 : outer_.back(); }
  /// Number of cells that touch a linked DOF.
  Index n_linked_cells() const { return n_general_; }
  /// Number of colours of the chunk schedule (see the file comment).
  Index n_colours() const { return Index(colour_start_.size()) - 1; }
  /// Number of stored scatter positions (one per block pair per cell).
  std::size_t n_positions() const { return n_pos_; }

  /// Threads used by `assemble` (>= 1; default 1). Results do not depend on it.
  void set_threads(int t) {
    ALEFSI_CHECK_ARG(t >= 1, "threads", "must be at least 1, got ", t);
    threads_ = t;
  }
  int threads() const { return threads_; }

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
    if (J && (J->rows() != n_unknowns() || J->nonZeros() != n_nonzeros())) take_pattern(*J);  // values: zeroed below
    if (r) r->resize(n_unknowns());
    Real* val = J ? J->valuePtr() : nullptr;
    const std::size_t nnz = J ? std::size_t(J->nonZeros()) : 0;
    const int nt = int(std::min<Index>(threads_, std::max<Index>(1, Index(chunk_cells_.size()))));
    // worker t: zero its slice of J and r, then the colours; the linked cells on thread 0
    auto work = [&](int t, auto&& sync) {
      if (val) std::fill(val + nnz * t / nt, val + nnz * (t + 1) / nt, Real(0));
      if (r) {
        const Index nu = n_unknowns();
        std::fill(r->data() + std::size_t(nu) * t / nt, r->data() + std::size_t(nu) * (t + 1) / nt, Real(0));
      }
      sync();
      LocalMat A;
      LocalVec re;
      for (Index col = 0; col < n_colours(); ++col) {
        const Index b = colour_start_[col], e = colour_start_[col + 1];
        // chunks of one colour, dealt round-robin (static: no shared counter to contend on)
        for (Index k = b + t; k < e; k += nt) {
          const Index ch = chunk_order_[k];
          for (Index i = chunk_start_[ch]; i < chunk_start_[ch + 1]; ++i) {
            const Index c = chunk_cells_[i];
            kernel.cell(c, gather(c, field), A, re);
            scatter(c, A, re, val, r);
          }
        }
        sync();
      }
      if (t == 0)
        for (Index c : linked_cells_) {
          kernel.cell(c, gather(c, field), A, re);
          scatter(c, A, re, val, r);
        }
    };
    if (nt == 1) {
      work(0, [] {});
      return;
    }
    std::barrier sync_point(nt);
    std::exception_ptr error;
    std::mutex error_mutex;
    std::atomic<bool> failed{false};
    // a throwing kernel must not leave the other threads waiting at a barrier: the failing
    // thread records the exception and keeps arriving at the barriers without working
    auto guarded = [&](int t) {
      bool ok = true;
      auto sync = [&] {
        sync_point.arrive_and_wait();
        if (failed.load()) throw Aborted{};
      };
      try {
        work(t, sync);
      } catch (const Aborted&) {
        ok = false;
      } catch (...) {
        {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
        }
        failed.store(true);
        ok = false;
      }
      if (!ok) {  // finish this thread's share of barrier phases: 1 (zeroing) + n_colours
        // phases already passed are not known here; arrive_and_drop removes this thread from
        // every later phase instead
        sync_point.arrive_and_drop();
      }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < nt; ++t) pool.emplace_back(guarded, t);
    guarded(0);
    for (auto& th : pool) th.join();
    if (error) std::rethrow_exception(error);
  }

  /// Gives `M` this assembler's pattern (n_unknowns square, compressed); its values are left
  /// uninitialised.
  void take_pattern(SparseMatrix& M) const {
    const Index n = n_unknowns();
    M.resize(n, n);
    M.resizeNonZeros(n_nonzeros());
    std::copy(outer_.begin(), outer_.end(), M.outerIndexPtr());
    std::copy(inner_.get(), inner_.get() + n_nonzeros(), M.innerIndexPtr());
  }

  /// Scatters one element's Jacobian/residual (exposed for benchmarks and custom loops).
  void scatter(Index c, const LocalMat& A, const LocalVec& re, Real* val, VecX* r) const {
    const Index* red = &red_[red_start_[c]];
    if (!general_[c]) {
      if (val) scatter_blocks(c, A.data(), N, val);
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
    if (val) scatter_blocks(c, Ar.data(), m, val);
    if (r)
      for (Index i = 0; i < m; ++i) (*r)[red[i]] += rr[i];
  }

 private:
  struct Aborted {};
  /// A run of local unknowns [start, start + size) of one cell; `stride`: the length of each
  /// of its columns in the CSR/CSC storage (consecutive columns of a block are that far apart).
  struct Block {
    std::int16_t start, size;
    Index stride;
  };

  // Adds the column-major local matrix A (leading dimension lda, the cell's local unknown
  // order) through the block positions. Block sizes 1..3 (scalars, 2D and 3D nodes) take
  // unrolled paths; larger blocks (a 3D body's 6 unknowns) the generic loop.
  void scatter_blocks(Index c, const Real* A, Index lda, Real* val) const {
    const Block* blk = &blk_[blk_start_[c]];
    const Index nb = blk_start_[c + 1] - blk_start_[c];
    const Index* pos = &pos_[pos_start_[c]];
    for (Index J = 0; J < nb; ++J, pos += nb) {
      const Block bj = blk[J];
      const Real* aj = A + std::ptrdiff_t(bj.start) * lda;
      switch (bj.size) {
        case 1: scatter_column_block<1>(blk, nb, pos, aj, lda, bj.stride, val); break;
        case 2: scatter_column_block<2>(blk, nb, pos, aj, lda, bj.stride, val); break;
        case 3: scatter_column_block<3>(blk, nb, pos, aj, lda, bj.stride, val); break;
        default:
          for (Index I = 0; I < nb; ++I) {
            const Real* a = aj + blk[I].start;
            Real* v = val + pos[I];
            for (int t = 0; t < bj.size; ++t, a += lda, v += bj.stride)
              for (int s = 0; s < blk[I].size; ++s) v[s] += a[s];
          }
      }
    }
  }
  template <int SJ>
  static void scatter_column_block(const Block* blk, Index nb, const Index* pos, const Real* aj, Index lda,
                                   Index stride, Real* val) {
    for (Index I = 0; I < nb; ++I) {
      const Real* a = aj + blk[I].start;
      Real* v = val + pos[I];
      switch (blk[I].size) {
        case 1: add_block<1, SJ>(a, lda, v, stride); break;
        case 2: add_block<2, SJ>(a, lda, v, stride); break;
        case 3: add_block<3, SJ>(a, lda, v, stride); break;
        default:
          for (int t = 0; t < SJ; ++t)
            for (int s = 0; s < blk[I].size; ++s) v[t * stride + s] += a[t * lda + s];
      }
    }
  }
  template <int SI, int SJ>
  static void add_block(const Real* a, Index lda, Real* v, Index stride) {
    for (int t = 0; t < SJ; ++t)
      for (int s = 0; s < SI; ++s) v[t * stride + s] += a[t * lda + s];
  }

  // Per cell: its reduced unknown list. Simple cells: N entries (unknown or -1 for fixed).
  // Linked cells: the distinct unknowns, plus for each local DOF entry its reduced index.
  void build_local_unknowns() {
    const Index nc = n_cells();
    general_.assign(nc, 0);
    red_start_.assign(nc + 1, 0);
    ent_start_.assign(nc + 1, 0);
    red_.reserve(std::size_t(nc) * N);
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

  // Pattern build, one column *group* at a time: a group is a run of consecutive unknowns
  // touched by exactly the same cells (the free components of one node), so its columns have
  // the same rows. The rows of a group (union of its cells' unknowns, found with a marker
  // array, then sorted) are computed once, and each cell touching the group gets the position
  // of each of its (row block, column block) pairs whose column block starts in the group.
  void build_pattern() {
    const Index n = n_unknowns(), nc = n_cells();
    // unknown -> cells touching it (in cell order)
    std::vector<Index> ustart(n + 1, 0);
    for (Index k = 0; k < red_start_[nc]; ++k)
      if (red_[k] >= 0) ++ustart[red_[k] + 1];
    std::partial_sum(ustart.begin(), ustart.end(), ustart.begin());
    std::vector<Index> ucell(ustart[n]);
    {
      std::vector<Index> fill(ustart.begin(), ustart.end() - 1);
      for (Index c = 0; c < nc; ++c)
        for (Index k = red_start_[c]; k < red_start_[c + 1]; ++k)
          if (red_[k] >= 0) ucell[fill[red_[k]]++] = c;
    }
    for (Index u = 0; u < n; ++u)
      if (ustart[u + 1] == ustart[u]) throw SolverError("unknown " + std::to_string(u) + " is coupled to nothing");
    // same_prev[u]: u continues the group of u - 1
    std::vector<char> same_prev(n, 0);
    for (Index u = 1; u < n; ++u)
      same_prev[u] = ustart[u + 1] - ustart[u] == ustart[u] - ustart[u - 1] &&
                     std::equal(ucell.begin() + ustart[u], ucell.begin() + ustart[u + 1], ucell.begin() + ustart[u - 1]);
    // blocks of each cell
    blk_start_.assign(nc + 1, 0);
    pos_start_.assign(nc + 1, 0);
    blk_.clear();
    blk_.reserve(std::size_t(nc) * N);
    for (Index c = 0; c < nc; ++c) {
      const Index* red = &red_[red_start_[c]];
      const Index m = red_start_[c + 1] - red_start_[c];
      for (Index k = 0; k < m;) {
        if (red[k] < 0) {
          ++k;
          continue;
        }
        Index e = k + 1;
        while (e < m && red[e] == red[e - 1] + 1 && same_prev[red[e]]) ++e;
        blk_.push_back(Block{std::int16_t(k), std::int16_t(e - k), 0});
        k = e;
      }
      blk_start_[c + 1] = Index(blk_.size());
      const std::int64_t nb = blk_start_[c + 1] - blk_start_[c];
      pos_start_[c + 1] = pos_start_[c] + nb * nb;
    }
    // every (row block, column block) pair of every cell is written below exactly once
    pos_.reset(new Index[std::size_t(pos_start_[nc])]);
    n_pos_ = std::size_t(pos_start_[nc]);
    // groups: first unknown and size of the group of each unknown
    std::vector<Index> gfirst(n);
    for (Index u = 0; u < n; ++u) gfirst[u] = same_prev[u] ? gfirst[u - 1] : u;
    std::vector<Index> gsize(n, 0);
    for (Index u = 0; u < n; ++u) ++gsize[gfirst[u]];
    // per block: the group it lies in (first unknown) and its offset in that group
    std::vector<Index> bgrp(blk_.size()), boff(blk_.size());
    for (Index c = 0; c < nc; ++c) {
      const Index* red = &red_[red_start_[c]];
      for (Index b = blk_start_[c]; b < blk_start_[c + 1]; ++b) {
        const Index u = red[blk_[b].start];
        bgrp[b] = gfirst[u];
        boff[b] = u - gfirst[u];
      }
    }
    outer_.assign(std::size_t(n) + 1, 0);
    Index* outer = outer_.data();
    // Per group (columns u0 .. u0 + g - 1, all with the same rows): the rows are whole groups
    // (a cell that touches one unknown of a group touches all of them), the distinct groups of
    // its cells' blocks, found with a stamp array (branch-free), sorted (a few tens, insertion
    // sort), expanded to unknowns. rank[v] is then the offset of group v's first row in these
    // columns, and each cell touching the group gets the positions of its block pairs whose
    // column block lies in it: column start + rank of the row block's group + the blocks'
    // offsets in their groups. The columns are written in order, each exactly once.
    std::int64_t bound = 0;  // sum over cells of (free unknowns)^2 >= nnz (~1.7x for P2/P1)
    for (Index c = 0; c < nc; ++c) {
      std::int64_t m = 0;
      for (Index b = blk_start_[c]; b < blk_start_[c + 1]; ++b) m += blk_[b].size;
      bound += m * m;
    }
    bound = std::min<std::int64_t>(bound, std::int64_t(n) * n);
    if (bound > std::numeric_limits<Index>::max())
      throw SolverError("Assembler: the matrix pattern may exceed 2^31 nonzeros (Index is 32 bit)");
    // allocated for the bound: the pages past the final size are never touched, so they cost
    // address space, not memory
    inner_.reset(new Index[std::size_t(bound) + 4]);  // + 4: the branch-free expansion below
    Index* inner = inner_.get();
    // per group: its blocks (index into blk_), in cell order
    std::vector<Index> gbstart(n + 1, 0), gblk(blk_.size());
    for (std::size_t b = 0; b < blk_.size(); ++b) ++gbstart[bgrp[b] + 1];
    std::partial_sum(gbstart.begin(), gbstart.end(), gbstart.begin());
    {
      std::vector<Index> at(gbstart.begin(), gbstart.end() - 1);
      for (std::size_t b = 0; b < blk_.size(); ++b) gblk[at[bgrp[b]]++] = Index(b);
    }
    std::vector<Index> bcell(blk_.size());  // cell of each block
    for (Index c = 0; c < nc; ++c) std::fill(bcell.begin() + blk_start_[c], bcell.begin() + blk_start_[c + 1], c);
    Index max_gsize = 1;
    for (Index u = 0; u < n; ++u) max_gsize = std::max(max_gsize, gsize[u]);
    std::vector<Index> stamp(n, -1), rank(n, 0), groups;
    for (Index u0 = 0; u0 < n;) {
      const Index g = gsize[u0];
      Index m = 0;
      for (Index k = gbstart[u0]; k < gbstart[u0 + 1]; ++k) {
        const Index c = bcell[gblk[k]];
        const Index b0 = blk_start_[c], b1 = blk_start_[c + 1];
        if (std::size_t(m + b1 - b0) > groups.size()) groups.resize(2 * std::size_t(m + b1 - b0));
        for (Index b = b0; b < b1; ++b) {
          const Index v = bgrp[b];
          groups[m] = v;
          m += stamp[v] != u0;
          stamp[v] = u0;
        }
      }
      sort_small(groups.data(), m);
      Index* col = inner + outer[u0];
      Index len = 0;
      if (max_gsize <= 4) {  // branch-free: 4 rows per group written, the excess overwritten next
        for (Index k = 0; k < m; ++k) {
          const Index v = groups[k];
          rank[v] = len;
          for (Index t = 0; t < 4; ++t) col[len + t] = v + t;
          len += gsize[v];
        }
      } else {
        for (Index k = 0; k < m; ++k) {
          const Index v = groups[k];
          rank[v] = len;
          for (Index t = 0; t < gsize[v]; ++t) col[len++] = v + t;
        }
      }
      for (Index t = 0; t < g; ++t) outer[u0 + t + 1] = outer[u0 + t] + len;
      for (Index t = 1; t < g; ++t) std::copy(col, col + len, inner + outer[u0 + t]);
      for (Index k = gbstart[u0]; k < gbstart[u0 + 1]; ++k) {
        const Index bj = gblk[k], c = bcell[bj];
        const Index b0 = blk_start_[c], nb = blk_start_[c + 1] - b0;
        blk_[bj].stride = len;
        const Index cj = outer[u0] + boff[bj] * len;
        Index* pj = &pos_[pos_start_[c] + (bj - b0) * nb];
        for (Index I = 0; I < nb; ++I) pj[I] = cj + rank[bgrp[b0 + I]] + boff[b0 + I];
      }
      u0 += g;
    }
  }

  // Sorts x[0 .. m) ascending: insertion sort for the few tens of a column group, std::sort
  // beyond.
  static void sort_small(Index* x, Index m) {
    if (m > 48) {
      std::sort(x, x + m);
      return;
    }
    for (Index i = 1; i < m; ++i) {
      const Index v = x[i];
      Index j = i;
      for (; j > 0 && x[j - 1] > v; --j) x[j] = x[j - 1];
      x[j] = v;
    }
  }

  // Thread schedule: chunks of consecutive simple cells, greedily coloured (a chunk takes the
  // lowest colour none of its unknowns has been given yet; 64 colours per round, chunks that
  // find none start a new round of 64).
  void build_schedule() {
    const Index nc = n_cells(), n = n_unknowns();
    chunk_cells_.clear();
    chunk_start_.assign(1, 0);
    linked_cells_.clear();
    for (Index c = 0; c < nc; ++c) {
      if (general_[c]) {
        linked_cells_.push_back(c);
        continue;
      }
      chunk_cells_.push_back(c);
      if (Index(chunk_cells_.size()) - chunk_start_.back() == chunk_size) chunk_start_.push_back(Index(chunk_cells_.size()));
    }
    if (chunk_start_.back() != Index(chunk_cells_.size())) chunk_start_.push_back(Index(chunk_cells_.size()));
    const Index nch = Index(chunk_start_.size()) - 1;
    std::vector<Index> colour(nch, -1);
    Index base = 0, left = nch;
    std::vector<std::uint64_t> used;
    while (left > 0) {  // one round of up to 64 colours over the chunks still uncoloured
      used.assign(n, 0);
      for (Index ch = 0; ch < nch; ++ch) {
        if (colour[ch] >= 0) continue;
        std::uint64_t busy = 0;
        for (Index i = chunk_start_[ch]; i < chunk_start_[ch + 1]; ++i) {
          const Index c = chunk_cells_[i];
          for (Index k = red_start_[c]; k < red_start_[c + 1]; ++k)
            if (red_[k] >= 0) busy |= used[red_[k]];
        }
        if (busy == ~std::uint64_t(0)) continue;
        const int bit = std::countr_one(busy);
        colour[ch] = base + bit;
        --left;
        for (Index i = chunk_start_[ch]; i < chunk_start_[ch + 1]; ++i) {
          const Index c = chunk_cells_[i];
          for (Index k = red_start_[c]; k < red_start_[c + 1]; ++k)
            if (red_[k] >= 0) used[red_[k]] |= std::uint64_t(1) << bit;
        }
      }
      base += 64;
    }
    // chunks sorted by colour (stable: chunk order within a colour), empty colours dropped
    const Index ncol = nch ? *std::max_element(colour.begin(), colour.end()) + 1 : 0;
    std::vector<Index> count(ncol + 1, 0);
    for (Index ch = 0; ch < nch; ++ch) ++count[colour[ch] + 1];
    std::partial_sum(count.begin(), count.end(), count.begin());
    chunk_order_.assign(nch, 0);
    {
      std::vector<Index> fill(count.begin(), count.end() - 1);
      for (Index ch = 0; ch < nch; ++ch) chunk_order_[fill[colour[ch]]++] = ch;
    }
    colour_start_.assign(1, 0);
    for (Index k = 1; k <= ncol; ++k)
      if (count[k] > count[k - 1]) colour_start_.push_back(count[k]);
  }

  const DofConstraints* cons_;
  std::vector<CellDofs> dofs_;
  std::vector<char> general_;
  Index n_general_ = 0;
  std::vector<Index> red_start_, red_, ent_start_, ent_;
  std::vector<Index> blk_start_;
  std::vector<Block> blk_;
  std::unique_ptr<Index[]> pos_;
  std::size_t n_pos_ = 0;
  std::vector<std::int64_t> pos_start_;  // can exceed 2^31 for big 3D P2 meshes
  std::vector<Index> chunk_cells_, chunk_start_, chunk_order_, colour_start_, linked_cells_;
  int threads_ = 1;
  std::vector<Index> outer_;           // CSC pattern: column starts
  std::unique_ptr<Index[]> inner_;     // row indices (allocated for an upper bound, outer_[n] used)
  mutable SparseMatrix matrix_;        // matrix(): built on demand
  mutable bool matrix_built_ = false;
};

}  // namespace alefsi
