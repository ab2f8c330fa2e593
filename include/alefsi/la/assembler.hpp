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
/// Memory. The build is bound by memory touched for the first time as much as by its work:
/// a fresh page costs a page fault and the kernel's clearing (on the VM of docs/performance.md
/// ~10 us per 4 KB page, as much as the build's own work on it). So every array is allocated
/// once, at its size or at a bound whose untouched tail costs nothing, and never zeroed when
/// it is written in full anyway (`detail::UninitArray`); arrays of 4 MB and more are mapped
/// 2 MB-aligned with transparent huge pages requested (Linux, `madvise`: one fault per 2 MB),
/// and so are the row indices and values of a matrix given the pattern (their ends, outside
/// whole huge pages, are faulted in by one call). `rebuild` (after a remesh) reuses the
/// previous pattern's arrays, and `take_pattern` / `assemble` reuse a matrix's storage when it
/// is large enough, so that a rebuild touches no fresh memory.
///
/// The kernel is called as `kernel.cell(c, u_e, A_e, r_e)` with the cell's local field values
/// u_e (constraint offsets included) and must fill the local Jacobian A_e and residual r_e,
/// both of the compile-time size `N` (the space's local field DOFs).
///
///     Assembler<Space::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
///     asmb.set_threads(2);                    // optional
///     asmb.assemble(kernel, field, &J, &r);   // J: asmb.matrix() shape, r: n_unknowns
///     asmb.rebuild(mesh.n_cells(), ..., cons); asmb.take_pattern(J);  // after a remesh
///
/// Cells of one part (`AssembledCells::part`: a process's cells under MPI, la/partition.hpp):
/// the n cells given are some of the mesh's, `cell_dofs(i)` and the kernel's `cell(i, ...)`
/// number them 0 .. n - 1, and an unknown that none of them touches has an empty column and row
/// (with all cells, such an unknown is an error: the system would be singular).
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

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/fem/constraints.hpp"

namespace alefsi {

using SparseMatrix = Eigen::SparseMatrix<Real, Eigen::ColMajor, Index>;

namespace detail {

/// Arrays of at least this many bytes are mapped on their own with transparent huge pages
/// requested (Linux), smaller ones come from the heap.
inline constexpr std::size_t huge_array_bytes = std::size_t(4) << 20;
inline constexpr std::size_t huge_page_bytes = std::size_t(2) << 20;

/// Asks the kernel to back the whole pages of [p, p + bytes) with transparent huge pages when
/// they are first touched (Linux with THP in "madvise" or "always" mode; elsewhere nothing).
/// Only worth it before the first touch.
inline void advise_huge_pages([[maybe_unused]] void* p, [[maybe_unused]] std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (bytes < huge_array_bytes) return;
  const auto page = std::uintptr_t(sysconf(_SC_PAGESIZE));
  const auto a = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t b = (a + page - 1) / page * page, e = (a + bytes) / page * page;
  if (e <= b) return;
  madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);  // advice only: errors ignored
#if defined(MADV_POPULATE_WRITE)
  // the ends outside whole huge pages stay 4 KB pages: faulted in by one call each rather
  // than one fault per page
  const std::uintptr_t hb = (b + huge_page_bytes - 1) / huge_page_bytes * huge_page_bytes;
  const std::uintptr_t he = e / huge_page_bytes * huge_page_bytes;
  if (hb >= he) {
    madvise(reinterpret_cast<void*>(b), e - b, MADV_POPULATE_WRITE);
    return;
  }
  if (hb > b) madvise(reinterpret_cast<void*>(b), hb - b, MADV_POPULATE_WRITE);
  if (e > he) madvise(reinterpret_cast<void*>(he), e - he, MADV_POPULATE_WRITE);
#endif
#endif
}

/// A fixed-size array of a trivial type whose elements are not initialised (every array of
/// the pattern build is written in full before it is read). Large arrays are mapped 2 MB
/// aligned with transparent huge pages requested (see the file comment: first-touch page
/// faults were the largest part of the build); `resize_for_overwrite` keeps the storage when
/// it is large enough.
template <class T>
class UninitArray {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

 public:
  UninitArray() = default;
  UninitArray(const UninitArray&) = delete;
  UninitArray& operator=(const UninitArray&) = delete;
  UninitArray(UninitArray&& o) noexcept { swap(o); }
  UninitArray& operator=(UninitArray&& o) noexcept {
    UninitArray t(std::move(o));
    swap(t);
    return *this;
  }
  ~UninitArray() { release(); }

  /// n elements of unspecified value.
  T* resize_for_overwrite(std::size_t n) {
    if (n > cap_) {
      release();
      acquire(n);
    }
    n_ = n;
    return p_;
  }
  T* assign(std::size_t n, const T& v) {
    std::fill_n(resize_for_overwrite(n), n, v);
    return p_;
  }
  /// n elements, the first min(n, size()) kept.
  T* resize_keep(std::size_t n) {
    if (n > cap_) {
      UninitArray t;
      t.acquire(n);
      std::copy(p_, p_ + std::min(n, n_), t.p_);
      swap(t);
    }
    n_ = n;
    return p_;
  }
  void clear() {
    release();
    n_ = 0;
  }

  std::size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  T* data() { return p_; }
  const T* data() const { return p_; }
  T& operator[](std::size_t i) { return p_[i]; }
  const T& operator[](std::size_t i) const { return p_[i]; }
  T* begin() { return p_; }
  T* end() { return p_ + n_; }
  const T* begin() const { return p_; }
  const T* end() const { return p_ + n_; }
  const T& back() const { return p_[n_ - 1]; }

 private:
  void swap(UninitArray& o) noexcept {
    std::swap(p_, o.p_);
    std::swap(n_, o.n_);
    std::swap(cap_, o.cap_);
    std::swap(mapped_, o.mapped_);
  }
  void acquire(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (bytes >= huge_array_bytes) {
      // map 2 MB more than the rounded size, keep a 2 MB-aligned run of it
      const std::size_t len = (bytes + huge_page_bytes - 1) / huge_page_bytes * huge_page_bytes;
      void* m = mmap(nullptr, len + huge_page_bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (m == MAP_FAILED) throw std::bad_alloc();
      const auto a = reinterpret_cast<std::uintptr_t>(m);
      const std::uintptr_t b = (a + huge_page_bytes - 1) / huge_page_bytes * huge_page_bytes;
      if (b > a) munmap(m, b - a);
      if (a + huge_page_bytes > b) munmap(reinterpret_cast<void*>(b + len), a + huge_page_bytes - b);
      madvise(reinterpret_cast<void*>(b), len, MADV_HUGEPAGE);
      p_ = reinterpret_cast<T*>(b);
      cap_ = len / sizeof(T);
      mapped_ = len;
      return;
    }
#endif
    p_ = n ? static_cast<T*>(::operator new(bytes)) : nullptr;
    cap_ = n;
    mapped_ = 0;
  }
  void release() {
    if (!p_) return;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (mapped_) {
      munmap(p_, mapped_);
      p_ = nullptr;
      cap_ = 0;
      return;
    }
#endif
    ::operator delete(p_);
    p_ = nullptr;
    cap_ = 0;
  }

  T* p_ = nullptr;
  std::size_t n_ = 0, cap_ = 0, mapped_ = 0;
};

}  // namespace detail

/// A cell kernel of N local field DOFs: fills the element Jacobian and residual.
template <class K, int N>
concept CellKernel = requires(const K& k, Index c, const Eigen::Matrix<Real, N, 1>& u,
                              Eigen::Matrix<Real, N, N>& A, Eigen::Matrix<Real, N, 1>& r) {
  k.cell(c, u, A, r);
};

/// Whether an Assembler covers all the mesh's cells or one part of them (file comment).
enum class AssembledCells { all, part };

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
  Assembler(Index n_cells, CellDofsFn&& cell_dofs, const DofConstraints& cons,
            AssembledCells cells = AssembledCells::all)
      : cons_(&cons), cells_(cells) {
    if (!cons.finalized()) throw Error("Assembler: DofConstraints must be finalized first");
    build(n_cells, cell_dofs);
  }

  /// Rebuilds for new cells and constraints (after a remesh): the same as a new
  /// `Assembler(n_cells, cell_dofs, cons)` (the thread count is kept), but the arrays of the
  /// previous pattern are reused where they are large enough, so that the build does not pay
  /// for fresh memory (see the file comment). A matrix that took the previous pattern must
  /// take the new one (`take_pattern`: it reuses the matrix's storage too). If it throws,
  /// the assembler may only be rebuilt or destroyed.
  template <class CellDofsFn>
  void rebuild(Index n_cells, CellDofsFn&& cell_dofs, const DofConstraints& cons,
               AssembledCells cells = AssembledCells::all) {
    if (!cons.finalized()) throw Error("Assembler: DofConstraints must be finalized first");
    cons_ = &cons;
    cells_ = cells;
    matrix_built_ = false;
    build(n_cells, cell_dofs);
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
    const std::size_t nnz = std::size_t(n_nonzeros());
    const Index* old_inner = M.innerIndexPtr();
    const Real* old_values = M.valuePtr();
    M.resize(n, n);
    M.resizeNonZeros(Index(nnz));
    // fresh storage (not the matrix's previous one): huge pages before the first touch
    if (M.innerIndexPtr() != old_inner) detail::advise_huge_pages(M.innerIndexPtr(), nnz * sizeof(Index));
    if (M.valuePtr() != old_values) detail::advise_huge_pages(M.valuePtr(), nnz * sizeof(Real));
    std::copy(outer_.begin(), outer_.end(), M.outerIndexPtr());
    expand_rows(M.innerIndexPtr());
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
    const auto li = std::lower_bound(linked_cells_.begin(), linked_cells_.end(), c) - linked_cells_.begin();
    const Index* ent = &ent_[ent_start_[li]];  // per local DOF entry: reduced index
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
  // The row indices from the rows by groups: every column of a group gets the same rows.
  void expand_rows(Index* inner) const {
    const Index ng = Index(gfirst_.size()) - 1;
    const Index* gf = gfirst_.data();
    for (Index g = 0; g < ng; ++g) {
      const Index u0 = gf[g], len = outer_[u0 + 1] - outer_[u0], sg = gf[g + 1] - u0;
      Index* col = inner + outer_[u0];
      const Index* x = gadj_.data() + gadj_at_[g];
      if (sg == 1) {
        for (Index k = 0; k < len; ++x)
          for (Index u = gf[*x]; u < gf[*x + 1]; ++u) col[k++] = u;
      } else if (sg == 2) {
        for (Index k = 0; k < len; ++x)
          for (Index u = gf[*x]; u < gf[*x + 1]; ++u, ++k) col[k] = col[len + k] = u;
      } else {
        for (Index k = 0; k < len; ++x)
          for (Index u = gf[*x]; u < gf[*x + 1]; ++u, ++k)
            for (Index t = 0; t < sg; ++t) col[t * len + k] = u;
      }
    }
  }

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

  // ---- pattern build ----------------------------------------------------------------------
  // Passes: the cells' unknowns (and the cells touching each unknown, counted); the node
  // groups; the cells' blocks; the incidences (the blocks of each group) with the position
  // widths; one visit per class (rows and positions); the column starts; the thread schedule.
  // Every array is written in full before it is read (no zeroing pass where none is needed),
  // allocated once at its size or a bound (an untouched tail takes no memory), large ones with
  // transparent huge pages requested (UninitArray).
  // per group during the build: the visit stamp, the rank (offset of the group's rows in the
  // columns being visited), the size (unknowns), the column length (a bound, then -1 until
  // visited, then the length)
  struct GroupState {
    Index stamp, rank, size, len;
  };
  struct Scratch {
    detail::UninitArray<Index> gid;          // per unknown: its group; then cursors, ranks
    detail::UninitArray<Index> gbstart;      // per group: its first incidence
    detail::UninitArray<GroupState> gs;      // per group
    detail::UninitArray<Index> bg;           // per block: its group
    detail::UninitArray<std::uint32_t> inc;  // per group: its blocks (cell << shift | block)
    Index max_gsize = 0, max_nb = 1;
    bool aligned = true;  // every block starts at its group's first unknown
  };

  template <class CellDofsFn>
  void build(Index nc, CellDofsFn& cell_dofs) {
    Scratch s;
    build_local_unknowns(nc, cell_dofs);
    build_groups(s);
    build_blocks(s);
    build_pattern(s);
    build_schedule(s);
  }

  // Per cell: its field DOFs and its reduced unknown list. Simple cells: N entries (unknown or
  // -1 for fixed). Linked cells: the distinct unknowns, plus for each local DOF entry its
  // reduced index (in ent_, from ent_start_ of the cell's place in linked_cells_). Also counts
  // the cells touching each unknown, in outer_ (which becomes the column starts later).
  template <class CellDofsFn>
  void build_local_unknowns(Index nc, CellDofsFn& cell_dofs) {
    using Kind = DofConstraints::Kind;
    const DofConstraints& cons = *cons_;
    CellDofs* dofs = dofs_.resize_for_overwrite(nc);
    char* general = general_.resize_for_overwrite(nc);
    Index* red_start = red_start_.resize_for_overwrite(std::size_t(nc) + 1);
    // N entries per simple cell; a linked cell can need more (grown below if so)
    Index* red = red_.resize_for_overwrite(std::size_t(nc) * N);
    Index* cnt = outer_.assign(std::size_t(n_unknowns()) + 1, 0);
    n_general_ = 0;
    linked_cells_.clear();
    ent_start_.assign(1, 0);
    ent_.clear();
    std::vector<Index> uniq;
    std::size_t used = 0;
    red_start[0] = 0;
    for (Index c = 0; c < nc; ++c) {
      const CellDofs d = cell_dofs(c);
      dofs[c] = d;
      std::array<Kind, N> kind;
      bool gen = false;
      for (int i = 0; i < N; ++i) {
        kind[i] = cons.kind(d[i]);
        gen |= kind[i] == Kind::linked;
      }
      general[c] = gen;
      if (!gen) {
        Index* r = red + used;
        for (int i = 0; i < N; ++i) r[i] = kind[i] == Kind::free ? cons.indices(d[i])[0] : -1;
        for (int i = 0; i < N; ++i)
          if (r[i] >= 0) ++cnt[r[i]];
        used += N;
      } else {
        ++n_general_;
        linked_cells_.push_back(c);
        uniq.clear();
        for (Index f : d)
          for (Index u : cons.indices(f)) uniq.push_back(u);
        std::sort(uniq.begin(), uniq.end());
        uniq.erase(std::unique(uniq.begin(), uniq.end()), uniq.end());
        const std::size_t need = used + uniq.size() + std::size_t(nc - c - 1) * N;
        if (need > red_.size()) red = red_.resize_keep(need + need / 8);
        std::copy(uniq.begin(), uniq.end(), red + used);
        used += uniq.size();
        for (Index u : uniq) ++cnt[u];
        for (Index f : d)
          for (Index u : cons.indices(f))
            ent_.push_back(Index(std::lower_bound(uniq.begin(), uniq.end(), u) - uniq.begin()));
        ent_start_.push_back(Index(ent_.size()));
      }
      red_start[c + 1] = Index(used);
    }
    red_.resize_keep(used);
  }

  // Node groups. A group is a run of consecutive unknowns touched by exactly the same cells
  // (the free components of one node; a body's unknowns): its columns have the same rows, and
  // the rows of any column are whole groups (a cell that touches one unknown of a group
  // touches all of them). u continues the group of u - 1 when the cells touching u are those
  // touching u - 1: as many, and each cell holding u holds u - 1 (a cell's unknowns are
  // distinct). s.gid[u]: u's group (numbered in unknown order); gfirst_[g]: its first unknown.
  void build_groups(Scratch& s) {
    const Index n = n_unknowns(), nc = n_cells();
    const Index* cnt = outer_.data();
    if (cells_ == AssembledCells::all)
      for (Index u = 0; u < n; ++u)
        if (cnt[u] == 0) throw SolverError("unknown " + std::to_string(u) + " is coupled to nothing");
    // gid (+ 4: the branch-free rank writes of build_pattern) first holds "same as u - 1"
    Index* gid = s.gid.resize_for_overwrite(std::size_t(n) + 4);
    if (n > 0) gid[0] = 0;
    for (Index u = 1; u < n; ++u) gid[u] = cnt[u] == cnt[u - 1];
    for (Index c = 0; c < nc; ++c) {
      const Index* red = &red_[red_start_[c]];
      const Index m = red_start_[c + 1] - red_start_[c];
      for (Index k = 0; k < m; ++k) {
        const Index u = red[k];
        if (u <= 0 || !gid[u] || (k > 0 && red[k - 1] == u - 1)) continue;
        if (std::find(red, red + m, u - 1) == red + m) gid[u] = 0;
      }
    }
    Index* gfirst = gfirst_.resize_for_overwrite(std::size_t(n) + 1);  // a bound: ng + 1 used
    Index ng = 0;
    for (Index u = 0; u < n; ++u) {
      if (!gid[u]) gfirst[ng++] = u;
      gid[u] = ng - 1;
    }
    gfirst[ng] = n;
    gfirst_.resize_keep(std::size_t(ng) + 1);
    s.max_gsize = 0;
    for (Index g = 0; g < ng; ++g) s.max_gsize = std::max(s.max_gsize, gfirst[g + 1] - gfirst[g]);
  }

  // Blocks of each cell (runs of local unknowns that are consecutive and of one group): their
  // start and size in blk_ (the columns are filled in at the end of build_pattern), their
  // group in s.bg. Per group: its blocks counted (in s.gbstart[g + 1]), its size, and a bound
  // on its column length (the unknowns of its cells, with repetitions, capped just above the
  // 16-bit range).
  void build_blocks(Scratch& s) {
    const Index nc = n_cells(), ng = Index(gfirst_.size()) - 1;
    const Index* gid = s.gid.data();
    const Index* gfirst = gfirst_.data();
    Index* blk_start = blk_start_.resize_for_overwrite(std::size_t(nc) + 1);
    Block* blk = blk_.resize_for_overwrite(red_.size());  // bounds: one block per unknown
    Index* bg = s.bg.resize_for_overwrite(red_.size());
    Index* count = s.gbstart.assign(std::size_t(ng) + 1, 0);
    GroupState* gs = s.gs.resize_for_overwrite(ng);
    for (Index g = 0; g < ng; ++g) gs[g] = GroupState{-1, 0, gfirst[g + 1] - gfirst[g], 0};
    Index nb_all = 0, max_nb = 1;
    bool aligned = true;
    blk_start[0] = 0;
    for (Index c = 0; c < nc; ++c) {
      const Index* red = &red_[red_start_[c]];
      const Index m = red_start_[c + 1] - red_start_[c];
      const Index b0 = nb_all;
      Index mc = 0;
      for (Index k = 0; k < m;) {
        if (red[k] < 0) {
          ++k;
          continue;
        }
        const Index g = gid[red[k]];
        aligned &= red[k] == gfirst[g];
        Index e = k + 1;
        while (e < m && red[e] == red[e - 1] + 1 && gid[red[e]] == g) ++e;
        blk[nb_all] = Block{std::int16_t(k), std::int16_t(e - k), 0, 0};
        bg[nb_all++] = g;
        ++count[g + 1];
        mc += e - k;
        k = e;
      }
      for (Index b = b0; b < nb_all; ++b) gs[bg[b]].len = std::min(gs[bg[b]].len + mc, len16 + 1);
      blk_start[c + 1] = nb_all;
      max_nb = std::max(max_nb, nb_all - b0);
    }
    blk_.resize_keep(std::size_t(nb_all));
    s.bg.resize_keep(std::size_t(nb_all));
    s.max_nb = max_nb;
    s.aligned = aligned;
  }

  static constexpr Index len8 = 256, len16 = 65536;  // longest columns with 8-, 16-bit positions

  // One visit per class: groups touched by the same cells (a *class*: the velocity and the
  // pressure at a vertex) have the same rows, found and stored once. The pattern is stored by
  // groups: each class's row groups, ascending (`take_pattern` expands them: a group's
  // unknowns are consecutive and groups are numbered in unknown order, so the rows come out
  // sorted).
  //
  // The visit of a class, led by the group v met first: the distinct groups of the blocks of
  // v's cells (a stamp, branch-free), sorted (a few tens: insertion sort), are v's row
  // groups; their ranks then give the offset of each row group (or row) in v's columns, and
  // each cell touching v gets the positions of its (row block, column block v) pairs: the
  // rank of each of its blocks; the cells' positions in the columns of v's class mates are
  // copies of those. Positions are relative to the column start (kept per block), so the
  // classes can be visited in any order: a class is visited when a cell first meets it, cell
  // by cell, so that the cells, blocks and positions being written stay in a window of the
  // cell order (visiting in unknown order sweeps over all cells once per kind of node).
  // Positions take 8 bits per entry when the cell's columns are at most 256 long, 16 bits up
  // to 65536 (all but cells on a large body), else 32.
  void build_pattern(Scratch& s) {
    const Index n = n_unknowns(), nc = n_cells(), ng = Index(gfirst_.size()) - 1;
    const Index* gfirst = gfirst_.data();
    const Index max_nb = s.max_nb, max_gsize = s.max_gsize;
    const bool aligned = s.aligned;
    Index* gbstart = s.gbstart.data();
    GroupState* gs = s.gs.data();
    const Index* bg = s.bg.data();
    Index max_inc = 0;
    for (Index g = 0; g < ng; ++g) max_inc = std::max(max_inc, gbstart[g + 1]);
    std::partial_sum(gbstart, gbstart + ng + 1, gbstart);
    // per group: its blocks as (cell << shift | local block index), in cell order
    const int shift = std::bit_width(std::uint32_t(max_nb - 1));
    if (std::uint64_t(nc) << shift > std::numeric_limits<std::uint32_t>::max())
      throw SolverError("Assembler: too many cells for the pattern build (cells x blocks per cell >= 2^32)");
    const std::uint32_t jmask = (std::uint32_t(1) << shift) - 1;
    std::uint32_t* inc = s.inc.resize_for_overwrite(blk_.size());
    // positions: per cell, nb x nb row offsets (row block I in the columns of block J at
    // J * nb + I), 8-bit if all its columns are at most len8 long, 16-bit if at most len16,
    // 32-bit otherwise. Every (row block, column block) pair of every cell is written below
    // exactly once.
    char* width = width_.resize_for_overwrite(nc);
    std::int64_t* pos_start = pos_start_.resize_for_overwrite(nc);
    const Index* bstart = blk_start_.data();
    std::int64_t npos[3] = {0, 0, 0};
    {
      Index* at = s.gid.data();  // insertion cursor per group (gid is no longer needed)
      std::copy(gbstart, gbstart + ng, at);
      for (Index c = 0; c < nc; ++c) {
        const Index b0 = bstart[c], nb = bstart[c + 1] - b0;
        Index longest = 0;
        for (Index J = 0; J < nb; ++J) {
          const Index g = bg[b0 + J];
          longest = std::max(longest, gs[g].len);
          inc[at[g]++] = std::uint32_t(c) << shift | std::uint32_t(J);
        }
        const int w = longest <= len8 ? 0 : longest <= len16 ? 1 : 2;
        width[c] = char(w);
        pos_start[c] = npos[w];
        npos[w] += std::int64_t(nb) * nb;
      }
    }
    std::uint8_t* pos8 = pos8_.resize_for_overwrite(std::size_t(npos[0]));
    std::uint16_t* pos16 = pos16_.resize_for_overwrite(std::size_t(npos[1]));
    Index* pos32 = pos32_.resize_for_overwrite(std::size_t(npos[2]));
    n_pos_ = std::size_t(npos[0] + npos[1] + npos[2]);
    n_pos_bytes_ = std::size_t(npos[0] + 2 * npos[1] + 4 * npos[2]);
    for (Index g = 0; g < ng; ++g) gs[g].len = -1;  // now: -1 until the group is visited
    // the row groups of the classes, in visiting order: at most one per (cell, row block,
    // column block), so allocated for that bound (the pages past the final size are never
    // touched)
    Index* gadj_at = gadj_at_.resize_for_overwrite(std::size_t(ng) + 1);
    Index* gadj = gadj_.resize_for_overwrite(n_pos_ + 1);
    // when not all blocks are aligned on their groups: rank[u], the offset of row u in the
    // columns being visited (gid's storage)
    Index* rank = s.gid.data();
    // nbrs[0]: a sentinel for sort_small, the candidates from nbrs[1]
    std::vector<Index> buf(std::size_t(max_inc) * std::size_t(max_nb) + 2);
    buf[0] = std::numeric_limits<Index>::min();
    Index* nbrs = buf.data() + 1;
    const Index* red_all = red_.data();
    const Index* rstart = red_start_.data();
    const Block* blk_all = blk_.data();
    Index a = 0;
    // cell c's positions in the columns of its block J: the ranks of its blocks
    auto put = [&](auto* pj, Index c, Index nb) {
      using P = std::remove_reference_t<decltype(*pj)>;
      const Index* b = bg + bstart[c];
      if (aligned) {
        const GroupState* g = gs;  // locals: the 8-bit stores may alias anything else
        for (Index I = 0; I < nb; ++I) pj[I] = P(g[b[I]].rank);
      } else {
        const Index* rk = rank;
        const Index* red = red_all + rstart[c];
        const Block* blk = blk_all + bstart[c];
        for (Index I = 0; I < nb; ++I) pj[I] = P(rk[red[blk[I].start]]);
      }
    };
    auto visit = [&](Index v) {
      Index m = 0;
      const Index k0 = gbstart[v], k1 = gbstart[v + 1];
      for (Index k = k0; k < k1; ++k) {
        const Index c = Index(inc[k] >> shift);
        for (Index b = bstart[c]; b < bstart[c + 1]; ++b) {
          const Index x = bg[b];
          nbrs[m] = x;
          m += gs[x].stamp != v;
          gs[x].stamp = v;
        }
      }
      sort_small(nbrs, m);
      Index len = 0;
      if (aligned) {
        for (Index k = 0; k < m; ++k) {
          GroupState& x = gs[nbrs[k]];
          x.rank = len;
          len += x.size;
        }
      } else if (max_gsize <= 4) {  // 4 entries per group (the excess is overwritten by the
                                    // next groups or belongs to no row of v)
        for (Index k = 0; k < m; ++k) {
          const Index u0 = gfirst[nbrs[k]];
          for (Index t = 0; t < 4; ++t) rank[u0 + t] = len + t;
          len += gs[nbrs[k]].size;
        }
      } else {
        for (Index k = 0; k < m; ++k)
          for (Index u = gfirst[nbrs[k]]; u < gfirst[nbrs[k] + 1]; ++u) rank[u] = len++;
      }
      std::copy(nbrs, nbrs + m, gadj + a);
      gadj_at[v] = a;
      a += m;
      gs[v].len = len;
      for (Index k = k0; k < k1; ++k) {
        const Index c = Index(inc[k] >> shift), J = Index(inc[k] & jmask);
        const Index nb = bstart[c + 1] - bstart[c];
        const std::int64_t at = pos_start[c] + std::int64_t(J) * nb;
        switch (width[c]) {
          case 0: put(pos8 + at, c, nb); break;
          case 1: put(pos16 + at, c, nb); break;
          default: put(pos32 + at, c, nb);
        }
      }
      // the groups touched by the same cells as v (the pressure at a velocity node: v's
      // class) have v's rows, and so each cell's positions in their columns are those in
      // v's: they are among the blocks of v's first cell after v's (the blocks before it
      // have been visited), not visited yet
      const Index c0 = Index(inc[k0] >> shift), nv = k1 - k0;
      for (Index b = bstart[c0] + Index(inc[k0] & jmask) + 1; b < bstart[c0 + 1]; ++b) {
        const Index g = bg[b];
        if (gs[g].len >= 0 || gbstart[g + 1] - gbstart[g] != nv) continue;
        const std::uint32_t* ig = inc + gbstart[g];
        Index k = 0;
        while (k < nv && ig[k] >> shift == inc[k0 + k] >> shift) ++k;
        if (k < nv) continue;
        gadj_at[g] = gadj_at[v];
        gs[g].len = len;
        for (k = 0; k < nv; ++k) {
          const Index c = Index(ig[k] >> shift), nb = bstart[c + 1] - bstart[c];
          const std::int64_t from = pos_start[c] + std::int64_t(inc[k0 + k] & jmask) * nb;
          const std::int64_t to = pos_start[c] + std::int64_t(ig[k] & jmask) * nb;
          switch (width[c]) {
            case 0: std::copy_n(pos8 + from, nb, pos8 + to); break;
            case 1: std::copy_n(pos16 + from, nb, pos16 + to); break;
            default: std::copy_n(pos32 + from, nb, pos32 + to);
          }
        }
      }
    };
    for (std::size_t b = 0; b < blk_.size(); ++b)
      if (gs[bg[b]].len < 0) visit(bg[b]);
    for (Index g = 0; g < ng; ++g)  // a group no cell touches (AssembledCells::part): empty columns
      if (gs[g].len < 0) gs[g].len = 0, gadj_at[g] = a;
    gadj_at[ng] = a;
    gadj_.resize_keep(std::size_t(a));
    // column starts (in unknown order), then each block's column start and length
    Index* outer = outer_.data();
    std::int64_t nnz = 0;
    for (Index g = 0; g < ng; ++g)
      for (Index u = gfirst[g]; u < gfirst[g + 1]; ++u, nnz += gs[g].len) outer[u] = Index(nnz);
    if (nnz > std::numeric_limits<Index>::max())
      throw SolverError("Assembler: the matrix pattern exceeds 2^31 nonzeros (Index is 32 bit)");
    outer[n] = Index(nnz);
    Block* blk = blk_.data();
    for (Index c = 0; c < nc; ++c) {
      const Index* red = red_all + rstart[c];
      for (Index b = bstart[c]; b < bstart[c + 1]; ++b) {
        blk[b].stride = gs[bg[b]].len;
        blk[b].col = outer[red[blk[b].start]];
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
  void build_schedule(Scratch& s) {
    const Index nc = n_cells();
    Index* cells = chunk_cells_.resize_for_overwrite(std::size_t(nc - n_general_));
    const Index ns = nc - n_general_;
    for (Index c = 0, i = 0; c < nc; ++c)
      if (!general_[c]) cells[i++] = c;
    const Index nch = (ns + chunk_size - 1) / chunk_size;
    chunk_start_.resize(std::size_t(nch) + 1);
    for (Index ch = 0; ch <= nch; ++ch) chunk_start_[ch] = std::min(ch * chunk_size, ns);
    // by groups: two cells share an unknown exactly when they share a group (a cell touching
    // one unknown of a group touches all of it), so colouring the groups of the cells' blocks
    // colours their unknowns
    std::vector<Index> colour(nch, -1);
    const Index ng = Index(gfirst_.size()) - 1;
    const Index* bg = s.bg.data();
    const Index* bstart = blk_start_.data();
    // `used`: the incidences' storage (touched already; one per block)
    std::uint32_t* used = s.inc.resize_for_overwrite(std::size_t(ng));
    Index base = 0, left = nch;
    while (left > 0) {  // one round of up to 32 colours over the chunks still uncoloured
      std::fill_n(used, ng, 0);
      for (Index ch = 0; ch < nch; ++ch) {
        if (colour[ch] >= 0) continue;
        std::uint32_t busy = 0;
        for (Index i = chunk_start_[ch]; i < chunk_start_[ch + 1]; ++i)
          for (Index b = bstart[cells[i]]; b < bstart[cells[i] + 1]; ++b) busy |= used[bg[b]];
        if (busy == ~std::uint32_t(0)) continue;
        const int bit = std::countr_one(busy);
        colour[ch] = base + bit;
        --left;
        for (Index i = chunk_start_[ch]; i < chunk_start_[ch + 1]; ++i)
          for (Index b = bstart[cells[i]]; b < bstart[cells[i] + 1]; ++b) used[bg[b]] |= std::uint32_t(1) << bit;
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
  detail::UninitArray<CellDofs> dofs_;
  detail::UninitArray<char> general_;
  Index n_general_ = 0;
  detail::UninitArray<Index> red_start_, red_;
  // linked cells (ascending) and, per linked cell, its entries' reduced indices at ent_start_[i]
  std::vector<Index> linked_cells_, ent_start_, ent_;
  detail::UninitArray<Index> blk_start_;
  detail::UninitArray<Block> blk_;
  // positions (row offsets in the column) of cell c at pos8_/pos16_/pos32_[pos_start_[c]] by
  // width_[c] = 0/1/2
  detail::UninitArray<std::uint8_t> pos8_;
  detail::UninitArray<std::uint16_t> pos16_;
  detail::UninitArray<Index> pos32_;
  detail::UninitArray<char> width_;
  std::size_t n_pos_ = 0, n_pos_bytes_ = 0;
  detail::UninitArray<std::int64_t> pos_start_;  // can exceed 2^31 for big 3D P2 meshes
  detail::UninitArray<Index> chunk_cells_;
  std::vector<Index> chunk_start_, chunk_order_, colour_start_;
  int threads_ = 1;
  AssembledCells cells_ = AssembledCells::all;
  detail::UninitArray<Index> outer_;  // CSC pattern: column starts
  // the rows by groups: group g = unknowns gfirst_[g] .. gfirst_[g + 1] - 1; its columns' rows
  // are the groups at gadj_[gadj_at_[g]], ascending, as many as make up the column length
  detail::UninitArray<Index> gfirst_, gadj_at_, gadj_;
  mutable SparseMatrix matrix_;  // matrix(): built on demand
  mutable bool matrix_built_ = false;
};

}  // namespace alefsi
