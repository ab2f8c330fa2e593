// Benchmarks of steady-Stokes assembly and of the SparseLU direct solve, on the structured
// unit square / unit cube: TaylorHood (P2/P1, "P2P1") and P1P1Gls ("P1P1GLS"), 2D and 3D.
// Results and their discussion: docs/performance.md.
//
//   cmake --preset bench && cmake --build --preset bench --target bench_assembly
//   bench/run_assembly.sh [assembly|lu|lu-long|all]
//   build/bench/bench/bench_assembly --benchmark_filter='P2P1/2D/(kernel|assemble)/512/'
//
// Benchmarks (N = cells per side of rectangle_mesh / box_mesh):
//   <pair>/<D>D/pattern/N    what a user pays before the first fill: Assembler construction (cell DOF
//                            copy, pattern by node groups, positions, schedule) + take_pattern into a new
//                            matrix (its row indices written, its values allocated); the previous
//                            assembler and matrix are released outside the timing. Counters: ctor_ms,
//                            take_ms (CPU per iteration), faults (minor page faults per iteration),
//                            first_fill_ms and fill_ms (CPU of the first Stokes assembly into the new
//                            matrix, which first touches its values, and of a second one)
//   <pair>/<D>D/repattern/N  the same with Assembler::rebuild and take_pattern into the previous matrix
//                            (a remesh that reuses the previous pattern's memory)
//   <pair>/<D>D/kernel/N     gather + StokesKernel::cell over all cells, no scatter
//   <pair>/<D>D/kernel_quad/N  the same with StokesQuadratureKernel (the former kernel, now the test
//                            oracle in tests/support/oracle_kernels.hpp, for reference)
//   <pair>/<D>D/scatter/N    Assembler::scatter of one fixed element matrix/residual for every cell
//   <pair>/<D>D/assemble/N   Assembler::assemble (zero J, gather, kernel, scatter), matrix + residual
//   <pair>/<D>D/assemble_t2/N  the same on 2 threads (Assembler::set_threads(2))
//   <pair>/<D>D/ns_<lin>[_kernel|_t2]/N  the same (assemble; kernel alone; 2 threads) with
//                            AleNavierStokesKernel, Newton or semi-implicit (see NsInputs)
//   <pair>/<D>D/ns_newton_kernel_quad/N  AleNavierStokesQuadratureKernel (the former kernel, the oracle) alone
//   <pair>/<D>D/lu_<ord>/N   SparseLu<ord>: analyse, factorise, solve (times as counters), fill
// Constraints as in Stokes::solve with every boundary tag Dirichlet: every velocity DOF on a
// boundary facet fixed (lid velocity (1,0[,0]) on the top / ymax side, 0 elsewhere) and
// pressure DOF 0 pinned. mu = 1, no body force. Single thread.
//
// Timing: every benchmark but lu measures the process CPU time (the CPU column: all threads)
// and reports rates per wall second (UseRealTime: the Time column is wall time). Counters:
// cells, dofs (unknowns after constraints), nnz, el/s (cells * iterations per wall second; per
// CPU second: cells / the CPU column), GFLOP/s (kernel: the nominal flop count of
// StokesKernel::cell per wall second, see flops_per_cell below), peak_MB (VmHWM of the process during that
// benchmark: malloc_trim + /proc/self/clear_refs at its start, so it includes the problem, the
// assembler and whatever the benchmark allocates).
// LU: analyse_s, factorise_s, solve_s (wall clock) and *_cpu_s (thread CPU time), LU_nnz
// (nonzeros of L + U), fill (LU_nnz / nnz), relres (||J x - b|| / ||b||).
//
// The problem (mesh, space, constraints, kernel, assembler) of the current size is cached
// between the benchmarks of that size, which are registered size-major.
#include <benchmark/benchmark.h>

#include <malloc.h>
#include <sys/resource.h>
#include <time.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/navier_stokes.hpp"
#include "alefsi/physics/stokes.hpp"

#include "../tests/support/oracle_kernels.hpp"  // the former kernels, timed for reference

namespace {

using namespace alefsi;

// ---- memory --------------------------------------------------------------------------
// Returns freed heap to the OS and resets the process's peak RSS (VmHWM) to its current RSS.
void reset_peak_rss() {
  malloc_trim(0);
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
}
double status_mb(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  const std::size_t n = std::strlen(key);
  while (std::getline(f, line))
    if (line.compare(0, n, key) == 0) return std::stod(line.substr(n + 1)) / 1024.0;  // kB -> MB
  return -1;
}
double peak_mb() { return status_mb("VmHWM:"); }

// ---- the problem -----------------------------------------------------------------------
// short names for the benchmark labels (no '/', so that filters stay simple)
template <class Pair>
constexpr const char* label = std::is_same_v<Pair, TaylorHood> ? "P2P1" : "P1P1GLS";
// the pair carries the GLS/PSPG terms (flop counts below)
template <class Pair>
constexpr bool gls = std::is_same_v<typename Pair::Stabilisation, GlsStabilisation>;

template <int D>
Mesh<D> make_mesh(int n) {
  if constexpr (D == 2)
    return rectangle_mesh(n, n);
  else
    return box_mesh(n, n, n);
}

template <int D, class Pair>
struct Problem {
  using Space = MixedSpace<D, Pair>;
  using Kernel = StokesKernel<D, Pair>;
  using QuadKernel = testing::StokesQuadratureKernel<D, Pair>;
  using NsKernel = AleNavierStokesKernel<D, Pair>;
  using NsQuadKernel = testing::AleNavierStokesQuadratureKernel<D, Pair>;
  using Asm = Assembler<Space::n_local>;
  static constexpr int lid_tag = D == 2 ? tags::top : tags::ymax;

  explicit Problem(int n)
      : mesh(make_mesh<D>(n)), space(mesh), cons(space.n_field()), kernel(space, 1.0), quad_kernel(space, 1.0),
        ns_newton(space, 1.0, 0.01, Linearisation::newton), ns_semi(space, 1.0, 0.01, Linearisation::semi_implicit),
        ns_newton_quad(space, 1.0, 0.01, Linearisation::newton) {
    const auto& vel = space.velocity();
    std::vector<char> done(vel.n_dofs(), 0);
    // the lid first so that its edge/corner DOFs take the lid value, as in a driven cavity
    std::vector<int> tag_order{lid_tag};
    for (int t = 1; t <= 2 * D; ++t)
      if (t != lid_tag) tag_order.push_back(t);
    for (int t : tag_order)
      for (Index i : vel.boundary_dofs(t)) {
        if (done[i]) continue;
        done[i] = 1;
        for (int k = 0; k < D; ++k) cons.fix(space.velocity_field(i, k), (t == lid_tag && k == 0) ? 1.0 : 0.0);
      }
    cons.fix(space.pressure_field(0), 0.0);
    cons.finalize();
    field = cons.expand(VecX::Zero(cons.n_unknowns()));
    // NS step inputs (NsInputs): BDF2 (a0 = 3/2), dt = 0.01, theta = 1, smooth non-zero
    // velocity fields for u^n, the history and u*, a rotating mesh velocity, no body force
    auto smooth = [&](Real phase) {
      VecX v = field;
      for (Index i = 0; i < vel.n_dofs(); ++i) {
        const Vec<D> x = vel.point(i);
        for (int k = 0; k < D; ++k) v[space.velocity_field(i, k)] = std::sin(3 * x[k] + phase) * std::cos(2 * x[(k + 1) % D]);
      }
      return v;
    };
    ns_field = smooth(0.0);
    previous = smooth(0.1);
    history = -2.0 * smooth(0.1) + 0.5 * smooth(0.2);
    extrapolated = smooth(0.05);
    mesh_velocity.resize(mesh.n_nodes());
    for (Index v = 0; v < mesh.n_nodes(); ++v) {
      const Vec<D> x = mesh.node(v);
      mesh_velocity[v] = Vec<D>::Zero();
      mesh_velocity[v][0] = 0.1 * (x[1] - 0.5);
      mesh_velocity[v][1] = -0.1 * (x[0] - 0.5);
    }
    StepInputs<D> in;
    in.dt = 0.01;
    in.theta = 1;
    in.a0 = 1.5;
    in.history = &history;
    in.previous = &previous;
    in.extrapolated = &extrapolated;
    in.mesh_velocity = &mesh_velocity;
    ns_newton.set_step(in);
    ns_semi.set_step(in);
    ns_newton_quad.set_step(in);
  }

  std::unique_ptr<Asm> build_assembler() const {
    return std::make_unique<Asm>(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
  }
  Asm& assembler() {
    if (!asmb) asmb = build_assembler();
    return *asmb;
  }

  Mesh<D> mesh;
  Space space;
  DofConstraints cons;
  Kernel kernel;
  QuadKernel quad_kernel;
  NsKernel ns_newton, ns_semi;
  NsQuadKernel ns_newton_quad;
  VecX field, ns_field, previous, history, extrapolated;
  std::vector<Vec<D>> mesh_velocity;
  std::unique_ptr<Asm> asmb;
};

// One problem alive at a time (type-erased), rebuilt when the (D, pair, N) key changes.
std::shared_ptr<void> g_problem;
std::string g_key;

template <int D, class Pair>
std::string problem_key(int n) {
  return std::string(label<Pair>) + "/" + std::to_string(D) + "/" + std::to_string(n);
}

// Call at the start of a benchmark: drops the cached problem if it is another one, then
// resets the peak RSS, then returns the (possibly new) problem. peak_MB thus covers what the
// benchmark holds: its problem (built now or cached) and what it allocates itself.
template <int D, class Pair>
Problem<D, Pair>& problem(int n) {
  const std::string key = problem_key<D, Pair>(n);
  if (key != g_key) {
    g_problem.reset();
    g_key.clear();
  }
  reset_peak_rss();
  if (key != g_key) {
    g_problem = std::make_shared<Problem<D, Pair>>(n);
    g_key = key;
  }
  return *static_cast<Problem<D, Pair>*>(g_problem.get());
}

// ---- nominal flop counts -------------------------------------------------------------------
// One flop per + - * (a multiply-add = 2 flops), counted from the code as written, useful lanes
// only (not the padding of AffineStokesForms' arrays), no body force.
//
// StokesKernel::cell (reference integrals, physics/affine_forms.hpp), with np_ = nv (nv + 1) / 2
// velocity pairs and n = D nv + np:
//   J, J^-1, det J                     D^2 + (10 in 2D, 50 in 3D)
//   gradient_pairs: det J J^-1 (D^2), T and B: 2 D^2 (2D - 1) np_
//   add_viscous per pair: trace (D - 1), * s (1 + D^2), diagonal + (D), += into A (D^2, and
//     D^2 more for the mirror block when a != b)
//   add_divergence: D^2 (scale) + D (2D - 1) nv np (contraction) + 4 D nv np (two scaled +=)
//   add_pressure_laplacian (GLS): J^-1 J^-T (D^2 (2D - 1)) + scale (D^2 + 1), per pressure pair
//     a <= b: 2 D^2, += (1, mirror 1)
//   r = A u: 2 n^2
template <int D, class Pair>
double flops_per_cell() {
  using K = StokesKernel<D, Pair>;
  constexpr double nv = K::nv, np = K::np, n = K::n_local, d = D;
  const double npairs = nv * (nv + 1) / 2, ppairs = np * (np + 1) / 2;
  double f = d * d + (D == 2 ? 10 : 50);
  f += d * d + 2 * d * d * (2 * d - 1) * npairs;
  f += npairs * ((d - 1) + 1 + d * d + d + d * d) + (npairs - nv) * d * d;
  f += d * d + d * (2 * d - 1) * nv * np + 4 * d * nv * np;
  if (gls<Pair>) f += d * d * (2 * d - 1) + d * d + 1 + ppairs * 2 * d * d + ppairs + (ppairs - np);
  return f + 2 * n * n;
}

// StokesQuadratureKernel::cell (the former kernel), with the loop-invariant w * mu (and w * tau)
// hoisted once per quadrature point. Per quadrature point q:
//   G = dphi_v[q] * Jinv                     2 nv D^2
//   viscous (a, b):  dot 2D, * 1, diag +D, off-diag D^2 * (2 mul + 1 add)
//                                            nv^2 (3D + 1 + 3D^2)
//   divergence (a, b, i): -w php G, two +=   4 nv np D
//   GLS: Gp 2 np D^2; pressure block np^2 (2D + 2); load np (2D + 2)
// Per cell: J (D^2 subtractions), inverse + determinant (~10 in 2D, ~50 in 3D), r = A u - F
// (2 n^2). The quadrature has 12 (2D) / 24 (3D) points for P2/P1 (degree 6), 6 / 14 for
// P1/P1 (degree 4).
template <int D, class Pair>
double quad_flops_per_cell() {
  using K = testing::StokesQuadratureKernel<D, Pair>;
  constexpr double nv = K::nv, np = K::np, n = K::n_local, d = D;
  const int nq = simplex_quadrature<D>(2 * K::V::degree + 2).size();
  double per_q = 2 * nv * d * d + nv * nv * (3 * d + 1 + 3 * d * d) + 4 * nv * np * d;
  if (gls<Pair>) per_q += 2 * np * d * d + np * np * (2 * d + 2) + np * (2 * d + 2);
  const double per_cell = d * d + (D == 2 ? 10 : 50) + 2 * n * n;
  return nq * per_q + per_cell;
}

// ||J x - b|| / ||b|| with plain loops (Eigen's AVX-512 norm() trips GCC 12's
// -Wmaybe-uninitialized inside the intrinsics headers, an error under -Werror).
double rel_residual(const SparseMatrix& J, const VecX& x, const VecX& b) {
  VecX res = -b;
  for (Index j = 0; j < J.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(J, j); it; ++it) res[it.row()] += it.value() * x[j];
  double rr = 0, bb = 0;
  for (Index i = 0; i < b.size(); ++i) rr += res[i] * res[i], bb += b[i] * b[i];
  return std::sqrt(rr / bb);
}

template <class Asm>
void size_counters(benchmark::State& state, const Asm& asmb) {
  state.counters["cells"] = double(asmb.n_cells());
  state.counters["dofs"] = double(asmb.n_unknowns());
  state.counters["nnz"] = double(asmb.n_nonzeros());
}

// ---- benchmarks ----------------------------------------------------------------------------
// Rates per wall second (the benchmarks are registered with UseRealTime) and per process-CPU
// second (MeasureProcessCPUTime: the CPU column covers every thread).
void rate_counters(benchmark::State& state, double cells_per_iteration, double flops_per_el = 0) {
  const double el = cells_per_iteration * double(state.iterations());
  state.counters["el/s"] = benchmark::Counter(el, benchmark::Counter::kIsRate);
  if (flops_per_el > 0) {
    state.counters["GFLOP/s"] = benchmark::Counter(el * flops_per_el * 1e-9, benchmark::Counter::kIsRate);
    state.counters["flop/el"] = flops_per_el;
  }
}

double process_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
long minor_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// Assembler::rebuild (absent before it was added: the benchmark also builds against older headers)
template <class A>
concept HasRebuild = requires(A& a, Index n, typename A::CellDofs (*f)(Index), const DofConstraints& c) {
  a.rebuild(n, f, c);
};

// pattern (rebuild = false) or repattern (rebuild = true), see the header
template <int D, class Pair>
void bm_pattern(benchmark::State& state, int n, bool rebuild) {
  auto& p = problem<D, Pair>(n);
  SparseMatrix J;
  if (rebuild) {
    p.assembler().take_pattern(J);
    std::fill(J.valuePtr(), J.valuePtr() + J.nonZeros(), Real(0));
  }
  double ctor = 0, take = 0;
  long faults = 0;
  for (auto _ : state) {
    if (!rebuild) {
      state.PauseTiming();
      p.asmb.reset();  // release the previous pattern and matrix outside the timing
      J = SparseMatrix();
      state.ResumeTiming();
    }
    const double c0 = process_cpu_s();
    const long f0 = minor_faults();
    if constexpr (HasRebuild<typename Problem<D, Pair>::Asm>) {
      if (rebuild) p.asmb->rebuild(p.mesh.n_cells(), [&](Index c) { return p.space.cell_field_dofs(c); }, p.cons);
    }
    if (!rebuild) p.asmb = p.build_assembler();
    const double c1 = process_cpu_s();
    p.asmb->take_pattern(J);
    benchmark::DoNotOptimize(J.innerIndexPtr());
    ctor += c1 - c0;
    take += process_cpu_s() - c1;
    faults += minor_faults() - f0;
  }
  const double it = double(state.iterations());
  size_counters(state, *p.asmb);
  rate_counters(state, double(p.asmb->n_cells()));
  state.counters["ctor_ms"] = 1e3 * ctor / it;
  state.counters["take_ms"] = 1e3 * take / it;
  state.counters["faults"] = double(faults) / it;
  state.counters["pos_MB"] = double(p.asmb->position_bytes()) / 1048576.0;
  state.counters["matrix_MB"] = double(p.asmb->n_nonzeros()) * (sizeof(Real) + sizeof(Index)) / 1048576.0;
  state.counters["colours"] = double(p.asmb->n_colours());
  state.counters["peak_MB"] = peak_mb();  // before the fills below
  // the first fill into the new matrix (its values first touched) and a second one
  VecX r;
  const double c0 = process_cpu_s();
  p.asmb->assemble(p.kernel, p.field, &J, &r);
  const double c1 = process_cpu_s();
  p.asmb->assemble(p.kernel, p.field, &J, &r);
  state.counters["first_fill_ms"] = 1e3 * (c1 - c0);
  state.counters["fill_ms"] = 1e3 * (process_cpu_s() - c1);
}

// which kernel a benchmark runs
enum class Which { stokes, stokes_quad, ns_newton, ns_semi, ns_newton_quad };
template <int D, class Pair>
struct Select {
  static const auto& kernel(Problem<D, Pair>& p, std::integral_constant<Which, Which::stokes>) { return p.kernel; }
  static const auto& kernel(Problem<D, Pair>& p, std::integral_constant<Which, Which::stokes_quad>) { return p.quad_kernel; }
  static const auto& kernel(Problem<D, Pair>& p, std::integral_constant<Which, Which::ns_newton>) { return p.ns_newton; }
  static const auto& kernel(Problem<D, Pair>& p, std::integral_constant<Which, Which::ns_semi>) { return p.ns_semi; }
  static const auto& kernel(Problem<D, Pair>& p, std::integral_constant<Which, Which::ns_newton_quad>) {
    return p.ns_newton_quad;
  }
};
template <Which W>
constexpr bool is_ns = W == Which::ns_newton || W == Which::ns_semi || W == Which::ns_newton_quad;

template <int D, class Pair, Which W>
void bm_kernel(benchmark::State& state, int n) {
  auto& p = problem<D, Pair>(n);
  const auto& asmb = p.assembler();
  const auto& kernel = Select<D, Pair>::kernel(p, std::integral_constant<Which, W>{});
  const VecX& field = is_ns<W> ? p.ns_field : p.field;
  typename Problem<D, Pair>::Asm::LocalMat A;
  typename Problem<D, Pair>::Asm::LocalVec r;
  for (auto _ : state) {
    for (Index c = 0; c < asmb.n_cells(); ++c) {
      const auto u = asmb.gather(c, field);
      kernel.cell(c, u, A, r);
      benchmark::DoNotOptimize(A.data());
      benchmark::DoNotOptimize(r.data());
    }
    benchmark::ClobberMemory();
  }
  size_counters(state, asmb);
  const double flops = W == Which::stokes ? flops_per_cell<D, Pair>()
                       : W == Which::stokes_quad ? quad_flops_per_cell<D, Pair>() : 0.0;
  rate_counters(state, double(asmb.n_cells()), flops);
  state.counters["peak_MB"] = peak_mb();
}

template <int D, class Pair>
void bm_scatter(benchmark::State& state, int n) {
  auto& p = problem<D, Pair>(n);
  const auto& asmb = p.assembler();
  SparseMatrix J;
  asmb.take_pattern(J);
  std::fill(J.valuePtr(), J.valuePtr() + J.nonZeros(), Real(0));
  VecX r = VecX::Zero(asmb.n_unknowns());
  // one realistic element matrix (cell 0's) scattered by every cell
  typename Problem<D, Pair>::Asm::LocalMat A;
  typename Problem<D, Pair>::Asm::LocalVec re;
  p.kernel.cell(0, asmb.gather(0, p.field), A, re);
  for (auto _ : state) {
    for (Index c = 0; c < asmb.n_cells(); ++c) asmb.scatter(c, A, re, J.valuePtr(), &r);
    benchmark::DoNotOptimize(J.valuePtr());
    benchmark::DoNotOptimize(r.data());
    benchmark::ClobberMemory();
  }
  size_counters(state, asmb);
  rate_counters(state, double(asmb.n_cells()));
  state.counters["peak_MB"] = peak_mb();
}

template <int D, class Pair, Which W>
void bm_assemble(benchmark::State& state, int n, int threads) {
  auto& p = problem<D, Pair>(n);
  auto& asmb = p.assembler();
  const auto& kernel = Select<D, Pair>::kernel(p, std::integral_constant<Which, W>{});
  const VecX& field = is_ns<W> ? p.ns_field : p.field;
  asmb.set_threads(threads);
  SparseMatrix J;  // as in Stokes::solve: a separate matrix, given the pattern by the first assembly
  VecX r;
  asmb.assemble(kernel, field, &J, &r);
  for (auto _ : state) {
    asmb.assemble(kernel, field, &J, &r);
    benchmark::DoNotOptimize(J.valuePtr());
    benchmark::DoNotOptimize(r.data());
  }
  asmb.set_threads(1);
  size_counters(state, asmb);
  rate_counters(state, double(asmb.n_cells()));
  state.counters["threads"] = threads;
  state.counters["peak_MB"] = peak_mb();
}

template <int D, class Pair, class Ordering>
void bm_lu(benchmark::State& state, int n) {
  using clock = std::chrono::steady_clock;
  auto secs = [](clock::time_point a, clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  auto cpu = [] {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
  };
  auto& p = problem<D, Pair>(n);
  const auto& asmb = p.assembler();
  SparseMatrix J;
  VecX r;
  asmb.assemble(p.kernel, p.field, &J, &r);
  const VecX b = -r;
  double ta = 0, tf = 0, ts = 0, ca = 0, cf = 0, cs = 0, lu_nnz = 0, relres = 0;
  for (auto _ : state) {
    SparseLu<Ordering> lu;
    const double c0 = cpu();
    const auto t0 = clock::now();
    lu.analyze(J);
    const double c1 = cpu();
    const auto t1 = clock::now();
    lu.factorize(J);
    const double c2 = cpu();
    const auto t2 = clock::now();
    const VecX x = lu.solve(b);
    const double c3 = cpu();
    const auto t3 = clock::now();
    ta += secs(t0, t1), tf += secs(t1, t2), ts += secs(t2, t3);
    ca += c1 - c0, cf += c2 - c1, cs += c3 - c2;
    state.PauseTiming();
    lu_nnz = double(lu.factor_nonzeros());
    relres = rel_residual(J, x, b);
    state.ResumeTiming();
  }
  size_counters(state, asmb);
  const double it = double(state.iterations());
  state.counters["analyse_s"] = ta / it;
  state.counters["factorise_s"] = tf / it;
  state.counters["solve_s"] = ts / it;
  state.counters["analyse_cpu_s"] = ca / it;
  state.counters["factorise_cpu_s"] = cf / it;
  state.counters["solve_cpu_s"] = cs / it;
  state.counters["LU_nnz"] = lu_nnz;
  state.counters["fill"] = lu_nnz / double(J.nonZeros());
  state.counters["relres"] = relres;
  state.counters["peak_MB"] = peak_mb();
}

// ---- registration ----------------------------------------------------------------------------
// Sizes. 2D: rectangle_mesh(N, N); 3D: box_mesh(N, N, N). 3D P2/P1: N = 32 has 0.82 M
// unknowns, N = 36 has 1.17 M; 3D P1/P1: N = 64 has 1.03 M.
const std::vector<int> sizes_2d{64, 128, 256, 512};
const std::vector<int> sizes_3d_th{8, 16, 24, 32, 36};
const std::vector<int> sizes_3d_p1{16, 32, 48, 64};
// SparseLU sizes (COLAMD): 2D P2/P1 N = 256 is the long one (minutes; DESIGN.md: 134 s).
const std::vector<int> lu_2d_th{16, 32, 64, 128, 256};
const std::vector<int> lu_2d_p1{64, 128, 256};
const std::vector<int> lu_3d_th{4, 6, 8, 10, 12};   // N = 12: 49 k unknowns
const std::vector<int> lu_3d_p1{8, 12, 16, 22};     // N = 22: 49 k unknowns
const std::vector<int> lu_amd_2d_th{8, 16, 32};     // AMD(A + A^T): the bad one

template <int D, class Pair>
void register_assembly(const std::vector<int>& sizes) {
  const std::string base = std::string(label<Pair>) + "/" + std::to_string(D) + "D/";
  // big cases run once (MinTime: the first iteration already exceeds it)
  auto reg = [&](const std::string& name, auto fn, auto... args) {
    benchmark::RegisterBenchmark(name.c_str(), fn, args...)
        ->Unit(benchmark::kMillisecond)->MinTime(0.3)->UseRealTime()->MeasureProcessCPUTime();
  };
  for (int n : sizes) {
    std::string s = "/";  // (not "/" + to_string: GCC 12 -O3 false -Wrestrict)
    s += std::to_string(n);
    reg(base + "pattern" + s, bm_pattern<D, Pair>, n, false);
    if constexpr (HasRebuild<typename Problem<D, Pair>::Asm>) reg(base + "repattern" + s, bm_pattern<D, Pair>, n, true);
    reg(base + "kernel" + s, bm_kernel<D, Pair, Which::stokes>, n);
    reg(base + "kernel_quad" + s, bm_kernel<D, Pair, Which::stokes_quad>, n);
    reg(base + "scatter" + s, bm_scatter<D, Pair>, n);
    reg(base + "assemble" + s, bm_assemble<D, Pair, Which::stokes>, n, 1);
    reg(base + "assemble_t2" + s, bm_assemble<D, Pair, Which::stokes>, n, 2);
    reg(base + "ns_newton_kernel" + s, bm_kernel<D, Pair, Which::ns_newton>, n);
    reg(base + "ns_newton_kernel_quad" + s, bm_kernel<D, Pair, Which::ns_newton_quad>, n);
    reg(base + "ns_newton" + s, bm_assemble<D, Pair, Which::ns_newton>, n, 1);
    reg(base + "ns_newton_t2" + s, bm_assemble<D, Pair, Which::ns_newton>, n, 2);
    reg(base + "ns_semi" + s, bm_assemble<D, Pair, Which::ns_semi>, n, 1);
  }
}

template <int D, class Pair, class Ordering>
void register_lu(const char* ord, const std::vector<int>& sizes) {
  const std::string base = std::string(label<Pair>) + "/" + std::to_string(D) + "D/lu_" + ord + "/";
  for (int n : sizes)
    benchmark::RegisterBenchmark((base + std::to_string(n)).c_str(), bm_lu<D, Pair, Ordering>, n)
        ->Unit(benchmark::kMillisecond)->Iterations(1);
}

}  // namespace

int main(int argc, char** argv) {
  using Colamd = Eigen::COLAMDOrdering<Index>;
  using Amd = Eigen::AMDOrdering<Index>;
  register_assembly<2, TaylorHood>(sizes_2d);
  register_assembly<2, P1P1Gls>(sizes_2d);
  register_assembly<3, TaylorHood>(sizes_3d_th);
  register_assembly<3, P1P1Gls>(sizes_3d_p1);
  register_lu<2, TaylorHood, Colamd>("colamd", lu_2d_th);
  register_lu<2, TaylorHood, Amd>("amd", lu_amd_2d_th);
  register_lu<2, P1P1Gls, Colamd>("colamd", lu_2d_p1);
  register_lu<3, TaylorHood, Colamd>("colamd", lu_3d_th);
  register_lu<3, P1P1Gls, Colamd>("colamd", lu_3d_p1);
  // Eigen::MetisOrdering needs metis.h (libmetis-dev), which is not installed here.
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
