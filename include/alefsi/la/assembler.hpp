#pragma once
/// \file la/assembler.hpp
/// In-house sparse assembly: the pattern is built once per mesh topology, element matrices
/// scatter through precomputed positions, optionally on several threads.
///
/// The global matrix is an Eigen column-major `SparseMatrix` (what SparseLU factorises) whose
/// structure is computed once, by the constructor, from the cells' field DOFs and the
/// `DofConstraints` (a cell couples every unknown its field DOFs depend on). The constructor
/// stores the pattern (column starts, and the rows by node groups: see below) and the scatter
/// positions only; a matrix passed to `assemble` receives that pattern (expanded to row
/// indices) when its shape differs, and `matrix()` builds a zero-valued copy on demand, so no
/// value or row-index array is allocated or touched until needed.
///
/// Blocks. A cell's local unknowns are grouped into *blocks*: runs of local DOFs whose unknowns
/// are consecutive and whose columns have the same rows (the free components of one velocity
/// node, interleaved in the field vector; a rigid body's d(d+1)/2 unknowns). Rows of a block
/// are contiguous in every column, and the columns of a block are equally long, so one stored
/// position per (row block, column block) pair addresses the whole D x D sub-matrix: D^2 fewer
/// positions than one per DOF pair (2D P2/P1: 81 instead of 225 per cell), and the pattern
/// build works per node instead of per unknown. A position is the row block's offset in the
/// column block's columns (each block keeps its column start and length), 8 bits wide when
/// the cell's columns are at most 256 long (2D), 16 bits up to 65536, 32 beyond (cells on a
/// large body). The rows of all columns of a node group are the same whole groups, stored
/// once per group (and once for groups touched by the same cells, such as the velocity and
/// the pressure at a vertex). Assembly does no search, no sort and no allocation.
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
#include <type_traits>
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
    build_local_unknowns(n_cells, cell_dofs);
    std::vector<std::uint32_t> scratch;
    build_pattern(scratch);
    build_schedule(scratch);
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
  /// Bytes taken by the scatter positions (1, 2 or 4 per position, see the file comment).
  std::size_t position_bytes() const { return n_pos_bytes_; }

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
    Index* inner = M.innerIndexPtr();
    const Index ng = Index(gfirst_.size()) - 1;
    for (Index g = 0; g < ng; ++g) {  // the first column of the group, copied to the others
      const Index u0 = gfirst_[g], len = outer_[u0 + 1] - outer_[u0];
      Index* col = inner + outer_[u0];
      const Index* x = gadj_.get() + gadj_at_[g];
      for (Index k = 0; k < len; ++x)
        for (Index u = gfirst_[*x]; u < gfirst_[*x + 1]; ++u) col[k++] = u;
      for (Index t = 1; t < gfirst_[g + 1] - u0; ++t) std::copy(col, col + len, col + t * len);
    }
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
  /// A run of local unknowns [start, start + size) of one cell; `col`: the start of the
  /// block's first column in the CSR/CSC storage, `stride`: the length of each of its columns
  /// (consecutive columns of a block are that far apart).
  struct Block {
    std::int16_t start, size;
    Index stride, col;
  };

  // Adds the column-major local matrix A (leading dimension lda, the cell's local unknown
  // order) through the block positions. Block sizes 1..3 (scalars, 2D and 3D nodes) take
  // unrolled paths; larger blocks (a 3D body's 6 unknowns) the generic loop.
  void scatter_blocks(Index c, const Real* A, Index lda, Real* val) const {
    switch (width_[c]) {
      case 0: scatter_blocks(c, A, lda, val, &pos8_[pos_start_[c]]); break;
      case 1: scatter_blocks(c, A, lda, val, &pos16_[pos_start_[c]]); break;
      default: scatter_blocks(c, A, lda, val, &pos32_[pos_start_[c]]);
    }
  }
  // pos: the cell's positions, the offsets of row block I in the columns of block J at
  // J * nb + I
  template <class P>
  void scatter_blocks(Index c, const Real* A, Index lda, Real* val, const P* pos) const {
    const Block* blk = &blk_[blk_start_[c]];
    const Index nb = blk_start_[c + 1] - blk_start_[c];
    for (Index J = 0; J < nb; ++J) {
      const Block bj = blk[J];
      const P* pj = pos + std::ptrdiff_t(J) * nb;
      const Index stride = bj.stride;
      const Real* aj = A + std::ptrdiff_t(bj.start) * lda;
      Real* vj = val + bj.col;
      switch (bj.size) {
        case 1: scatter_column_block<1>(blk, nb, pj, aj, lda, stride, vj); break;
        case 2: scatter_column_block<2>(blk, nb, pj, aj, lda, stride, vj); break;
        case 3: scatter_column_block<3>(blk, nb, pj, aj, lda, stride, vj); break;
        default:
          for (Index I = 0; I < nb; ++I) {
            const Real* a = aj + blk[I].start;
            Real* v = vj + pj[I];
            for (int t = 0; t < bj.size; ++t, a += lda, v += stride)
              for (int s = 0; s < blk[I].size; ++s) v[s] += a[s];
          }
      }
    }
  }
  template <int SJ, class P>
  static void scatter_column_block(const Block* blk, Index nb, const P* pos, const Real* aj, Index lda,
                                   Index stride, Real* val) {
    for (Index I = 0; I < nb; ++I) {
      const Real* a = aj + blk[I].start;
      Real* v = val + pos[I];  // val: the block's column start
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

  // Per cell: its field DOFs and its reduced unknown list. Simple cells: N entries (unknown or
  // -1 for fixed). Linked cells: the distinct unknowns, plus for each local DOF entry its
  // reduced index. Also counts the cells touching each unknown, in outer_ (which becomes the
  // column starts in build_pattern).
  template <class CellDofsFn>
  void build_local_unknowns(Index nc, CellDofsFn& cell_dofs) {
    using Kind = DofConstraints::Kind;
    dofs_.resize(nc);
    general_.assign(nc, 0);
    red_start_.assign(nc + 1, 0);
    ent_start_.assign(nc + 1, 0);
    red_.reserve(std::size_t(nc) * N);
    outer_.assign(std::size_t(n_unknowns()) + 1, 0);
    Index* cnt = outer_.data();
    std::vector<Index> uniq;
    for (Index c = 0; c < nc; ++c) {
      dofs_[c] = cell_dofs(c);
      const CellDofs& d = dofs_[c];
      bool gen = false;
      for (Index f : d) gen |= cons_->kind(f) == Kind::linked;
      general_[c] = gen;
      if (!gen) {
        for (Index f : d) {
          const Index u = cons_->kind(f) == Kind::free ? cons_->indices(f)[0] : -1;
          red_.push_back(u);
          if (u >= 0) ++cnt[u];
        }
      } else {
        ++n_general_;
        uniq.clear();
        for (Index f : d)
          for (Index u : cons_->indices(f)) uniq.push_back(u);
        std::sort(uniq.begin(), uniq.end());
        uniq.erase(std::unique(uniq.begin(), uniq.end()), uniq.end());
        red_.insert(red_.end(), uniq.begin(), uniq.end());
        for (Index u : uniq) ++cnt[u];
        for (Index f : d)
          for (Index u : cons_->indices(f))
            ent_.push_back(Index(std::lower_bound(uniq.begin(), uniq.end(), u) - uniq.begin()));
      }
      red_start_[c + 1] = static_cast<Index>(red_.size());
      ent_start_[c + 1] = static_cast<Index>(ent_.size());
    }
  }

  // Pattern build by node *groups*. A group is a run of consecutive unknowns touched by
  // exactly the same cells (the free components of one node; a body's unknowns): its columns
  // have the same rows, and the rows of any column are whole groups (a cell that touches one
  // unknown of a group touches all of them). The pattern is stored by groups: each group's
  // row groups, ascending (`take_pattern` expands them: a group's unknowns are consecutive
  // and groups are numbered in unknown order, so the rows come out sorted). Groups touched by
  // the same cells (a *class*: the velocity and the pressure at a vertex) have the same rows,
  // found and stored once.
  //
  // One visit per class, led by the group v met first: the distinct groups of the blocks of
  // v's cells (a stamp array, branch-free), sorted (a few tens: insertion sort), are v's row
  // groups; rank[] then gives the offset of each row group (or row) in v's columns, and each
  // cell touching a group of the class gets the positions of its (row block, column block in
  // the group) pairs: the rank of each of its blocks. Positions are relative to the column
  // start (kept per block), so the classes can be visited in any order: a class is visited
  // when a cell first meets it, cell by cell, so that the cells, blocks and positions being
  // written stay in a window of the cell order (visiting in unknown order sweeps over all
  // cells once per kind of node). Positions take 8 bits per entry when the cell's columns
  // are at most 256 long, 16 bits up to 65536 (all but cells on a large body), else 32.
  //
  // The (group, cell) incidences live in `scratch`, left allocated (touched) for
  // build_schedule.
  void build_pattern(std::vector<std::uint32_t>& scratch) {
    const Index n = n_unknowns(), nc = n_cells();
    Index* outer = outer_.data();  // the cell counts until the column starts are known
    for (Index u = 0; u < n; ++u)
      if (outer[u] == 0) throw SolverError("unknown " + std::to_string(u) + " is coupled to nothing");
    // u continues the group of u - 1 when the cells touching u are those touching u - 1: as
    // many, and each cell holding u holds u - 1 (a cell's unknowns are distinct)
    std::vector<char> same_prev(n, 0);
    for (Index u = 1; u < n; ++u) same_prev[u] = outer[u] == outer[u - 1];
    for (Index c = 0; c < nc; ++c) {
      const Index* red = &red_[red_start_[c]];
      const Index m = red_start_[c + 1] - red_start_[c];
      for (Index k = 0; k < m; ++k) {
        const Index u = red[k];
        if (u <= 0 || !same_prev[u] || (k > 0 && red[k - 1] == u - 1)) continue;
        if (std::find(red, red + m, u - 1) == red + m) same_prev[u] = 0;
      }
    }
    // gid[u]: u's group (numbered in unknown order); gfirst_[g]: its first unknown. gid's
    // storage is reused below (+ 4: the branch-free rank writes).
    std::vector<Index> gid(std::size_t(n) + 4);
    Index ng = 0;
    for (Index u = 0; u < n; ++u) {
      ng += !same_prev[u];
      gid[u] = ng - 1;
    }
    gfirst_.assign(std::size_t(ng) + 1, 0);
    for (Index u = 0; u < n; ++u) gfirst_[gid[u] + 1] = u + 1;
    const Index* gfirst = gfirst_.data();
    Index max_gsize = 0;
    for (Index g = 0; g < ng; ++g) max_gsize = std::max(max_gsize, gfirst[g + 1] - gfirst[g]);
    // blocks of each cell; until the columns are known, `col` holds the block's group
    blk_start_.assign(nc + 1, 0);
    blk_.clear();
    blk_.reserve(red_.size());
    std::vector<Index> gbstart(std::size_t(ng) + 1, 0);  // per group: its blocks, counted, then CSR starts
    Index max_nb = 1;
    bool aligned = true;  // every block starts at its group's first unknown
    for (Index c = 0; c < nc; ++c) {
      const Index* red = &red_[red_start_[c]];
      const Index m = red_start_[c + 1] - red_start_[c];
      for (Index k = 0; k < m;) {
        if (red[k] < 0) {
          ++k;
          continue;
        }
        const Index g = gid[red[k]];
        aligned &= red[k] == gfirst[g];
        Index e = k + 1;
        while (e < m && red[e] == red[e - 1] + 1 && gid[red[e]] == g) ++e;
        blk_.push_back(Block{std::int16_t(k), std::int16_t(e - k), 0, g});
        ++gbstart[g + 1];
        k = e;
      }
      blk_start_[c + 1] = Index(blk_.size());
      max_nb = std::max(max_nb, blk_start_[c + 1] - blk_start_[c]);
    }
    Index max_inc = 0;
    for (Index g = 0; g < ng; ++g) max_inc = std::max(max_inc, gbstart[g + 1]);
    std::partial_sum(gbstart.begin(), gbstart.end(), gbstart.begin());
    // per group: its blocks as (cell << shift | local block index), in cell order; glen[g]
    // first bounds g's column length (the unknowns of its cells, with repetitions)
    const int shift = std::bit_width(std::uint32_t(max_nb - 1));
    if (std::uint64_t(nc) << shift > std::numeric_limits<std::uint32_t>::max())
      throw SolverError("Assembler: too many cells for the pattern build (cells x blocks per cell >= 2^32)");
    const std::uint32_t jmask = (std::uint32_t(1) << shift) - 1;
    scratch.resize(std::max<std::size_t>(blk_.size(), n));  // build_schedule needs n
    std::uint32_t* inc = scratch.data();
    std::vector<Index> glen(ng, 0);
    constexpr Index len8 = 256, len16 = 65536;  // longest columns with 8-, 16-bit positions
    {
      Index* at = gid.data();  // insertion cursor per group
      std::copy(gbstart.begin(), gbstart.end() - 1, at);
      for (Index c = 0; c < nc; ++c) {
        const Index b0 = blk_start_[c], b1 = blk_start_[c + 1];
        Index mc = 0;
        for (Index b = b0; b < b1; ++b) mc += blk_[b].size;
        for (Index b = b0; b < b1; ++b) {
          const Index g = blk_[b].col;
          inc[at[g]++] = std::uint32_t(c) << shift | std::uint32_t(b - b0);
          glen[g] = std::min(glen[g] + mc, len16 + 1);
        }
      }
    }
    // positions: per cell, nb x nb row offsets (row block I in the columns of block J at
    // J * nb + I), 8-bit if all its columns are at most len8 long, 16-bit if at most len16,
    // 32-bit otherwise. Every (row block, column block) pair of every cell is written below
    // exactly once.
    width_.assign(nc, 0);
    pos_start_.assign(nc, 0);
    std::int64_t npos[3] = {0, 0, 0};
    for (Index c = 0; c < nc; ++c) {
      const Index b0 = blk_start_[c], nb = blk_start_[c + 1] - b0;
      Index longest = 0;
      for (Index b = b0; b < b0 + nb; ++b) longest = std::max(longest, glen[blk_[b].col]);
      const int w = longest <= len8 ? 0 : longest <= len16 ? 1 : 2;
      width_[c] = char(w);
      pos_start_[c] = npos[w];
      npos[w] += std::int64_t(nb) * nb;
    }
    pos8_.reset(new std::uint8_t[std::size_t(npos[0])]);
    pos16_.reset(new std::uint16_t[std::size_t(npos[1])]);
    pos32_.reset(new Index[std::size_t(npos[2])]);
    n_pos_ = std::size_t(npos[0] + npos[1] + npos[2]);
    n_pos_bytes_ = std::size_t(npos[0] + 2 * npos[1] + 4 * npos[2]);
    std::fill(glen.begin(), glen.end(), -1);  // now: -1 until the group is visited
    // the row groups of the classes, in visiting order: at most one per (cell, row block,
    // column block), so allocated for that bound (the pages past the final size are never
    // touched)
    gadj_at_.assign(std::size_t(ng) + 1, 0);
    gadj_.reset(new Index[n_pos_ + 1]);
    Index* gadj = gadj_.get();
    // rank[x]: the offset of row group x in the columns being visited (when all blocks are
    // aligned on their groups), else rank[u] the offset of row u; gid's storage
    Index* rank = gid.data();
    // nbrs[0]: a sentinel for sort_small, the candidates from nbrs[1]
    std::vector<Index> stamp(ng, -1), buf(std::size_t(max_inc) * std::size_t(max_nb) + 2);
    buf[0] = std::numeric_limits<Index>::min();
    Index* nbrs = buf.data() + 1;
    const Block* blk_all = blk_.data();
    const Index* bstart = blk_start_.data();
    Index a = 0;
    // the positions of the blocks in group v (v's rows in rank)
    auto positions = [&](Index v) {
      auto put = [&](auto* pj, Index nb, const Block* blk, const Index* red) {
        using P = std::remove_reference_t<decltype(*pj)>;
        const Index* rk = rank;  // a local: the 8-bit stores may alias anything else
        if (aligned)
          for (Index I = 0; I < nb; ++I) pj[I] = P(rk[blk[I].col]);
        else
          for (Index I = 0; I < nb; ++I) pj[I] = P(rk[red[blk[I].start]]);
      };
      const Index k1 = gbstart[v + 1];
      for (Index k = gbstart[v]; k < k1; ++k) {
        const Index c = Index(inc[k] >> shift), J = Index(inc[k] & jmask);
        const Index b0 = bstart[c], nb = bstart[c + 1] - b0;
        const std::int64_t at = pos_start_[c] + std::int64_t(J) * nb;
        const Index* red = &red_[red_start_[c]];
        switch (width_[c]) {
          case 0: put(&pos8_[at], nb, blk_all + b0, red); break;
          case 1: put(&pos16_[at], nb, blk_all + b0, red); break;
          default: put(&pos32_[at], nb, blk_all + b0, red);
        }
      }
    };
    auto visit = [&](Index v) {
      Index m = 0;
      const Index k0 = gbstart[v], k1 = gbstart[v + 1];
      for (Index k = k0; k < k1; ++k) {
        const Index c = Index(inc[k] >> shift);
        const Block* b = blk_all + bstart[c];
        const Block* e = blk_all + bstart[c + 1];
        for (; b < e; ++b) {
          const Index x = b->col;
          nbrs[m] = x;
          m += stamp[x] != v;
          stamp[x] = v;
        }
      }
      sort_small(nbrs, m);
      Index len = 0;
      if (aligned) {
        for (Index k = 0; k < m; ++k) {
          rank[nbrs[k]] = len;
          len += gfirst[nbrs[k] + 1] - gfirst[nbrs[k]];
        }
      } else if (max_gsize <= 4) {  // 4 entries per group (the excess is overwritten by the
                                    // next groups or belongs to no row of v)
        for (Index k = 0; k < m; ++k) {
          const Index u0 = gfirst[nbrs[k]];
          for (Index t = 0; t < 4; ++t) rank[u0 + t] = len + t;
          len += gfirst[nbrs[k] + 1] - u0;
        }
      } else {
        for (Index k = 0; k < m; ++k)
          for (Index u = gfirst[nbrs[k]]; u < gfirst[nbrs[k] + 1]; ++u) rank[u] = len++;
      }
      std::copy(nbrs, nbrs + m, gadj + a);
      gadj_at_[v] = a;
      a += m;
      glen[v] = len;
      positions(v);
      // the groups touched by the same cells as v (the pressure at a velocity node: v's
      // class) have v's rows: they are among the blocks of v's first cell after v's (the
      // blocks before it have been visited), not visited yet
      const Index c0 = Index(inc[k0] >> shift), nv = k1 - k0;
      for (Index b = bstart[c0] + Index(inc[k0] & jmask) + 1; b < bstart[c0 + 1]; ++b) {
        const Index g = blk_all[b].col;
        if (glen[g] >= 0 || gbstart[g + 1] - gbstart[g] != nv) continue;
        Index k = 0;
        while (k < nv && inc[gbstart[g] + k] >> shift == inc[k0 + k] >> shift) ++k;
        if (k < nv) continue;
        gadj_at_[g] = gadj_at_[v];
        glen[g] = len;
        positions(g);
      }
    };
    for (const Block& b : blk_)
      if (glen[b.col] < 0) visit(b.col);
    gadj_at_[ng] = a;
    // column starts (in unknown order), then each block's column start
    std::int64_t nnz = 0;
    for (Index g = 0; g < ng; ++g)
      for (Index u = gfirst[g]; u < gfirst[g + 1]; ++u, nnz += glen[g]) outer[u] = Index(nnz);
    if (nnz > std::numeric_limits<Index>::max())
      throw SolverError("Assembler: the matrix pattern exceeds 2^31 nonzeros (Index is 32 bit)");
    outer[n] = Index(nnz);
    for (Index c = 0; c < nc; ++c) {
      const Index* red = &red_[red_start_[c]];
      for (Index b = blk_start_[c]; b < blk_start_[c + 1]; ++b) {
        blk_[b].stride = glen[blk_[b].col];
        blk_[b].col = outer[red[blk_[b].start]];
      }
    }
  }

  // Sorts x[0 .. m) ascending (x[-1] must be a sentinel no greater than any of them):
  // insertion sort for the few tens of a column group, std::sort beyond.
  static void sort_small(Index* x, Index m) {
    if (m > 64) {
      std::sort(x, x + m);
      return;
    }
    for (Index i = 1; i < m; ++i) {
      const Index v = x[i];
      Index j = i;
      for (; x[j - 1] > v; --j) x[j] = x[j - 1];
      x[j] = v;
    }
  }

  // Thread schedule: chunks of consecutive simple cells, greedily coloured (a chunk takes the
  // lowest colour none of its unknowns has been given yet; 32 colours per round, chunks that
  // find none start a new round of 32: the colouring does not depend on the round size).
  // `used`: a buffer already touched by build_pattern.
  void build_schedule(std::vector<std::uint32_t>& used) {
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
    while (left > 0) {  // one round of up to 32 colours over the chunks still uncoloured
      used.assign(n, 0);
      for (Index ch = 0; ch < nch; ++ch) {
        if (colour[ch] >= 0) continue;
        std::uint32_t busy = 0;
        for (Index i = chunk_start_[ch]; i < chunk_start_[ch + 1]; ++i) {
          const Index c = chunk_cells_[i];
          for (Index k = red_start_[c]; k < red_start_[c + 1]; ++k)
            if (red_[k] >= 0) busy |= used[red_[k]];
        }
        if (busy == ~std::uint32_t(0)) continue;
        const int bit = std::countr_one(busy);
        colour[ch] = base + bit;
        --left;
        for (Index i = chunk_start_[ch]; i < chunk_start_[ch + 1]; ++i) {
          const Index c = chunk_cells_[i];
          for (Index k = red_start_[c]; k < red_start_[c + 1]; ++k)
            if (red_[k] >= 0) used[red_[k]] |= std::uint32_t(1) << bit;
        }
      }
      base += 32;
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
  // positions (row offsets in the column) of cell c at pos8_/pos16_/pos32_[pos_start_[c]] by
  // width_[c] = 0/1/2
  std::unique_ptr<std::uint8_t[]> pos8_;
  std::unique_ptr<std::uint16_t[]> pos16_;
  std::unique_ptr<Index[]> pos32_;
  std::vector<char> width_;
  std::size_t n_pos_ = 0, n_pos_bytes_ = 0;
  std::vector<std::int64_t> pos_start_;  // can exceed 2^31 for big 3D P2 meshes
  std::vector<Index> chunk_cells_, chunk_start_, chunk_order_, colour_start_, linked_cells_;
  int threads_ = 1;
  std::vector<Index> outer_;           // CSC pattern: column starts
  // the rows by groups: group g = unknowns gfirst_[g] .. gfirst_[g + 1] - 1; its columns' rows
  // are the groups at gadj_[gadj_at_[g]], ascending, as many as make up the column length
  std::vector<Index> gfirst_, gadj_at_;
  std::unique_ptr<Index[]> gadj_;
  mutable SparseMatrix matrix_;        // matrix(): built on demand
  mutable bool matrix_built_ = false;
};

}  // namespace alefsi
