// ellipse_settling — an ellipse settling in a vertical channel turns broadside and finds the
// centreline (Xia et al. 2009, J. Fluid Mech. 625, 249: the "horizontal" mode).
//
// What it shows: a free non-circular body (the built-in mesher's `Ellipse` hole, its exact shape
// for contact) in Navier–Stokes flow at a moderate Reynolds number, remeshing around it as it
// falls, and a result set beside a published one.
//
// Set-up (scenes::SettlingEllipse, the Feel++ ALE benchmark's statement of Xia et al.'s case):
// channel 0.4 x 2.8 cm, no-slip walls (top included: the buoyancy is then exact); an ellipse
// of semi-axes 0.05 and 0.025 cm (aspect ratio 2, blockage 0.25), density 1.1 g/cm^3, centre
// (0.2, 2.4), major axis at --angle (default 45 degrees) from the horizontal; fluid density 1,
// viscosity 0.01 g/(cm s); g = 981 cm/s^2. Taylor–Hood, BDF2/BDF2E, Newton.
//
// How to run:   ./ellipse_settling [--h-body 0.004] [--dt 1e-3] [--t-end 1.7] [--curved] [--output DIR]
//               [--semi-minor 0.025]   (0.05: a disk of the same density, settling down the centreline)
//   (`--help` lists every option with its default).
// What it prints: a progress line every 10 steps; when the centre passes y = 2.0, 1.5, 1.0,
//   0.6 cm: t, settling speed U = -V_y, the major axis' angle from the horizontal (degrees),
//   the centre's x, and the Reynolds number U (2a) / nu; then the run's summary and time split.
//   It writes DIR/bodies.csv (every step) and DIR/flow.pvd (every --vtu-every steps).
// Expected: the ellipse swings out towards a wall while it turns past the horizontal, then
//   settles broadside (angle -> 0) on the centreline at U ~ 1.3 cm/s (Re ~ 13); measured
//   values and the reference's (read off Xia et al.'s figures) in docs/results.md, "An ellipse
//   settling in a channel".
#include <alefsi/alefsi.hpp>
#include <alefsi/app.hpp>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <vector>

using namespace alefsi;
using Config = FlowConfig<2, TaylorHood, BDF2_BDF2E>;
using Flow = AleFlow<Config>;

int main(int argc, char** argv) try {
  const Real mu = 0.01;
  Real dt = 1e-3, t_end = 1.7, h_body = 0.004, h_far = 0.03, angle_deg = 45, tolerance = 0, semi_minor = 0.025;
  std::filesystem::path out = "output/ellipse_settling", restart;
  int vtu_every = 0, checkpoint_every = 100;
  bool curved = false;
  Options opt("ellipse_settling", "An ellipse settling in a 0.4 x 2.8 cm channel (Xia et al. 2009): it turns broadside.");
  opt.add("dt", dt, "time step (s); with --tolerance > 0 the first one")
      .add("tolerance", tolerance, "local error tolerance of adaptive steps (0: fixed dt)")
      .add("t-end", t_end, "final time (s)")
      .add("h-body", h_body, "mesh size within the ellipse's bounding circle (cm)")
      .add("h-far", h_far, "largest mesh size (cm)")
      .add("angle", angle_deg, "initial angle of the major axis from the horizontal (degrees)")
      .add("semi-minor", semi_minor, "semi-minor axis b (cm; a = 0.05; b = a: a disk)")
      .add("output", out, "folder for bodies.csv, flow.pvd, checkpoint.bin")
      .add("vtu-every", vtu_every, "VTU output every N steps (0: none)")
      .add("checkpoint-every", checkpoint_every, "checkpoint every N steps (0: none)")
      .add("restart", restart, "continue from this checkpoint")
      .flag("curved", curved, "isoparametric P2 cells on the ellipse (default: straight cells, a polygon)");
  if (!opt.parse(argc, argv, std::cout)) return 0;
  opt.print(std::cout);
  ALEFSI_CHECK_ARG(std::isfinite(angle_deg), "--angle", "must be finite, got ", angle_deg);
  ALEFSI_CHECK_ARG(semi_minor > 0 && semi_minor <= 0.05, "--semi-minor", "must be in (0, a = 0.05], got ", semi_minor);

  scenes::SettlingEllipse scene;
  scene.ellipse.angle = angle_deg * std::numbers::pi / 180;
  scene.ellipse.b = semi_minor;
  scene.curved = curved;
  Mesh<2> mesh = restart.empty() ? scene.mesh(h_body, h_far) : read_checkpoint_mesh<2>(restart);
  std::cout << "ellipse " << scene.ellipse.a << " x " << scene.ellipse.b << " cm in a " << scene.width << " x "
            << scene.height << " cm channel, Taylor-Hood" << (curved ? " (curved cells on the ellipse), " : ", ")
            << Config::Scheme::name << ": " << mesh.n_nodes() << " nodes, " << mesh.n_cells() << " triangles\n";
  Flow flow(std::move(mesh), {.rho = scene.rho_f, .mu = mu});
  scene.configure(flow, h_body, h_far);
  if (!restart.empty()) {
    flow.load_checkpoint(restart);
    std::cout << "restarted from " << restart << " at t = " << flow.time() << "\n";
  }

  // --- samples as the centre passes given heights (linear between the two steps) ----------
  const std::vector<Real> heights{2.0, 1.5, 1.0, 0.6};
  std::size_t next = 0;
  while (next < heights.size() && flow.body_centre(0)[1] <= heights[next]) ++next;
  struct Sample {
    Real t, y, U, angle, x;
  };
  auto sample = [&] {
    const auto Z = flow.body_velocity(0);
    // the major axis' angle from the horizontal, in (-90, 90] degrees (the ellipse is symmetric)
    Real a = std::remainder(flow.body_angle(0), std::numbers::pi) * 180 / std::numbers::pi;
    if (a <= -90) a += 180;
    return Sample{flow.time(), flow.body_centre(0)[1], -Z[1], a, flow.body_centre(0)[0]};
  };
  Sample last = sample();
  std::cout << std::fixed;
  RunOptions ro{.dt = dt, .t_end = t_end, .tolerance = tolerance, .land_on = {}, .output = out, .vtu_every = vtu_every,
                .checkpoint_every = checkpoint_every};
  ro.on_step = [&] {
    const Sample now = sample();
    while (next < heights.size() && now.y <= heights[next]) {
      const Real s = (last.y - heights[next]) / (last.y - now.y);
      auto lerp = [s](Real p, Real q) { return p + s * (q - p); };
      const Real U = lerp(last.U, now.U);
      std::cout << std::setprecision(4) << "  y = " << heights[next] << " cm at t = " << lerp(last.t, now.t)
                << " s: U = " << U << " cm/s, angle " << std::setprecision(2) << lerp(last.angle, now.angle)
                << " deg, x = " << std::setprecision(4) << lerp(last.x, now.x)
                << " cm, Re = U 2a / nu = " << std::setprecision(2) << U * 2 * scene.ellipse.a / (mu / scene.rho_f)
                << "\n";
      ++next;
    }
    last = now;
  };
  const RunSummary s = run(flow, ro);
  app::print_run(std::cout, s, s.wall_seconds, app::cpu_seconds());
  return 0;
} catch (const std::exception& e) {
  std::cerr << "ellipse_settling: " << e.what() << "\n";
  return 1;
}
