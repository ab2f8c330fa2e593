// The iterative path for 3D (la/krylov.hpp) against the direct solvers on the 3D Stokes
// systems: lid-driven cavity on box_mesh(N, N, N) (6 N^3 tetrahedra), P2/P1 and P1/P1-GLS,
// mu = 1, every boundary velocity fixed (lid z = 1: (1, 0, 0)), pressure DOF 0 pinned.
// Optionally (--mass G) a time-step mass term G * M_u is added to the velocity block (the
// (rho a0 / dt) part of an ALE step) to exercise the Cahouet–Chabard Schur approximation.
// Results and discussion: docs/solvers.md, "Iterative path for 3D".
//
//   cmake --build build/bench --target bench_krylov3d
//   OPENBLAS_NUM_THREADS=1 build/bench/bench/bench_krylov3d --sizes 8,12,16 --pairs P2P1
//
// Options: --sizes N,N,..  (default 8,16)
//          --pairs P2P1,P1P1GLS   (default both)
//          --solvers a,b,..  (default krylov,krylov-mass,umfpack): krylov (SaddlePointGmres<3>,
//                   algebraic Schur), krylov-mass (with saddle_point_blocks: pressure mass,
//                   Cahouet–Chabard when --mass > 0), krylov-ns and krylov-mass-ns (the same on
//                   the cavity assembled without the pin, the constant pressure as the
//                   solver's null space, as a closed-domain flow hands it; compared with the
//                   pinned direct solution on the pinned system's unknowns), umfpack
//                   (UmfPackLu symmetric), sparselu (SparseLu<>), bicgstab (BiCgStabIlut,
//                   tolerance --tol, 2000 iterations);
//                   with PETSc (built against alefsi::petsc): petsc (PetscKrylov<3>: GMRES +
//                   fieldsplit Schur, BoomerAMG, selfp), petsc-mass (with the blocks: the
//                   pressure mass), mumps (PetscDirect). Under `mpirun -n P` pass only these:
//                   every rank runs the others too. PETSc options after "--".
//          --parts   (PETSc solvers, under mpirun) each rank keeps only the matrix of its cells
//                   (Morton parts, la/partition.hpp) and PETSc sums the parts, as a flow does
//                   (sim/discretisation.hpp); the whole matrix is dropped before the solvers,
//                   the residual is the sum of the parts' products. Peak MB: the largest rank's.
//          --direct-max N   (default 16) largest N for the direct solvers
//          --tol T   (default 1e-8) GMRES relative tolerance; --restart M (default 60);
//          --augment K (default 2: LGMRES corrections kept across restarts, 0: GMRES(M))
//          --strength THETA, --sweeps S   AMG strength threshold (0.08) and Gauss–Seidel sweeps (1)
//          --mass G  (default 0) add G * M_u (consistent velocity mass) to the velocity block
//
// One markdown line per (pair, N, solver): unknowns, nnz, set-up (analyse + factorise) CPU s,
// solve CPU s, wall s of both, GMRES iterations, AMG levels and operator complexity, peak RSS
// (VmHWM after a reset before that solver; includes the problem, 'base' MB), ||K x - b|| / ||b||,
// and, when a direct solution is there, ||u - u_direct|| / ||u_direct|| and the same for the
// pressure modulo a constant (the mean over the pressure unknowns).
#include <malloc.h>
#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/krylov.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/la/suitesparse.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/stokes.hpp"
#include "../tests/support/stokes_systems.hpp"
#ifdef ALEFSI_HAVE_PETSC
#include "alefsi/la/petsc.hpp"
#endif

namespace {

using namespace alefsi;

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
double status_mb(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  const std::size_t n = std::strlen(key);
  while (std::getline(f, line))
    if (line.compare(0, n, key) == 0) return std::stod(line.substr(n + 1)) / 1024.0;
  return -1;
}
void reset_peak_rss() {
  malloc_trim(0);
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
}

using System = alefsi::testing::SaddleSystem;
using alefsi::testing::cavity3d;

struct Options {
  std::vector<int> sizes{8, 16};
  std::vector<std::string> pairs{"P2P1", "P1P1GLS"};
  std::vector<std::string> solvers{"krylov", "krylov-mass", "umfpack"};
  int direct_max = 16;
  double mass = 0;
  bool parts = false;
  KrylovOptions krylov;
};

bool has(const std::vector<std::string>& v, const std::string& s) {
  for (const auto& x : v)
    if (x == s) return true;
  return false;
}

template <class T>
std::vector<T> split(const std::string& s) {
  std::vector<T> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::stringstream is(item);
    T v;
    is >> v;
    out.push_back(v);
  }
  return out;
}

struct Row {
  double setup = 0, solve = 0, wall = 0, peak = 0, relres = 0;
  int iterations = -1, levels = 0;
  double complexity = 0;
};

template <class Solver>
Row run(const System& s, Solver&& solver, VecX& x) {
  Row row;
  reset_peak_rss();
  const double c0 = cpu_seconds(), w0 = wall_seconds();
  solver.analyze(s.A);
  solver.factorize(s.A);
  const double c1 = cpu_seconds();
  x = solver.solve(s.b);
  const double c2 = cpu_seconds(), w2 = wall_seconds();
  row.setup = c1 - c0;
  row.solve = c2 - c1;
  row.wall = w2 - w0;
  row.peak = status_mb("VmHWM:");
  row.relres = (s.A * x - s.b).norm() / s.b.norm();
  if constexpr (requires { solver.iterations(); solver.velocity_amg(); }) {
    row.iterations = solver.iterations();
    row.levels = solver.velocity_amg().n_levels();
    row.complexity = solver.velocity_amg().operator_complexity();
  } else if constexpr (requires { solver.iterations(); }) {
    row.iterations = solver.iterations();
  }
  return row;
}

#ifdef ALEFSI_HAVE_PETSC
/// In parts: the rank's matrix `part`, summed by PETSc; the residual sums the parts' products
/// and the peak is the largest rank's.
template <class Solver>
Row run_parts(const SparseMatrix& part, const VecX& b, Solver&& solver, VecX& x) {
  Row row;
  reset_peak_rss();
  const double c0 = cpu_seconds(), w0 = wall_seconds();
  solver.set_summed(true);
  solver.analyze(part);
  solver.factorize(part);
  const double c1 = cpu_seconds();
  x = solver.solve(b);
  const double c2 = cpu_seconds(), w2 = wall_seconds();
  row.setup = c1 - c0, row.solve = c2 - c1, row.wall = w2 - w0;
  std::vector<int> peak{-int(status_mb("VmHWM:"))};
  solver.min(peak);
  row.peak = -peak[0];
  VecX r = part * x;
  solver.sum(r);
  row.relres = (r - b).norm() / b.norm();
  if constexpr (requires { solver.iterations(); }) row.iterations = solver.iterations();
  return row;
}
#endif

template <class Pair>
void bench(const Options& o, const char* pair) {
  for (int n : o.sizes) {
    const double c0 = cpu_seconds();
#ifdef ALEFSI_HAVE_PETSC
    const int parts = o.parts ? PetscSession::size() : 1, me = o.parts ? PetscSession::rank() : 0;
#else
    const int parts = 1, me = 0;
#endif
    System s = cavity3d<Pair>(n, o.mass, parts, me);
    const double assemble = cpu_seconds() - c0;  // (in parts: the whole matrix, then the part)
    const Index rows = s.A.rows();
    const double nnz = double(s.A.nonZeros());
    if (parts > 1) s.A = SparseMatrix(), malloc_trim(0);  // the ranks keep their parts only
    const double base = status_mb("VmRSS:");
    std::optional<VecX> direct;
    // velocity and pressure errors against the direct solution, the pressure modulo a constant
    // (pinning DOF 0 leaves the constant mode nearly singular: it carries most of x - x_direct)
    const Index nu = rows - s.blocks.n_pressure - s.blocks.n_extra, np = s.blocks.n_pressure;
    auto difference = [&](const VecX& x) {
      const VecX du = x.head(nu) - direct->head(nu);
      VecX dp = x.segment(nu, np) - direct->segment(nu, np);
      dp.array() -= dp.mean();
      VecX pd = direct->segment(nu, np);
      pd.array() -= pd.mean();
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.1e / %.1e", du.norm() / direct->head(nu).norm(), dp.norm() / pd.norm());
      return std::string(buf);
    };
    auto print = [&](const char* solver, const Row& r, const VecX& x) {
      std::printf("| %s | %d | %d | %.3g | %s | %.3g | %.3g | %.3g | %s | %s | %.0f | %.1e | %s |\n", pair, n,
                  int(rows), nnz, solver, r.setup, r.solve, r.wall,
                  r.iterations >= 0 ? std::to_string(r.iterations).c_str() : "",
                  r.levels ? (std::to_string(r.levels) + " / " + std::to_string(r.complexity).substr(0, 4)).c_str() : "",
                  r.peak, r.relres,
                  direct ? difference(x).c_str() : "");
      std::fflush(stdout);
    };
    std::fprintf(stderr, "%s N = %d: %d unknowns, assembled in %.1f s CPU, base %.0f MB%s\n", pair, n, int(rows),
                 assemble, base, parts > 1 ? " (this rank, its part)" : "");
    VecX x;
#ifdef ALEFSI_HAVE_PETSC
    if (parts > 1) {  // only the PETSc solvers take parts
      const std::string label = " (" + std::to_string(parts) + " ranks, parts)";
      const PetscKrylovOptions popt{.tolerance = o.krylov.tolerance, .restart = o.krylov.restart};
      if (has(o.solvers, "mumps") && n <= o.direct_max) {
        const Row r = run_parts(s.part, s.b, PetscDirect{}, x);
        direct = x;
        print(("PETSc MUMPS LU" + label).c_str(), r, x);
      }
      for (const char* name : {"petsc", "petsc-mass"}) {
        if (!has(o.solvers, name)) continue;
        SaddlePointBlocks blocks = s.blocks;  // in parts a rank's diagonal cannot tell the pressures
        if (std::string(name) == "petsc") blocks.pressure_mass = SparseMatrix();  // PetscKrylov: selfp
        PetscKrylov<3> k(popt);
        k.set_blocks(blocks);
        const Row r = run_parts(s.part, s.b, k, x);
        print(("PETSc GMRES + fieldsplit (BoomerAMG, " + std::string(name == std::string("petsc") ? "selfp" : "pressure mass") +
               ")" + label).c_str(), r, x);
      }
      continue;
    }
#endif
#ifdef ALEFSI_HAVE_SUITESPARSE
    if (has(o.solvers, "umfpack") && n <= o.direct_max) {
      try {
        const Row r = run(s, UmfPackLu{}, x);
        direct = x;
        print("UMFPACK, symmetric", r, x);
      } catch (const SolverError& e) {
        std::printf("| %s | %d | %d | %.3g | UMFPACK, symmetric | fails: %s (peak %.0f MB) | | | | | | | |\n", pair, n,
                    int(s.A.rows()), double(s.A.nonZeros()), e.what(), status_mb("VmHWM:"));
        std::fflush(stdout);
      }
    }
#endif
    if (has(o.solvers, "sparselu") && n <= o.direct_max) {
      try {
        const Row r = run(s, SparseLu<>{}, x);
        if (!direct) direct = x;
        print("SparseLU, saddle-point AMD", r, x);
      } catch (const SolverError& e) {
        std::printf("| %s | %d | %d | %.3g | SparseLU | fails: %s | | | | | | | |\n", pair, n, int(s.A.rows()),
                    double(s.A.nonZeros()), e.what());
      }
    }
    if (has(o.solvers, "bicgstab")) {
      try {
        const Row r = run(s, BiCgStabIlut{o.krylov.tolerance, 2000}, x);
        print("BiCGSTAB + ILUT (1e-4, 20)", r, x);
      } catch (const SolverError& e) {
        std::printf("| %s | %d | %d | %.3g | BiCGSTAB + ILUT (1e-4, 20) | fails: %s | | | | | | | |\n", pair, n,
                    int(s.A.rows()), double(s.A.nonZeros()), e.what());
        std::fflush(stdout);
      }
    }
    if (has(o.solvers, "krylov")) {
      const Row r = run(s, SaddlePointGmres<3>(o.krylov), x);
      print("GMRES + AMG, lumped Schur", r, x);
    }
    if (has(o.solvers, "krylov-mass")) {
      SaddlePointGmres<3> k(o.krylov);
      k.set_blocks(s.blocks);
      const Row r = run(s, k, x);
      print(o.mass > 0 ? "GMRES + AMG, mass + Cahouet–Chabard" : "GMRES + AMG, pressure mass", r, x);
    }
    if (has(o.solvers, "krylov-ns") || has(o.solvers, "krylov-mass-ns")) {
      // unpinned: the same unknowns with pressure DOF 0 (the first pressure) kept
      const System u = cavity3d<Pair>(n, o.mass, 1, 0, false);
      auto as_pinned = [&](const VecX& y) {
        VecX v(rows);
        v.head(nu) = y.head(nu);
        v.tail(rows - nu) = y.tail(rows - nu);  // pressures 1.. and the (no) extras
        return v;
      };
      for (const char* name : {"krylov-ns", "krylov-mass-ns"}) {
        if (!has(o.solvers, name)) continue;
        const bool mass = std::string(name) == "krylov-mass-ns";
        SaddlePointGmres<3> k(o.krylov);
        k.set_pressure_null_space(true);
        if (mass) k.set_blocks(u.blocks);
        VecX y;
        const Row r = run(u, k, y);
        x = as_pinned(y);
        const char* label = !mass       ? "GMRES + AMG, lumped Schur, null space"
                            : o.mass > 0 ? "GMRES + AMG, mass + Cahouet–Chabard, null space"
                                         : "GMRES + AMG, pressure mass, null space";
        print(label, r, x);
      }
    }
#ifdef ALEFSI_HAVE_PETSC
    const std::string ranks = " (" + std::to_string(PetscSession::size()) + " rank" + (PetscSession::size() > 1 ? "s)" : ")");
    const PetscKrylovOptions popt{.tolerance = o.krylov.tolerance, .restart = o.krylov.restart};
    if (has(o.solvers, "mumps") && n <= o.direct_max) {
      const Row r = run(s, PetscDirect{}, x);
      if (!direct) direct = x;
      print(("PETSc MUMPS LU" + ranks).c_str(), r, x);
    }
    if (has(o.solvers, "petsc")) {
      const Row r = run(s, PetscKrylov<3>(popt), x);
      print(("PETSc GMRES + fieldsplit (BoomerAMG, selfp)" + ranks).c_str(), r, x);
    }
    if (has(o.solvers, "petsc-mass")) {
      PetscKrylov<3> k(popt);
      k.set_blocks(s.blocks);
      const Row r = run(s, k, x);
      print(("PETSc GMRES + fieldsplit (BoomerAMG, pressure mass)" + ranks).c_str(), r, x);
    }
#endif
  }
}

}  // namespace

int main(int argc, char** argv) {
#ifdef ALEFSI_HAVE_PETSC
  PetscSession petsc(argc, argv);
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--") argc = i;  // PETSc's options follow
  if (PetscSession::rank() > 0 && !std::freopen("/dev/null", "w", stdout)) return 1;  // rank 0 prints the table
#endif
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "missing value after %s\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--sizes") o.sizes = split<int>(next());
    else if (a == "--pairs") o.pairs = split<std::string>(next());
    else if (a == "--solvers") o.solvers = split<std::string>(next());
    else if (a == "--direct-max") o.direct_max = std::stoi(next());
    else if (a == "--tol") o.krylov.tolerance = std::stod(next());
    else if (a == "--restart") o.krylov.restart = std::stoi(next());
    else if (a == "--augment") o.krylov.augment = std::stoi(next());
    else if (a == "--strength") o.krylov.amg.strength = std::stod(next());
    else if (a == "--sweeps") o.krylov.amg.sweeps = std::stoi(next());
    else if (a == "--cycles") o.krylov.velocity_cycles = std::stoi(next());
    else if (a == "--coarse") o.krylov.amg.coarse_size = std::stoi(next());
    else if (a == "--mass") o.mass = std::stod(next());
    else if (a == "--parts") o.parts = true;
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
#ifdef ALEFSI_HAVE_PETSC
  if (o.parts && (o.mass != 0 || !(has(o.solvers, "petsc") || has(o.solvers, "petsc-mass") || has(o.solvers, "mumps")))) {
    std::fprintf(stderr, "--parts takes the PETSc solvers (petsc, petsc-mass, mumps) and no --mass\n");
    return 2;
  }
#else
  if (o.parts) {
    std::fprintf(stderr, "--parts needs PETSc (this build has none)\n");
    return 2;
  }
#endif
  std::printf("| pair | N | unknowns | nnz | solver | set-up s | solve s | wall s | its | AMG levels / complexity | peak MB | residual | vs direct: u / p |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  if (has(o.pairs, "P2P1")) bench<TaylorHood>(o, "P2/P1");
  if (has(o.pairs, "P1P1GLS")) bench<P1P1Gls>(o, "P1/P1-GLS");
  return 0;
}
