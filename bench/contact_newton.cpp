// Newton in contact, 3D: two spheres inside the contact range, the coupling between their rows
// in the Jacobian (la/coupling.hpp) against it lagged (`LaggedPairCoupling`, the flow before
// the coupling). The set-up of examples/dkt3d.cpp (box x, y in [-3, 3], z in [0, 24], d = 1,
// rho_p / rho_f = 1.14, nu = 4.7e-3, g = 1, Taylor–Hood, BDF2/BDF2E, SaddlePointGmres, contact
// by eq. (24) on the approach speed and the spring of range h_body / 2): the leading sphere at
// (0, 0, 20), the trailing one above it, 0.05 to the side, its surface `--gap` away; falling at
// -0.38 and -0.45 (the pair's speeds before the kiss, docs/results.md) in fluid at rest. Steps
// of 0.01, 0.03, 0.1, then `--steps` of `--dt` (the adaptive runs' steps while close: 0.2-0.7).
// Both variants run on the same mesh in this process, one after the other, and must agree.
// Needs alefsi::gmsh. Results: docs/results.md ("Two spheres drafting, kissing and tumbling").
//
//   cmake --preset bench && cmake --build build/bench --target contact_newton
//   OPENBLAS_NUM_THREADS=1 build/bench/bench/contact_newton --level 0.75 --gap 0.025 --dt 0.3
//
// Prints per step and variant: Newton iterations, GMRES iterations, active contacts, the
// centres' distance, wall time; then the totals (wall and CPU) and the largest difference of
// the two variants' body velocities.
#include <alefsi/alefsi.hpp>
#include <alefsi/app.hpp>
#include <alefsi/la/krylov.hpp>
#include <alefsi/mesh/generate/gmsh_mesher.hpp>
#include <alefsi/scenes/spheres_settling_in_box.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <vector>

using namespace alefsi;
using Flow = AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, NavierStokes, SaddlePointGmres<3>>>;

int main(int argc, char** argv) try {
  Real level = 0.75, gap = 0.025, dt = 0.3;
  int steps = 4;
  Options opt("contact_newton", "Newton iterations of two spheres in contact: the pair coupling in the Jacobian or lagged.");
  opt.add("level", level, "mesh level of examples/dkt3d: h_body = d / (8 level)")
      .add("gap", gap, "the spheres' initial surface gap (units of d)")
      .add("dt", dt, "the step after the three start-up steps")
      .add("steps", steps, "steps of dt");
  if (!opt.parse(argc, argv, std::cout)) return 0;
  ALEFSI_CHECK_ARG(level >= 0.5 && level <= 4, "level", "must be in [0.5, 4], got ", level);
  ALEFSI_CHECK_ARG(gap > 0 && gap < 1, "gap", "must be in (0, 1), got ", gap);
  ALEFSI_CHECK_ARG(dt > 0, "dt", "must be positive, got ", dt);
  const BoxDomain box{.lo = Vec<3>(-3, -3, 0), .hi = Vec<3>(3, 3, 24)};
  const Real h_body = 1.0 / (8 * level);
  const Vec<3> lead(0, 0, 20), trail(0.05, 0, 20 + std::sqrt((1 + gap) * (1 + gap) - 0.05 * 0.05));
  const scenes::SpheresSettlingInBox scene{.box = box,
                                           .spheres = {{lead, 0.5, 7}, {trail, 0.5, 8}},
                                           .rho_f = 1,
                                           .mu = 4.7e-3,
                                           .rho_p = 1.14,
                                           .g = 1,
                                           .h_body = h_body,
                                           .h_far = std::min(8 * h_body, 0.75),
                                           .grading = 0.25,
                                           .velocities = {Vec<3>(0, 0, -0.38), Vec<3>(0, 0, -0.45)}};
  scene.validate();
  const Mesh<3> mesh = gmsh_box_mesh(box, scene.spheres, scene.size_rule()(scene.spheres));
  std::cout << "level " << level << " (h_body = d / " << 8 * level << "): " << mesh.n_cells() << " tetrahedra; gap "
            << gap << ", contact range " << h_body / 2 << "\n";
  std::vector<Real> dts = {0.01, 0.03, 0.1};
  dts.insert(dts.end(), std::size_t(steps), dt);

  std::vector<std::vector<Vec<6>>> velocities(2);
  for (bool coupled : {true, false}) {
    Flow flow(mesh, scene.flow_options());
    scene.configure(flow);  // the pair coupled in the Newton matrix
    if (!coupled)
      flow.set_contact_model(
          std::make_unique<LaggedPairCoupling<3>>(DefaultContact<3>::collisions(scene.collisions())));
    std::cout << (coupled ? "coupled" : "lagged") << ":\n";
    const auto wall0 = std::chrono::steady_clock::now();
    const Real cpu0 = app::cpu_seconds();
    int newton = 0;
    for (Real h : dts) {
      const auto t0 = std::chrono::steady_clock::now();
      const StepReport rep = flow.step(h);
      newton += rep.newton_iterations;
      velocities[coupled ? 0 : 1].push_back(flow.body_velocity(0));
      velocities[coupled ? 0 : 1].push_back(flow.body_velocity(1));
      std::cout << "  t " << std::setw(6) << flow.time() << "  dt " << std::setw(5) << h << "  newton "
                << std::setw(2) << rep.newton_iterations << "  gmres " << std::setw(4)
                << rep.linear.iterative_iterations << "  contacts " << flow.stats().contacts << "  distance "
                << std::setprecision(5) << (flow.body_centre(1) - flow.body_centre(0)).norm() << std::setprecision(6)
                << "  wall " << std::chrono::duration<Real>(std::chrono::steady_clock::now() - t0).count() << " s\n";
    }
    std::cout << "  total: " << newton << " Newton iterations, "
              << std::chrono::duration<Real>(std::chrono::steady_clock::now() - wall0).count() << " s wall, "
              << app::cpu_seconds() - cpu0 << " s CPU\n";
  }
  Real diff = 0, scale = 0;
  for (std::size_t i = 0; i < velocities[0].size(); ++i) {
    diff = std::max(diff, (velocities[0][i] - velocities[1][i]).norm());
    scale = std::max(scale, velocities[0][i].norm());
  }
  std::cout << "largest difference of the body velocities, coupled against lagged: " << diff / scale
            << " of the largest; peak " << app::peak_mb() << " MB\n";
  return 0;
} catch (const std::exception& e) {
  std::cerr << "contact_newton: " << e.what() << "\n";
  return 1;
}
