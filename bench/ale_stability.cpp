// Largest stable time step of each ALE scheme on a reference problem, by bisection.
//
//   cmake ... -DALEFSI_BUILD_BENCH=ON && cmake --build <dir> --target ale_stability   (or by hand:)
//   g++ -std=c++20 -O3 -march=native -DNDEBUG -Iinclude -I/usr/include/eigen3 bench/ale_stability.cpp -o /tmp/ale_stability
//     (by hand without SuiteSparse: no --solver umfpack; add -DALEFSI_HAVE_SUITESPARSE
//      -I/usr/include/suitesparse ... -lumfpack -lcholmod for it; the CMake target does that)
//   /tmp/ale_stability [--schemes MR_AB,BDF2_BDF2E,BDF2_AB,BDF3_BDF3E,BSS] [--h 0.05] [--mu 1,0.01]
//                      [--T 2] [--min-steps 200] [--dt-lo 0.005] [--dt-hi 0.5] [--tol 0.02]
//                      [--lin newton|semi] [--mesh-motion shear|rigid] [--max-drift D] [--csv FILE]
//                      [--trace DT] [--inner fixed|free] [--rho-s R] [--pair gls|th]
//                      [--solver sparselu|umfpack] [--startup-steps 10] [--energy-bound F]
//                      [--probes DT1,DT2,...] [--remesh Q] [--remesh-size] [--u-bound F]
//                      [--trace-every N]
//   `--help` lists every option with its default; a run starts by echoing the values it uses.
//   Quick check (a few seconds): --schemes BSS --mu 1 --h 0.1 --probes 0.1 --min-steps 5 --T 0.5
//
//   --schemes  by key (MR_AB) or display name (MR/AB), alefsi::dispatch_scheme.
//   --solver   linear solver of the flow system: SparseLu<> (default; saddle-point AMD) or
//              UmfPackLu (needs ALEFSI_HAVE_SUITESPARSE). Same results to solver round-off.
//   --trace DT one run per scheme and mu at DT, printing per step: E, max |u|, E^{n+1}/E^n,
//              drift, min quality, body w, Newton iterations and the step's wall time by phase
//              (mesh velocity, assembly, factorisation, solves): the first 12 steps, then about 40
//              lines, or every N-th step with --trace-every N.
//   --probes   runs these dt per scheme and mu (no bisection) and prints a table of outcomes.
//   --remesh Q (--inner free only) AleFlow::set_remeshing with trigger quality Q, walls = the
//              outer circle, no size function (the adaptation keeps the mesh's own edge lengths;
//              only the quality triggers); the body is a disk (radius R1, scenes::Annulus), so the
//              adaptation keeps it on its circle. The probe line counts the remeshes.
//   --remesh-size  with --remesh: target size uniform h, whose size band (an edge off h by
//              more than 70 %) also triggers: in the sheared annulus that remeshes at most steps.
// Every probe line gives its wall time and process CPU time (std::clock) (the table and the CSV
// give both per scheme), the largest |x_g| of a free body (|xg|) and the largest E^{n+1}/E^n at
// the steps the energy test checked (Er; 0 if it checked none: runs of <= --startup-steps steps).
//
// Problem (the annulus of the paper's Figure 7 set-up, WITHOUT the free inner body): fluid in
// R1 = 0.25 < |x| < R2 = 1, rho = 1, mu from --mu (each value is a separate table row); the
// outer cylinder turns at omega = 1 rad/s (u = omega (-y, x) on the outer wall, from t = 0:
// impulsive start), the inner cylinder is a fixed no-slip wall (u = 0; --inner free below makes
// it the paper's free body), fluid initially at rest. P1/P1-GLS (--pair) on the scene's mesh
// (alefsi/scenes/annulus.hpp: annulus_unstructured(R1, R2, h)).
// Mesh motion (--mesh-motion):
//   shear (default): the outer-wall nodes move with the wall (set_mesh_velocity(outer) = the
//       rotation velocity), the inner-wall nodes stay, the interior follows the elasticity
//       problem: every step runs the mesh-velocity solve, and the mesh shears (the outer ring
//       turns by omega t against the fixed inner ring). At h = 0.05 the smallest cell quality
//       falls from 0.63 to 0.03 by t = 2 s and a cell inverts near t = 6.3-6.7 s for every dt
//       (the motion, not the scheme), so any run longer than ~6 s ends with "mesh";
//   rigid: the inner-wall nodes also get the rotation velocity (they slide along the fixed inner
//       wall, whose fluid velocity stays 0), so the elasticity solution is the rigid rotation
//       and the mesh turns without distortion; runs of any length are possible.
// The wall nodes are advanced by the scheme's position formula (delta_lg X^{n+1} = dt V with V
// evaluated on the extrapolated positions), not placed on their circles, so they drift off
// them: the position update is an explicit integrator of dX/dt = omega x X (BSS: forward Euler,
// radius * sqrt(1 + (omega dt)^2) per step). The drift max ||X_v| - R| over the wall nodes is
// monitored and is a failure criterion (below).
//
// "Stable" at dt: the run reaches max(T, min_steps * dt) (default max(2 s, 200 steps)) and none
// of these happens at any step:
//   newton   Newton does not converge (25 iterations, relative residual 1e-10), or the linear
//            solver fails;
//   blow-up  a non-finite value, or max |u_h| > 10 x the maximal wall speed (omega R2 = 1);
//   energy   after the start-up (step n >= --startup-steps, default 10, and t >= 10 x the
//            diffusive time h^2 rho / mu, capped at 1 s) the kinetic energy grows by more than
//            10 % in one step, E^{n+1} > 1.1 E^n. Why that is safe for a spin-up from rest: if
//            E(t) is concave with E(0) = 0 then E(t + dt) / E(t) <= 1 + dt / t, and t >= 10 dt
//            after 10 steps. The test is therefore never active in a run of 10 steps or fewer
//            (dt > T / 11 with the free body's short runs): there only blow-up, drift, newton,
//            mesh and the opt-in E-bound can fail a probe;
//   drift    a wall node is more than --max-drift (default h; 0 disables) off its circle: the
//            domain is no longer the annulus (at dt = 0.5 BDF3/BDF3E shrinks the whole mesh
//            towards the centre while the flow criteria stay quiet, so this one is needed);
//   E-bound  only with --energy-bound F (off by default; the tables in docs/ale_benchmarks.md
//            were measured without it; active from the first step): E > F x E_max, E_max = 1/2 rho |Omega| (omega R2)^2, the
//            energy of the whole fluid at the largest wall speed (|u| <= omega R2 for this flow).
//            Catches slow energy growth the 10 %-per-step test misses (MR/AB, mu = 0.01).
//   u-bound  only with --u-bound F (off by default): after the start-up (the energy test's window)
//            max |u_h| > F x omega R2. For this flow |u| <= omega R2 (maximum principle; the
//            free body turns no faster than the outer wall); F = 1.1 leaves room for discrete
//            overshoot (the runs judged stable here stay below 1.03 omega R2). Catches the slow growth that the per-step
//            energy test misses in long runs (MR/AB above dt ~ 0.2: w drifts to 0.9 or 1.4 over
//            tens of seconds, E never grows 10 % in one step);
//   mesh     a cell is inverted or degenerate, or the elasticity matrix is not SPD. This is a
//            failure of the mesh motion, not of the time scheme; it is reported separately
//            and counted as "not stable" by the bisection (the table says so).
// Bisection: dt_hi (--dt-hi) is tried first (stable: the result is ">= dt_hi"), then dt_lo
// (unstable: "< dt_lo"); then geometric bisection dt = sqrt(lo hi) until hi / lo <= 1 + tol
// (default 2 %); the result is lo, the largest dt found stable. It assumes stability is
// monotone in dt, which bisection cannot check.
//
// --inner free: the paper's set-up (section 6.3, the Figure 7 case: scenes::Annulus, the fluid
// starting at rest): the inner cylinder is a FREE rigid body (density --rho-s, default 1.25:
// I = rho_s pi R1^4 / 2) driven by the fluid, coupled monolithically (its (V1, V2, w3) are
// unknowns of the flow system). The outer wall's *mesh*
// velocity is 0 (only its fluid velocity turns: a tangential mesh velocity would move its nodes
// off the circle), the body's surface nodes follow its exact rigid motion, the interior follows
// the elasticity problem; --mesh-motion is ignored. The mesh shears as the body turns (by about
// omega t rad against the fixed outer ring; at h = 0.05 the smallest cell quality falls from
// 0.6 to 0.035 by t = 2 s), so the free runs are short and end at a fixed time: defaults T = 1 s,
// min-steps 5 (overridable). Extra failure criterion: |w_body| > 10 omega (blow-up).
// With a free body the outer-wall nodes do not move, so "drift" measures how far the body's
// centre has left the axis (exactly 0 for this flow). That offset grows smoothly with dt (MR/AB,
// h = 0.05: 1.3e-5, 7.5e-4, 5.6e-3 at dt = 0.02, 0.1, 0.22 by t = 1.5), so it is an accuracy
// threshold, and its default (h) is stricter on finer meshes: give --max-drift explicitly to
// compare meshes. "mesh" failures at large dt are single steps that invert a cell next to the
// body (h = 0.01: inverted cells at radius 0.252-0.256, one at 0.299), also right after a
// remesh; --remesh lifts only the slow shear of long runs. Long runs: --remesh 0.35 --T 30 --u-bound 1.1
// --max-drift 0 (the body centre may move; the adaptation keeps the disk and walls exact).
// The paper's critical steps (P1/P1-GLS, h = 0.01: 0.06, 0.110, 0.108, 0.113, 0.025 for MR/AB,
// BDF2/BDF2E, BDF2/AB, BDF3/BDF3E, BSS) are for this set-up; docs/results.md gives ours and
// the h they were measured at.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "alefsi/app/options.hpp"
#include "alefsi/la/suitesparse.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/scenes/annulus.hpp"
#include "alefsi/sim/ale_flow.hpp"
#include "alefsi/time/schemes.hpp"

namespace {

using namespace alefsi;
using Clock = std::chrono::steady_clock;

constexpr Real R1 = 0.25, R2 = 1.0, omega = 1.0, rho = 1.0;
constexpr Real wall_speed = omega * R2;

// The paper's annulus (alefsi/scenes/annulus.hpp), outer wall at omega from t = 0+; rho_s is the
// free inner cylinder's density (--inner free).
scenes::Annulus annulus(Real rho_s) {
  return {.r1 = R1, .r2 = R2, .rho_s = rho_s, .omega = [](Real) { return omega; }};
}

struct Settings {
  Real h = 0.05, T = -1, dt_lo = 0.005, dt_hi = 0.5, tol = 0.02;  // T < 0: 2, or 1 with --inner free
  int min_steps = -1, startup_steps = 10;                          // min_steps < 0: 200, or 5 with --inner free
  Linearisation lin = Linearisation::newton;
  Real max_drift = -1;  // < 0: h; 0: no drift criterion
  Real energy_bound = 0;  // > 0: unstable if E > energy_bound * E_max (opt-in, see the header)
  Real u_bound = 0;       // > 0: unstable if max |u_h| > u_bound * omega R2 after the start-up (opt-in)
  bool rigid = false;  // --mesh-motion rigid: the inner-wall nodes slide with the rotation too
  Real trace_dt = 0;  // > 0: one verbose run at this dt per scheme and mu, no bisection
  int trace_every = 0;  // --trace-every N: print every N-th step (default: the first 12, then ~40 lines)
  bool free_body = false;  // --inner free: the inner cylinder is a free rigid body (the paper's set-up)
  Real rho_s = 1.25;       // its density
  bool taylor_hood = false;  // --pair th (default P1/P1-GLS, the paper's pair for this study)
  bool umfpack = false;      // --solver umfpack (default sparselu: SparseLu<>, saddle-point AMD)
  Real remesh_quality = 0;   // --remesh Q (> 0, free body only): AleFlow::set_remeshing, trigger quality Q
  bool remesh_size = false;  // --remesh-size: also a target size h (and its size-band trigger)
  std::vector<Real> probe_dts;  // --probes DT1,DT2,...: these probes per scheme and mu, no bisection
};

enum class Outcome { stable, newton, blowup, energy, bound, ubound, drift, mesh };
const char* outcome_name(Outcome o) {
  switch (o) {
    case Outcome::stable: return "stable";
    case Outcome::newton: return "newton";
    case Outcome::blowup: return "blow-up";
    case Outcome::energy: return "energy";
    case Outcome::bound: return "E-bound";
    case Outcome::ubound: return "u-bound";
    case Outcome::drift: return "drift";
    case Outcome::mesh: return "mesh";
  }
  return "?";
}

struct Probe {
  Real dt = 0;
  Outcome outcome = Outcome::stable;
  int steps = 0, target = 0, remeshes = 0;
  Real t = 0, umax = 0, energy = 0, energy_max = 0, drift = 0, min_quality = 1, wall = 0, cpu = 0, body_w = 0,
       body_x = 0,  // free body: the largest |x_g| over the run (0 for the exact flow)
       max_ratio = 0;  // the largest E^{n+1}/E^n at the steps the energy test checked (0: none)
  std::string detail;
};

// Kinetic energy 1/2 rho int |u|^2 of the P1 velocity (exact P1 mass matrix) and max |u| at
// the velocity DOFs.
template <class Flow>
std::pair<Real, Real> energy_and_umax(const Flow& flow) {
  const auto& sp = flow.space();
  const auto& mesh = flow.mesh();
  const VecX& f = flow.field();
  auto vel = [&](Index i) { return Vec<2>(f[sp.velocity_field(i, 0)], f[sp.velocity_field(i, 1)]); };
  Real E = 0, umax = 0;
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    const auto& d = sp.velocity().cell_dofs(c);
    Real s2 = 0;
    Vec<2> sum = Vec<2>::Zero();
    for (int a = 0; a < 3; ++a) {
      const Vec<2> ua = vel(d[a]);
      s2 += ua.squaredNorm();
      sum += ua;
    }
    E += mesh.measure(c) / 12 * (s2 + sum.squaredNorm());
  }
  for (Index i = 0; i < sp.velocity().n_dofs(); ++i) {
    const Vec<2> ui = vel(i);
    if (!std::isfinite(ui[0]) || !std::isfinite(ui[1])) return {NAN, INFINITY};
    umax = std::max(umax, ui.norm());
  }
  return {0.5 * rho * E, umax};
}

template <class Scheme, class Pair, class Solver>
Probe run_probe(const Mesh<2>& mesh0, Real mu, Real dt, const Settings& s, bool trace) {
  const auto t0 = Clock::now();
  const std::clock_t c0 = std::clock();
  Probe p;
  p.dt = dt;
  p.target = std::max(s.min_steps, int(std::ceil(s.T / dt - 1e-9)));
  // energy check from here on: n >= startup_steps and t >= 10 h^2 rho / mu (<= 1 s)
  const Real t_startup = std::min(1.0, 10 * s.h * s.h * rho / mu);
  const scenes::Annulus scene = annulus(s.rho_s);
  AleFlow<FlowConfig<2, Pair, Scheme, NavierStokes, Solver>> flow(mesh0, FlowOptions{rho, mu, s.lin, 25, 1e-10});
  if (s.free_body) {
    // the paper's set-up: the outer wall's fluid velocity, its mesh velocity 0 (the default); a
    // free inner cylinder, a disk (kept on its circle by the adaptation)
    scene.configure(flow);
    if (s.remesh_quality > 0) {
      RemeshOptions ro{.enabled = true, .trigger_quality = s.remesh_quality,
                       .walls = {Circle{Vec<2>::Zero(), R2, tags::outer}}, .size = {}, .adapt = {}};
      // --remesh-size: target size h, and the size band (|L - h| / h > 0.7) triggers too
      if (s.remesh_size) ro.size = [h = s.h](const std::vector<Circle>&) { return uniform_size(h); };
      flow.set_remeshing(std::move(ro));
    }
  } else {
    // this benchmark's own variant: a fixed inner wall, the outer wall's nodes turning with it
    auto rotation = [scene](const Vec<2>& x, Real t) { return scene.wall_velocity(x, t); };
    flow.set_velocity(tags::outer, rotation);
    flow.set_velocity(tags::inner, [](const Vec<2>&, Real) { return Vec<2>(Vec<2>::Zero()); });
    flow.set_mesh_velocity(tags::outer, rotation);
    if (s.rigid) flow.set_mesh_velocity(tags::inner, rotation);  // nodes slide along the fixed inner wall
  }
  std::vector<Index> outer = flow.mesh().boundary_nodes(tags::outer), inner = flow.mesh().boundary_nodes(tags::inner);
  const Real max_drift = s.max_drift < 0 ? s.h : s.max_drift;
  // |u| <= omega R2 for this flow, so E <= E_cap = 1/2 rho |Omega| (omega R2)^2
  Real area = 0;
  for (Index c = 0; c < mesh0.n_cells(); ++c) area += mesh0.measure(c);
  const Real E_cap = 0.5 * rho * area * wall_speed * wall_speed;
  Real E_prev = 0;
  for (int n = 0; n < p.target; ++n) {
    StepReport rep;
    const auto ts = Clock::now();
    try {
      rep = flow.step(dt);
    } catch (const MeshError& e) {
      p.outcome = Outcome::mesh, p.detail = e.what();
      break;
    } catch (const SolverError& e) {
      const std::string w = e.what();
      p.outcome = w.find("mesh-velocity") != std::string::npos ? Outcome::mesh : Outcome::newton;
      p.detail = w;
      break;
    }
    p.steps = n + 1;
    p.t = flow.time();
    p.remeshes = flow.stats().remeshes;
    if (rep.remeshed)  // new node numbering
      outer = flow.mesh().boundary_nodes(tags::outer), inner = flow.mesh().boundary_nodes(tags::inner);
    const auto [E, umax] = energy_and_umax(flow);
    p.umax = std::max(p.umax, umax);
    p.energy = E;
    p.energy_max = std::max(p.energy_max, E);
    for (Index v : outer) p.drift = std::max(p.drift, std::abs(flow.mesh().node(v).norm() - R2));
    for (Index v : inner) p.drift = std::max(p.drift, std::abs(flow.mesh().node(v).norm() - R1));
    if (trace && (n < 12 || (n + 1) % (s.trace_every > 0 ? s.trace_every : std::max(1, p.target / 40)) == 0)) {
      Real q = 1;
      for (Index c = 0; c < flow.mesh().n_cells(); ++c) q = std::min(q, flow.mesh().quality(c));
      std::printf("    n=%4d t=%8.4f E=%.6e umax=%.4f E/Eprev=%.4f drift=%.2e minq=%.3f w=%.5f |xg|=%.2e | %d it, %.2f s "
                  "(mesh %.2f, asm %.2f, fact %.2f, solve %.2f)\n",
                  n + 1, p.t, E, umax, E_prev > 0 ? E / E_prev : 0.0, p.drift, q,
                  s.free_body ? flow.body_velocity(0)[2] : 0.0, s.free_body ? flow.body_centre(0).norm() : 0.0,
                  rep.newton_iterations,
                  std::chrono::duration<double>(Clock::now() - ts).count(), rep.t_mesh_velocity, rep.t_assembly,
                  rep.t_factorize, rep.t_solve);
      std::fflush(stdout);
    }
    if (!std::isfinite(E) || umax > 10 * wall_speed) {
      p.outcome = Outcome::blowup;
      p.detail = "max |u| = " + std::to_string(umax);
      break;
    }
    if (s.free_body) {
      const Real w = flow.body_velocity(0)[2];
      p.body_w = w;
      p.body_x = std::max(p.body_x, flow.body_centre(0).norm());
      if (!std::isfinite(w) || std::abs(w) > 10 * omega) {
        p.outcome = Outcome::blowup;
        p.detail = "body w = " + std::to_string(w);
        break;
      }
    }
    if (s.energy_bound > 0 && E > s.energy_bound * E_cap) {
      p.outcome = Outcome::bound;
      p.detail = "E = " + std::to_string(E) + " > " + std::to_string(s.energy_bound) + " x E_max = " + std::to_string(E_cap);
      break;
    }
    if (max_drift > 0 && p.drift > max_drift) {
      p.outcome = Outcome::drift;
      p.detail = "wall nodes " + std::to_string(p.drift) + " off their circle";
      break;
    }
    const bool after_startup = n + 1 > s.startup_steps && p.t >= t_startup;
    if (s.u_bound > 0 && after_startup && umax > s.u_bound * wall_speed) {
      p.outcome = Outcome::ubound;
      p.detail = "max |u| = " + std::to_string(umax) + " > " + std::to_string(s.u_bound) + " x omega R2";
      break;
    }
    if (after_startup) p.max_ratio = std::max(p.max_ratio, E / E_prev);
    if (after_startup && E > 1.1 * E_prev) {
      p.outcome = Outcome::energy;
      p.detail = "E^{n+1}/E^n = " + std::to_string(E / E_prev);
      break;
    }
    E_prev = E;
  }
  for (Index c = 0; c < flow.mesh().n_cells(); ++c) p.min_quality = std::min(p.min_quality, flow.mesh().quality(c));
  p.wall = std::chrono::duration<double>(Clock::now() - t0).count();
  p.cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  return p;
}

// --pair and --solver: SparseLu<> in every build (the default), UMFPACK in a build with SuiteSparse.
template <class Scheme>
Probe probe(const Mesh<2>& mesh0, Real mu, Real dt, const Settings& s, bool trace) {
  const auto with_solver = [&]<class Solver>() {
    return s.taylor_hood ? run_probe<Scheme, TaylorHood, Solver>(mesh0, mu, dt, s, trace)
                         : run_probe<Scheme, P1P1Gls, Solver>(mesh0, mu, dt, s, trace);
  };
#ifdef ALEFSI_HAVE_SUITESPARSE
  if (s.umfpack) return with_solver.template operator()<UmfPackLu>();
#endif
  return with_solver.template operator()<SparseLu<>>();
}

struct Result {
  std::string scheme;
  Real mu = 0;
  std::string dt_max;       // "0.123", ">= 0.5", "< 0.005"
  Real lo = 0, hi = 0;      // bracket
  Probe first_unstable;     // the failing probe closest to the threshold
  Probe last_stable;
  int probes = 0;
  double wall = 0, cpu = 0;
};

void print_probe(const Probe& p) {
  std::printf("  dt=%.5f %-8s steps %4d/%-4d t=%7.3f umax=%.3f E=%.4e Emax=%.4e drift=%.1e minq=%.3f w=%.4f |xg|=%.1e Er=%.3f%s "
              "(%.1f s wall, %.1f s CPU)%s%s\n",
              p.dt, outcome_name(p.outcome), p.steps, p.target, p.t, p.umax, p.energy, p.energy_max, p.drift,
              p.min_quality, p.body_w, p.body_x, p.max_ratio, p.remeshes > 0 ? (" remeshes=" + std::to_string(p.remeshes)).c_str() : "",
              p.wall, p.cpu,
              p.detail.empty() ? "" : "  ", p.detail.c_str());
  std::fflush(stdout);
}

template <class Scheme>
Result bisect(const Mesh<2>& mesh, Real mu, const Settings& s) {
  const auto t0 = Clock::now();
  Result r;
  r.scheme = Scheme::name, r.mu = mu;
  std::printf("%s, mu = %g:\n", Scheme::name, mu);
  auto run = [&](Real dt) {
    ++r.probes;
    Probe p = probe<Scheme>(mesh, mu, dt, s, false);
    r.cpu += p.cpu;
    print_probe(p);
    return p;
  };
  Probe hi = run(s.dt_hi);
  if (hi.outcome == Outcome::stable) {
    r.dt_max = ">= " + std::to_string(s.dt_hi);
    r.lo = r.hi = s.dt_hi, r.last_stable = hi;
  } else {
    Probe lo = run(s.dt_lo);
    if (lo.outcome != Outcome::stable) {
      r.dt_max = "< " + std::to_string(s.dt_lo);
      r.lo = r.hi = s.dt_lo, r.first_unstable = lo;
    } else {
      while (hi.dt / lo.dt > 1 + s.tol) {
        Probe m = run(std::sqrt(lo.dt * hi.dt));
        (m.outcome == Outcome::stable ? lo : hi) = m;
      }
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.4f", lo.dt);
      r.dt_max = buf, r.lo = lo.dt, r.hi = hi.dt, r.last_stable = lo, r.first_unstable = hi;
    }
  }
  r.wall = std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

// "a" or "b": true for b; anything else throws naming the option.
bool choice(const std::string& value, const char* option, const char* a, const char* b) {
  ALEFSI_CHECK_ARG(value == a || value == b, option, "must be ", a, " or ", b, ", got '", value, "'");
  return value == b;
}

}  // namespace

int main(int argc, char** argv) try {
  Settings s;
  std::vector<std::string> schemes{"MR_AB", "BDF2_BDF2E", "BDF2_AB", "BDF3_BDF3E", "BSS"};
  std::vector<Real> mus{1, 0.01};
  std::string csv, inner = "fixed", pair = "gls", solver = "sparselu", lin = "newton", motion = "shear";
  Options opt("ale_stability", "Largest stable time step of each ALE scheme on the annulus, by bisection (see the file comment).");
  opt.add("schemes", schemes, "schemes, comma-separated (" + scheme_names() + ")")
      .add("h", s.h, "mesh size")
      .add("mu", mus, "viscosities, comma-separated (a table row each)")
      .add("T", s.T, "run to max(T, min-steps dt) (< 0: 2, or 1 with --inner free)")
      .add("min-steps", s.min_steps, "at least this many steps (< 0: 200, or 5 with --inner free)")
      .add("startup-steps", s.startup_steps, "the energy test starts after this many steps")
      .add("dt-lo", s.dt_lo, "bisection: the smallest dt")
      .add("dt-hi", s.dt_hi, "bisection: the largest dt, tried first")
      .add("tol", s.tol, "bisection: stop when dt_hi / dt_lo <= 1 + tol")
      .add("lin", lin, "newton or semi (semi-implicit)")
      .add("mesh-motion", motion, "shear or rigid (fixed inner wall only)")
      .add("max-drift", s.max_drift, "a wall node this far off its circle fails the run (< 0: h, 0: off)")
      .add("energy-bound", s.energy_bound, "unstable if E > F x E_max (0: off)")
      .add("u-bound", s.u_bound, "unstable if max |u| > F x omega R2 after the start-up (0: off)")
      .add("inner", inner, "fixed (a no-slip wall) or free (the paper's free rigid body)")
      .add("rho-s", s.rho_s, "density of the free inner cylinder")
      .add("pair", pair, "gls (P1/P1-GLS) or th (P2/P1)")
      .add("solver", solver, "sparselu or umfpack (a build with SuiteSparse)")
      .add("remesh", s.remesh_quality, "--inner free: remesh below this cell quality (0: off)")
      .flag("remesh-size", s.remesh_size, "with --remesh: target size h (its size band triggers too)")
      .add("probes", s.probe_dts, "run these dt (comma-separated) instead of the bisection")
      .add("trace", s.trace_dt, "one verbose run at this dt per scheme and mu (0: off)")
      .add("trace-every", s.trace_every, "with --trace: print every N-th step (0: the first 12, then ~40 lines)")
      .add("csv", csv, "CSV file of the bisection's results");
  if (!opt.parse(argc, argv, std::cout)) return 0;
  s.free_body = choice(inner, "--inner", "fixed", "free");
  s.taylor_hood = choice(pair, "--pair", "gls", "th");
  s.umfpack = choice(solver, "--solver", "sparselu", "umfpack");
#ifndef ALEFSI_HAVE_SUITESPARSE
  ALEFSI_CHECK_ARG(!s.umfpack, "--solver", "umfpack: built without SuiteSparse (ALEFSI_HAVE_SUITESPARSE)");
#endif
  s.lin = choice(lin, "--lin", "newton", "semi") ? Linearisation::semi_implicit : Linearisation::newton;
  s.rigid = choice(motion, "--mesh-motion", "shear", "rigid");
  // the free body's runs are short: the mesh shears as it turns (file comment)
  if (s.T < 0) s.T = s.free_body ? 1 : 2;
  if (s.min_steps < 0) s.min_steps = s.free_body ? 5 : 200;
  for (const auto& key : schemes) dispatch_scheme(key, []<class S>() {}, "--schemes");  // every name known
  ALEFSI_CHECK_ARG(s.remesh_quality == 0 || (s.free_body && s.remesh_quality > 0 && s.remesh_quality < 1), "--remesh",
                   "needs --inner free and 0 < Q < 1, got ", s.remesh_quality);
  ALEFSI_CHECK_ARG(s.h > 0, "--h", "must be positive, got ", s.h);
  ALEFSI_CHECK_ARG(s.dt_lo > 0, "--dt-lo", "must be positive, got ", s.dt_lo);
  ALEFSI_CHECK_ARG(s.dt_hi > s.dt_lo, "--dt-hi", "must exceed --dt-lo, got ", s.dt_hi);
  ALEFSI_CHECK_ARG(s.tol > 0, "--tol", "must be positive, got ", s.tol);
  ALEFSI_CHECK_ARG(!mus.empty() && std::all_of(mus.begin(), mus.end(), [](Real m) { return m > 0; }), "--mu",
                   "needs positive viscosities");
  ALEFSI_CHECK_ARG(s.startup_steps >= 0, "--startup-steps", "must be >= 0, got ", s.startup_steps);
  ALEFSI_CHECK_ARG(std::all_of(s.probe_dts.begin(), s.probe_dts.end(), [](Real d) { return d > 0; }), "--probes",
                   "needs positive time steps");
  opt.print(std::cout);

  const auto tm = Clock::now();
  const scenes::Annulus scene = annulus(s.rho_s);
  const Mesh<2> mesh = scene.mesh(s.h);
  std::printf("annulus R1=%g R2=%g, h=%g: %ld nodes, %ld triangles, %ld DOFs (P1/P1-GLS), meshed in %.2f s\n", R1, R2,
              s.h, long(mesh.n_nodes()), long(mesh.n_cells()), long(3 * mesh.n_nodes()),
              std::chrono::duration<double>(Clock::now() - tm).count());
  if (s.free_body)
    std::printf("inner cylinder: FREE rigid body, rho_s = %g (I = %.4g); outer-wall mesh velocity 0\n", s.rho_s,
                scene.inner_body().inertia);
  std::printf("pair %s, linear solver %s\n", s.taylor_hood ? "P2/P1" : "P1/P1-GLS", s.umfpack ? "UMFPACK" : "SparseLU");
  std::printf("omega=%g, rho=%g, %s, mesh motion %s, run to max(T=%g, %d steps), start-up %d steps, max drift %g, "
              "bisection tol %g%%\n",
              omega, rho, s.lin == Linearisation::newton ? "Newton" : "semi-implicit", s.free_body ? "elastic (free body)" : s.rigid ? "rigid" : "shear", s.T,
              s.min_steps, s.startup_steps, s.max_drift < 0 ? s.h : s.max_drift, 100 * s.tol);
  // --- one verbose run per scheme and mu
  if (s.trace_dt > 0) {
    for (Real mu : mus)
      for (const auto& key : schemes) {
        std::printf("%s, mu = %g, dt = %g:\n", key.c_str(), mu, s.trace_dt);
        dispatch_scheme(key, [&]<class Scheme>() { print_probe(probe<Scheme>(mesh, mu, s.trace_dt, s, true)); });
      }
    return 0;
  }
  // --- the given time steps, no bisection
  if (!s.probe_dts.empty()) {
    std::vector<std::string> rows;
    for (Real mu : mus)
      for (const auto& key : schemes)
        for (Real dt : s.probe_dts) {
          std::printf("%s, mu = %g:\n", key.c_str(), mu);
          const Probe p = dispatch_scheme(key, [&]<class Scheme>() { return probe<Scheme>(mesh, mu, dt, s, false); });
          print_probe(p);
          char row[256];
          std::snprintf(row, sizeof row, "| %s | %g | %g | %s | %d/%d | %.3f | %.3f | %.3f | %.0f |", key.c_str(), mu, dt,
                        outcome_name(p.outcome), p.steps, p.target, p.t, p.umax, p.min_quality, p.cpu);
          rows.push_back(row);
        }
    std::printf("\n| scheme | mu | dt | outcome | steps | t reached | max abs u | min quality | CPU (s) |\n|---|---|---|---|---|---|---|---|---|\n");
    for (const auto& r : rows) std::printf("%s\n", r.c_str());
    return 0;
  }
  // --- the bisection
  std::vector<Result> results;
  for (Real mu : mus)
    for (const auto& key : schemes)
      results.push_back(dispatch_scheme(key, [&]<class Scheme>() { return bisect<Scheme>(mesh, mu, s); }));
  std::printf("\n| scheme | mu | largest stable dt | first unstable dt (reason, at t) | wall drift at dt_max | probes | wall (s) | CPU (s) |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const auto& r : results) {
    char fu[160] = "-";
    if (r.first_unstable.dt > 0)
      std::snprintf(fu, sizeof fu, "%.4f (%s, t = %.3f)", r.first_unstable.dt, outcome_name(r.first_unstable.outcome),
                    r.first_unstable.t);
    char dr[32] = "-";
    if (r.last_stable.dt > 0) std::snprintf(dr, sizeof dr, "%.1e", r.last_stable.drift);
    std::printf("| %s | %g | %s | %s | %s | %d | %.0f | %.0f |\n", r.scheme.c_str(), r.mu, r.dt_max.c_str(), fu, dr,
                r.probes, r.wall, r.cpu);
  }
  if (!csv.empty()) {
    std::ofstream f(csv);
    f << "scheme,inner,rho_s,mu,h,linearisation,dt_max,bracket_lo,bracket_hi,first_unstable_reason,first_unstable_t,"
         "drift_at_dt_max,probes,wall_s,cpu_s\n";
    for (const auto& r : results)
      f << r.scheme << ',' << (s.free_body ? "free" : "fixed") << ',' << (s.free_body ? s.rho_s : 0.0) << ',' << r.mu << ',' << s.h << ',' << (s.lin == Linearisation::newton ? "Newton" : "semi-implicit")
        << ',' << r.dt_max << ',' << r.lo << ',' << r.hi << ','
        << (r.first_unstable.dt > 0 ? outcome_name(r.first_unstable.outcome) : "") << ',' << r.first_unstable.t << ','
        << r.last_stable.drift << ',' << r.probes << ',' << r.wall << ',' << r.cpu << '\n';
    std::printf("wrote %s\n", csv.c_str());
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "ale_stability: %s\n", e.what());
  return 1;
}
