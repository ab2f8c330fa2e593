// sphere_settling — a sphere settling from the centre of a closed spherical container, in 3D:
// Navier–Stokes, Taylor–Hood, BDF2/BDF2E, the sphere free in 6 degrees of freedom under gravity,
// the mesh moved by elasticity (scenes/settling_sphere.hpp). The same program runs on one core
// with alefsi's own iterative solver, or under mpirun with PETSc's: one type differs.
//
// What it shows: the sphere (a = 0.25 cm, rho_s = 1.5 g/cm^3) starts at rest at the centre of
// a container of radius 2 cm filled with a viscous fluid (rho_f = 1, mu = 10 P), accelerates and
// approaches its terminal speed; at Re = 0.025 that is the creeping-flow speed with the
// concentric-spheres wall factor K(a / b) (Haberman & Sayre 1958), U = 4.925 / mu cm/s. It
// drifts a little below the centre meanwhile (0.05 cm by t = 0.1 s), which changes the drag
// by a small amount.
// With --start-z -1.55 --contact --mu 1 --t-end 0.3 it starts 0.2 cm above the bottom, lands on
// the container's wall through the collision model (eq. 24 + spring) and settles at the gap where
// the spring carries its buoyant weight, rho (1 - sqrt(W' / F_0)) = 0.025 cm (0.0249 at
// t = 0.3 s, 113 adaptive steps, 61 s). It keeps sliding slowly (0.02 cm/s): the wall is the
// container's triangles, and the nearest one's normal is a few degrees off the vertical.
//
// How to run: ./sphere_settling [--layers 2] [--grading 2] [--dt 0.005] [--t-end 0.1]
//             [--mu 10] [--start-z 0] [--contact] [--output DIR] [--vtu-every 0]
//             [--checkpoint-every 0] [--restart]
//             (`--help` lists the options). --restart continues from DIR/checkpoint.bin (with
//             the same options; on any number of ranks).
// What it prints: the mesh and unknowns, a progress line every 10 steps, then the sphere's
// depth and velocity at t_end against the terminal speed, the solver's iterations, the wall and
// CPU times, the peak memory and the time of each phase (on rank 0: under MPI it assembles its
// part of the cells). It writes DIR/bodies.csv (one row per step: centre,
// orientation, velocity, hydrodynamic load), DIR/flow.pvd with its VTU files (--vtu-every)
// and DIR/checkpoint.bin (--checkpoint-every), through alefsi::run (sim/driver.hpp).
//
// Under MPI (target sphere_settling_mpi, built when alefsi::petsc is found): the solver type is
// alefsi::PetscKrylov<3> (GMRES, fieldsplit Schur, BoomerAMG on the velocities) instead of
// alefsi::SaddlePointGmres<3>:
//   mpirun -n 2 ./sphere_settling_mpi [options as above] [-- PETSc options, e.g. -ksp_monitor]
// Every rank holds the mesh and the whole state; the solves are distributed; rank 0 prints and
// writes. The trajectory is the serial one to the solvers' tolerance (docs/performance.md).
// (PETSc's C types Vec and Mat are global: this file spells alefsi::Vec out.)
#include <alefsi/alefsi.hpp>
#include <alefsi/app.hpp>
#include <alefsi/la/krylov.hpp>
#ifdef ALEFSI_SETTLING_PETSC
#include <alefsi/la/petsc.hpp>
#endif

#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <string>

using namespace alefsi;

#ifdef ALEFSI_SETTLING_PETSC
using Solver = PetscKrylov<3>;
#else
using Solver = SaddlePointGmres<3>;
#endif
using Flow = AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, NavierStokes, Solver>>;

namespace {

struct Settings {
  scenes::SettlingSphere scene;
  Real dt = 0.005, t_end = 0.1;
  int vtu_every = 0, checkpoint_every = 0;
  Real start_z = 0;
  bool restart = false, contact = false;
  std::filesystem::path output = "sphere_settling_out";
};

bool parse(int argc, char** argv, Settings& o) {
  Options opt("sphere_settling", "A sphere settling from the centre of a spherical container (3D, Navier–Stokes).");
  opt.add("layers", o.scene.layers, "cell layers across the gap (336 layers^3 tetrahedra)")
      .add("grading", o.scene.grading, "pull of the layers towards the sphere (1: none)")
      .add("mu", o.scene.mu, "viscosity (P)")
      .add("start-z", o.start_z, "the sphere's height at t = 0 (cm; the container's centre is 0)")
      .flag("contact", o.contact, "collisions with the container (eq. 24 + spring)")
      .add("dt", o.dt, "time step (s)")
      .add("t-end", o.t_end, "end time (s)")
      .add("output", o.output, "folder for bodies.csv, VTU and checkpoints")
      .add("vtu-every", o.vtu_every, "a VTU file every this many steps (0: none)")
      .add("checkpoint-every", o.checkpoint_every, "a checkpoint every this many steps (0: only with --restart)")
      .flag("restart", o.restart, "continue from <output>/checkpoint.bin");
  return opt.parse(argc, argv, std::cout);
}


}  // namespace

int settling_main(int argc, char** argv) try {
#ifdef ALEFSI_SETTLING_PETSC
  const bool root = PetscSession::rank() == 0;  // it prints (petsc_main) and writes
#else
  const bool root = true;
#endif
  Settings o;
  if (!parse(argc, argv, o)) return 0;
  const auto wall0 = std::chrono::steady_clock::now();
  const Real cpu0 = app::cpu_seconds();
  o.scene.start = alefsi::Vec<3>(0, 0, o.start_z);
  const scenes::SettlingSphere& scene = o.scene;
  const auto checkpoint = o.output / "checkpoint.bin";
  Flow flow(o.restart ? read_checkpoint_mesh<3>(checkpoint) : scene.mesh(), scene.flow_options());
  scene.configure(flow);
  if (o.contact) flow.set_collisions(scene.collisions());
  if (o.restart) flow.load_checkpoint(checkpoint);
  std::cout << "sphere_settling (" << Solver::name << "): " << flow.mesh().n_cells() << " tetrahedra, "
            << flow.space().n_field() + Flow::body_dofs << " unknowns; a = " << scene.a << ", b = " << scene.b
            << ", mu = " << scene.mu << "; from t = " << flow.time() << " to " << o.t_end << " in steps of " << o.dt
            << "\n";
  RunOptions run_opt;
  run_opt.dt = o.dt, run_opt.t_end = o.t_end, run_opt.tolerance = 0;  // fixed steps
  run_opt.output = o.output, run_opt.vtu_every = o.vtu_every, run_opt.checkpoint_every = o.checkpoint_every;
  run_opt.writer = root;  // under MPI: rank 0 writes, every rank steps
  const RunSummary sum = run(flow, run_opt);
  const alefsi::Vec<6> Z = flow.body_velocity(0);
  const Real U = scene.terminal_speed(), depth = -flow.body_centre(0)[2];
  std::cout << std::setprecision(8) << "t = " << flow.time() << ": depth " << depth << " cm, velocity (" << Z[0]
            << ", " << Z[1] << ", " << Z[2] << ") cm/s, spin |w| = " << std::setprecision(2) << Z.tail<3>().norm()
            << "\n  -v_z / U_terminal = " << std::setprecision(6) << -Z[2] / U << " (U = " << U
            << " cm/s: creeping flow, concentric spheres, K = " << scene.wall_factor() << ")\n";
  if (o.contact)
    std::cout << "  gap " << std::setprecision(6) << flow.body_gaps()[0] << " cm, at rest it would be "
              << scene.resting_gap() << " cm (the spring carries the buoyant weight)\n";
  std::cout
            << "  " << sum.steps << " steps, last solve " << flow.solver().iterations() << " iterations; wall "
            << std::setprecision(3)
            << std::chrono::duration<Real>(std::chrono::steady_clock::now() - wall0).count() << " s, CPU "
            << app::cpu_seconds() - cpu0 << " s, peak " << std::setprecision(0) << std::fixed << app::peak_mb()
            << " MB (this rank); files in " << o.output.string() << "\n"
            << std::setprecision(2) << "  phases (rank 0): mesh velocity " << sum.t_mesh_velocity << " s, assembly "
            << sum.t_assembly << " s (" << flow.assembled_cells() << " of " << flow.mesh().n_cells()
            << " cells), preconditioner set-up " << sum.t_factorize << " s, solves " << sum.t_solve << " s\n";
  return 0;
} catch (const std::exception& e) {
  std::cerr << "sphere_settling: " << e.what() << "\n";
  return 1;
}

int main(int argc, char** argv) {
#ifdef ALEFSI_SETTLING_PETSC
  return petsc_main(argc, argv, settling_main);  // PETSc's options after "--"; all ranks end on an error
#else
  return settling_main(argc, argv);
#endif
}
