// long_run — runs that must hold for 10^4 steps (issue 18): no NaN, no growth of memory,
// energy bounded by what drives the flow. Two scenes, each on its run() driver with remeshing:
//   long_run dkt      the paper's DKT (section 6.2) at its resolution (h 0.02 / 0.15 cm, P1/P1-GLS,
//                     BDF2/BDF2E, dt 1e-3 s): 10^4 steps, t = 10 s, the disks come to rest on the
//                     floor. Bound: kinetic energy (fluid + disks) <= the work of the net weight
//                     (weight - buoyancy) over the disks' fall.
//   long_run annulus  the paper's annulus (section 6.3: r1 0.25, r2 1, rho_s 1.25, mu 0.01, wall
//                     omega = 1 from t = 0+), h 0.05, P1/P1-GLS, MR/AB, dt 2e-3: 10^4 steps, t = 20; the free
//                     inner cylinder spins up and its rotation tangles the mesh, which is adapted
//                     whenever its quality drops below 0.35. Bound: the energy of rigid rotation at
//                     omega = 1 (the state the spin-up tends to). `--spin 20 --rho-s 1000`: the
//                     cylinder starts at 20 rad/s and, heavy, keeps turning: a remesh every few steps.
// From step 100 on (before it nearly nothing is dissipated, so E is close to its bound and the
// lumped energy's quadrature error decides), a step whose energy exceeds its bound is counted.
// Every `--report` steps: time, remeshes, the mesh's cells, resident memory (VmRSS) and its
// peak (VmHWM) from /proc/self/status, the kinetic energy (fluid, by the vertex-lumped mass of
// the velocity at the vertices) and its bound. Exit status 1 on a NaN, an energy above its bound, or a run failure.
// Command and measured numbers: docs/performance.md ("Long runs").
#include <alefsi/alefsi.hpp>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

using namespace alefsi;

namespace {

/// The bytes the allocator has handed out and not got back (MB): glibc's mallinfo2, heap and
/// mmapped blocks; -1 without glibc. Unlike the RSS it does not depend on where the allocator
/// put the blocks (glibc raises its mmap threshold as large blocks are freed, so the solver's
/// large blocks move from mmap to the heap, whose pages stay resident).
double allocated_mb() {
#if defined(__GLIBC__)
  const auto m = mallinfo2();
  return double(m.uordblks + m.hblkhd) / 1048576.0;
#else
  return -1;
#endif
}

/// VmRSS and VmHWM of this process (MB), from /proc/self/status (0 where it is not readable).
std::pair<double, double> memory_mb() {
  std::ifstream in("/proc/self/status");
  double rss = 0, hwm = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) rss = std::stod(line.substr(6)) / 1024;
    if (line.rfind("VmHWM:", 0) == 0) hwm = std::stod(line.substr(6)) / 1024;
  }
  return {rss, hwm};
}

/// 1/2 rho int |u|^2 with the velocity at the vertices and the vertex-lumped mass (|cell| / 3 each).
template <class Flow>
Real fluid_energy(const Flow& flow, Real rho) {
  const auto& m = flow.mesh();
  const auto& sp = flow.space();
  Real e = 0;
  for (Index c = 0; c < m.n_cells(); ++c)
    for (Index v : m.cell(c)) {
      const Index i = sp.velocity().node_dof(v);
      const Real ux = flow.field()[sp.velocity_field(i, 0)], uy = flow.field()[sp.velocity_field(i, 1)];
      e += m.measure(c) / 3 * 0.5 * rho * (ux * ux + uy * uy);
    }
  return e;
}

/// 1/2 m |v|^2 + 1/2 I omega^2 of the bodies, with their masses and moments of inertia.
template <class Flow>
Real bodies_energy(const Flow& flow, const std::vector<RigidBody2D>& bodies) {
  Real e = 0;
  for (std::size_t b = 0; b < flow.n_bodies(); ++b) {
    const auto v = flow.body_velocity(b);
    e += 0.5 * bodies[b].mass * (v[0] * v[0] + v[1] * v[1]) + 0.5 * bodies[b].inertia * v[2] * v[2];
  }
  return e;
}

template <class Flow, class Bound>
int monitor_run(Flow& flow, const std::vector<RigidBody2D>& bodies, Real rho, Real dt, int steps, int report,
                const std::string& name, Bound bound) {
  int step = 0, bad = 0;
  Real emax_ratio = 0;
  const auto wall0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  std::printf("| %s step | t | remeshes | cells | RSS (MB) | peak RSS (MB) | allocated (MB) | E (fluid + bodies) | bound | wall (s) | CPU (s) |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|\n", name.c_str());
  RunOptions ro;
  ro.dt = dt;
  ro.t_end = flow.time() + steps * dt;
  ro.progress_every = 0;
  ro.log = nullptr;
  ro.on_step = [&] {
    ++step;
    if (!flow.field().allFinite()) throw SolverError("non-finite field at step " + std::to_string(step));
    const Real e = fluid_energy(flow, rho) + bodies_energy(flow, bodies), b = bound(flow);
    // from step 100 on: at the start nearly nothing is dissipated yet, E ~ bound, and the
    // vertex-lumped energy is not the discrete one
    if (step >= 100) {
      emax_ratio = std::max(emax_ratio, e / b);
      if (e > b) ++bad;
    }
    if (step % report == 0 || step == steps) {
      const auto [rss, hwm] = memory_mb();
      std::printf("| %d | %.3f | %ld | %ld | %.1f | %.1f | %.1f | %.5g | %.5g | %.0f | %.0f |\n", step, flow.time(),
                  long(flow.stats().remeshes), long(flow.mesh().n_cells()), rss, hwm, allocated_mb(), e, b,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count(),
                  double(std::clock() - cpu0) / CLOCKS_PER_SEC);
      std::fflush(stdout);
    }
  };
  try {
    run(flow, ro);
  } catch (const Error& err) {
    std::printf("%s failed at step %d: %s\n", name.c_str(), step, err.what());
    return 1;
  }
  std::printf("\n%s: %d steps, largest E / bound from step 100 %.4f, steps above the bound: %d\n", name.c_str(), step, emax_ratio, bad);
  return bad == 0 ? 0 : 1;
}

int dkt(int steps, int report) {
  const auto scene = scenes::SettlingDisks::dkt(0.001);
  const Real hb = 0.02, hf = 0.15, rho = 1;
  using Flow = AleFlow<FlowConfig<2, P1P1Gls, BDF2_BDF2E>>;
  Flow flow(scene.mesh(hb, hf), FlowOptions{.rho = rho, .mu = 0.01, .linearisation = Linearisation::semi_implicit});
  scene.configure(flow, hb, hf);
  std::vector<Real> y0;
  for (std::size_t b = 0; b < flow.n_bodies(); ++b) y0.push_back(flow.body_centre(b)[1]);
  // the net weight's work over the fall so far: what the kinetic energy cannot exceed
  const auto bound = [&, y0](const Flow& f) {
    Real w = 0;
    for (std::size_t b = 0; b < f.n_bodies(); ++b) w += scene.net_weight(b) * (y0[b] - f.body_centre(b)[1]);
    return w;
  };
  std::vector<RigidBody2D> bodies;
  for (const Circle& c : scene.disks) bodies.push_back(disk_body(c.tag, c.centre, c.radius, scene.rho_s));
  return monitor_run(flow, bodies, rho, 1e-3, steps, report, "dkt", bound);
}

int annulus(int steps, int report, Real spin, Real rho_s) {
  scenes::Annulus scene{.rho_s = rho_s};
  scene.initial_velocity = Vec<3>(0, 0, spin);
  const Real h = 0.05, rho = 1;
  using Flow = AleFlow<FlowConfig<2, P1P1Gls, MR_AB>>;
  Flow flow(scene.mesh(h), FlowOptions{.rho = rho, .mu = 0.01});
  scene.configure(flow);
  flow.set_remeshing({.enabled = true,
                      .walls = {Circle{Vec<2>::Zero(), scene.r2, tags::outer}},
                      .size = [h](const std::vector<Circle>&) { return SizeFunction([h](const Vec<2>&) { return h; }); },
                      .adapt = {}});
  scene.start_with_moving_wall(flow);
  // rigid rotation at max(omega_wall = 1, |spin|): fluid 1/2 rho int r^2 dA plus the cylinder's
  // 1/2 I (with a spin the cylinder starts faster than the wall and is slowed down)
  const Real r1 = scene.r1, r2 = scene.r2, w = std::max(1.0, std::abs(spin));
  const Real rigid =
      w * w * (0.25 * rho * std::numbers::pi * (std::pow(r2, 4) - std::pow(r1, 4)) + 0.5 * scene.inner_body().inertia);
  return monitor_run(flow, {scene.inner_body()}, rho, 2e-3, steps, report, "annulus",
                     [rigid](const Flow&) { return rigid; });
}

}  // namespace

int main(int argc, char** argv) try {
  std::string mode;
  int steps = 10000, report = 1000;
  Real spin = 0, rho_s = 1.25;
  Options opt("long_run", "Runs of 10^4 steps: no NaN, no memory growth, energy bounded (see the file comment).");
  opt.positional("mode", mode, "dkt | annulus")
      .add("steps", steps, "number of steps")
      .add("report", report, "a table row every N steps")
      .add("spin", spin, "annulus: the inner cylinder's initial angular velocity (a stress test of remeshing)")
      .add("rho-s", rho_s, "annulus: the inner cylinder's density");
  if (!opt.parse(argc, argv, std::cout)) return 0;
  opt.print(std::cout);
  ALEFSI_CHECK_ARG(steps >= 1 && report >= 1, "--steps, --report", "must be >= 1");
  if (mode == "dkt") return dkt(steps, report);
  if (mode == "annulus") return annulus(steps, report, spin, rho_s);
  throw InvalidArgument("mode", "dkt or annulus, got '" + mode + "'");
} catch (const std::exception& e) {
  std::fprintf(stderr, "long_run: %s\n", e.what());
  return 1;
}
