// annulus — the paper's section 6.3: fluid between a turning outer cylinder and a free inner one.
//
// What it shows: a free rigid body (the inner cylinder, radius R1 = 0.25) driven by the fluid
// that the outer cylinder (R2 = 1, omega_2 = 1 rad/s from t = 0+) drags along; the ALE flow
// (alefsi::AleFlow, any of the five schemes, Taylor-Hood or P1/P1-GLS) against the
// finite-difference solution of the reduced problem (26) (alefsi/reference/annulus.hpp).
// The outer wall's *mesh* velocity is 0 (only the fluid velocity is driven there: a tangential
// mesh velocity would move its nodes off the circle); the body's surface nodes follow its exact
// rigid motion and the interior nodes the elasticity problem (15)-(16).
//
// How to run:
//   annulus table1 [--schemes MR_AB,...] [--pair th|gls] [--h H] [--h-wall HW] [--kmax K]
//                  [--kref KR] [--ref-scheme S] [--lin newton|semi] [--wall-start moving|rest]
//                  [--damped-start M] [--start-up midpoint|bdf] [--graded-start F] [--csv FILE]
//       Table 1: mu = 0.01, rho = 1, rho_1 = 1.25; E = ||u(0.8) - u_h(0.8)||_L2(Omega_h(0.8))
//       for dt = 0.05 2^-k, k = 0..K, with orders, (a) against the FD reference (N = 6000 cells,
//       dt = 0.05 / 1024: its own error is ~1e-7) and (b) against a fine-dt FEM solution on the
//       same mesh (scheme --ref-scheme, default BDF3_BDF3E, dt = 0.05 2^-KR, default KR = K + 3),
//       which isolates the time error. Also |omega_h - omega| at 0.8 (tiny: the cylinder has
//       barely started to turn, see docs/results.md). --wall-start: the initial FE velocity on
//       the outer wall, the wall speed (default) or 0 (AleFlow's default: the flow then starts
//       O(dt) late and every scheme is first order; docs/results.md). --damped-start M: the
//       first step of every run (the fine-dt reference too) as M backward-Euler substeps
//       (FlowOptions::damped_start, Rannacher's start; extrapolated for BDF3); default 0: the
//       multistep start-up (MR/AB steps), which does not damp the wall jump. --start-up bdf: the
//       BDF schemes' start-up steps are BSS then BDF2/BDF2E (FlowOptions::start_up); --graded-start F:
//       every fixed-dt run (the reference too) first grows its steps from F dt (dt/dt0)^((q-2)/2)
//       to dt (time/step_sequence.hpp), then keeps dt. --convection off:
//       unsteady Stokes instead of Navier-Stokes (a diagnostic; every mode accepts it).
//   annulus smooth [same options] [--mu M] [--rho-s R] [--ramp TAU] [--T T] [--dt0 DT]
//       Time-order study that exercises the coupling: mu = 1, rho_1 = 1.25 (Figure 7 set-up),
//       outer wall started smoothly, omega_2(t) = 1 - exp(-(t/TAU)^4), TAU = 0.1; errors at
//       T = 0.4 for dt = DT 2^-k (DT = 0.02): velocity L2 and inner angular velocity.
//   annulus speed [same options as smooth] [--lins newton,semi]
//       Speed against error (paper 6.3, the smooth-start coupled case of `smooth`): for every
//       scheme and linearisation (Newton, semi-implicit), E at T (velocity L2 against the FD
//       reference and against the fine-dt FEM solution: BDF3/BDF3E with Newton at
//       dt = DT 2^-KR) and the run's wall and CPU time (process CPU time, std::clock) for
//       dt = DT 2^-k, k = 0..K. Plot: docs/img/annulus_speed_plot.py. With --tolerances T1,T2,...
//       also adaptive runs (run(): error control, PI controller, first step --dt-first) of the
//       BDF schemes, the same measures beside steps, rejections and the range of dt (--output DIR:
//       each adaptive run's step log DIR/<scheme>_<lin>_tol<T>/bodies.csv).
//   annulus fig7 [--pair th|gls] [--h H] [--dt DT] [--scheme S] [--curved] [--csv FILE]
//       Figure 7: mu = rho_f = 1, t* (the inner cylinder reaches omega = 1/2, half the final
//       value) against I^ = rho_1 / 64 for rho_1 = 1e-6 .. 1e2, FEM (MR/AB as in the paper)
//       against the FD reference; CSV (plot: docs/img/annulus_plot.py). --curved (every mode,
//       P2/P1): isoparametric cells on both cylinders instead of polygons.
// What it prints: the tables (markdown) and the CSV files named by --csv.
// Expected (measured, docs/results.md): every scheme at its design order against the fine-dt
// FEM solution; against the FD reference the error levels off at the spatial error; t* of the
// FEM within 1 % of the FD value for every rho_1, no instability.
#include <alefsi/alefsi.hpp>
#include <alefsi/reference/annulus.hpp>

#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <utility>
#include <string>
#include <vector>

using namespace alefsi;
using std::numbers::pi;
using Clock = std::chrono::steady_clock;

namespace {

// --- the linear solver ---------------------------------------------------------------------------
// The sweeps factorise Taylor-Hood saddle-point matrices of 2e4-1e5 unknowns thousands of times:
// DefaultDirectSolver is UMFPACK with its symmetric strategy when alefsi was built with
// SuiteSparse, else SparseLU with the saddle-point AMD ordering (docs/solvers.md: both within
// 1.5x of each other; COLAMD was 10x slower).
using Solver = DefaultDirectSolver;

// --- the set-up ------------------------------------------------------------------------------
struct Scene {
  Real r1 = 0.25, r2 = 1.0, rho = 1.0, mu = 0.01, rho_s = 1.25;
  Real ramp = 0;  // 0: impulsive start (omega_2 = 1 for t > 0); > 0: 1 - exp(-(t/ramp)^4)
  // Impulsive start: the initial FE field on the outer wall. true: the wall's velocity at t = 0+
  // (u_h^0 = the Dirichlet data, 0 inside); false: at rest like the fluid (AleFlow's default,
  // u_h^0 = 0): the wall DOFs then jump within the first step, which the first (MR/AB start-up)
  // step turns into a ramp over [0, dt]: the flow starts O(dt) late and every scheme is O(dt).
  bool wall_moving_at_0 = true;
  int damped_start = 0;  // FlowOptions::damped_start: 0 = the multistep start-up, M = M backward-Euler substeps
  StartUp start_up = StartUp::midpoint;  // FlowOptions::start_up: the multistep start-up's formulas
  // > 0: fixed-dt runs start with graded_start (time/step_sequence.hpp) from the first step
  // graded dt (dt / graded_dt0)^((q - 2) / 2), q the scheme's order (simulate_with)
  Real graded = 0, graded_dt0 = 0.05;
  bool convection = true;  // false: unsteady Stokes (a diagnostic: no advection of start-up errors)
  bool curved = false;     // isoparametric P2 cells on both cylinders (AleFlow::curve_boundary; P2/P1 only)
  Real omega2(Real t) const { return ramp > 0 ? 1 - std::exp(-std::pow(t / ramp, 4)) : 1.0; }
  // the physical set-up (alefsi/scenes/annulus.hpp)
  scenes::Annulus annulus() const {
    return {.r1 = r1, .r2 = r2, .rho_s = rho_s, .omega = [s = *this](Real t) { return s.omega2(t); }};
  }
  Real inertia() const { return annulus().inner_body().inertia; }  // = rho_s pi R1^4 / 2
  Real ihat() const { return annulus().inertia_ratio(rho); }       // = rho_s / 64
  reference::AnnulusProblem fd_problem() const {
    reference::AnnulusProblem p;
    p.r1 = r1, p.r2 = r2, p.rho = rho, p.mu = mu, p.inertia = inertia();
    p.outer_omega = [s = *this](Real t) { return s.omega2(t); };
    return p;
  }
};

struct Settings {
  std::vector<std::string> schemes{"MR_AB", "BDF2_BDF2E", "BDF2_AB", "BDF3_BDF3E", "BSS"};
  std::string pair = "th", ref_scheme = "BDF3_BDF3E", csv;
  std::string output;  // speed: a folder for the adaptive runs' bodies.csv (t, dt, error estimate, ...)
  Real h = 0.04, h_wall = 0;  // h_wall > 0: graded towards the outer wall, h(x) = min(h, h_wall + 0.25 (R2 - |x|))
  int kmax = 4, kref = -1;
  Real dt0 = 0.05, T = 0.8, dt = 0.002;
  std::vector<Real> tolerances;  // speed: adaptive runs (run()) at these tolerances
  Real dt_first = 1e-4;          // their first step
  Linearisation lin = Linearisation::newton;
};

Mesh<2> make_mesh(const Scene& sc, const Settings& s) { return sc.annulus().mesh(s.h, s.h_wall); }

// --- one FEM run -------------------------------------------------------------------------------
// Advances n steps of dt and calls obs(flow, step, report) after each; rigid inner body, driven outer wall.
// The flow options of a run of Scheme.
template <class Scheme>
FlowOptions flow_options(const Scene& sc, Linearisation lin) {
  FlowOptions fo{sc.rho, sc.mu, lin, 25, 1e-10, sc.damped_start};
  fo.start_up = Scheme::theta == 1 ? sc.start_up : StartUp::midpoint;  // MR/AB starts with its own
  return fo;
}
// Isoparametric cells on both cylinders (sc.curved, Taylor-Hood only); before the initial field,
// which is set at the velocity DOFs' (then curved) points.
template <class Flow>
void curve_cylinders(Flow& flow, const Scene& sc) {
  if (!sc.curved) return;
  if constexpr (Flow::Space::VelocityElement::degree == 2) {
    flow.curve_boundary(tags::inner, onto_sphere<2>(Vec<2>::Zero(), sc.r1));
    flow.curve_boundary(tags::outer, onto_sphere<2>(Vec<2>::Zero(), sc.r2));
  } else {
    throw InvalidArgument("--curved", "isoparametric cells need P2 velocities: use --pair th");
  }
}
template <class Pair, class Scheme, bool Convection, class Obs>
void simulate_with(const Mesh<2>& mesh, const Scene& sc, Real dt, int n, Linearisation lin, Obs&& obs) {
  using Equations = std::conditional_t<Convection, NavierStokes, UnsteadyStokes>;
  AleFlow<FlowConfig<2, Pair, Scheme, Equations, Solver>> flow(mesh, flow_options<Scheme>(sc, lin));
  const scenes::Annulus an = sc.annulus();
  an.configure(flow);
  curve_cylinders(flow, sc);
  if (sc.wall_moving_at_0 && sc.omega2(0) != 0) an.start_with_moving_wall(flow);
  int k0 = 1;  // the first step on the grid k dt
  if (sc.graded > 0) {
    // first step F dt (dt / dt0)^((q - 2) / 2): the start-up BSS step's error, O(first^2), is O(dt^q)
    const Real first = sc.graded * dt * std::pow(dt / sc.graded_dt0, (Scheme::order - 2) / 2.0);
    Real sum = 0;
    for (Real h : graded_start(dt, first, max_step_ratio<Scheme>())) flow.step(h), sum += h;
    k0 = int(std::lround(sum / dt)) + 1;
  }
  for (int k = k0; k <= n; ++k) {
    const StepReport rep = flow.step(dt);
    obs(flow, k, rep);
  }
}
// Advances to T by run() with adaptive steps (tolerance tol, first step dt_first) and calls
// obs(flow, summary) at T.
template <class Pair, class Scheme, class Obs>
void simulate_adaptive(const Mesh<2>& mesh, const Scene& sc, Real tol, Real dt_first, Real T, Linearisation lin,
                       const std::filesystem::path& output, Obs&& obs) {
  FlowOptions fo = flow_options<Scheme>(sc, lin);
  fo.tau_dt = dt_first;  // P1/P1-GLS: tau must not change with the steps
  AleFlow<FlowConfig<2, Pair, Scheme, NavierStokes, Solver>> flow(mesh, fo);
  const scenes::Annulus an = sc.annulus();
  an.configure(flow);
  curve_cylinders(flow, sc);
  if (sc.wall_moving_at_0 && sc.omega2(0) != 0) an.start_with_moving_wall(flow);
  RunOptions ro;
  ro.dt = dt_first, ro.t_end = T, ro.tolerance = tol, ro.progress_every = 0, ro.log = nullptr, ro.output = output;
  ro.velocity_scale = sc.r2;  // the outer wall's final speed (omega_2 -> 1): the flow starts from rest
  const RunSummary sum = run(flow, ro);
  obs(flow, sum);
}
template <class Pair, class Scheme, class Obs>
void simulate(const Mesh<2>& mesh, const Scene& sc, Real dt, int n, Linearisation lin, Obs&& obs) {
  if (sc.convection) simulate_with<Pair, Scheme, true>(mesh, sc, dt, n, lin, std::forward<Obs>(obs));
  else simulate_with<Pair, Scheme, false>(mesh, sc, dt, n, lin, std::forward<Obs>(obs));
}

// ||u_h - u||_L2 of the velocity entries of `field` on the space's current mesh.
template <class Space>
Real velocity_l2_error(const Space& space, const VecX& field, const std::function<Vec<2>(const Vec<2>&)>& u) {
  const std::function<Mat<2>(const Vec<2>&)> no_grad = [](const Vec<2>&) { return Mat<2>(Mat<2>::Zero()); };
  const std::function<Real(const Vec<2>&)> no_p = [](const Vec<2>&) { return 0.0; };
  return flow_errors(space, field, u, no_grad, no_p).u_l2;
}

// ||u_h - u_FD e_theta||_L2 on the flow's current mesh.
template <class Flow>
Real error_vs_fd(const Flow& flow, const reference::AnnulusSolver& fd) {
  return velocity_l2_error(flow.space(), flow.field(), [&](const Vec<2>& x) {
    const Real r = x.norm();
    return Vec<2>(fd.velocity(r) / r * Vec<2>(-x[1], x[0]));
  });
}

// ||u_h - u_ref||_L2 on the flow's current mesh, u_ref given by its field vector on the same
// mesh topology (the meshes at t differ by the O(dt^p) difference of the mesh motions).
template <class Flow>
Real error_vs_field(const Flow& flow, const VecX& ref) {
  return velocity_l2_error(flow.space(), VecX(flow.field() - ref), [](const Vec<2>&) { return Vec<2>(Vec<2>::Zero()); });
}

// --- run-time choice of the compile-time types -----------------------------------------------
template <class F>
void with_types(const std::string& pair, const std::string& scheme, F&& f) {
  auto pick = [&]<class Pair>() {
    dispatch_scheme(scheme, [&]<class Scheme>() { f.template operator()<Pair, Scheme>(); }, "--schemes");
  };
  if (pair == "th") pick.template operator()<TaylorHood>();
  else if (pair == "gls") pick.template operator()<P1P1Gls>();
  else throw InvalidArgument("--pair", "th or gls, got " + pair);
}

const char* display_name(const std::string& key) {
  return dispatch_scheme(key, []<class S>() { return S::name; }, "--schemes");
}

// The paper's Table 1 (E at t = 0.8, dt = 0.05 2^-k); BSS is not in the table.
Real paper_table1(const std::string& scheme, int k) {
  static const Real mr[] = {5.5839e-02, 2.7349e-02, 1.3514e-02, 6.6154e-03, 2.0392e-03};
  static const Real b2e[] = {4.8643e-02, 1.4622e-02, 3.7499e-03, 9.3618e-04, 5.9122e-04};
  static const Real b2ab[] = {7.2598e-02, 3.7336e-02, 1.8516e-02, 5.2342e-03, 1.2755e-03};
  static const Real b3[] = {1.2816e-01, 6.7750e-02, 3.0934e-02, 4.1583e-03, 6.9390e-04};
  if (k < 0 || k > 4) return NAN;
  if (scheme == "MR_AB") return mr[k];
  if (scheme == "BDF2_BDF2E") return b2e[k];
  if (scheme == "BDF2_AB") return b2ab[k];
  if (scheme == "BDF3_BDF3E") return b3[k];
  return NAN;
}

std::string fmt(const char* f, Real v) {
  if (!std::isfinite(v)) return "";
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

void print_start(const Scene& sc) {
  if (!sc.convection) std::printf("convection OFF (unsteady Stokes: a diagnostic, not the paper's problem)\n");
  if (sc.damped_start > 0)
    std::printf("start-up: damped, the first step as %d backward-Euler substeps (extrapolated for order >= 3), every run\n",
                sc.damped_start);
  const char* steps = sc.start_up == StartUp::bdf ? "BSS, BDF2/BDF2E start-up steps for the BDF schemes" : "MR/AB start-up steps";
  if (sc.damped_start == 0) std::printf("start-up: the multistep one (%s)\n", steps);
  else std::printf("  then %s\n", steps);
  if (sc.graded > 0)
    std::printf("graded start: fixed-dt runs grow from %g dt (dt / %g)^((q - 2) / 2) to dt (time/step_sequence.hpp)\n",
                sc.graded, sc.graded_dt0);
}

// --- Table 1 and the smooth-start study --------------------------------------------------------
int time_orders(const Scene& sc, const Settings& s, bool paper) {
  const Mesh<2> mesh = make_mesh(sc, s);
  const int kref = s.kref >= 0 ? s.kref : s.kmax + 3;
  const int n0 = int(std::lround(s.T / s.dt0));
  std::printf("annulus: R1 = %g, R2 = %g, rho = %g, mu = %g, rho_1 = %g (I^ = %.4g), %s start%s; T = %g\n", sc.r1, sc.r2,
              sc.rho, sc.mu, sc.rho_s, sc.ihat(), sc.ramp > 0 ? "smooth" : "impulsive",
              sc.ramp > 0 ? "" : sc.wall_moving_at_0 ? " (u_h^0 = wall speed on the wall)" : " (u_h^0 = 0 on the wall)", s.T);
  print_start(sc);
  std::printf("mesh: %ld nodes, %ld triangles (h = %g%s), pair %s, %s, %s\n", long(mesh.n_nodes()), long(mesh.n_cells()), s.h,
              s.h_wall > 0 ? (", graded to " + fmt("%g", s.h_wall) + " at the outer wall").c_str() : "",
              s.pair == "th" ? "P2/P1" : "P1/P1-GLS", s.lin == Linearisation::newton ? "Newton" : "semi-implicit", Solver::name);
  // FD reference (its error ~1e-7 at these settings: tests/physics/test_annulus.cpp)
  auto t0 = Clock::now();
  reference::AnnulusSolver fd(sc.fd_problem(), {6000, s.dt0 / 1024, 2});
  fd.advance_to(s.T);
  std::printf("FD reference: N = 6000, dt = %g: omega(T) = %.6e (%.1f s)\n", s.dt0 / 1024, fd.omega(),
              std::chrono::duration<double>(Clock::now() - t0).count());
  // fine-dt FEM reference on the same mesh
  VecX uref;
  Real wref = 0, eref_fd = 0;
  t0 = Clock::now();
  with_types(s.pair, s.ref_scheme, [&]<class Pair, class Scheme>() {
    const int n = n0 << kref;
    simulate<Pair, Scheme>(mesh, sc, s.dt0 / (1 << kref), n, s.lin, [&](const auto& flow, int k, const StepReport&) {
      if (k == n) uref = flow.field(), wref = flow.body_velocity(0)[2], eref_fd = error_vs_fd(flow, fd);
    });
  });
  std::printf("FEM reference: %s, dt = %g: omega(T) = %.6e, E vs FD = %.4e (the spatial error) (%.0f s)\n",
              display_name(s.ref_scheme), s.dt0 / (1 << kref), wref, eref_fd,
              std::chrono::duration<double>(Clock::now() - t0).count());
  std::fflush(stdout);
  std::ofstream csv;
  if (!s.csv.empty()) {
    csv.open(s.csv);
    csv << "scheme,k,dt,E_fd,order_fd,E_time,order_time,omega,omega_err_fd,omega_err_time,paper_E,newton_avg,wall_s\n";
  }
  std::printf("\n| scheme | k | dt | E vs FD | order | E vs fine-dt FEM | order | |w - w_FD| | |w - w_fine| |%s steps/s |\n",
              paper ? " paper E |" : "");
  std::printf("|---|---|---|---|---|---|---|---|---|%s---|\n", paper ? "---|" : "");
  for (const auto& key : s.schemes) {
    Real prev_fd = NAN, prev_t = NAN;
    for (int k = 0; k <= s.kmax; ++k) {
      const Real dt = s.dt0 / (1 << k);
      const int n = n0 << k;
      Real efd = NAN, et = NAN, w = NAN;
      long newton = 0;
      const auto tk = Clock::now();
      try {
        with_types(s.pair, key, [&]<class Pair, class Scheme>() {
          simulate<Pair, Scheme>(mesh, sc, dt, n, s.lin, [&](const auto& flow, int step, const StepReport& rep) {
            newton += rep.newton_iterations;
            if (step == n) efd = error_vs_fd(flow, fd), et = error_vs_field(flow, uref), w = flow.body_velocity(0)[2];
          });
        });
      } catch (const Error& e) {
        std::printf("| %s | %d | %g | failed: %s |\n", display_name(key), k, dt, e.what());
        continue;
      }
      const double wall = std::chrono::duration<double>(Clock::now() - tk).count();
      const Real ofd = std::log2(prev_fd / efd), ot = std::log2(prev_t / et);
      const Real pe = paper ? paper_table1(key, k) : NAN;  // the paper's Table 1 is for the impulsive start only
      std::printf("| %s | %d | %.6g | %.4e | %s | %.4e | %s | %.2e | %.2e |%s %.1f |\n", display_name(key), k, dt, efd,
                  fmt("%.2f", ofd).c_str(), et, fmt("%.2f", ot).c_str(), std::abs(w - fd.omega()), std::abs(w - wref),
                  paper ? (" " + fmt("%.4e", pe) + " |").c_str() : "", n / wall);
      std::fflush(stdout);
      if (csv.is_open())
        csv << key << ',' << k << ',' << dt << ',' << efd << ',' << fmt("%.4f", ofd) << ',' << et << ','
            << fmt("%.4f", ot) << ',' << w << ',' << std::abs(w - fd.omega()) << ',' << std::abs(w - wref) << ','
            << fmt("%.4e", pe) << ',' << Real(newton) / n << ',' << wall << '\n';
      prev_fd = efd, prev_t = et;
    }
  }
  return 0;
}

// --- speed against error --------------------------------------------------------------------
// Every (linearisation, scheme, dt) run is timed from the flow's construction to the last step
// (mesh-velocity set-up, symbolic analysis and every step included: the time to solution);
// the error evaluation at T is not timed.
int speed_error(const Scene& sc, const Settings& s, const std::vector<Linearisation>& lins) {
  const Mesh<2> mesh = make_mesh(sc, s);
  const int kref = s.kref >= 0 ? s.kref : s.kmax + 3;
  const int n0 = int(std::lround(s.T / s.dt0));
  std::printf("annulus speed/error: R1 = %g, R2 = %g, rho = %g, mu = %g, rho_1 = %g, %s start (ramp %g); T = %g\n", sc.r1,
              sc.r2, sc.rho, sc.mu, sc.rho_s, sc.ramp > 0 ? "smooth" : "impulsive", sc.ramp, s.T);
  std::printf("mesh: %ld nodes, %ld triangles (h = %g), pair %s, %s\n", long(mesh.n_nodes()), long(mesh.n_cells()), s.h,
              s.pair == "th" ? "P2/P1" : "P1/P1-GLS", Solver::name);
  print_start(sc);
  reference::AnnulusSolver fd(sc.fd_problem(), {6000, s.dt0 / 1024, 2});
  fd.advance_to(s.T);
  VecX uref;
  Real eref_fd = 0;
  with_types(s.pair, s.ref_scheme, [&]<class Pair, class Scheme>() {
    const int n = n0 << kref;
    simulate<Pair, Scheme>(mesh, sc, s.dt0 / (1 << kref), n, Linearisation::newton,
                           [&](const auto& flow, int k, const StepReport&) {
                             if (k == n) uref = flow.field(), eref_fd = error_vs_fd(flow, fd);
                           });
  });
  std::printf("FD reference N = 6000, dt = %g; fine-dt FEM %s + Newton, dt = %g: %.4e from FD (the spatial error)\n",
              s.dt0 / 1024, display_name(s.ref_scheme), s.dt0 / (1 << kref), eref_fd);
  std::ofstream csv;
  if (!s.csv.empty()) {
    csv.open(s.csv);
    csv << "scheme,linearisation,k,dt,steps,E_fd,E_time,omega_err_fd,newton_avg,wall_s,cpu_s,tolerance\n";
  }
  std::printf("\n| scheme | linearisation | dt | E vs FD | E vs fine-dt FEM | iterations/step | wall (s) | CPU (s) |\n"
              "|---|---|---|---|---|---|---|---|\n");
  for (Linearisation lin : lins)
    for (const auto& key : s.schemes)
      for (int k = 0; k <= s.kmax; ++k) {
        const Real dt = s.dt0 / (1 << k);
        const int n = n0 << k;
        Real efd = NAN, et = NAN, ew = NAN, wall = 0, cpu = 0;
        long its = 0;
        try {
          with_types(s.pair, key, [&]<class Pair, class Scheme>() {
            const auto w0 = Clock::now();
            const std::clock_t c0 = std::clock();
            simulate<Pair, Scheme>(mesh, sc, dt, n, lin, [&](const auto& flow, int step, const StepReport& rep) {
              its += rep.newton_iterations;
              if (step < n) return;
              wall = std::chrono::duration<double>(Clock::now() - w0).count();
              cpu = Real(std::clock() - c0) / CLOCKS_PER_SEC;
              efd = error_vs_fd(flow, fd), et = error_vs_field(flow, uref);
              ew = std::abs(flow.body_velocity(0)[2] - fd.omega());
            });
          });
        } catch (const Error& e) {
          std::printf("| %s | %d | %g | failed: %s |\n", display_name(key), k, dt, e.what());
          continue;
        }
        const char* ln = lin == Linearisation::newton ? "newton" : "semi";
        std::printf("| %s | %s | %.6g | %.4e | %.4e | %.2f | %.2f | %.2f |\n", display_name(key), ln, dt, efd, et,
                    Real(its) / n, wall, cpu);
        if (csv.is_open())
          csv << key << ',' << ln << ',' << k << ',' << dt << ',' << n << ',' << efd << ',' << et << ',' << ew << ','
              << Real(its) / n << ',' << wall << ',' << cpu << ",0\n"
              << std::flush;
      }
  // adaptive steps (run()), the same measures; MR/AB has none (theory.md 9.1)
  if (!s.tolerances.empty())
    std::printf("\n| scheme | linearisation | tolerance | steps (rejected) | dt min .. max | E vs FD | E vs fine-dt FEM | "
                "wall (s) | CPU (s) |\n|---|---|---|---|---|---|---|---|---|\n");
  for (Linearisation lin : lins)
    for (const auto& key : s.schemes)
      for (Real tol : s.tolerances) {
        if (key == "MR_AB") continue;
        const char* ln = lin == Linearisation::newton ? "newton" : "semi";
        Real efd = NAN, et = NAN, ew = NAN, wall = 0, cpu = 0;
        RunSummary sum;
        try {
          with_types(s.pair, key, [&]<class Pair, class Scheme>() {
            const auto w0 = Clock::now();
            const std::clock_t c0 = std::clock();
            const std::filesystem::path out =
                s.output.empty() ? "" : s.output + "/" + key + "_" + ln + "_tol" + fmt("%g", tol);
            simulate_adaptive<Pair, Scheme>(mesh, sc, tol, s.dt_first, s.T, lin, out, [&](const auto& flow, const RunSummary& r) {
              wall = std::chrono::duration<double>(Clock::now() - w0).count();
              cpu = Real(std::clock() - c0) / CLOCKS_PER_SEC;
              sum = r;
              efd = error_vs_fd(flow, fd), et = error_vs_field(flow, uref);
              ew = std::abs(flow.body_velocity(0)[2] - fd.omega());
            });
          });
        } catch (const Error& e) {
          std::printf("| %s | tol %g | failed: %s |\n", display_name(key), tol, e.what());
          continue;
        }
        std::printf("| %s | %s | %.0e | %d (%d) | %.1e .. %.1e | %.4e | %.4e | %.2f | %.2f |\n", display_name(key), ln, tol,
                    sum.steps, sum.rejected, sum.dt_smallest, sum.dt_largest, efd, et, wall, cpu);
        if (csv.is_open())
          csv << key << ',' << ln << ",-1," << sum.dt_largest << ',' << sum.steps << ',' << efd << ',' << et << ','
              << ew << ",," << wall << ',' << cpu << ',' << tol << '\n'
              << std::flush;
      }
  return 0;
}

// --- Figure 7 ----------------------------------------------------------------------------------
int figure7(const Scene& base, const Settings& s) {
  const Mesh<2> mesh = make_mesh(base, s);
  const std::string key = s.schemes.size() == 1 ? s.schemes[0] : "MR_AB";
  std::printf("Figure 7: mu = %g, rho = %g, omega_2 = 1 from t = 0+; FEM %s, %s, h = %g (%ld triangles), dt = %g\n",
              base.mu, base.rho, display_name(key), s.pair == "th" ? "P2/P1" : "P1/P1-GLS", s.h, long(mesh.n_cells()), s.dt);
  print_start(base);
  std::ofstream csv;
  if (!s.csv.empty()) {
    csv.open(s.csv);
    csv << "rho_1,I_hat,tstar_fd,tstar_fem,rel_diff,omega_max_fem,steps,wall_s\n";
  }
  std::printf("\n| rho_1 | I^ | t* (FD) | t* (FEM) | rel. diff. | max omega_h | steps |\n|---|---|---|---|---|---|---|\n");
  // t* by linear interpolation between the two levels around omega = 1/2 (final value 1)
  auto crossing = [](Real t0, Real w0, Real t1, Real w1) { return t0 + (0.5 - w0) / (w1 - w0) * (t1 - t0); };
  for (int e = -6; e <= 2; ++e) {
    Scene sc = base;
    sc.rho_s = std::pow(10.0, e);
    reference::AnnulusSolver fd(sc.fd_problem(), {2000, 2e-5, 2});
    Real tfd = NAN, tp = 0, wp = 0;
    while (fd.time() < 20) {
      fd.step();
      if (fd.omega() >= 0.5) {
        tfd = crossing(tp, wp, fd.time(), fd.omega());
        break;
      }
      tp = fd.time(), wp = fd.omega();
    }
    Real tfem = NAN, wmax = 0;
    int steps = 0;
    const auto tk = Clock::now();
    try {
      with_types(s.pair, key, [&]<class Pair, class Scheme>() {
        Real t0 = 0, w0 = 0;
        const int nmax = int(std::ceil(1.2 * tfd / s.dt)) + 10;  // past t*, max |omega_h| checked on the way
        simulate<Pair, Scheme>(mesh, sc, s.dt, nmax, s.lin, [&](const auto& flow, int step, const StepReport&) {
          const Real w = flow.body_velocity(0)[2];
          wmax = std::max(wmax, std::abs(w));
          if (!std::isfinite(w)) throw SolverError("non-finite body velocity");
          if (std::isnan(tfem) && w >= 0.5) tfem = crossing(t0, w0, flow.time(), w), steps = step;
          t0 = flow.time(), w0 = w;
        });
      });
    } catch (const Error& err) {
      std::printf("rho_1 = %g failed: %s\n", sc.rho_s, err.what());
    }
    const double wall = std::chrono::duration<double>(Clock::now() - tk).count();
    std::printf("| %g | %.4g | %.5f | %.5f | %.2e | %.5f | %d |\n", sc.rho_s, sc.ihat(), tfd, tfem, tfem / tfd - 1, wmax,
                steps);
    std::fflush(stdout);
    if (csv.is_open())
      csv << sc.rho_s << ',' << sc.ihat() << ',' << tfd << ',' << tfem << ',' << tfem / tfd - 1 << ',' << wmax << ','
          << steps << ',' << wall << '\n';
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) try {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress of long sweeps under nohup
  // the mode sets the defaults of the other options
  std::string mode = argc > 1 ? argv[1] : "table1";
  Scene sc;
  Settings s;
  if (mode == "smooth") sc.mu = 1, sc.ramp = 0.1, s.T = 0.4, s.dt0 = 0.02, s.h = 0.05;
  if (mode == "speed") sc.mu = 1, sc.ramp = 0.1, s.T = 0.4, s.dt0 = 0.02, s.h = 0.08;
  if (mode == "fig7") sc.mu = 1, s.schemes = {"MR_AB"};
  std::string start_up = "midpoint";
  std::string lin = "newton", wall_start = sc.wall_moving_at_0 ? "moving" : "rest", convection = "on";
  std::vector<std::string> lins = {"newton", "semi"};
  Options opt("annulus", "The paper's annulus (section 6.3); modes table1, smooth, speed, fig7 (see the file comment).");
  opt.positional("mode", mode, "table1 | smooth | speed | fig7")
      .add("schemes", s.schemes, "schemes, comma-separated (" + scheme_names() + ")")
      .add("pair", s.pair, "th (P2/P1) or gls (P1/P1-GLS)")
      .add("h", s.h, "mesh size")
      .add("h-wall", s.h_wall, "mesh size at the outer wall (0: uniform h)")
      .add("kmax", s.kmax, "dt = dt0 2^-k, k = 0..kmax")
      .add("kref", s.kref, "the fine-dt FEM reference at dt0 2^-kref (-1: kmax + 3)")
      .add("ref-scheme", s.ref_scheme, "scheme of the fine-dt FEM reference")
      .add("lin", lin, "newton or semi (table1, smooth, fig7)")
      .add("lins", lins, "linearisations of the speed study")
      .add("tolerances", s.tolerances, "speed: also adaptive runs (run()) at these error tolerances")
      .add("dt-first", s.dt_first, "speed: the adaptive runs' first step")
      .add("output", s.output, "speed: folder for each adaptive run's bodies.csv (dt, error estimate per step)")
      .add("csv", s.csv, "CSV file of the results")
      .add("mu", sc.mu, "viscosity")
      .add("rho-s", sc.rho_s, "density of the inner cylinder")
      .add("ramp", sc.ramp, "smooth start omega_2 = 1 - exp(-(t/ramp)^4); 0: impulsive")
      .add("T", s.T, "final time")
      .add("dt0", s.dt0, "largest time step of the sweeps")
      .add("dt", s.dt, "time step (fig7)")
      .add("wall-start", wall_start, "the initial FE velocity on the outer wall: moving or rest")
      .add("damped-start", sc.damped_start, "the first step as M backward-Euler substeps (0: multistep start-up)")
      .add("start-up", start_up, "the multistep start-up's formulas: midpoint (MR/AB) or bdf (BSS, BDF2; BDF schemes)")
      .add("graded-start", sc.graded,
           "fixed-dt runs: the first steps grow from F dt (dt / dt0)^((q - 2) / 2) to dt, q the order (0: none)")
      .add("convection", convection, "on, or off (unsteady Stokes: a diagnostic)")
      .flag("curved", sc.curved, "isoparametric P2 cells on both cylinders (--pair th)");
  if (!opt.parse(argc, argv, std::cout)) return 0;
  sc.graded_dt0 = s.dt0;
  opt.print(std::cout);
  auto linearisation = [](const std::string& l) {
    if (l != "newton" && l != "semi") throw InvalidArgument("--lin", "newton or semi, got " + l);
    return l == "semi" ? Linearisation::semi_implicit : Linearisation::newton;
  };
  s.lin = linearisation(lin);
  std::vector<Linearisation> lin_list;
  for (const auto& l : lins) lin_list.push_back(linearisation(l));
  sc.wall_moving_at_0 = wall_start != "rest";
  if (start_up != "midpoint" && start_up != "bdf") throw InvalidArgument("--start-up", "midpoint or bdf, got " + start_up);
  sc.start_up = start_up == "bdf" ? StartUp::bdf : StartUp::midpoint;
  sc.convection = convection != "off";
  if (mode == "table1") return time_orders(sc, s, true);
  if (mode == "smooth") return time_orders(sc, s, false);
  if (mode == "speed") return speed_error(sc, s, lin_list);
  if (mode == "fig7") return figure7(sc, s);
  throw InvalidArgument("mode", "table1, smooth, speed or fig7, got " + mode);
} catch (const std::exception& e) {
  std::fprintf(stderr, "annulus: %s\n", e.what());
  return 1;
}
