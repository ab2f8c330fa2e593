// Direct solvers on the 2D unit-square systems: the steady Stokes matrix (driven cavity,
// P2/P1 and P1/P1-GLS) with every linear-solver policy available, and the SPD mesh-velocity
// (elasticity) matrix with the Cholesky policies. Results and discussion: docs/solvers.md.
//
//   cmake --preset bench && cmake --build --preset bench --target bench_solvers
//   OPENBLAS_NUM_THREADS=1 build/bench/bench/bench_solvers                      # N = 64 128 256
//   build/bench/bench/bench_solvers --sizes 32,64 --pairs P2P1 --repeat 5 --solvers saddle,umfpack-sym
//
// Options: --sizes N,N,..  (default 64,128,256; N squares per side, each cut in two)
//          --pairs P2P1,P1P1GLS,MESH   (default all three; MESH = the mesh-velocity problem)
//          --solvers a,b,..  (default all available): saddle (SparseLu<>, saddle-point AMD),
//                   amd (SparseLu<AMDOrdering>), colamd (SparseLu<COLAMD>), umfpack-sym,
//                   umfpack-auto (UmfPackLu strategies), simplicial (SimplicialLlt), cholmod
//          --repeat R   (default 3) runs of analyse + factorise + solve; each phase's minimum
//          --colamd-max N   (default 128) largest N for COLAMD (N = 256 takes minutes)
//          --pivot-threshold T   SparseLU's diagonal pivot threshold for the symmetric
//                   orderings (saddle, amd; default SparseLu's, 1e-6)
//          --precision M   instead of the table: SparseLU (saddle-point AMD) factors in double
//                   and in single precision as GMRES preconditioners (factorisation reuse,
//                   la/linear_solve.hpp), by la/gmres.hpp, plain and flexible (FGMRES), on the
//                   flow matrices (P2P1, P1P1GLS; MESH is skipped) with a mass term M times
//                   the velocity diagonal added (the rho / dt of a time step; 0: steady Stokes)
//
//   OPENBLAS_NUM_THREADS=1 build/bench/bench/bench_solvers --pairs P1P1GLS --sizes 144 --precision 5
//
// One line per (problem, N, solver), markdown table: unknowns, nnz, analyse / factorise /
// solve CPU seconds (process CPU time, so BLAS threads count; minimum over the repeats),
// factorise wall seconds (minimum), nnz(L+U) (L only for Cholesky), fill = that / nnz(A),
// peak RSS of the process during the runs of that solver (VmHWM after resetting it; includes
// the problem, about 'base' MB) and ||A x - b|| / ||b||.
// The machine is shared: CPU time is the figure to compare; wall time is printed as a check.
#include <malloc.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/gmres.hpp"
#include "alefsi/la/ordering.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/la/suitesparse.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/mesh_motion.hpp"
#include "alefsi/physics/stokes.hpp"

namespace {

using namespace alefsi;

// ---- clocks and memory -------------------------------------------------------------------
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
    if (line.compare(0, n, key) == 0) return std::stod(line.substr(n + 1)) / 1024.0;  // kB -> MB
  return -1;
}
// Returns freed heap to the OS and resets the peak RSS (VmHWM) to the current RSS.
void reset_peak_rss() {
  malloc_trim(0);
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
}

// ---- the systems ---------------------------------------------------------------------------
struct LinearSystem {
  SparseMatrix A;
  VecX b;
};

// Driven cavity: every boundary velocity fixed (lid (1, 0)), pressure DOF 0 pinned, mu = 1;
// with `mass` > 0 the velocity diagonal times 1 + mass (a time step's lumped rho / dt, `mass`
// times the viscous diagonal).
template <class Pair>
LinearSystem stokes_system(int n, double mass = 0) {
  const Mesh<2> mesh = rectangle_mesh(n, n);
  MixedSpace<2, Pair> space(mesh);
  StokesKernel<2, Pair> kernel(space, 1.0);
  DofConstraints cons(space.n_field());
  const auto& vel = space.velocity();
  std::vector<char> done(vel.n_dofs(), 0);
  std::vector<int> order{tags::top};
  for (int t = 1; t <= 4; ++t)
    if (t != tags::top) order.push_back(t);
  for (int t : order)
    for (Index i : vel.boundary_dofs(t)) {
      if (done[i]) continue;
      done[i] = 1;
      for (int k = 0; k < 2; ++k) cons.fix(space.velocity_field(i, k), (t == tags::top && k == 0) ? 1.0 : 0.0);
    }
  cons.fix(space.pressure_field(0), 0.0);
  cons.finalize();
  Assembler<MixedSpace<2, Pair>::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); },
                                               cons);
  LinearSystem s;
  VecX r;
  asmb.assemble(kernel, cons.expand(VecX::Zero(cons.n_unknowns())), &s.A, &r);
  s.b = -r;
  if (mass > 0) {
    VecX velocity = VecX::Zero(space.n_field());
    for (Index i = 0; i < vel.n_dofs(); ++i)
      for (int k = 0; k < 2; ++k) velocity[space.velocity_field(i, k)] = 1;
    const VecX free = cons.restrict_free(velocity);
    for (Index i = 0; i < s.A.rows(); ++i)
      if (free[i] == 1) s.A.coeffRef(i, i) *= 1 + mass;
  }
  return s;
}

// A solver policy that hands the matrix and right-hand side it is given to the benchmark:
// ElasticMeshMotion assembles its matrix internally.
struct Capture {
  static constexpr const char* name = "capture";
  LinearSystem* out;
  void analyze(const SparseMatrix&) {}
  void factorize(const SparseMatrix& A) { out->A = A; }
  VecX solve(const VecX& b) {
    out->b = b;
    return VecX::Zero(b.size());
  }
};
LinearSystem* g_capture = nullptr;
struct GlobalCapture : Capture {
  GlobalCapture() : Capture{g_capture} {}
};

// The mesh-velocity (elasticity, lambda = -mu = -1/|K|) system on the unit square with the
// interior nodes displaced smoothly (cells of varying size) and walls rotating about the centre.
LinearSystem mesh_velocity_system(int n) {
  const Mesh<2> mesh = rectangle_mesh(n, n);
  std::vector<Vec<2>> x = mesh.coordinates();
  for (auto& p : x)
    p += 0.1 * Vec<2>(std::sin(3 * p[1]), std::cos(2 * p[0])).cwiseProduct(p.cwiseProduct(Vec<2>::Ones() - p));
  LinearSystem s;
  g_capture = &s;
  ElasticMeshMotion<2, GlobalCapture> motion(mesh);
  motion.solve(x, [](Index, const Vec<2>& p) { return Vec<2>(-(p[1] - 0.5), p[0] - 0.5); });
  g_capture = nullptr;
  return s;
}

// ||A x - b|| / ||b|| with plain loops (Eigen's AVX-512 norm() trips GCC 12's
// -Wmaybe-uninitialized under -march=native).
Real relative_residual(const SparseMatrix& A, const VecX& x, const VecX& b) {
  VecX r = -b;
  for (Index j = 0; j < A.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) r[it.row()] += it.value() * x[j];
  double rr = 0, bb = 0;
  for (Index i = 0; i < b.size(); ++i) rr += r[i] * r[i], bb += b[i] * b[i];
  return std::sqrt(rr / bb);
}

// Factors in double and in single precision as right preconditioners to 1e-13 (the
// factorisation reuse's tolerance), by la/gmres.hpp's GMRES, plain and flexible: on the
// factorised matrix itself and on a later matrix of the same pattern, each entry moved by an
// independent random relative amount in [-1e-3, 1e-3]. Prints the times and the applications
// of P^-1 (a plain GMRES cycle applies it once more than its steps).
template <class Pair>
void precision_study(const std::string& pair, int n, double mass, int repeat, double pivot_threshold) {
  const LinearSystem s = stokes_system<Pair>(n, mass);
  SparseMatrix later = s.A;
  unsigned state = 12345;  // a fixed sequence: the same perturbation every run
  for (Index k = 0; k < later.nonZeros(); ++k) {
    state = state * 1664525u + 1013904223u;
    later.valuePtr()[k] *= 1 + 1e-3 * (double(state) / 4294967296.0 * 2 - 1);
  }
  using SpF = Eigen::SparseMatrix<float, Eigen::ColMajor, Index>;
  Eigen::SparseLU<SparseMatrix, SaddlePointAmdOrdering<Index>> lu;
  Eigen::SparseLU<SpF, SaddlePointAmdOrdering<Index>> luf;
  const double t = pivot_threshold < 0 ? SparseLu<>::default_pivot_threshold : pivot_threshold;
  lu.isSymmetric(true), luf.isSymmetric(true);
  lu.setPivotThreshold(t), luf.setPivotThreshold(float(t));
  const SpF Af = s.A.cast<float>();
  lu.analyzePattern(s.A), luf.analyzePattern(Af);
  double fd = 1e300, ff = 1e300, sd = 1e300, sf = 1e300;
  VecX x;
  Eigen::VectorXf xf;
  const Eigen::VectorXf bf = s.b.cast<float>();
  for (int r = 0; r < repeat; ++r) {
    double c0 = cpu_seconds();
    lu.factorize(s.A);
    double c1 = cpu_seconds();
    luf.factorize(Af);
    double c2 = cpu_seconds();
    fd = std::min(fd, c1 - c0), ff = std::min(ff, c2 - c1);
    c0 = cpu_seconds();
    for (int k = 0; k < 10; ++k) x = lu.solve(s.b);
    c1 = cpu_seconds();
    for (int k = 0; k < 10; ++k) xf = luf.solve(bf);  // without the casts of a double vector
    c2 = cpu_seconds();
    sd = std::min(sd, (c1 - c0) / 10), sf = std::min(sf, (c2 - c1) / 10);
  }
  if (lu.info() != Eigen::Success || luf.info() != Eigen::Success) {
    std::printf("| %s | %d | factorisation failed |\n", pair.c_str(), n);
    return;
  }
  int applications = 0;
  auto pd = [&](const VecX& v) { return ++applications, VecX(lu.solve(v)); };
  auto pf = [&](const VecX& v) { return ++applications, VecX(luf.solve(v.cast<float>()).cast<double>()); };
  GmresWork work;
  // "n/c": the tolerance not met in 200
  auto count = [&](const SparseMatrix& M, auto& precondition, bool flexible) {
    applications = 0;
    const GmresOptions opt{.tolerance = 1e-13, .max_iterations = 200, .restart = 200, .flexible = flexible};
    return gmres(M, s.b, precondition, opt, x, work).converged ? std::to_string(applications) : std::string("n/c");
  };
  std::string cols;
  for (const SparseMatrix* M : std::array<const SparseMatrix*, 2>{&s.A, &later})
    for (bool flexible : {false, true})
      cols += " " + count(*M, pd, flexible) + " / " + count(*M, pf, flexible) + " |";
  std::printf("| %s | %d | %d | %g | %.3f / %.3f | %.4f / %.4f | %.1e / %.1e |%s\n", pair.c_str(), n, int(s.A.rows()),
              mass, fd, ff, sd, sf, relative_residual(s.A, lu.solve(s.b), s.b),
              relative_residual(s.A, luf.solve(bf).cast<double>(), s.b), cols.c_str());
  std::fflush(stdout);
}

// ---- one solver on one system ----------------------------------------------------------------
struct Result {
  double analyse = 1e300, factorise = 1e300, solve = 1e300, factorise_wall = 1e300;
  double factor_nnz = 0, peak_mb = 0, relres = 0;
};

template <class Solver, class Make>
Result run(const LinearSystem& s, int repeat, Make make) {
  Result res;
  reset_peak_rss();
  for (int k = 0; k < repeat; ++k) {
    Solver solver = make();
    const double c0 = cpu_seconds();
    solver.analyze(s.A);
    const double c1 = cpu_seconds(), w1 = wall_seconds();
    solver.factorize(s.A);
    const double c2 = cpu_seconds(), w2 = wall_seconds();
    const VecX x = solver.solve(s.b);
    const double c3 = cpu_seconds();
    res.analyse = std::min(res.analyse, c1 - c0);
    res.factorise = std::min(res.factorise, c2 - c1);
    res.factorise_wall = std::min(res.factorise_wall, w2 - w1);
    res.solve = std::min(res.solve, c3 - c2);
    res.factor_nnz = double(solver.factor_nonzeros());
    res.relres = relative_residual(s.A, x, s.b);
  }
  res.peak_mb = status_mb("VmHWM:");
  return res;
}

struct Options {
  std::vector<int> sizes{64, 128, 256};
  std::vector<std::string> pairs{"P2P1", "P1P1GLS", "MESH"};
  std::vector<std::string> solvers;
  int repeat = 3;
  int colamd_max = 128;
  double pivot_threshold = -1;  // < 0: SparseLu's default
  double precision_mass = -1;   // >= 0: the precision study with this mass term
};

bool wanted(const Options& o, const std::string& s) {
  return o.solvers.empty() || std::find(o.solvers.begin(), o.solvers.end(), s) != o.solvers.end();
}

void print_row(const std::string& problem, int n, const LinearSystem& s, const std::string& solver, double base_mb,
               const Result& r) {
  std::printf("| %s | %d | %d | %.3g | %s | %.3f | %.3f | %.3f | %.3f | %.3g | %.1f | %.0f | %.0f | %.1e |\n",
              problem.c_str(), n, int(s.A.rows()), double(s.A.nonZeros()), solver.c_str(), r.analyse, r.factorise,
              r.factorise_wall, r.solve, r.factor_nnz, r.factor_nnz / double(s.A.nonZeros()), r.peak_mb, base_mb,
              r.relres);
  std::fflush(stdout);
}

void flow_problem(const Options& o, const std::string& pair, int n) {
  const LinearSystem s = pair == "P2P1" ? stokes_system<TaylorHood>(n) : stokes_system<P1P1Gls>(n);
  reset_peak_rss();
  const double base = status_mb("VmRSS:");
  auto go = [&](const char* key, const char* label, auto make) {
    using Solver = decltype(make());
    if (!wanted(o, key)) return;
    try {
      print_row(pair, n, s, label, base, run<Solver>(s, o.repeat, make));
    } catch (const SolverError& e) {
      std::printf("| %s | %d | %d | %.3g | %s | failed: %s |\n", pair.c_str(), n, int(s.A.rows()), double(s.A.nonZeros()),
                  label, e.what());
    }
  };
  const double t = o.pivot_threshold;
  go("saddle", "SparseLU, saddle-point AMD", [t] { return t < 0 ? SparseLu<>() : SparseLu<>(t); });
  go("amd", "SparseLU, AMD", [t] {
    using Lu = SparseLu<Eigen::AMDOrdering<Index>>;
    return t < 0 ? Lu() : Lu(t);
  });
  if (n <= o.colamd_max)
    go("colamd", "SparseLU, COLAMD", [] { return SparseLu<Eigen::COLAMDOrdering<Index>>(); });
#ifdef ALEFSI_HAVE_SUITESPARSE
  go("umfpack-sym", "UMFPACK, symmetric", [] { return UmfPackLu(UmfPackLu::Strategy::symmetric); });
  go("umfpack-auto", "UMFPACK, auto", [] { return UmfPackLu(UmfPackLu::Strategy::automatic); });
#endif
}

void mesh_problem(const Options& o, int n) {
  const LinearSystem s = mesh_velocity_system(n);
  reset_peak_rss();
  const double base = status_mb("VmRSS:");
  auto go = [&](const char* key, const char* label, auto make) {
    using Solver = decltype(make());
    if (!wanted(o, key)) return;
    try {
      print_row("MESH", n, s, label, base, run<Solver>(s, o.repeat, make));
    } catch (const SolverError& e) {
      std::printf("| MESH | %d | %d | %.3g | %s | failed: %s |\n", n, int(s.A.rows()), double(s.A.nonZeros()), label,
                  e.what());
    }
  };
  go("simplicial", "SimplicialLLT", [] { return SimplicialLlt(); });
#ifdef ALEFSI_HAVE_SUITESPARSE
  go("cholmod", "CHOLMOD supernodal", [] { return CholmodLlt(); });
#endif
  go("saddle", "SparseLU, saddle-point AMD", [] { return SparseLu<>(); });
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], val = argv[i + 1];
    if (key == "--sizes") {
      o.sizes.clear();
      for (const auto& v : split(val)) o.sizes.push_back(std::stoi(v));
    } else if (key == "--pairs") {
      o.pairs = split(val);
    } else if (key == "--solvers") {
      o.solvers = split(val);
    } else if (key == "--repeat") {
      o.repeat = std::max(1, std::stoi(val));
    } else if (key == "--colamd-max") {
      o.colamd_max = std::stoi(val);
    } else if (key == "--pivot-threshold") {
      o.pivot_threshold = std::stod(val);
    } else if (key == "--precision") {
      o.precision_mass = std::stod(val);
    } else {
      std::fprintf(stderr, "unknown option %s (see the comment at the top of bench/bench_solvers.cpp)\n", key.c_str());
      return 2;
    }
  }
  if (argc % 2 == 0) {
    std::fprintf(stderr, "options come in pairs: --key value\n");
    return 2;
  }
  const char* blas_threads = std::getenv("OPENBLAS_NUM_THREADS");
  std::printf("# bench_solvers: repeat %d (minimum CPU time), OPENBLAS_NUM_THREADS=%s, pivot threshold %g, SuiteSparse %s\n",
              o.repeat, blas_threads ? blas_threads : "(unset)",
              o.pivot_threshold < 0 ? SparseLu<>::default_pivot_threshold : o.pivot_threshold,
#ifdef ALEFSI_HAVE_SUITESPARSE
              "yes"
#else
              "no"
#endif
  );
  if (o.precision_mass >= 0) {
    std::printf("| problem | N | unknowns | mass | factorise s, double / single | solve s, double / single | "
                "rel. residual, double / single | P^-1 applications to 1e-13, same matrix: GMRES, double / single | "
                "flexible GMRES | later matrix: GMRES | flexible GMRES |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const auto& pair : o.pairs)
      for (int n : o.sizes) {
        if (pair == "P2P1") precision_study<TaylorHood>(pair, n, o.precision_mass, o.repeat, o.pivot_threshold);
        else if (pair == "P1P1GLS") precision_study<P1P1Gls>(pair, n, o.precision_mass, o.repeat, o.pivot_threshold);
      }
    return 0;
  }
  std::printf("| problem | N | unknowns | nnz | solver | analyse s | factorise s | factorise wall s | solve s | "
              "nnz(L+U) | fill | peak MB | base MB | rel. residual |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& pair : o.pairs)
    for (int n : o.sizes) {
      if (pair == "MESH")
        mesh_problem(o, n);
      else if (pair == "P2P1" || pair == "P1P1GLS")
        flow_problem(o, pair, n);
      else
        std::fprintf(stderr, "unknown problem %s\n", pair.c_str());
    }
  return 0;
}
