// oscillating_cylinder — a cylinder oscillating in-line in a fluid at rest (Dütsch, Durst, Becker
// & Lienhart 1998, J. Fluid Mech. 360: Re = 100, KC = 5): the ALE benchmark for a driven body.
//
// What it shows: a body whose motion is prescribed moves the mesh (elastic mesh velocity), and its
// in-line force comes from the residual of the rows it would have if it were free
// (BodySystem::driven_loads), the same code that couples free bodies.
//
// Set-up (scenes::OscillatingCylinder): D = 1, Um = 1, nu = 0.01, f = 0.2 (T = 5), amplitude
// A = Um / (2 pi f) = 0.796; x(t) = -A sin(2 pi f t), so the start is impulsive (damped start);
// box [-15, 15]^2 with no-slip walls; rho = 1.
// Reported: per period, Morison's coefficients C_D (drag) and C_I (inertia) fitted to the in-line
// force, F = -1/2 rho D C_D u|u| - rho (pi D^2 / 4) C_I du/dt, and the largest |F|.
// How to run: `oscillating_cylinder` (minutes); `--help` lists the options (pair, mesh sizes, dt,
// periods, box size, CSV of t, x, u, F_x, F_y).
// Expected (docs/results.md): Dütsch et al. fit C_D = 2.09, C_I = 1.45 to their computed force;
// Wang's (1968) attached-flow asymptotics at beta = Re / KC = 20 give C_D = 1.32, C_I = 1.51
// (no separation: the drag is lower).
#include <alefsi/alefsi.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using namespace alefsi;

namespace {

template <class Pair>
int simulate(const scenes::OscillatingCylinder& scene, Real h_body, Real h_far, int steps_per_period, int periods,
             const std::string& csv_path) {
  const Mesh<2> mesh = scene.mesh(h_body, h_far);
  using Flow = AleFlow<FlowConfig<2, Pair, BDF2_BDF2E>>;
  Flow flow(mesh, scene.options());
  scene.configure(flow);
  std::printf("oscillating cylinder (Re = %g, KC = %g): %s, BDF2/BDF2E; %ld nodes, %ld triangles, %ld unknowns; "
              "h at the cylinder %g; T = %g, %d steps per period\n",
              scene.reynolds, scene.kc, Pair::name, long(mesh.n_nodes()), long(mesh.n_cells()),
              long(flow.space().n_field()), h_body, scene.period(), steps_per_period);
  const Real dt = scene.period() / steps_per_period;
  std::vector<Real> t{0}, fx{0};
  std::ofstream csv;
  if (!csv_path.empty()) {
    csv.open(csv_path);
    csv.precision(12);
    csv << "t,x,u,F_x,F_y\n";
  }
  const auto wall0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  Real max_position_error = 0;
  for (int p = 0; p < periods; ++p) {
    Real fmax = 0;
    for (int k = 1; k <= steps_per_period; ++k) {
      flow.step(dt);
      const auto load = flow.body_hydrodynamic_load(0);
      t.push_back(flow.time());
      fx.push_back(load[0]);
      fmax = std::max(fmax, std::abs(load[0]));
      const Real x = flow.body_centre(0)[0];
      max_position_error = std::max(max_position_error, std::abs(x - scene.position(flow.time())));
      if (csv.is_open()) csv << flow.time() << ',' << x << ',' << flow.body_velocity(0)[0] << ',' << load[0] << ',' << load[1] << '\n';
    }
    const auto m = scene.morison(t, fx, p * scene.period());
    std::printf("  period %2d: C_D %.4f  C_I %.4f  max |F_x| %.4f\n", p + 1, m.drag, m.inertia, fmax);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const double cpu = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  const auto m = scene.morison(t, fx, (periods - 1) * scene.period());
  std::printf("\nlast period | C_D %.4f | C_I %.4f | (Dütsch et al. 1998: 2.09, 1.45; Wang 1968, attached: 1.32, 1.51) | "
              "body path error %.1e | %.1f s wall, %.1f s CPU\n",
              m.drag, m.inertia, max_position_error, wall, cpu);
  return 0;
}

}  // namespace

int main(int argc, char** argv) try {
  scenes::OscillatingCylinder scene;
  std::string pair = "th", csv;
  Real h_body = 0.04, h_far = 1.0;
  int steps = 200, periods = 5;
  Options opt("oscillating_cylinder",
              "A cylinder oscillating in-line in a fluid at rest (Dütsch et al. 1998, Re = 100, KC = 5): Morison's "
              "coefficients of its in-line force.");
  opt.add("pair", pair, "th (P2/P1) or gls (P1/P1-GLS)")
      .add("h-body", h_body, "mesh size at the cylinder")
      .add("h-far", h_far, "largest mesh size")
      .add("steps", steps, "time steps per period")
      .add("periods", periods, "periods to run (the last is reported)")
      .add("half-width", scene.half_width, "the box is [-L, L]^2")
      .add("re", scene.reynolds, "Reynolds number Um D / nu")
      .add("kc", scene.kc, "Keulegan-Carpenter number Um / (f D)")
      .add("csv", csv, "CSV file of t, x, u, F_x, F_y");
  if (!opt.parse(argc, argv, std::cout)) return 0;
  opt.print(std::cout);
  ALEFSI_CHECK_ARG(steps >= 8, "--steps", "at least 8 steps per period, got ", steps);
  ALEFSI_CHECK_ARG(periods >= 1, "--periods", "at least 1, got ", periods);
  if (pair == "th") return simulate<TaylorHood>(scene, h_body, h_far, steps, periods, csv);
  if (pair == "gls") return simulate<P1P1Gls>(scene, h_body, h_far, steps, periods, csv);
  throw InvalidArgument("--pair", "th or gls, got " + pair);
} catch (const std::exception& e) {
  std::fprintf(stderr, "oscillating_cylinder: %s\n", e.what());
  return 1;
}
