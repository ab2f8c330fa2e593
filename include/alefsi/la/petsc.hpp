#pragma once
/// \file la/petsc.hpp
/// PETSc linear-solver policies, for runs under `mpirun` (optional: link the CMake target
/// `alefsi::petsc`, defined when pkg-config finds PETSc at configure time; Debian: petsc-dev).
///
/// The model is a shared mesh: every rank holds the whole mesh and runs the whole program on it,
/// and the matrix and its solves are distributed. A flow (sim/discretisation.hpp) on several
/// ranks assembles in parts: each rank the Jacobian of its own cells (PT-Scotch's part through
/// MatPartitioning, `petsc_partition`; a Morton part, la/partition.hpp, without a partitioner) with the library's kernels, into the pattern of those cells, and the
/// residual is summed over the ranks (`set_summed(true)`). The rows of PETSc's AIJ matrix
/// (MPIAIJ on several ranks) belong to the lowest rank whose cells touch them and are numbered
/// rank after rank; each rank hands its part's entries to PETSc's COO interface, which sums the
/// parts (sending the entries of other ranks' rows: the interface). A matrix passed whole (the
/// default, e.g. a system assembled by the caller on every rank) is split into contiguous
/// ranges of rows instead, each rank setting its own. Either way the positions are found once
/// per sparsity pattern (`analyze`), and each new matrix is a copy of values (`factorize`),
/// with no per-entry search. `solve(b)` takes the whole right-hand side and gathers the solution
/// to every rank, so the rest of the program (Newton updates, bodies, output) runs on the same
/// numbers everywhere. What this model costs per rank and where it stops: docs/performance.md,
/// "PETSc and MPI".
///
///   PetscDirect      MUMPS LU (KSPPREONLY + PCLU); `direct = true`, so the flow's factorisation
///                    reuse (la/linear_solve.hpp) works with it.
///   PetscKrylov<D>   GMRES, right-preconditioned (it stops on the unpreconditioned residual,
///                    as GMRES's recurrence estimates it), restart 60,
///                    with PCFIELDSPLIT in Schur form (upper factorisation) on the split
///                    [u ∪ z | p] of a flow system (la/saddle_point_blocks.hpp: velocities, body
///                    unknowns, pressures): hypre BoomerAMG on split 0 (velocities and bodies), and
///                    for the Schur complement either the pressure mass matrix, -(M_p / mu + C),
///                    with SSOR (steady Stokes: blocks given by `set_blocks` with
///                    mass_coefficient 0, as saddle_point_blocks(space, cons, mu, 0) makes them) or PETSc's
///                    -(B diag(A)^-1 B^T + C) ("selfp", the time-step regime where rho/dt
///                    dominates) with BoomerAMG.
///
/// Both apply their defaults and then read PETSc's options database (KSPSetFromOptions), so every
/// default can be changed at run time: `-ksp_type fgmres`, `-ksp_rtol 1e-10`, `-ksp_monitor`,
/// `-ksp_view`, `-pc_fieldsplit_schur_fact_type full`, `-fieldsplit_0_pc_type gamg`,
/// `-fieldsplit_1_pc_type jacobi`, `-pc_factor_mat_solver_type superlu_dist`. The splits are
/// named "0" and "1". A prefix (constructor argument) keeps two solvers' options apart.
///
///     int main(int argc, char** argv) {
///       alefsi::PetscSession petsc(argc, argv);          // MPI and PETSc, finalised at exit
///       using Cfg = alefsi::FlowConfig<3, alefsi::TaylorHood, alefsi::BDF2_BDF2E>
///                       ::with_solver<alefsi::PetscKrylov<3>>;
///       alefsi::AleFlow<Cfg> flow(mesh, {rho, mu});      // the same program as serial
///       ...
///     }
///
/// Solvers must be destroyed before the session ends (declare the session first). A solve that
/// does not converge throws `SolverError` (PETSc's reason, the iterations, the residual) on every
/// rank alike, so a driver may retry the step; a failed PETSc call throws `PetscError` (not a
/// SolverError: a rank's PETSc objects may be half-built after it, and the other ranks may be
/// waiting in a collective call; under MPI, catch it and call MPI_Abort). A new sparsity pattern
/// is recognised (size, entries and a hash of the indices) and analysed again.
#if !__has_include(<petscksp.h>)
#error "alefsi/la/petsc.hpp needs PETSc: link the CMake target alefsi::petsc (apt install petsc-dev)"
#endif

#include <petscksp.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <cstdio>
#include <exception>
#include <iostream>
#include <set>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/partition.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/la/saddle_point_blocks.hpp"
#include "alefsi/la/solvers.hpp"

static_assert(std::is_same_v<PetscScalar, double> && std::is_same_v<PetscReal, double>,
              "alefsi/la/petsc.hpp needs PETSc's real double-precision build (Debian: petsc-dev's PETSc.pc)");

namespace alefsi {

/// A PETSc call failed (la/petsc.hpp): the call and PETSc's message.
class PetscError : public Error {
 public:
  using Error::Error;
};

namespace detail {
/// Throws PetscError naming `call` when a PETSc call failed.
inline void petsc_check(PetscErrorCode code, const char* call) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw PetscError(std::string("PETSc: ") + call + " failed (error " + std::to_string(int(code)) + ": " +
                   (text ? text : "unknown") + ")");
}
/// A hash of a compressed matrix's pattern (its index arrays), to recognise a new pattern.
inline std::uint64_t pattern_hash(const SparseMatrix& A) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the indices
  auto mix = [&h](Index v) { h = (h ^ std::uint64_t(std::uint32_t(v))) * 1099511628211ull; };
  for (Index j = 0; j <= A.outerSize(); ++j) mix(A.outerIndexPtr()[j]);
  for (Index k = 0; k < A.nonZeros(); ++k) mix(A.innerIndexPtr()[k]);
  return h;
}
}  // namespace detail

#define ALEFSI_PETSC(call) ::alefsi::detail::petsc_check((call), #call)

/// MPI and PETSc for the lifetime of a scope: PetscInitialize with the program's arguments (so
/// that PETSc options on the command line reach the options database), PetscFinalize at the end.
/// When PETSc is already initialised (by the caller), it leaves it so.
class PetscSession {
 public:
  PetscSession(int& argc, char**& argv, const char* help = nullptr) {
    PetscBool up = PETSC_FALSE;
    ALEFSI_PETSC(PetscInitialized(&up));
    if (up) return;
    ALEFSI_PETSC(PetscInitialize(&argc, &argv, nullptr, help));
    owner_ = true;
  }
  PetscSession(const PetscSession&) = delete;
  PetscSession& operator=(const PetscSession&) = delete;
  ~PetscSession() {
    if (owner_) PetscFinalize();
  }
  /// This process's rank and the number of ranks in PETSC_COMM_WORLD.
  static int rank() {
    int r = 0;
    MPI_Comm_rank(PETSC_COMM_WORLD, &r);
    return r;
  }
  static int size() {
    int s = 1;
    MPI_Comm_size(PETSC_COMM_WORLD, &s);
    return s;
  }

 private:
  bool owner_ = false;
};

/// The `main` of a program run under mpirun (examples/sphere_settling.cpp): a PetscSession
/// around `body(argc, argv)`, with argv cut at "--" (what follows is PETSc's options, already in
/// its database) and std::cout silent on ranks other than 0 (rank 0 prints). An exception from
/// `body` is printed (std::cerr) and makes the status 1; a non-zero status on several ranks ends
/// them all (MPI_Abort: the others may be waiting for this one in a collective call), before
/// the session's PetscFinalize, which would wait for them.
///
///     int main(int argc, char** argv) { return alefsi::petsc_main(argc, argv, program_main); }
template <class Body>
int petsc_main(int argc, char** argv, Body&& body) {
  PetscSession session(argc, argv);
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--") {
      argc = i;
      break;
    }
  std::streambuf* const out = std::cout.rdbuf();
  if (PetscSession::rank() != 0) std::cout.rdbuf(nullptr);
  int status = 1;
  try {
    status = body(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << (argc > 0 ? argv[0] : "alefsi") << ": " << e.what() << "\n";
  }
  std::cout.rdbuf(out);
  if (status != 0 && PetscSession::size() > 1) MPI_Abort(PETSC_COMM_WORLD, status);
  return status;
}

namespace detail {

/// The part (rank) of each cell of `mesh` by PETSc's MatPartitioning on the cells' dual graph
/// (two cells adjacent when they share a facet): PT-Scotch or ParMETIS, whichever PETSc has
/// (`-mat_partitioning_type` chooses another), each rank passing a contiguous range of the
/// graph's rows; the parts are gathered, so every rank gets the whole array. Empty when PETSc has
/// neither partitioner (the caller then cuts along the Morton curve, la/partition.hpp); all 0 on
/// one rank.
template <int D>
std::vector<int> petsc_partition(const Mesh<D>& mesh) {
  const Index nc = mesh.n_cells();
  if (PetscSession::size() == 1) return std::vector<int>(std::size_t(nc), 0);
#if defined(PETSC_HAVE_PTSCOTCH) || defined(PETSC_HAVE_PARMETIS)
  PetscInt local = PETSC_DECIDE, global = PetscInt(nc), end = 0;
  ALEFSI_PETSC(PetscSplitOwnership(PETSC_COMM_WORLD, &local, &global));
  if (MPI_Scan(&local, &end, 1, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD) != MPI_SUCCESS)
    throw PetscError("PETSc: MPI_Scan of the cell ranges failed");
  const Index c0 = Index(end - local), c1 = Index(end);
  std::vector<PetscInt> nbr;
  std::vector<PetscInt> start{0};
  for (Index c = c0; c < c1; ++c) {
    for (Index f : mesh.cell_facets(c)) {
      const auto& fc = mesh.facet_cells(f);
      const Index other = fc[0] == c ? fc[1] : fc[0];
      if (other >= 0) nbr.push_back(PetscInt(other));
    }
    std::sort(nbr.begin() + start.back(), nbr.end());  // MatCreateMPIAdj wants each row sorted
    start.push_back(PetscInt(nbr.size()));
  }
  // MatCreateMPIAdj takes arrays from PetscMalloc and frees them with the matrix
  PetscInt *ia = nullptr, *ja = nullptr;
  ::Mat adj = nullptr;  // once created, it owns ia and ja (a failed creation may leak them)
  MatPartitioning mp = nullptr;
  IS is = nullptr, all = nullptr;
  auto release = [&] {
    const bool arrays_in_adj = adj != nullptr;
    if (all) ISDestroy(&all);
    if (is) ISDestroy(&is);
    if (mp) MatPartitioningDestroy(&mp);
    if (adj) MatDestroy(&adj);
    if (!arrays_in_adj) PetscFree(ia), PetscFree(ja);
  };
  std::vector<int> part(static_cast<std::size_t>(nc));
  try {
    ALEFSI_PETSC(PetscMalloc1(start.size(), &ia));
    ALEFSI_PETSC(PetscMalloc1(std::max<std::size_t>(nbr.size(), 1), &ja));
    std::copy(start.begin(), start.end(), ia);
    std::copy(nbr.begin(), nbr.end(), ja);
    ALEFSI_PETSC(MatCreateMPIAdj(PETSC_COMM_WORLD, local, global, ia, ja, nullptr, &adj));
    ALEFSI_PETSC(MatPartitioningCreate(PETSC_COMM_WORLD, &mp));
    ALEFSI_PETSC(MatPartitioningSetAdjacency(mp, adj));
    ALEFSI_PETSC(MatPartitioningSetNParts(mp, PetscSession::size()));
#ifdef PETSC_HAVE_PTSCOTCH
    ALEFSI_PETSC(MatPartitioningSetType(mp, MATPARTITIONINGPTSCOTCH));
#else
    ALEFSI_PETSC(MatPartitioningSetType(mp, MATPARTITIONINGPARMETIS));
#endif
    ALEFSI_PETSC(MatPartitioningSetFromOptions(mp));
    ALEFSI_PETSC(MatPartitioningApply(mp, &is));
    ALEFSI_PETSC(ISAllGather(is, &all));
    const PetscInt* p = nullptr;
    ALEFSI_PETSC(ISGetIndices(all, &p));
    for (Index c = 0; c < nc; ++c) part[std::size_t(c)] = int(p[c]);
    ALEFSI_PETSC(ISRestoreIndices(all, &p));
  } catch (...) {
    release();
    throw;
  }
  release();
  return part;
#else
  (void)mesh;
  return {};
#endif
}

/// The distributed copy of a matrix assembled on every rank, its KSP, and the vectors of a
/// solve: what PetscDirect and PetscKrylov share.
class PetscSystem {
 public:
  explicit PetscSystem(std::string prefix) : prefix_(std::move(prefix)) {
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (!up) throw PetscError("PETSc solver created before PETSc was initialised (construct an alefsi::PetscSession first)");
  }
  PetscSystem(const PetscSystem&) = delete;
  PetscSystem& operator=(const PetscSystem&) = delete;
  ~PetscSystem() {
    PetscBool down = PETSC_FALSE;
    PetscFinalized(&down);
    if (down) return;  // too late to destroy PETSc objects: left to the process's exit
    destroy_pattern();
  }

  /// The rows this rank owns and their entries' positions in the matrix's value array; the
  /// distributed matrix and vectors, preallocated from the pattern (COO); a new KSP (its type
  /// and preconditioner are set by the policy at the next factorisation: `take_first`).
  void analyze(const SparseMatrix& A) {
    ALEFSI_CHECK_ARG(A.rows() == A.cols(), "A", "must be square, got ", A.rows(), " x ", A.cols());
    check_compressed(A);
    destroy_pattern();
    try {
      build(A);
    } catch (...) {
      destroy_pattern();  // nothing half-built: the next factorisation analyses again
      throw;
    }
  }

  /// Whether `A` has another pattern than the one analysed (or none was); with summed parts,
  /// whether any rank's part has a new pattern (so that all analyse together).
  bool new_pattern(const SparseMatrix& A) const {
    int fresh = !mat_ || A.rows() != n_ || A.nonZeros() != nnz_ || detail::pattern_hash(A) != hash_;
    if (summed_ && MPI_Allreduce(MPI_IN_PLACE, &fresh, 1, MPI_INT, MPI_MAX, PETSC_COMM_WORLD) != MPI_SUCCESS)
      throw PetscError("PETSc: MPI_Allreduce of the pattern flags failed");
    return fresh != 0;
  }

  /// With `summed` (and more than one rank), the matrix each rank passes is its part (the
  /// entries of its cells: la/partition.hpp) and the distributed matrix is the sum of the parts.
  /// A row belongs to the lowest rank whose part has entries in it; PETSc numbers each rank's
  /// rows after the lower ranks' (in the library's order within a rank), so that a rank owns the
  /// rows of its cells and sends only its interface entries. Takes effect at the next analysis.
  void set_summed(bool summed) {
    summed = summed && PetscSession::size() > 1;
    if (summed == summed_) return;
    summed_ = summed;
    destroy_pattern();
  }
  bool summed() const { return summed_; }
  /// Sums `v` over the ranks, each rank getting the same bits (reduced on rank 0, broadcast).
  static void sum(VecX& v) {
    if (PetscSession::size() == 1) return;
    const int n = int(v.size());
    VecX total = PetscSession::rank() == 0 ? VecX(n) : VecX();
    if (MPI_Reduce(v.data(), PetscSession::rank() == 0 ? total.data() : nullptr, n, MPI_DOUBLE, MPI_SUM, 0,
                   PETSC_COMM_WORLD) != MPI_SUCCESS)
      throw PetscError("PETSc: MPI_Reduce of a summed vector failed");
    if (PetscSession::rank() == 0) v = std::move(total);
    if (MPI_Bcast(v.data(), n, MPI_DOUBLE, 0, PETSC_COMM_WORLD) != MPI_SUCCESS)
      throw PetscError("PETSc: MPI_Bcast of a summed vector failed");
  }
  /// Whether `b` holds on every rank.
  static bool all(bool b) {
    int v = b;
    if (MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT, MPI_LAND, PETSC_COMM_WORLD) != MPI_SUCCESS)
      throw PetscError("PETSc: MPI_Allreduce of a flag failed");
    return v != 0;
  }
  /// The elementwise minimum of `w` over the ranks.
  static void min(std::vector<int>& w) {
    if (MPI_Allreduce(MPI_IN_PLACE, w.data(), int(w.size()), MPI_INT, MPI_MIN, PETSC_COMM_WORLD) != MPI_SUCCESS)
      throw PetscError("PETSc: MPI_Allreduce of a minimum failed");
  }

  /// Copies A's values into the distributed matrix, a new pattern being analysed first (then
  /// it returns true: the caller's index sets follow the new rows). `setup` then factorises
  /// (MUMPS) or sets the preconditioner up (BoomerAMG), reusing the symbolic work of the same
  /// pattern.
  bool set_matrix(const SparseMatrix& A) {
    check_compressed(A);
    const bool fresh = new_pattern(A);  // one pass over the indices per matrix
    if (fresh) analyze(A);
    set_values(A);
    return fresh;
  }
  /// Copies the values of A, whose pattern is the one just analysed (no check).
  void set_values(const SparseMatrix& A) {
    const Real* v = A.valuePtr();
    const PetscScalar* coo = values_.data();
    if (all_entries_) {  // the COO order is A's own: its value array as it is
      ALEFSI_ASSERT(A.nonZeros() == nnz_);
      if constexpr (std::is_same_v<PetscScalar, Real>) coo = v;
      else for (Index e = 0; e < nnz_; ++e) values_[std::size_t(e)] = PetscScalar(v[e]);
    } else {
      for (std::size_t e = 0; e < position_.size(); ++e) values_[e] = PetscScalar(v[position_[e]]);
    }
    ALEFSI_PETSC(MatSetValuesCOO(mat_, coo, INSERT_VALUES));
    ALEFSI_PETSC(KSPSetOperators(ksp_, mat_, mat_));
  }
  void setup() { ALEFSI_PETSC(KSPSetUp(ksp_)); }

 private:
  // A must be compressed; with summed parts the ranks agree first (none throws alone before a
  // collective call)
  void check_compressed(const SparseMatrix& A) const {
    const bool ok = summed_ ? all(A.isCompressed()) : A.isCompressed();
    ALEFSI_CHECK_ARG(ok, "A", A.isCompressed() ? "is not compressed on another rank" : "must be compressed (makeCompressed)");
  }

  void build(const SparseMatrix& A) {
    n_ = A.rows();
    nnz_ = A.nonZeros();
    hash_ = detail::pattern_hash(A);
    PetscInt local = PETSC_DECIDE, global = PetscInt(n_);
    std::vector<PetscInt> ci, cj;
    position_.clear(), values_.clear();
    owned_.clear();
    all_entries_ = summed_;
    if (!summed_) {  // contiguous ranges of the library's numbering; each rank sets its rows
      perm_.clear();
      ALEFSI_PETSC(PetscSplitOwnership(PETSC_COMM_WORLD, &local, &global));
      PetscInt end = 0;
      if (MPI_Scan(&local, &end, 1, MPIU_INT, MPI_SUM, PETSC_COMM_WORLD) != MPI_SUCCESS)
        throw PetscError("PETSc: MPI_Scan of the row ranges failed");
      row_begin_ = Index(end - local), row_end_ = Index(end);
      for (Index i = row_begin_; i < row_end_; ++i) owned_.push_back(i);
      for (Index j = 0; j < n_; ++j)
        for (Index k = A.outerIndexPtr()[j]; k < A.outerIndexPtr()[j + 1]; ++k) {
          const Index i = A.innerIndexPtr()[k];
          if (i < row_begin_ || i >= row_end_) continue;
          ci.push_back(PetscInt(i)), cj.push_back(PetscInt(j)), position_.push_back(k);
        }
    } else {  // parts: rows owned by the lowest rank that has entries in them (set_summed)
      const int rank = PetscSession::rank(), size = PetscSession::size();
      std::vector<int> owner(std::size_t(n_), std::numeric_limits<int>::max());
      for (Index k = 0; k < nnz_; ++k) owner[std::size_t(A.innerIndexPtr()[k])] = rank;
      min(owner);
      std::vector<Index> begin(std::size_t(size) + 1, 0);
      for (Index i = 0; i < n_; ++i) {
        if (owner[std::size_t(i)] >= size)
          throw PetscError("PETSc: row " + std::to_string(i) + " of the summed matrix has no entry on any rank");
        ++begin[std::size_t(owner[std::size_t(i)]) + 1];
      }
      for (int p = 0; p < size; ++p) begin[std::size_t(p) + 1] += begin[std::size_t(p)];
      row_begin_ = begin[std::size_t(rank)], row_end_ = begin[std::size_t(rank) + 1];
      local = PetscInt(row_end_ - row_begin_);
      perm_.resize(std::size_t(n_));
      for (Index i = 0; i < n_; ++i) {
        const int p = owner[std::size_t(i)];
        perm_[std::size_t(i)] = PetscInt(begin[std::size_t(p)]++);
        if (p == rank) owned_.push_back(i);
      }
      ci.reserve(std::size_t(nnz_)), cj.reserve(std::size_t(nnz_));
      for (Index j = 0; j < n_; ++j)  // every entry of the part, in A's order: PETSc sends the others' rows
        for (Index k = A.outerIndexPtr()[j]; k < A.outerIndexPtr()[j + 1]; ++k)
          ci.push_back(perm_[std::size_t(A.innerIndexPtr()[k])]), cj.push_back(perm_[std::size_t(j)]);
    }
    // the values in COO order: the positions of the owned rows' entries (whole matrices), or
    // all of A's entries in its order (parts: no copy when PETSc's scalar is ours)
    if (!all_entries_) values_.resize(position_.size());
    else if (!std::is_same_v<PetscScalar, Real>) values_.resize(std::size_t(nnz_));
    ALEFSI_PETSC(MatCreate(PETSC_COMM_WORLD, &mat_));
    ALEFSI_PETSC(MatSetSizes(mat_, local, local, global, global));
    ALEFSI_PETSC(MatSetType(mat_, MATAIJ));
    ALEFSI_PETSC(MatSetPreallocationCOO(mat_, PetscCount(ci.size()), ci.data(), cj.data()));
    ALEFSI_PETSC(MatCreateVecs(mat_, &x_, &b_));
    ALEFSI_PETSC(VecScatterCreateToAll(x_, &gather_, &x_all_));
    ALEFSI_PETSC(KSPCreate(PETSC_COMM_WORLD, &ksp_));
    if (!prefix_.empty()) ALEFSI_PETSC(KSPSetOptionsPrefix(ksp_, prefix_.c_str()));
    first_ = true;
  }

 public:
  /// Solves with the KSP; `b` and the returned solution are whole (every rank's copy).
  VecX solve(const VecX& b) {
    ALEFSI_CHECK_ARG(b.size() == n_, "b", "has ", b.size(), " entries, the matrix ", n_, " rows");
    PetscScalar* pb = nullptr;
    ALEFSI_PETSC(VecGetArray(b_, &pb));
    for (std::size_t k = 0; k < owned_.size(); ++k) pb[k] = b[owned_[k]];
    ALEFSI_PETSC(VecRestoreArray(b_, &pb));
    ALEFSI_PETSC(KSPSolve(ksp_, b_, x_));
    KSPConvergedReason local;
    ALEFSI_PETSC(KSPGetConvergedReason(ksp_, &local));
    // a failed preconditioner may be flagged on some ranks only: agree before throwing
    int r = int(local), reason_all = 0;
    if (MPI_Allreduce(&r, &reason_all, 1, MPI_INT, MPI_MIN, PETSC_COMM_WORLD) != MPI_SUCCESS)
      throw PetscError("PETSc: MPI_Allreduce of the converged reason failed");
    const auto reason = KSPConvergedReason(reason_all);
    PetscInt its = 0;
    ALEFSI_PETSC(KSPGetIterationNumber(ksp_, &its));
    iterations_ = int(its);
    if (reason < 0) {
      PetscReal rnorm = 0;
      KSPGetResidualNorm(ksp_, &rnorm);
      char res[32];
      std::snprintf(res, sizeof res, "%.3e", double(rnorm / std::max<Real>(b.norm(), 1e-300)));
      throw SolverError(std::string("PETSc KSP did not converge: ") + KSPConvergedReasons[reason] + " after " +
                        std::to_string(its) + " iterations, relative residual " + res);
    }
    ALEFSI_PETSC(VecScatterBegin(gather_, x_, x_all_, INSERT_VALUES, SCATTER_FORWARD));
    ALEFSI_PETSC(VecScatterEnd(gather_, x_, x_all_, INSERT_VALUES, SCATTER_FORWARD));
    VecX x(n_);
    const PetscScalar* px = nullptr;
    ALEFSI_PETSC(VecGetArrayRead(x_all_, &px));
    for (Index i = 0; i < n_; ++i) x[i] = Real(px[petsc_row(i)]);
    ALEFSI_PETSC(VecRestoreArrayRead(x_all_, &px));
    return x;
  }

  KSP ksp() const { return ksp_; }
  ::Mat matrix() const { return mat_; }
  Index rows() const { return n_; }
  /// This rank's rows of PETSc's matrix [row_begin, row_end), in PETSc's numbering.
  Index row_begin() const { return row_begin_; }
  Index row_end() const { return row_end_; }
  /// The library's index of each of this rank's rows, in PETSc's order.
  const std::vector<Index>& owned() const { return owned_; }
  /// PETSc's row of the library's unknown i.
  Index petsc_row(Index i) const { return perm_.empty() ? i : Index(perm_[std::size_t(i)]); }
  int iterations() const { return iterations_; }
  const std::string& prefix() const { return prefix_; }
  /// The value of `-<prefix><name>` in the options database ("" when unset).
  std::string option(const std::string& name) const {
    char value[256] = "";
    PetscBool set = PETSC_FALSE;
    ALEFSI_PETSC(PetscOptionsGetString(nullptr, nullptr, ("-" + prefix_ + name).c_str(), value, sizeof value, &set));
    return set ? std::string(value) : std::string();
  }
  /// True once after each analysis: the KSP's type and options are set then.
  bool take_first() { return std::exchange(first_, false); }
  /// Sets `-<prefix><name> value` in PETSc's (global) options database unless the user gave that
  /// option (an option a solver set before is a default, not the user's: it is set again, so a
  /// value set in code after a solver's default is overwritten at that solver's next analysis;
  /// pass such settings on the command line, in PETSC_OPTIONS or with another prefix).
  void default_option(const char* name, const char* value) const {
    static std::set<std::string> defaults;  // the options solvers set, not the user
    const std::string key = "-" + prefix_ + name;
    PetscBool given = PETSC_FALSE;
    ALEFSI_PETSC(PetscOptionsHasName(nullptr, nullptr, key.c_str(), &given));
    if (given && !defaults.count(key)) return;
    ALEFSI_PETSC(PetscOptionsSetValue(nullptr, key.c_str(), value));
    defaults.insert(key);
  }

 private:
  void destroy_pattern() {
    n_ = nnz_ = 0;
    if (ksp_) KSPDestroy(&ksp_);
    if (gather_) VecScatterDestroy(&gather_);
    if (x_all_) VecDestroy(&x_all_);
    if (x_) VecDestroy(&x_);
    if (b_) VecDestroy(&b_);
    if (mat_) MatDestroy(&mat_);
  }

  std::string prefix_;
  KSP ksp_ = nullptr;
  ::Mat mat_ = nullptr;
  ::Vec x_ = nullptr, b_ = nullptr, x_all_ = nullptr;
  VecScatter gather_ = nullptr;
  Index n_ = 0, nnz_ = 0, row_begin_ = 0, row_end_ = 0;
  std::uint64_t hash_ = 0;
  std::vector<Index> position_;       // value-array positions of this rank's entries (COO order)
  bool all_entries_ = false;          // parts: the COO entries are all of A's, in its order
  std::vector<Index> owned_;          // the library's indices of this rank's rows (PETSc order)
  std::vector<PetscInt> perm_;        // PETSc's row of each unknown (empty: the same index)
  bool summed_ = false;
  std::vector<PetscScalar> values_;  // their values, in COO order
  int iterations_ = 0;
  bool first_ = true;
};

}  // namespace detail

namespace detail {
/// What PetscDirect and PetscKrylov share: the distributed system, and the interface of assembly
/// in parts (SummedPartsSolver, la/partition.hpp).
class PetscPolicy {
 public:
  /// Assembly in parts (la/partition.hpp): with `set_summed(true)` on more than one rank, each
  /// rank passes the matrix of its cells and the solve is with their sum (PetscSystem::set_summed).
  void set_summed(bool summed) { sys_.set_summed(summed); }
  int parts() const { return PetscSession::size(); }
  int part() const { return PetscSession::rank(); }
  /// The rank of each cell when assembling in parts (detail::petsc_partition: PT-Scotch).
  template <int Dim>
  std::vector<int> partition(const Mesh<Dim>& mesh) const {
    return detail::petsc_partition(mesh);
  }
  void sum(VecX& v) const { detail::PetscSystem::sum(v); }
  void min(std::vector<int>& w) const { detail::PetscSystem::min(w); }
  /// This rank's rows [row_begin, row_end) of PETSc's matrix.
  Index row_begin() const { return sys_.row_begin(); }
  Index row_end() const { return sys_.row_end(); }
  KSP ksp() const { return sys_.ksp(); }

 protected:
  explicit PetscPolicy(std::string prefix) : sys_(std::move(prefix)) {}
  PetscSystem sys_;
};
}  // namespace detail

/// MUMPS LU through PETSc (file comment). Options: `-pc_factor_mat_solver_type`, `-mat_mumps_*`.
class PetscDirect : public detail::PetscPolicy {
 public:
  static constexpr const char* name = "PETSc LU (MUMPS)";
  static constexpr bool direct = true;

  explicit PetscDirect(std::string prefix = "") : PetscPolicy(std::move(prefix)) {}
  void analyze(const SparseMatrix& A) { sys_.analyze(A); }
  void factorize(const SparseMatrix& A) {
    sys_.set_matrix(A);
    if (sys_.take_first()) {
      PC pc;
      ALEFSI_PETSC(KSPSetType(sys_.ksp(), KSPPREONLY));
      ALEFSI_PETSC(KSPGetPC(sys_.ksp(), &pc));
      ALEFSI_PETSC(PCSetType(pc, PCLU));
      ALEFSI_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
      ALEFSI_PETSC(KSPSetFromOptions(sys_.ksp()));
    }
    sys_.setup();
  }
  VecX solve(const VecX& b) { return sys_.solve(b); }
};

/// Options of PetscKrylov that are not PETSc's own (those come from the options database).
struct PetscKrylovOptions {
  Real tolerance = 1e-8;  ///< on ||b - K x|| / ||b|| (-ksp_rtol overrides)
  int max_iterations = 1000;
  int restart = 60;
  std::string prefix{};  ///< options prefix of this solver's KSP ("" : -ksp_type, ...)
};

/// GMRES with a fieldsplit-Schur preconditioner through PETSc (file comment). `D`: the
/// dimension (the policy's type names it, as SaddlePointGmres<D>'s does; the splits do not
/// depend on it).
template <int D>
class PetscKrylov : public detail::PetscPolicy {
 public:
  static constexpr const char* name = "PETSc GMRES+fieldsplit(Schur, BoomerAMG)";

  explicit PetscKrylov(PetscKrylovOptions opt = {}) : PetscPolicy(opt.prefix), opt_(std::move(opt)) {
    ALEFSI_CHECK_ARG(opt_.tolerance > 0 && opt_.tolerance < 1, "tolerance", "must be in (0, 1), got ", opt_.tolerance);
    ALEFSI_CHECK_ARG(opt_.max_iterations >= 1, "max_iterations", "must be positive");
    ALEFSI_CHECK_ARG(opt_.restart >= 1, "restart", "must be positive");
  }
  ~PetscKrylov() { destroy_splits(); }
  PetscKrylov(const PetscKrylov&) = delete;
  PetscKrylov& operator=(const PetscKrylov&) = delete;

  /// The space's blocks (la/saddle_point_blocks.hpp; optional): the split sizes, and the pressure
  /// mass matrix for the Schur complement of steady Stokes (mass_coefficient 0). Takes effect at
  /// the next `factorize`. Blocks that change only the time-step mass (a flow's gamma, at every
  /// change of dt) keep the analysis and the KSP.
  void set_blocks(SaddlePointBlocks blocks) {
    const bool same = analyzed_ && !use_mass_ && !mass_path(blocks) && blocks.n_pressure == split_.n_pressure &&
                      blocks.n_extra == split_.n_extra;
    blocks_ = std::move(blocks);
    if (!same) analyzed_ = false;
  }

  void analyze(const SparseMatrix& A) {
    analyzed_ = false;
    // (the same on every rank: no rank throws alone)
    ALEFSI_CHECK_ARG(!sys_.summed() || blocks_, "A",
                     "assembled in parts needs the blocks (set_blocks): a part's diagonal does not show the pressures");
    split_ = saddle_point_split(A, blocks_ ? &*blocks_ : nullptr, name);
    sys_.analyze(A);
    make_splits();
  }

  void factorize(const SparseMatrix& A) {
    if (sys_.summed()) analyzed_ = detail::PetscSystem::all(analyzed_);  // every rank takes the same path
    if (!analyzed_) {
      analyze(A);
      sys_.set_values(A);
    } else if (sys_.set_matrix(A)) {  // a new pattern (e.g. after a remesh): new splits
      analyzed_ = false;
      split_ = saddle_point_split(A, blocks_ ? &*blocks_ : nullptr, name);
      make_splits();
    }
    if (sys_.take_first()) configured_ = false;
    try {
      if (!configured_) configure(A);
      else if (use_mass_) set_schur_values(A);  // its -C part follows the matrix
    } catch (...) {
      analyzed_ = false;  // a half-configured preconditioner: a new KSP at the next factorize
      throw;
    }
    sys_.setup();
  }
  VecX solve(const VecX& b) { return sys_.solve(b); }
  /// Assembly in parts (PetscPolicy): a change of the setting analyses afresh.
  void set_summed(bool summed) {
    const bool was = sys_.summed();
    sys_.set_summed(summed);
    if (sys_.summed() != was) analyzed_ = false;
  }

  int iterations() const { return sys_.iterations(); }
  Index n_pressure() const { return split_.n_pressure; }
  Index n_extra() const { return split_.n_extra; }
  /// Whether the Schur complement is preconditioned by the pressure mass matrix (else selfp).
  bool pressure_mass() const { return use_mass_; }

 private:
  // The splits' index sets: this rank's rows of split 0 (velocities [0, nu) and bodies
  // [nu + np, n)) and of split 1 (pressures), in PETSc's numbering
  void make_splits() {
    const Index p0 = split_.n_velocity, e0 = p0 + split_.n_pressure;
    std::vector<PetscInt> rows0, rows1;
    for (std::size_t k = 0; k < sys_.owned().size(); ++k) {
      const Index i = sys_.owned()[k];
      (i >= p0 && i < e0 ? rows1 : rows0).push_back(PetscInt(sys_.row_begin() + Index(k)));
    }
    destroy_splits();
    ALEFSI_PETSC(ISCreateGeneral(PETSC_COMM_WORLD, PetscInt(rows0.size()), rows0.data(), PETSC_COPY_VALUES, &is0_));
    ALEFSI_PETSC(ISCreateGeneral(PETSC_COMM_WORLD, PetscInt(rows1.size()), rows1.data(), PETSC_COPY_VALUES, &is1_));
    analyzed_ = true;
    configured_ = false;
  }


  // The KSP's type, splits and defaults, then the options database.
  void configure(const SparseMatrix& A) {
    KSP ksp = sys_.ksp();
    PC pc;
    ALEFSI_PETSC(KSPSetType(ksp, KSPGMRES));
    ALEFSI_PETSC(KSPGMRESSetRestart(ksp, PetscInt(opt_.restart)));
    ALEFSI_PETSC(KSPSetPCSide(ksp, PC_RIGHT));
    ALEFSI_PETSC(KSPSetTolerances(ksp, PetscReal(opt_.tolerance), 0.0, PETSC_DEFAULT, PetscInt(opt_.max_iterations)));
    ALEFSI_PETSC(KSPGetPC(ksp, &pc));
    ALEFSI_PETSC(PCSetType(pc, PCFIELDSPLIT));
    ALEFSI_PETSC(PCFieldSplitSetIS(pc, "0", is0_));
    ALEFSI_PETSC(PCFieldSplitSetIS(pc, "1", is1_));
    ALEFSI_PETSC(PCFieldSplitSetType(pc, PC_COMPOSITE_SCHUR));
    ALEFSI_PETSC(PCFieldSplitSetSchurFactType(pc, PC_FIELDSPLIT_SCHUR_FACT_UPPER));
    use_mass_ = blocks_ && mass_path(*blocks_);
    if (use_mass_) {
      set_schur_matrix(A);
      ALEFSI_PETSC(PCFieldSplitSetSchurPre(pc, PC_FIELDSPLIT_SCHUR_PRE_USER, schur_pre_));
    } else {
      ALEFSI_PETSC(PCFieldSplitSetSchurPre(pc, PC_FIELDSPLIT_SCHUR_PRE_SELFP, nullptr));
    }
    // BoomerAMG as tuned for 3D elasticity-like blocks (HMIS coarsening, ext+i interpolation
    // truncated to 4 entries, strong threshold 0.5 in 3D): 5x faster than hypre's defaults on the
    // P2/P1 cavity (docs/performance.md, "PETSc and MPI")
    auto boomeramg = [&](const std::string& split, const char* strength) {
      sys_.default_option((split + "pc_type").c_str(), "hypre");
      if (sys_.option(split + "pc_type") != "hypre") return;  // the user chose another
      sys_.default_option((split + "pc_hypre_type").c_str(), "boomeramg");
      if (sys_.option(split + "pc_hypre_type") != "boomeramg") return;
      sys_.default_option((split + "pc_hypre_boomeramg_coarsen_type").c_str(), "HMIS");
      sys_.default_option((split + "pc_hypre_boomeramg_interp_type").c_str(), "ext+i");
      sys_.default_option((split + "pc_hypre_boomeramg_P_max").c_str(), "4");
      sys_.default_option((split + "pc_hypre_boomeramg_strong_threshold").c_str(), strength);
    };
    sys_.default_option("fieldsplit_0_ksp_type", "preonly");
    boomeramg("fieldsplit_0_", D == 3 ? "0.5" : "0.25");
    sys_.default_option("fieldsplit_1_ksp_type", "preonly");
    if (use_mass_)  // SSOR on the pressure mass: linear, a condition number of O(1)
      sys_.default_option("fieldsplit_1_pc_type", "sor");
    else
      boomeramg("fieldsplit_1_", "0.25");
    ALEFSI_PETSC(KSPSetFromOptions(ksp));
    configured_ = true;
  }
  // Whether the Schur complement is preconditioned by the pressure mass (steady Stokes).
  bool mass_path(const SaddlePointBlocks& b) const {
    return b.mass_coefficient == 0 && b.pressure_mass.rows() == b.n_pressure && b.n_pressure > 0;
  }
  // Visits this rank's entries of S~ (in the order set_schur_matrix and set_schur_values share):
  // f(i, j, value) with i, j in split 1's numbering; M_p's entries of this rank's pressure rows,
  // and A's pressure block in this rank's rows (its whole part when the matrix is summed).
  template <class F>
  void schur_entries(const SparseMatrix& A, F&& f) const {
    const SparseMatrix& Mp = blocks_->pressure_mass;
    const Index p0 = split_.n_velocity, np = split_.n_pressure;
    auto mine = [&](Index j) { return schur_index_[std::size_t(j)] >= schur_lo_ && schur_index_[std::size_t(j)] < schur_hi_; };
    for (Index j = 0; j < np; ++j) {
      const PetscInt sj = schur_index_[std::size_t(j)];
      for (SparseMatrix::InnerIterator it(Mp, j); it; ++it)
        if (mine(it.row())) f(schur_index_[std::size_t(it.row())], sj, -it.value() / blocks_->mu);
      for (SparseMatrix::InnerIterator it(A, p0 + j); it; ++it)  // COO sums repeated entries
        if (it.row() >= p0 && it.row() < p0 + np && (sys_.summed() || mine(it.row() - p0)))
          f(schur_index_[std::size_t(it.row() - p0)], sj, it.value());
    }
  }
  // S~ = -C - M_p / mu (PETSc's Schur complement is A_pp - B A^-1 B^T, negative: A_pp = -C),
  // in the numbering of split 1: PETSc numbers a split's unknowns in the order of its rows, so a
  // pressure's index there is the count of pressures before its row, and this rank's pressures
  // are [schur_lo_, schur_hi_).
  void set_schur_matrix(const SparseMatrix& A) {
    const Index p0 = split_.n_velocity, np = split_.n_pressure;
    std::vector<std::pair<Index, Index>> rows(static_cast<std::size_t>(np));  // (PETSc row, pressure)
    for (Index j = 0; j < np; ++j) rows[std::size_t(j)] = {sys_.petsc_row(p0 + j), j};
    std::sort(rows.begin(), rows.end());
    schur_index_.resize(std::size_t(np));
    schur_lo_ = schur_hi_ = 0;
    for (Index k = 0; k < np; ++k) {
      schur_index_[std::size_t(rows[std::size_t(k)].second)] = PetscInt(k);
      if (rows[std::size_t(k)].first < sys_.row_begin()) schur_lo_ = schur_hi_ = PetscInt(k + 1);
      else if (rows[std::size_t(k)].first < sys_.row_end()) schur_hi_ = PetscInt(k + 1);
    }
    const PetscInt lo = schur_lo_, hi = schur_hi_;
    std::vector<PetscInt> ci, cj;
    schur_entries(A, [&](Index i, Index j, Real) { ci.push_back(PetscInt(i)), cj.push_back(PetscInt(j)); });
    if (schur_pre_) MatDestroy(&schur_pre_);
    ALEFSI_PETSC(MatCreate(PETSC_COMM_WORLD, &schur_pre_));
    ALEFSI_PETSC(MatSetSizes(schur_pre_, PetscInt(hi - lo), PetscInt(hi - lo), PetscInt(np), PetscInt(np)));
    ALEFSI_PETSC(MatSetType(schur_pre_, MATAIJ));
    ALEFSI_PETSC(MatSetPreallocationCOO(schur_pre_, PetscCount(ci.size()), ci.data(), cj.data()));
    set_schur_values(A);
  }
  void set_schur_values(const SparseMatrix& A) {
    schur_values_.clear();
    schur_entries(A, [&](Index, Index, Real v) { schur_values_.push_back(PetscScalar(v)); });
    ALEFSI_PETSC(MatSetValuesCOO(schur_pre_, schur_values_.data(), INSERT_VALUES));
  }
  void destroy_splits() {
    PetscBool down = PETSC_FALSE;
    PetscFinalized(&down);
    if (down) return;
    if (is0_) ISDestroy(&is0_);
    if (is1_) ISDestroy(&is1_);
    if (schur_pre_) MatDestroy(&schur_pre_);
  }

  PetscKrylovOptions opt_;
  std::optional<SaddlePointBlocks> blocks_;
  SaddlePointSplit split_;
  IS is0_ = nullptr, is1_ = nullptr;
  ::Mat schur_pre_ = nullptr;
  std::vector<PetscScalar> schur_values_;
  std::vector<PetscInt> schur_index_;  // each pressure's index in split 1
  PetscInt schur_lo_ = 0, schur_hi_ = 0;  // this rank's range there
  bool analyzed_ = false, configured_ = false, use_mass_ = false;
};

static_assert(LinearSolver<PetscDirect> && DirectSolver<PetscDirect>, "PetscDirect must model DirectSolver");
static_assert(LinearSolver<PetscKrylov<3>>, "PetscKrylov must model LinearSolver");
static_assert(SummedPartsSolver<PetscDirect> && SummedPartsSolver<PetscKrylov<3>>,
              "the PETSc policies must take assembly in parts");

}  // namespace alefsi
