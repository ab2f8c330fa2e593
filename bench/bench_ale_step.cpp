// Cost of one ALE Navier-Stokes time step (AleFlow, sim/ale_flow.hpp) and error against wall
// time for the five ALE schemes. A plain program (not Google Benchmark): a time step is
// stateful and seconds long at the larger sizes, so every number is one measured step or the
// average of a few. Commands and measured numbers: docs/ale_benchmarks.md.
//
//   g++ -std=c++20 -O3 -march=native -DNDEBUG -Iinclude -I/usr/include/eigen3 bench/bench_ale_step.cpp -o /tmp/bench_ale_step
//   /tmp/bench_ale_step steps [--only SUBSTR] [--max-dofs N] [--steps K] [--csv FILE (ale_step.csv)]  # part 1
//   /tmp/bench_ale_step error [--repeats R] [--csv FILE (docs/img/error_vs_time.csv)]             # part 2
//
// Part 1 ("steps"): BDF2/BDF2E, structured unit square rectangle_mesh(n, n) / unit cube
// box_mesh(n, n, n), Taylor-Hood and P1/P1-GLS, Newton and semi-implicit. The flow is the
// manufactured solution of tests/physics/test_ale.cpp (u = g(t) (y^2, x^2) for P2/P1,
// g(t) (x, -y) for P1/P1, and their 3D analogues; Dirichlet data from u on the whole boundary;
// body force) with rho = 1, mu = 0.01 (|u| ~ 1.5 on a unit domain: Re ~ 150). The mesh moves:
// the nodes of one wall (2D: bottom; 3D: zmin) slide along it with 0.3 sin(pi x) [sin(pi y)]
// cos(t) in x, and the interior follows the elasticity problem, so every step runs the
// mesh-velocity solve. dt = 0.02, Newton to 1e-10 (relative max-norm residual).
// Step 1 is the MR/AB start-up step and contains the one-off symbolic analyses (SparseLU
// analyzePattern and the elasticity Cholesky analyzePattern); it is reported separately, and
// the next --steps K (default 3; 1 or 2 for the largest cases) BDF2 steps are averaged.
// Columns: the StepReport phases (mesh velocity / assembly / factorisation / solve) and the
// rest of the step as measured around AleFlow::step ("other": extrapolation, Dirichlet data,
// pressure shift, history copies, mesh orientation checks).
//
// Part 2 ("error"): the manufactured solution exactly as in test_ale (rho = 1.3, mu = 0.4,
// T = 1, 4 x 4 mesh, so the spatial error is zero), elastic mesh motion (bottom wall sliding),
// all five schemes x {Newton (tolerance 1e-12), semi-implicit} x {P2/P1, P1/P1-GLS} x
// dt = T/10 .. T/320. Error ||u(T) - u_h||_L2; wall time of the whole run (construction + all
// steps), the minimum over --repeats R runs (default 3). Writes docs/img/error_vs_time.csv by
// default (plot: bench/plot_error_vs_time.py).
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <numbers>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "alefsi/fem/norms.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/sim/ale_flow.hpp"

namespace {

using namespace alefsi;
using std::numbers::pi;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// ---- memory: peak RSS of the process since the last reset ------------------------------
void reset_peak_rss() {
  malloc_trim(0);
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
}
double peak_rss_mb() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  return 0;
}

// ---- the manufactured solution (as Exact<D, Pair> in tests/physics/test_ale.cpp) --------
inline Real g(Real t) { return std::cos(2 * t) + 0.5; }
inline Real dg(Real t) { return -2 * std::sin(2 * t); }

template <int D, class Pair>
struct Exact {
  Real rho, mu;
  static constexpr bool quad = std::is_same_v<Pair, TaylorHood>;
  static Vec<D> shape(const Vec<D>& x) {  // divergence-free
    if constexpr (D == 2) return quad ? Vec<2>(x[1] * x[1], x[0] * x[0]) : Vec<2>(x[0], -x[1]);
    else return quad ? Vec<3>(x[1] * x[1], x[2] * x[2], x[0] * x[0]) : Vec<3>(x[0], x[1], -2 * x[2]);
  }
  static Mat<D> shape_grad(const Vec<D>& x) {
    Mat<D> G = Mat<D>::Zero();
    if constexpr (D == 2) {
      if (quad) G(0, 1) = 2 * x[1], G(1, 0) = 2 * x[0];
      else G(0, 0) = 1, G(1, 1) = -1;
    } else {
      if (quad) G(0, 1) = 2 * x[1], G(1, 2) = 2 * x[2], G(2, 0) = 2 * x[0];
      else G(0, 0) = 1, G(1, 1) = 1, G(2, 2) = -2;
    }
    return G;
  }
  static Vec<D> u(const Vec<D>& x, Real t) { return g(t) * shape(x); }
  static Real p(const Vec<D>& x, Real t) { return g(t) * (x.sum() - 0.5 * D); }
  Vec<D> f(const Vec<D>& x, Real t) const {
    const Vec<D> s = shape(x);
    const Vec<D> lap = quad ? Vec<D>::Constant(2.0) : Vec<D>::Zero();
    return rho * (dg(t) * s + g(t) * g(t) * shape_grad(x) * s) - mu * g(t) * lap + Vec<D>::Constant(g(t));
  }
};

template <int D>
Mesh<D> unit_mesh(int n) {
  if constexpr (D == 2) return rectangle_mesh(n, n);
  else return box_mesh(n, n, n);
}

// Sets up the manufactured-solution problem on a moving mesh (one wall sliding, elasticity).
template <int D, class Pair, class Scheme>
void setup_mms(AleFlow<FlowConfig<D, Pair, Scheme>>& flow, const Exact<D, Pair>& ex) {
  for (int t = 1; t <= 2 * D; ++t) flow.set_velocity(t, Exact<D, Pair>::u);
  const int wall = D == 2 ? tags::bottom : tags::zmin;
  flow.set_mesh_velocity(wall, [](const Vec<D>& x, Real t) {
    Vec<D> v = Vec<D>::Zero();
    v[0] = 0.3 * std::sin(pi * x[0]) * std::cos(t);
    if constexpr (D == 3) v[0] *= std::sin(pi * x[1]);
    return v;
  });
  flow.set_force([ex](const Vec<D>& x, Real t) { return ex.f(x, t); });
  flow.set_initial_velocity([](const Vec<D>& x) { return Exact<D, Pair>::u(x, 0.0); });
}

template <int D, class Pair, class Scheme>
Real velocity_error(const AleFlow<FlowConfig<D, Pair, Scheme>>& flow) {
  using Ex = Exact<D, Pair>;
  const Real T = flow.time();
  const auto e = flow_errors<D, Pair>(
      flow.space(), flow.field(), [&](const Vec<D>& x) { return Ex::u(x, T); },
      [&](const Vec<D>& x) { return Mat<D>(g(T) * Ex::shape_grad(x)); }, [&](const Vec<D>& x) { return Ex::p(x, T); });
  return e.u_l2;
}

// Velocity unknowns left after the Dirichlet constraints (every boundary tag) and the pinned
// pressure DOF, as AleFlow sets them up.
template <int D, class Pair>
Index n_unknowns(const MixedSpace<D, Pair>& space) {
  std::set<Index> fixed;
  for (int t = 1; t <= 2 * D; ++t)
    for (Index i : space.velocity().boundary_dofs(t)) fixed.insert(i);
  return space.n_field() - D * Index(fixed.size()) - 1;
}

// ======================================================================================
// Part 1: cost of one step
// ======================================================================================
struct Phases {
  double wall = 0, mesh_v = 0, assembly = 0, factorize = 0, solve = 0;
  double its = 0;
  void add(const StepReport& r, double w) {
    wall += w, mesh_v += r.t_mesh_velocity, assembly += r.t_assembly, factorize += r.t_factorize, solve += r.t_solve;
    its += r.newton_iterations;
  }
  Phases scaled(double s) const { return {wall * s, mesh_v * s, assembly * s, factorize * s, solve * s, its * s}; }
  double other() const { return wall - mesh_v - assembly - factorize - solve; }
};

struct StepRow {
  std::string name;
  int D = 0, n = 0;
  std::string pair, lin;
  Index cells = 0, dofs = 0, unknowns = 0;
  double t_setup = 0;
  Phases first, avg;
  int measured = 0;
  double err = 0, peak_mb = 0;
};

template <int D, class Pair>
StepRow run_steps(int n, Linearisation lin, int measured, Real dt) {
  reset_peak_rss();
  StepRow row;
  row.D = D, row.n = n, row.pair = Pair::name, row.lin = lin == Linearisation::newton ? "Newton" : "semi-impl";
  row.measured = measured;
  const Exact<D, Pair> ex{1.0, 0.01};
  auto t0 = Clock::now();
  AleFlow<FlowConfig<D, Pair, BDF2_BDF2E>> flow(unit_mesh<D>(n), FlowOptions{ex.rho, ex.mu, lin, 25, 1e-10});
  setup_mms(flow, ex);
  row.t_setup = seconds_since(t0);
  row.cells = flow.mesh().n_cells();
  row.dofs = flow.space().n_field();
  row.unknowns = n_unknowns(flow.space());
  for (int s = 0; s <= measured; ++s) {
    t0 = Clock::now();
    const StepReport rep = flow.step(dt);
    const double w = seconds_since(t0);
    (s == 0 ? row.first : row.avg).add(rep, w);
  }
  row.avg = row.avg.scaled(1.0 / measured);
  row.err = velocity_error(flow);
  row.peak_mb = peak_rss_mb();
  return row;
}

void print_step_header() {
  std::printf("%-4s %-10s %-9s %4s %8s %8s %8s | %-44s | %-52s | %7s %8s\n", "D", "pair", "lin", "n", "cells", "DOFs",
              "unknowns", "first step (s): wall  meshV  asm   fact  its", "later steps avg (s): wall  meshV  asm  fact  solve  its",
              "peakMB", "err_L2");
}

void print_step_row(const StepRow& r) {
  std::printf("%-4d %-10s %-9s %4d %8ld %8ld %8ld | %8.3f %6.3f %6.3f %6.3f %4.0f       | %8.3f %6.3f %6.3f %6.3f %6.3f %4.1f (%d) | %7.0f %8.1e\n",
              r.D, r.pair.c_str(), r.lin.c_str(), r.n, long(r.cells), long(r.dofs), long(r.unknowns), r.first.wall,
              r.first.mesh_v, r.first.assembly, r.first.factorize, r.first.its, r.avg.wall, r.avg.mesh_v, r.avg.assembly,
              r.avg.factorize, r.avg.solve, r.avg.its, r.measured, r.peak_mb, r.err);
  std::fflush(stdout);
}

int part_steps(const std::string& only, long max_dofs, const std::string& csv_path, int steps_default) {
  struct Case {
    int D;
    bool th;
    int n;
    int measured;  // later steps averaged (0: default)
    bool newton;   // the Newton variant too (semi-implicit always)
  };
  // Sizes: SparseLU factorisation time grows fast (bench_assembly: 3D P2/P1 n = 12, 39k
  // unknowns, 40-50 s per factorisation), so the largest 3D cases run semi-implicit only.
  const std::vector<Case> cases{
      {2, true, 16, 0, true},   {2, true, 32, 0, true},   {2, true, 64, 0, true},   {2, true, 96, 2, true},
      {2, false, 32, 0, true},  {2, false, 64, 0, true},  {2, false, 128, 0, true}, {2, false, 256, 2, false},
      {3, true, 4, 0, true},    {3, true, 6, 0, true},    {3, true, 8, 0, true},    {3, true, 10, 1, true},
      {3, true, 12, 1, false},  {3, false, 8, 0, true},   {3, false, 12, 0, true},  {3, false, 16, 0, true},
      {3, false, 22, 1, false},
  };
  std::vector<StepRow> rows;
  print_step_header();
  for (const Case& c : cases)
    for (int l = 0; l < 2; ++l) {
      const Linearisation lin = l == 0 ? Linearisation::newton : Linearisation::semi_implicit;
      if (lin == Linearisation::newton && !c.newton) continue;
      const std::string tag = std::to_string(c.D) + "D-" + (c.th ? "TH" : "P1P1") + "-" + std::to_string(c.n) + "-" +
                              (l == 0 ? "newton" : "semi");
      if (!only.empty() && tag.find(only) == std::string::npos) continue;
      // DOF estimate before building anything
      const long nn = c.D == 2 ? long(c.n + 1) * (c.n + 1) : long(c.n + 1) * (c.n + 1) * (c.n + 1);
      const long nv = c.th ? (c.D == 2 ? long(2 * c.n + 1) * (2 * c.n + 1) : long(2 * c.n + 1) * (2 * c.n + 1) * (2 * c.n + 1)) : nn;
      if (c.D * nv + nn > max_dofs) continue;
      const int measured = c.measured > 0 ? std::min(c.measured, steps_default) : steps_default;
      StepRow r;
      if (c.D == 2) r = c.th ? run_steps<2, TaylorHood>(c.n, lin, measured, 0.02) : run_steps<2, P1P1Gls>(c.n, lin, measured, 0.02);
      else r = c.th ? run_steps<3, TaylorHood>(c.n, lin, measured, 0.02) : run_steps<3, P1P1Gls>(c.n, lin, measured, 0.02);
      r.name = tag;
      print_step_row(r);
      rows.push_back(r);
    }
  if (!csv_path.empty()) {
    std::ofstream f(csv_path);
    f << "case,D,pair,linearisation,n,cells,dofs,unknowns,setup_s,first_wall_s,first_mesh_velocity_s,first_assembly_s,"
         "first_factorize_s,first_solve_s,first_other_s,first_newton,measured_steps,wall_s,mesh_velocity_s,assembly_s,"
         "factorize_s,solve_s,other_s,newton,peak_rss_mb,err_u_l2\n";
    for (const auto& r : rows)
      f << r.name << ',' << r.D << ',' << r.pair << ',' << r.lin << ',' << r.n << ',' << r.cells << ',' << r.dofs << ','
        << r.unknowns << ',' << r.t_setup << ',' << r.first.wall << ',' << r.first.mesh_v << ',' << r.first.assembly << ','
        << r.first.factorize << ',' << r.first.solve << ',' << r.first.other() << ',' << r.first.its << ',' << r.measured
        << ',' << r.avg.wall << ',' << r.avg.mesh_v << ',' << r.avg.assembly << ',' << r.avg.factorize << ','
        << r.avg.solve << ',' << r.avg.other() << ',' << r.avg.its << ',' << r.peak_mb << ',' << r.err << '\n';
    std::printf("wrote %s\n", csv_path.c_str());
  }
  return 0;
}

// ======================================================================================
// Part 2: error against wall time, five schemes
// ======================================================================================
struct ErrRow {
  std::string pair, scheme, lin;
  int steps = 0;
  double dt = 0, err = 0, wall = 0;
  long newton = 0;
};

template <class Pair, class Scheme>
ErrRow run_error(int steps, Linearisation lin, int repeats) {
  constexpr int D = 2;
  const Exact<D, Pair> ex{1.3, 0.4};
  const Real T = 1.0, dt = T / steps;
  ErrRow row;
  row.pair = Pair::name, row.scheme = Scheme::name, row.lin = lin == Linearisation::newton ? "Newton" : "semi-implicit";
  row.steps = steps, row.dt = dt, row.wall = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = Clock::now();
    AleFlow<FlowConfig<D, Pair, Scheme>> flow(rectangle_mesh(4, 4), FlowOptions{ex.rho, ex.mu, lin, 25, 1e-12});
    setup_mms(flow, ex);
    long its = 0;
    for (int n = 0; n < steps; ++n) its += flow.step(dt).newton_iterations;
    row.wall = std::min(row.wall, seconds_since(t0));
    row.err = velocity_error(flow);
    row.newton = its;
  }
  return row;
}

template <class Pair, class Scheme>
void error_series(std::vector<ErrRow>& rows, int repeats) {
  for (int l = 0; l < 2; ++l)
    for (int s = 10; s <= 320; s *= 2) {
      const ErrRow r = run_error<Pair, Scheme>(s, l == 0 ? Linearisation::newton : Linearisation::semi_implicit, repeats);
      std::printf("%-10s %-11s %-13s %4d %10.3e %10.3e %6ld %10.3e\n", r.pair.c_str(), r.scheme.c_str(), r.lin.c_str(),
                  r.steps, r.dt, r.err, r.newton, r.wall);
      std::fflush(stdout);
      rows.push_back(r);
    }
}

template <class Pair>
void error_pair(std::vector<ErrRow>& rows, int repeats) {
  error_series<Pair, MR_AB>(rows, repeats);
  error_series<Pair, BDF2_BDF2E>(rows, repeats);
  error_series<Pair, BDF2_AB>(rows, repeats);
  error_series<Pair, BDF3_BDF3E>(rows, repeats);
  error_series<Pair, BSS>(rows, repeats);
}

int part_error(const std::string& csv_path, int repeats) {
  std::vector<ErrRow> rows;
  std::printf("%-10s %-11s %-13s %4s %10s %10s %6s %10s\n", "pair", "scheme", "lin", "N", "dt", "err_L2", "solves", "wall_s");
  error_pair<TaylorHood>(rows, repeats);
  error_pair<P1P1Gls>(rows, repeats);
  std::ofstream f(csv_path);
  f << "pair,scheme,linearisation,steps,dt,err_u_l2,linear_solves,wall_s\n";
  for (const auto& r : rows)
    f << r.pair << ',' << r.scheme << ',' << r.lin << ',' << r.steps << ',' << r.dt << ',' << r.err << ',' << r.newton
      << ',' << r.wall << '\n';
  std::printf("wrote %s\n", csv_path.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string mode = argc > 1 ? argv[1] : "";
  std::string only, csv;
  long max_dofs = 1L << 40;
  int repeats = 3, steps = 3;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--only") only = next();
    else if (a == "--max-dofs") max_dofs = std::atol(next().c_str());
    else if (a == "--csv") csv = next();
    else if (a == "--repeats") repeats = std::max(1, std::atoi(next().c_str()));
    else if (a == "--steps") steps = std::max(1, std::atoi(next().c_str()));
    else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  try {
    if (mode == "steps") return part_steps(only, max_dofs, csv.empty() ? "ale_step.csv" : csv, steps);
    if (mode == "error") return part_error(csv.empty() ? "docs/img/error_vs_time.csv" : csv, repeats);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr,
               "usage: %s steps [--only SUBSTR] [--max-dofs N] [--steps K] [--csv FILE]\n"
               "       %s error [--repeats R] [--csv FILE]\n",
               argv[0], argv[0]);
  return 2;
}
