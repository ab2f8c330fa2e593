// squirmer_box — a sphere squirmer swimming the length of a closed box in Stokes flow, in 3D:
// Taylor–Hood, BDF2 positions, the squirmer free and force-free in 6 degrees of freedom, the
// mesh moved by elasticity and remeshed by gmsh as the sphere leaves it behind
// (sim/remesher3d.hpp). Needs alefsi::gmsh (apt install libgmsh-dev).
//
// The set-up: sphere of radius a = 0.5 (diameter d = 1) with the squirmer slip
// u_s = (B1 + B2 cos(theta)) sin(theta) e_theta about the swimming axis e = +z
// (physics/rigid_body.hpp, squirmer_slip; B1 = 1.5: unbounded speed U = 2 B1 / 3 = 1, Blake
// 1971), massless (force- and torque-free), in the closed box x, y in [-W/2, W/2], z in [0, L]
// (no-slip walls), starting on the axis at z0 (its front gap to the floor z0 - a) and swimming
// up until its centre reaches L - z0. Stokes: rho -> 0 (1e-12), mu = 1, no convection, so each
// step is the steady problem on the moved geometry and the speed depends only on where the
// sphere is. In a closed box the slip is made discretely flux-free on each mesh
// (BodySystem::remove_slip_flux): the value removed is printed per remesh.
//
// What it checks: (1) the speed against the unbounded 2 B1 / 3 as the squirmer leaves the floor,
// crosses the middle of the box and nears the ceiling; (2) that the moving, remeshed run is the
// sequence of steady problems it should be: at `--references` heights the speed of a fresh
// steady solve (a new mesh with the sphere there, one step on a fixed mesh) beside the run's
// (interpolated in z). The run starts from the steady speed at z0 (the first of the references),
// not from rest.
//
// Levels: h_body = d / (5 level) at the sphere, growing by `grading` with the distance to
// h_far = min(6 h_body, 1); dt = 0.1 d / (U level).
//
// How to run: ./squirmer_box [--level 1] [--width 8] [--length 16] [--z0 1.5] [--B2 0]
//             [--references 3] [--steady-only] [--output DIR] [--vtu-every 0]
//             (`--help` lists the options; --steady-only: the references alone, for a level study)
// What it prints: the mesh, a progress line every 10 steps, the references, then the speed at
// the start, its largest value and where, the speed at mid-box against U, the remeshes (wall
// time, cells, worst quality before / after), the steps, wall and CPU times with their split and
// the peak memory. It writes DIR/bodies.csv (through alefsi::run) and DIR/speed.csv (t, z,
// V_z / U, |V_xy| / U, |w| a / U, slip flux removed / U; references: z, V_z / U).
// `python3 examples/plot_squirmer_box.py DIR [DIR2 ...]` draws the speed against z.
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
#include <vector>

using namespace alefsi;
using Flow = AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, UnsteadyStokes, SaddlePointGmres<3>>>;

namespace {

constexpr Real d = 1, a = d / 2, mu = 1, rho = 1e-12;
constexpr int sphere_tag = 7;
const Vec<3> e_z(0, 0, 1);

struct Settings {
  Real level = 1, width = 8, length = 16, z0 = 1.5, B1 = 1.5, B2 = 0, grading = 0.3;
  int references = 3;
  bool steady_only = false;
  std::filesystem::path output = "squirmer_box_out";
  int vtu_every = 0;
};

bool parse(int argc, char** argv, Settings& o) {
  Options opt("squirmer_box", "A sphere squirmer swimming the length of a closed box in Stokes flow (3D).");
  opt.add("level", o.level, "mesh and time level: h_body = d / (5 level), dt = 0.1 / level")
      .add("width", o.width, "the box's side W across (x and y), in d")
      .add("length", o.length, "the box's length L along z (the swimming axis), in d")
      .add("z0", o.z0, "the centre's start height (the run stops at L - z0)")
      .add("B1", o.B1, "first squirming mode (unbounded speed 2 B1 / 3)")
      .add("B2", o.B2, "second squirming mode (pusher < 0, puller > 0)")
      .add("grading", o.grading, "growth of the mesh size with the distance to the sphere")
      .add("references", o.references, "fresh steady solves at this many heights from z0 to L / 2 (>= 1)")
      .flag("steady-only", o.steady_only, "only the fresh steady solves (a level study of the speed)")
      .add("output", o.output, "folder for bodies.csv, speed.csv and VTU")
      .add("vtu-every", o.vtu_every, "a VTU file every this many steps (0: none)");
  if (!opt.parse(argc, argv, std::cout)) return false;
  ALEFSI_CHECK_ARG(o.level >= 0.5 && o.level <= 4, "--level", "must be in [0.5, 4], got ", o.level);
  ALEFSI_CHECK_ARG(o.width > 2 * d, "--width", "must exceed d = 1, with room for the mesh, got ", o.width);
  ALEFSI_CHECK_ARG(o.z0 > a + 0.1 && 2 * o.z0 < o.length - 0.5, "--z0",
                   "the sphere must start clear of the floor (z0 > 0.6) and below the middle "
                   "(z0 < (L - 0.5) / 2), got ", o.z0);
  ALEFSI_CHECK_ARG(o.B1 > 0 && std::isfinite(o.B1), "--B1", "must be positive (it swims up), got ", o.B1);
  ALEFSI_CHECK_ARG(o.references >= 1, "--references", "must be >= 1, got ", o.references);
  opt.print(std::cout);
  return true;
}

struct Scene {
  BoxDomain box;
  Real h_body, h_far, grading;
  std::function<SizeFunction3D(const std::vector<Sphere>&)> size() const {
    return [h_body = h_body, h_far = h_far, grading = grading](const std::vector<Sphere>& s) {
      return graded_size(s, h_body, h_far, grading);
    };
  }
  Mesh<3> mesh(Real z, GmshMeshReport* report = nullptr) const {
    const std::vector<Sphere> s = {{Vec<3>(0, 0, z), a, sphere_tag}};
    return gmsh_box_mesh(box, s, size()(s), {}, report);
  }
};

// No-slip walls, the massless squirmer at height z with velocity Z0 at t0.
void configure(Flow& flow, const Scene& scene, const Settings& o, Real z, const Vec<6>& Z0) {
  for (int t : scene.box.tags)
    flow.set_velocity(t, [](const alefsi::Vec<3>&, Real) { return alefsi::Vec<3>(0, 0, 0); });
  RigidBody3D body = massless_sphere(sphere_tag, alefsi::Vec<3>(0, 0, z), a);
  body.slip = squirmer_slip(o.B1, o.B2, e_z);
  body.velocity = Z0;
  flow.add_body(body);
}

// The steady squirmer at height z on a fresh mesh: one step on the fixed mesh (BDF2's first step
// from rest is backward Euler, whose mass term vanishes with rho -> 0). Prints the mesh and the
// solve.
Vec<6> steady(const Scene& scene, const Settings& o, Real z) {
  Flow flow(scene.mesh(z), {.rho = rho, .mu = mu, .linearisation = Linearisation::semi_implicit});
  configure(flow, scene, o, z, Vec<6>::Zero());
  flow.set_prescribed_mesh_velocity([](const alefsi::Vec<3>&, Real) { return alefsi::Vec<3>(0, 0, 0); });
  const StepReport rep = flow.step(1.0);
  std::cout << "  steady at z = " << std::setprecision(4) << z << " (" << flow.mesh().n_cells() << " tetrahedra, "
            << flow.space().n_field() + Flow::body_dofs << " unknowns, " << rep.linear.iterative_iterations
            << " GMRES iterations): V_z / U = " << std::setprecision(6) << flow.body_velocity(0)[2] / (2 * o.B1 / 3)
            << std::endl;
  return flow.body_velocity(0);
}

}  // namespace

int main(int argc, char** argv) try {
  Settings o;
  if (!parse(argc, argv, o)) return 0;
  const auto wall0 = std::chrono::steady_clock::now();
  const Real cpu0 = app::cpu_seconds();
  const Real U = 2 * o.B1 / 3, z_end = o.length - o.z0;
  const Real h_body = d / (5 * o.level);
  const Scene scene{.box = {.lo = alefsi::Vec<3>(-o.width / 2, -o.width / 2, 0),
                            .hi = alefsi::Vec<3>(o.width / 2, o.width / 2, o.length)},
                    .h_body = h_body,
                    .h_far = std::min(6 * h_body, 1.0),
                    .grading = o.grading};
  std::filesystem::create_directories(o.output);

  // the references: fresh steady solves from z0 to mid-box
  std::vector<std::pair<Real, Vec<6>>> refs;
  const auto ref0 = std::chrono::steady_clock::now();
  for (int i = 0; i < o.references; ++i) {
    const Real z = o.references == 1 ? o.z0 : o.z0 + (0.5 * o.length - o.z0) * i / (o.references - 1);
    refs.emplace_back(z, steady(scene, o, z));
  }
  const Real t_refs = std::chrono::duration<Real>(std::chrono::steady_clock::now() - ref0).count();
  if (o.steady_only) {
    std::cout << "  references: " << std::setprecision(3) << t_refs << " s wall, " << app::cpu_seconds() - cpu0
              << " s CPU, peak " << app::peak_mb() << " MB\n";
    return 0;
  }

  GmshMeshReport first;
  Flow flow(scene.mesh(o.z0, &first), {.rho = rho, .mu = mu, .linearisation = Linearisation::semi_implicit});
  configure(flow, scene, o, o.z0, refs.front().second);
  auto remesher = std::make_unique<Remesher3D>(Remesh3DOptions{.box = scene.box, .size = scene.size(), .mesher = {}});
  const Remesher3D& remeshes = *remesher;
  flow.set_remesher(std::move(remesher));
  std::cout << "squirmer_box (" << Flow::Solver::name << "), level " << o.level << ": h_body = d / " << 5 * o.level
            << ", " << flow.mesh().n_cells() << " tetrahedra, " << flow.space().n_field() + Flow::body_dofs
            << " unknowns (gmsh " << std::setprecision(3) << first.seconds << " s); U = 2 B1 / 3 = " << U
            << "; from z = " << o.z0 << " to " << z_end << "\n";

  std::ofstream csv(o.output / "speed.csv");
  csv << "t,z,Vz_over_U,Vxy_over_U,w_a_over_U,slip_flux_removed_over_U\n" << std::setprecision(10);
  std::vector<std::pair<Real, Real>> track;  // (z, V_z)
  RunOptions run_opt;
  run_opt.dt = 0.1 * d / (U * o.level);
  run_opt.t_end = 10 * (z_end - o.z0) / U;  // a bound: the run stops at z_end
  run_opt.tolerance = 0;
  run_opt.output = o.output, run_opt.vtu_every = o.vtu_every;
  auto record = [&] {
    const Vec<6> Z = flow.body_velocity(0);
    const Real z = flow.body_centre(0)[2];
    track.emplace_back(z, Z[2]);
    csv << flow.time() << ',' << z << ',' << Z[2] / U << ',' << Z.head<2>().norm() / U << ','
        << Z.tail<3>().norm() * a / U << ',' << flow.slip_flux_removed(0) / U << std::endl;
  };
  record();
  run_opt.on_step = record;
  run_opt.stop_when = [&] { return flow.body_centre(0)[2] >= z_end; };
  const RunSummary sum = run(flow, run_opt);

  // the run's speed at the references' heights (linear in z between steps)
  auto run_speed = [&](Real z) {
    for (std::size_t i = 1; i < track.size(); ++i)
      if (track[i].first >= z) {
        const Real s = (z - track[i - 1].first) / (track[i].first - track[i - 1].first);
        return (1 - s) * track[i - 1].second + s * track[i].second;
      }
    return track.back().second;
  };
  csv << "\nreference_z,reference_Vz_over_U,run_Vz_over_U\n";
  std::cout << std::setprecision(5) << "the run against fresh steady solves (V_z / U):\n";
  for (const auto& [z, Z] : refs) {
    csv << z << ',' << Z[2] / U << ',' << run_speed(z) / U << '\n';
    std::cout << "  z = " << z << ": steady " << Z[2] / U << ", run " << run_speed(z) / U << " (" << std::showpos
              << 100 * (run_speed(z) / Z[2] - 1) << std::noshowpos << " %)\n";
  }
  const auto fastest = std::max_element(track.begin(), track.end(),
                                        [](const auto& p, const auto& q) { return p.second < q.second; });
  const Real mid = run_speed(0.5 * o.length);
  const Real wall = std::chrono::duration<Real>(std::chrono::steady_clock::now() - wall0).count();
  std::cout << "speed / U: " << track.front().second / U << " at the start (z = " << o.z0 << "), largest "
            << fastest->second / U << " at z = " << fastest->first << ", " << mid / U << " at mid-box (z = "
            << 0.5 * o.length << ": " << std::showpos << 100 * (mid / U - 1) << std::noshowpos << " % from unbounded), "
            << track.back().second / U << " at z = " << track.back().first << "\n";
  app::print_remeshes(std::cout, remeshes.reports());
  std::cout << "  references: " << std::setprecision(3) << t_refs << " s wall\n";
  app::print_run(std::cout, sum, wall, app::cpu_seconds() - cpu0);
  return 0;
} catch (const std::exception& e) {
  std::cerr << "squirmer_box: " << e.what() << "\n";
  return 1;
}
