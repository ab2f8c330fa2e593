// ten_cate — a sphere settling in a closed box onto its floor, in 3D (ten Cate et al., "Particle
// imaging velocimetry experiments and lattice-Boltzmann simulations on a single sphere settling
// under gravity", Phys. Fluids 14, 4012, 2002): Navier–Stokes, Taylor–Hood, BDF2/BDF2E with
// adaptive steps, the sphere free in 6 degrees of freedom, the mesh moved by elasticity and
// remeshed by gmsh when it has degraded (sim/remesher3d.hpp), the landing through the collision
// model (eq. 24 + spring). Needs alefsi::gmsh (apt install libgmsh-dev).
//
// The experiment: box 100 x 100 x 160 mm, no-slip walls; nylon sphere D = 15 mm,
// rho_p = 1120 kg/m^3, released from rest with its bottom 120 mm above the floor; four silicone
// oils, E1-E4 (Re 1.5 to 31.9), whose measured largest settling speeds are
//   E1 rho_f 970, mu 0.373 Pa s: 0.0360 m/s;   E2 965, 0.212: 0.0572;
//   E3 962, 0.113: 0.0873;                       E4 960, 0.058: 0.1222.
// Lengths in m, SI units throughout.
//
// Levels: the mesh size at the sphere is h_body = D / (4 + 4 level) (level 1: D / 8, 2: D / 12,
// 3: D / 16), growing by `grading` with the distance to h_far = 8 h_body (at most 10 mm); the
// time tolerance is 1e-3 / 2^(level - 1) of the velocity scale. --curved: isoparametric P2
// cells on the sphere (the polyhedron inscribed in it makes the straight runs fall faster than
// their resolution; near the floor, new cells too coarse for the gap keep straight edges).
//
// How to run: ./ten_cate [--case E4] [--level 1] [--t-end 1.5] [--output DIR] [--vtu-every 0]
//             [--checkpoint-every 0] [--restart] [--no-reuse] [--curved]   (`--help` lists the options)
// What it prints: the mesh, a progress line every 10 steps, then u_max (the largest settling
// speed) and when it was reached beside the measured value, the height of the sphere's bottom
// and its speed at t_end, when it came within the collision range of the floor and when it
// stopped (speed below 1 % of u_max), the remeshes (wall time, cells, worst quality before / after), the
// steps, the wall and CPU times with their split and the peak memory, the linear solves
// (preconditioner set-ups, GMRES iterations per solve). It writes DIR/bodies.csv
// (through alefsi::run: centre, quaternion, velocity, loads, gap per step), the flow's VTU
// series (--vtu-every) and checkpoints (--checkpoint-every).
#include <alefsi/alefsi.hpp>
#include <alefsi/app.hpp>
#include <alefsi/la/krylov.hpp>
#include <alefsi/sim/remesher3d.hpp>

#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <string>

using namespace alefsi;
// the linear solver: a compile-time choice (-DALEFSI_TEN_CATE_SOLVER=UmfPackLu for the direct one)
#ifndef ALEFSI_TEN_CATE_SOLVER
#define ALEFSI_TEN_CATE_SOLVER SaddlePointGmres<3>
#endif
using Flow = AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, NavierStokes, ALEFSI_TEN_CATE_SOLVER>>;

namespace {

struct Oil {
  Real rho, mu, re, u_measured;
};
// ten Cate et al. (2002), table 1
const std::map<std::string, Oil> oils = {{"E1", {970, 0.373, 1.5, 0.0360}},
                                         {"E2", {965, 0.212, 4.1, 0.0572}},
                                         {"E3", {962, 0.113, 11.6, 0.0873}},
                                         {"E4", {960, 0.058, 31.9, 0.1222}}};

constexpr Real D = 0.015, a = D / 2, rho_p = 1120, g = 9.81;
constexpr int sphere_tag = 7;
const BoxDomain box{.lo = Vec<3>(-0.05, -0.05, 0), .hi = Vec<3>(0.05, 0.05, 0.16)};
const Vec<3> start(0, 0, 0.12 + a);

struct Settings {
  std::string oil = "E4";
  int level = 1;
  Real t_end = 1.5, grading = 0.25, tolerance = 0;
  bool no_reuse = false, curved = false;
  app::RunFiles files{.output = "ten_cate_out"};
};

bool parse(int argc, char** argv, Settings& o) {
  Options opt("ten_cate", "A sphere settling onto the floor of a box: ten Cate et al. (2002), cases E1-E4 (3D).");
  opt.add("case", o.oil, "E1, E2, E3 or E4 (the oil)")
      .add("level", o.level, "mesh and time level: h_body = D / (4 + 4 level), tolerance 1e-3 / 2^(level - 1)")
      .add("grading", o.grading, "growth of the mesh size with the distance to the sphere")
      .add("tolerance", o.tolerance, "the time tolerance (0: the level's)")
      .add("t-end", o.t_end, "end time (s)")
      .flag("no-reuse", o.no_reuse, "set the preconditioner up at every Newton iteration (for comparison)")
      .flag("curved", o.curved, "isoparametric P2 cells on the sphere (default: straight cells, a polyhedron)");
  o.files.add_to(opt);
  return opt.parse(argc, argv, std::cout);
}


}  // namespace

int main(int argc, char** argv) try {
  Settings o;
  if (!parse(argc, argv, o)) return 0;
  ALEFSI_CHECK_ARG(oils.count(o.oil) == 1, "case", "must be E1, E2, E3 or E4, got ", o.oil);
  ALEFSI_CHECK_ARG(o.level >= 1 && o.level <= 6, "level", "must be in 1..6, got ", o.level);
  const Oil oil = oils.at(o.oil);
  const auto wall0 = std::chrono::steady_clock::now();
  const Real cpu0 = app::cpu_seconds();

  const Real h_body = D / (4 + 4 * o.level);
  const scenes::SpheresSettlingInBox scene{.box = box,
                                           .spheres = {{start, a, sphere_tag}},
                                           .rho_f = oil.rho,
                                           .mu = oil.mu,
                                           .rho_p = rho_p,
                                           .g = g,
                                           .h_body = h_body,
                                           .h_far = std::min(8 * h_body, 0.01),
                                           .grading = o.grading};
  scene.validate();
  const auto checkpoint = o.files.checkpoint();
  GmshMeshReport first;
  Mesh<3> mesh = o.files.restart ? read_checkpoint_mesh<3>(checkpoint)
                                 : gmsh_box_mesh(box, scene.spheres, scene.size_rule()(scene.spheres), {}, &first);
  FlowOptions flow_opt = scene.flow_options();
  flow_opt.reuse_factorisation = !o.no_reuse;
  Flow flow(std::move(mesh), flow_opt);
  // no-slip walls, the free sphere, gravity with the sphere's exact buoyancy (with
  // rho_p / rho_f = 1.15-1.17 the polyhedral hole's volume error would enter the net weight six
  // times over), contact by eq. (24) on the approach speed (the paper's |V| form makes the sphere
  // rebound: docs/results.md) and a spring of range h_body / 2 carrying 4 buoyant weights
  scene.configure(flow);
  // --curved: the sphere's edges get their mid nodes on it, carried by its rigid map and placed
  // anew on every new mesh (the box's walls are flat)
  if (o.curved) flow.curve_boundary(sphere_tag, onto_sphere<3>(start, a));
  auto remesher = std::make_unique<Remesher3D>(Remesh3DOptions{.box = box, .size = scene.size_rule(), .mesher = {}});
  const Remesher3D& remeshes = *remesher;
  flow.set_remesher(std::move(remesher));
  if (o.files.restart) flow.load_checkpoint(checkpoint);
  std::cout << "ten_cate (" << Flow::Solver::name << ") " << o.oil << " (Re " << oil.re << "), level " << o.level << ": h_body = D / "
            << 4 + 4 * o.level << ", " << flow.mesh().n_cells() << " tetrahedra" << (o.curved ? " (curved on the sphere)" : "") << ", "
            << flow.space().n_field() + Flow::body_dofs << " unknowns";
  if (!o.files.restart) std::cout << " (gmsh " << std::setprecision(3) << first.seconds << " s)";
  std::cout << "; from t = " << flow.time() << " to " << o.t_end << " s\n";

  // the largest settling speed and when
  Real u_max = 0, t_max = 0;
  RunOptions run_opt;
  run_opt.dt = 1e-3, run_opt.t_end = o.t_end;
  run_opt.tolerance = o.tolerance > 0 ? o.tolerance : 1e-3 / std::pow(2.0, o.level - 1);
  run_opt.velocity_scale = 0.1 * oil.u_measured;
  o.files.apply(run_opt);
  // the landing: the first step within the collision range (gap <= a / 10) and the first after
  // it at which the sphere moves at less than 1 % of u_max
  Real t_touch = -1, t_rest = -1;
  run_opt.on_step = [&] {
    const Real speed = flow.body_velocity(0).head<3>().norm();
    if (-flow.body_velocity(0)[2] > u_max) u_max = -flow.body_velocity(0)[2], t_max = flow.time();
    if (t_touch < 0 && flow.body_gaps()[0] <= 0.1 * a) t_touch = flow.time();
    if (t_touch >= 0 && t_rest < 0 && speed < 0.01 * u_max) t_rest = flow.time();
  };
  const RunSummary sum = run(flow, run_opt);

  const Real wall = std::chrono::duration<Real>(std::chrono::steady_clock::now() - wall0).count();
  std::cout << std::setprecision(4) << o.oil << ": u_max " << u_max << " m/s at t = " << t_max << " s; measured "
            << oil.u_measured << " m/s: " << std::showpos << 100 * (u_max / oil.u_measured - 1) << std::noshowpos
            << " %\n  at t = " << flow.time() << " s: bottom of the sphere " << 1e3 * (flow.body_centre(0)[2] - a)
            << " mm above the floor (gap " << 1e3 * flow.body_gaps()[0] << " mm), speed " << -flow.body_velocity(0)[2]
            << " m/s\n";
  if (t_touch >= 0) std::cout << "  within the collision range (gap <= a / 10) from t = " << t_touch << " s";
  if (t_rest >= 0) std::cout << ", at rest (speed < 1 % of u_max) from t = " << t_rest << " s";
  if (t_touch >= 0) std::cout << "\n";
  app::print_remeshes(std::cout, remeshes.reports());
  if (o.curved)
    std::cout << "  curved edges the remeshes left straight (their cells' maps too near to folding): "
              << flow.stats().straightened << "\n";
  app::print_run(std::cout, sum, wall, app::cpu_seconds() - cpu0);
  return 0;
} catch (const std::exception& e) {
  std::cerr << "ten_cate: " << e.what() << "\n";
  return 1;
}
