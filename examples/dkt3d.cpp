// dkt3d — two spheres drafting, kissing and tumbling in a closed box, in 3D: Navier–Stokes,
// Taylor–Hood, BDF2/BDF2E with adaptive steps, both spheres free in 6 degrees of freedom, the
// mesh moved by elasticity and remeshed by gmsh when it has degraded (sim/remesher3d.hpp),
// collisions between the spheres and with the walls (eq. 24 + spring). Needs alefsi::gmsh (apt
// install libgmsh-dev).
//
// The set-up (of the 3D drafting-kissing-tumbling studies with fictitious-domain and
// immersed-boundary codes): box x, y in [-3, 3], z in [0, 24], no-slip walls; spheres of
// diameter d = 1, rho_p / rho_f = 1.14, nu = 4.7e-3 (rho_f = 1, mu = 4.7e-3), g = 1 along -z;
// the leading sphere's centre at (0, 0, 20), the trailing one's at (0.05, 0, 21.5): the small
// sideways offset seeds the tumble. Units: d, and time in d / (g d)^{1/2}.
//
// Levels: the mesh size at the spheres is h_body = d / (8 level) (level 1: d / 8, 2: d / 16;
// fractional levels in [0.5, 4] too, e.g. 0.75: d / 6, 1.5: d / 12),
// growing by `grading` with the distance to h_far = min(8 h_body, 0.75); the time tolerance is
// 1e-3 / 2^(level - 1) of the velocity scale (0.1 of the buoyant velocity scale).
//
// How to run: ./dkt3d [--level 1] [--t-end 40] [--output DIR] [--vtu-every 0]
//             [--checkpoint-every 0] [--restart]    (`--help` lists the options)
// What it prints: the mesh, a progress line every 10 steps, then the kissing time (the first time
// the centres are within 1.005 d; the spring of range h_body / 2 may hold them farther apart, so
// the closest approach and its time are printed too), the largest tilt of the pair (the angle of the line of centres
// against the vertical) and when, where the spheres are at t_end, the remeshes, the steps, the
// wall and CPU times with their split, the peak memory and the linear solves. It writes
// DIR/bodies.csv (through alefsi::run: centre, quaternion, velocity, loads, gap per step and
// body) and DIR/pair.csv (t, centre distance / d, tilt in degrees; a restart keeps its rows up
// to the checkpoint and counts them in the summary), the VTU series (--vtu-every) and
// checkpoints (--checkpoint-every).
#include <alefsi/alefsi.hpp>
#include <alefsi/app.hpp>
#include <alefsi/la/krylov.hpp>
#include <alefsi/sim/remesher3d.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

using namespace alefsi;
using Flow = AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, NavierStokes, SaddlePointGmres<3>>>;

namespace {

constexpr Real d = 1, a = d / 2, rho_f = 1, rho_p = 1.14, nu = 4.7e-3, g = 1;
constexpr int lead_tag = 7, trail_tag = 8;
const BoxDomain box{.lo = Vec<3>(-3, -3, 0), .hi = Vec<3>(3, 3, 24)};
const Vec<3> lead_start(0, 0, 20), trail_start(0.05, 0, 21.5);

struct Settings {
  Real level = 1;
  Real t_end = 40, grading = 0.25, tolerance = 0;
  app::RunFiles files{.output = "dkt3d_out"};
};

bool parse(int argc, char** argv, Settings& o) {
  Options opt("dkt3d", "Two spheres drafting, kissing and tumbling in a closed box (3D).");
  opt.add("level", o.level, "mesh and time level: h_body = d / (8 level), tolerance 1e-3 / 2^(level - 1)")
      .add("grading", o.grading, "growth of the mesh size with the distance to the spheres")
      .add("tolerance", o.tolerance, "the time tolerance (0: the level's)")
      .add("t-end", o.t_end, "end time");
  o.files.add_to(opt);
  return opt.parse(argc, argv, std::cout);
}

}  // namespace

int main(int argc, char** argv) try {
  Settings o;
  if (!parse(argc, argv, o)) return 0;
  ALEFSI_CHECK_ARG(o.level >= 0.5 && o.level <= 4, "level", "must be in [0.5, 4], got ", o.level);
  const auto wall0 = std::chrono::steady_clock::now();
  const Real cpu0 = app::cpu_seconds();

  const Real h_body = d / (8 * o.level);
  const scenes::SpheresSettlingInBox scene{.box = box,
                                           .spheres = {{lead_start, a, lead_tag}, {trail_start, a, trail_tag}},
                                           .rho_f = rho_f,
                                           .mu = nu * rho_f,
                                           .rho_p = rho_p,
                                           .g = g,
                                           .h_body = h_body,
                                           .h_far = std::min(8 * h_body, 0.75),
                                           .grading = o.grading};
  scene.validate();
  const auto checkpoint = o.files.checkpoint();
  GmshMeshReport first;
  Mesh<3> mesh = o.files.restart ? read_checkpoint_mesh<3>(checkpoint)
                                 : gmsh_box_mesh(box, scene.spheres, scene.size_rule()(scene.spheres), {}, &first);
  Flow flow(std::move(mesh), scene.flow_options());
  // no-slip walls, the free spheres, gravity with exact buoyancy, contact by eq. (24) on the
  // approach speed and a spring of range h_body / 2 carrying 4 buoyant weights
  scene.configure(flow);
  auto remesher = std::make_unique<Remesher3D>(Remesh3DOptions{.box = box, .size = scene.size_rule(), .mesher = {}});
  const Remesher3D& remeshes = *remesher;
  flow.set_remesher(std::move(remesher));
  if (o.files.restart) flow.load_checkpoint(checkpoint);
  std::cout << "dkt3d (" << Flow::Solver::name << "), level " << o.level << ": h_body = d / " << 8 * o.level << ", "
            << flow.mesh().n_cells() << " tetrahedra, " << flow.space().n_field() + 2 * Flow::body_dofs
            << " unknowns";
  if (!o.files.restart) std::cout << " (gmsh " << std::setprecision(3) << first.seconds << " s)";
  std::cout << "; from t = " << flow.time() << " to " << o.t_end << "\n";

  std::filesystem::create_directories(o.files.output);
  Real t_kiss = -1, tilt_max = 0, t_tilt = 0, dist_min = std::numeric_limits<Real>::infinity(), t_min = 0;
  auto record = [&](Real t, Real dist, Real tilt) {  // dist in units of d
    if (t_kiss < 0 && dist <= 1.005) t_kiss = t;
    if (dist < dist_min) dist_min = dist, t_min = t;
    if (tilt > tilt_max) tilt_max = tilt, t_tilt = t;
  };
  // pair.csv: on a restart its rows up to the checkpoint's time are kept (and counted in the
  // summary), the later ones (written after the checkpoint, before the run stopped) dropped;
  // the kept rows go to a new file that replaces the old one whole
  const std::filesystem::path pair_file = o.files.output / "pair.csv";
  std::string kept = "t,distance,tilt_deg\n";
  if (std::ifstream old{pair_file}; o.files.restart && old) {
    std::string line;
    for (int n = 1; std::getline(old, line); ++n) {
      if (n == 1 && line.rfind("t,", 0) == 0) continue;  // the header
      Real t, dist, tilt;
      char c1, c2;
      std::istringstream in(line);
      if (!(in >> t >> c1 >> dist >> c2 >> tilt) || c1 != ',' || c2 != ',')
        throw IoError(pair_file.string() + ":" + std::to_string(n) + ": not a row 't,distance,tilt_deg': '" + line + "'");
      if (t > flow.time() + 1e-12 * std::max(Real(1), flow.time())) break;
      record(t, dist, tilt);
      kept += line + '\n';
    }
  }
  {
    const std::filesystem::path tmp = pair_file.string() + ".tmp";
    std::ofstream(tmp, std::ios::trunc) << kept;
    std::filesystem::rename(tmp, pair_file);
  }
  std::ofstream pair(pair_file, std::ios::app);
  pair << std::setprecision(10);
  RunOptions run_opt;
  run_opt.dt = 1e-2, run_opt.t_end = o.t_end;
  run_opt.tolerance = o.tolerance > 0 ? o.tolerance : 1e-3 / std::pow(2.0, o.level - 1);
  run_opt.velocity_scale = 0.1 * std::sqrt((rho_p / rho_f - 1) * g * d);
  o.files.apply(run_opt);
  run_opt.on_step = [&] {
    const alefsi::Vec<3> r = flow.body_centre(1) - flow.body_centre(0);  // leading to trailing
    const Real dist = r.norm();
    const Real tilt = std::acos(std::clamp(std::abs(r[2]) / dist, Real(0), Real(1))) * 180 / std::numbers::pi;
    record(flow.time(), dist / d, tilt);
    pair << flow.time() << ',' << dist / d << ',' << tilt << std::endl;  // whole rows, should the run stop
  };
  const RunSummary sum = run(flow, run_opt);

  const Real wall = std::chrono::duration<Real>(std::chrono::steady_clock::now() - wall0).count();
  std::cout << std::setprecision(4);
  if (t_kiss >= 0) std::cout << "kissing (centres within 1.005 d) at t = " << t_kiss;
  else std::cout << "no kiss (centres within 1.005 d) by t = " << flow.time();
  std::cout << "; closest approach: centres " << dist_min << " d apart at t = " << t_min
            << "; largest tilt of the pair " << tilt_max << " deg at t = " << t_tilt << "\n";
  for (int k = 0; k < 2; ++k)
    std::cout << "  at t = " << flow.time() << ": " << (k == 0 ? "leading " : "trailing") << " sphere at ("
              << flow.body_centre(k).transpose() << "), velocity (" << flow.body_velocity(k).head<3>().transpose()
              << ")\n";
  app::print_remeshes(std::cout, remeshes.reports());
  app::print_run(std::cout, sum, wall, app::cpu_seconds() - cpu0);
  return 0;
} catch (const std::exception& e) {
  std::cerr << "dkt3d: " << e.what() << "\n";
  return 1;
}
