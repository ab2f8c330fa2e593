// The PETSc solver policies (la/petsc.hpp), on one rank and under `mpirun -n 2`: each rank
// solves the distributed system and compares the gathered answer with the serial solve that it
// computes itself (every rank holds the whole matrix), so the several-rank answer is checked
// against the one-rank answer to the solver tolerance. Built only when PETSc is found.
//
//   build/release/tests/alefsi_test_petsc                       one rank
//   mpirun -n 2 build/release/tests/alefsi_test_petsc           two ranks
//   ... -- -ksp_monitor                                         PETSc options after "--"
// PETSc's C types Vec and Mat live in the global namespace: with `using namespace alefsi`,
// alefsi's Vec<D> and Mat<D> are spelled out.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "../support/stokes_systems.hpp"
#include "alefsi/fem/norms.hpp"
#include "alefsi/la/petsc.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/mesh/io/gmsh.hpp"
#include "alefsi/la/krylov.hpp"
#include "alefsi/physics/stokes.hpp"
#include "alefsi/scenes/settling_sphere.hpp"
#include "alefsi/sim/ale_flow.hpp"
#include "alefsi/sim/driver.hpp"

using namespace alefsi;
using alefsi::testing::cavity3d;
using std::numbers::pi;

namespace {

Real relative_residual(const SparseMatrix& A, const VecX& x, const VecX& b) { return (A * x - b).norm() / b.norm(); }

VecX serial_solve(const SparseMatrix& A, const VecX& b) {
  SparseLu<> lu;
  lu.analyze(A);
  lu.factorize(A);
  return lu.solve(b);
}

// Every row is owned by exactly one rank, in rank order.
template <class S>
void check_ownership(const S& s, Index n) {
  long long mine = s.row_end() - s.row_begin(), total = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_LONG_LONG, MPI_SUM, PETSC_COMM_WORLD);
  CHECK(total == n);
  if (PetscSession::rank() == PetscSession::size() - 1) CHECK(s.row_end() == n);
  if (PetscSession::rank() == 0) CHECK(s.row_begin() == 0);
}

// 3D manufactured solution (as tests/physics/test_stokes.cpp): u = (s c c, c s c, -2 c c s),
// p = c c c, mu = 0.7.
constexpr Real mu = 0.7;
alefsi::Vec<3> exact_u(const alefsi::Vec<3>& x) {
  const Real s0 = std::sin(pi * x[0]), c0 = std::cos(pi * x[0]), s1 = std::sin(pi * x[1]), c1 = std::cos(pi * x[1]),
             s2 = std::sin(pi * x[2]), c2 = std::cos(pi * x[2]);
  return {s0 * c1 * c2, c0 * s1 * c2, -2 * c0 * c1 * s2};
}
alefsi::Mat<3> exact_grad(const alefsi::Vec<3>& x) {
  const Real s0 = std::sin(pi * x[0]), c0 = std::cos(pi * x[0]), s1 = std::sin(pi * x[1]), c1 = std::cos(pi * x[1]),
             s2 = std::sin(pi * x[2]), c2 = std::cos(pi * x[2]);
  alefsi::Mat<3> g;
  g << c0 * c1 * c2, -s0 * s1 * c2, -s0 * c1 * s2,  //
      -s0 * s1 * c2, c0 * c1 * c2, -c0 * s1 * s2,   //
      2 * s0 * c1 * s2, 2 * c0 * s1 * s2, -2 * c0 * c1 * c2;
  return pi * g;
}
Real exact_p(const alefsi::Vec<3>& x) { return std::cos(pi * x[0]) * std::cos(pi * x[1]) * std::cos(pi * x[2]); }
alefsi::Vec<3> exact_f(const alefsi::Vec<3>& x) {
  const Real s0 = std::sin(pi * x[0]), c0 = std::cos(pi * x[0]), s1 = std::sin(pi * x[1]), c1 = std::cos(pi * x[1]),
             s2 = std::sin(pi * x[2]), c2 = std::cos(pi * x[2]);
  return 3 * pi * pi * mu * exact_u(x) - pi * alefsi::Vec<3>(s0 * c1 * c2, c0 * s1 * c2, c0 * c1 * s2);
}

}  // namespace

TEST_CASE("PetscDirect (MUMPS) and PetscKrylov solve 3D Stokes (P2/P1, P1/P1-GLS) as the serial SparseLU does",
          "[petsc][cavity][quick]") {
  for (int pair = 0; pair < 2; ++pair) {
    const auto s = pair == 0 ? cavity3d<TaylorHood>(6) : cavity3d<P1P1Gls>(8);
    const VecX reference = serial_solve(s.A, s.b);
    {
      PetscDirect lu;
      lu.analyze(s.A);
      for (int rep = 0; rep < 2; ++rep) {  // a second factorisation of the same pattern
        lu.factorize(s.A);
        const VecX x = lu.solve(s.b);
        CHECK(relative_residual(s.A, x, s.b) <= 1e-12);
        CHECK((x - reference).norm() <= 1e-10 * reference.norm());
      }
      check_ownership(lu, s.A.rows());
    }
    for (bool blocks : {false, true}) {
      CAPTURE(pair, blocks);
      PetscKrylov<3> k({.tolerance = 1e-11});
      if (blocks) k.set_blocks(s.blocks);
      k.analyze(s.A);
      k.factorize(s.A);
      CHECK(k.n_pressure() == s.blocks.n_pressure);  // without blocks: from the diagonal's sign
      CHECK(k.n_extra() == 0);
      CHECK(k.pressure_mass() == blocks);
      const VecX x = k.solve(s.b);
      std::cout << "PETSc GMRES+fieldsplit, " << (pair == 0 ? "P2/P1" : "P1/P1-GLS") << ", "
                << (blocks ? "Schur ~ M_p/mu" : "Schur ~ selfp") << ": " << k.iterations() << " iterations, "
                << s.A.rows() << " unknowns, " << PetscSession::size() << " rank(s)\n";
      // GMRES stops on its recurrence's estimate of the residual; the computed one differs by
      // rounding, a few percent of the tolerance at most
      CHECK(relative_residual(s.A, x, s.b) <= 1.1e-11);
      // ||x - x*|| <= ||K^-1|| ||r||: the pinned-pressure system has ||K^-1|| ||K|| ~ 1e4 here
      CHECK((x - reference).norm() <= 1e-6 * reference.norm());
      check_ownership(k, s.A.rows());
    }
  }
}

TEST_CASE("assembled in parts: each rank passes the matrix of its cells, and MUMPS and GMRES solve with their sum",
          "[petsc][cavity][parts][quick]") {
  // the cavity's cells in Morton parts, one per rank (la/partition.hpp); PETSc sums the parts
  // (COO entries of other ranks' rows are sent) and the rows belong to the lowest rank touching them
  const int parts = PetscSession::size(), me = PetscSession::rank();
  for (int pair = 0; pair < 2; ++pair) {
    CAPTURE(pair);
    const auto s = pair == 0 ? cavity3d<TaylorHood>(6, 0, parts, me) : cavity3d<P1P1Gls>(8, 0, parts, me);
    const SparseMatrix& mine = parts > 1 ? s.part : s.A;
    if (parts > 1) CHECK(mine.nonZeros() < s.A.nonZeros());
    const VecX reference = serial_solve(s.A, s.b);
    PetscDirect lu;
    lu.set_summed(true);
    lu.factorize(mine);
    const VecX x = lu.solve(s.b);
    CHECK((x - reference).norm() <= 1e-10 * reference.norm());
    check_ownership(lu, s.A.rows());
    // the Schur complement by the pressure mass (steady Stokes: mass coefficient 0) and by
    // PETSc's selfp (the time-step path, chosen by a positive coefficient)
    for (Real coefficient : {0.0, 1.0}) {
      CAPTURE(coefficient);
      SaddlePointBlocks blocks = s.blocks;
      blocks.mass_coefficient = coefficient;
      PetscKrylov<3> k({.tolerance = 1e-11});
      k.set_summed(true);
      k.set_blocks(blocks);
      k.factorize(mine);
      CHECK(k.pressure_mass() == (coefficient == 0));
      const VecX y = k.solve(s.b);
      CHECK(relative_residual(s.A, y, s.b) <= 1.1e-11);
      CHECK((y - reference).norm() <= 1e-6 * reference.norm());
      check_ownership(k, s.A.rows());
    }
  }
}

TEST_CASE("MatPartitioning (PT-Scotch) gives every rank the same balanced parts of the cells",
          "[petsc][parts][quick]") {
  // the flow's partition of the cells under MPI (sim/discretisation.hpp); PT-Scotch's load
  // imbalance target is 1 % (-mat_partitioning_ptscotch_imbalance 0.01)
  const Mesh<3> mesh = read_gmsh<3>(std::string(ALEFSI_TEST_DATA_DIR) + "/gmsh/sphere_in_box3d.msh").mesh;
  const int parts = PetscSession::size();
  const std::vector<int> part = PetscKrylov<3>().partition(mesh);
  REQUIRE(part.size() == std::size_t(mesh.n_cells()));
  std::vector<int> low = part, high = part, minus = part;
  for (int& p : minus) p = -p;
  high = minus;
  PetscDirect().min(low), PetscDirect().min(high);  // the same array on every rank: min = max
  CHECK(low == part);
  CHECK(high == minus);
  REQUIRE(std::all_of(part.begin(), part.end(), [&](int p) { return p >= 0 && p < parts; }));
  std::vector<Index> size(std::size_t(parts), 0);
  for (int p : part) ++size[std::size_t(p)];
  const Real mean = Real(mesh.n_cells()) / parts;
  CHECK(*std::max_element(size.begin(), size.end()) <= 1.01 * mean + 1);
  std::cout << "PT-Scotch parts of " << mesh.n_cells() << " cells:";
  for (Index n : size) std::cout << " " << n;
  std::cout << "\n";
}

TEST_CASE("PetscKrylov: bad input and a solve that cannot converge are typed errors", "[petsc][quick]") {
  CHECK_THROWS_AS(PetscKrylov<3>({.tolerance = 0}), InvalidArgument);
  CHECK_THROWS_AS(PetscKrylov<3>({.restart = 0}), InvalidArgument);
  PetscKrylov<3> k;
  SparseMatrix spd(2, 2);
  spd.insert(0, 0) = 1, spd.insert(1, 1) = 2;
  spd.makeCompressed();
  CHECK_THROWS_AS(k.analyze(spd), SolverError);  // no saddle point: nothing to call pressure
  // two iterations cannot reach 1e-12: the error names the reason and the residual
  const auto s = cavity3d<TaylorHood>(4);
  PetscKrylov<3> few({.tolerance = 1e-12, .max_iterations = 2});
  few.analyze(s.A);
  few.factorize(s.A);
  CHECK_THROWS_WITH(few.solve(s.b), Catch::Contains("DIVERGED_ITS") && Catch::Contains("relative residual") &&
                                        Catch::Contains("e-"));
  VecX wrong = VecX::Ones(3);
  CHECK_THROWS_AS(few.solve(wrong), InvalidArgument);
  // in parts a rank's diagonal does not show the pressures: the blocks are needed, and every
  // rank refuses alike; an uncompressed part is refused on every rank too
  PetscKrylov<3> parts_without_blocks;
  parts_without_blocks.set_summed(true);
  if (PetscSession::size() > 1)
    CHECK_THROWS_WITH(parts_without_blocks.factorize(s.A), Catch::Contains("set_blocks"));
  SparseMatrix loose = s.A;
  if (PetscSession::rank() == 0) loose.coeffRef(0, 0) += 0;  // still compressed
  if (PetscSession::rank() == 0) loose.uncompress();
  PetscDirect parts_lu;
  parts_lu.set_summed(true);
  if (PetscSession::size() > 1)
    CHECK_THROWS_WITH(parts_lu.factorize(loose), Catch::Contains("compressed"));
  // a singular matrix: MUMPS's failure is a SolverError on every rank alike (the reason is
  // agreed across ranks before anyone throws), not a hang
  SparseMatrix singular(4, 4);
  singular.insert(0, 0) = 1, singular.insert(1, 1) = 1, singular.insert(2, 2) = 1, singular.insert(3, 3) = 0;
  singular.insert(2, 3) = 0, singular.insert(3, 2) = 0;
  singular.makeCompressed();
  PetscDirect lu;
  CHECK_THROWS_AS(
      [&] {
        lu.factorize(singular);
        return lu.solve(VecX::Ones(4));
      }(),
      Error);
}

TEST_CASE("3D Taylor–Hood solved through PetscKrylov converges at rates 3 / 2 with the serial errors",
          "[petsc][convergence]") {
  // the errors of the PETSc solves equal the SparseLU solves' to 1e-7 (the solver tolerance,
  // 1e-10, times the system's conditioning), so the rates are those of
  // tests/physics/test_stokes.cpp: asserted over n = 8 -> 12 with the same bands
  std::vector<Real> N, eu, eh;
  for (int n : {4, 8, 12}) {
    const Mesh<3> mesh = box_mesh(n, n, n);
    Stokes<3, TaylorHood> stokes(mesh, mu, exact_f);
    for (Index f : mesh.boundary_facets()) stokes.set_velocity(mesh.facet_tag(f), exact_u);
    const VecX field = stokes.solve(PetscKrylov<3>({.tolerance = 1e-10}));
    const VecX serial = stokes.solve();
    const auto e = flow_errors<3, TaylorHood>(stokes.space(), field, exact_u, exact_grad, exact_p);
    const auto e0 = flow_errors<3, TaylorHood>(stokes.space(), serial, exact_u, exact_grad, exact_p);
    CHECK(e.u_l2 == Approx(e0.u_l2).epsilon(1e-7));
    CHECK(e.u_h1 == Approx(e0.u_h1).epsilon(1e-7));
    CHECK(e.p_l2 == Approx(e0.p_l2).epsilon(1e-6));
    N.push_back(Real(field.size())), eu.push_back(e.u_l2), eh.push_back(e.u_h1);
    std::cout << "3D Taylor-Hood via PETSc, n = " << n << ": |u-uh|_L2 " << e.u_l2 << ", |u-uh|_H1 " << e.u_h1
              << ", |p-ph|_L2 " << e.p_l2 << "\n";
  }
  CHECK(observed_rate(N[1], eu[1], N[2], eu[2], 3) == Approx(3.0).margin(0.2));
  CHECK(observed_rate(N[1], eh[1], N[2], eh[2], 3) == Approx(2.0).margin(0.15));
}

TEST_CASE("AleFlow with PetscKrylov<3> or PetscDirect: 3D Navier–Stokes steps with a free sphere match the serial "
          "direct solve",
          "[petsc][bodies3d][quick]") {
  // a free, neutrally buoyant sphere in simple shear (as tests/fem/test_solvers.cpp with
  // SaddlePointGmres): the 6 body unknowns join split 0, beside the velocities
  const Real a = 0.2, gamma = 1.0;
  auto run = [&](auto& flow) {
    flow.set_velocity(1, [&](const alefsi::Vec<3>& x, Real) { return alefsi::Vec<3>(gamma * x[1], 0.0, 0.0); });
    flow.add_body(sphere_body(5, alefsi::Vec<3>::Zero(), a, 1.0));
    flow.set_initial_velocity([&](const alefsi::Vec<3>& x) { return alefsi::Vec<3>(gamma * x[1], 0.0, 0.0); });
    StepReport rep;
    for (int n = 0; n < 2; ++n) rep = flow.step(0.05);
    return rep;
  };
  const Mesh<3> mesh = read_gmsh<3>(std::string(ALEFSI_TEST_DATA_DIR) + "/gmsh/sphere_in_box3d.msh").mesh;
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E>> serial(mesh, FlowOptions{1.0, 1.0});
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E>::with_solver<PetscKrylov<3>>> krylov(mesh, FlowOptions{1.0, 1.0});
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E>::with_solver<PetscDirect>> direct(mesh, FlowOptions{1.0, 1.0});
  run(serial);
  const StepReport rk = run(krylov);
  run(direct);
  CHECK(rk.newton_iterations <= 4);  // GMRES to 1e-8 per Newton update, Newton to 1e-10
  const VecX& u0 = serial.field();
  CHECK((krylov.field() - u0).norm() <= 1e-7 * u0.norm());
  CHECK((krylov.body_velocity(0) - serial.body_velocity(0)).norm() <= 1e-7 * serial.body_velocity(0).norm());
  CHECK((direct.field() - u0).norm() <= 1e-10 * u0.norm());
  CHECK((direct.body_velocity(0) - serial.body_velocity(0)).norm() <= 1e-10 * serial.body_velocity(0).norm());
  // on several ranks each assembles the cells of its part (la/partition.hpp): the parts cover
  // the mesh once
  for (Index mine : {krylov.assembled_cells(), direct.assembled_cells()}) {
    Index total = 0;
    MPI_Allreduce(&mine, &total, 1, MPI_INT, MPI_SUM, PETSC_COMM_WORLD);
    CHECK(total == mesh.n_cells());
    if (PetscSession::size() > 1) CHECK(mine < mesh.n_cells());
  }
  // a checkpoint of the serial flow (its direct solver keeps its factors for reuse) continues
  // on N ranks in parts, where the flow's factors are not reused: as the serial flow does
  const auto file = std::filesystem::temp_directory_path() /
                    ("alefsi_test_bodies3d_" + std::to_string(PetscSession::rank()) + ".bin");
  serial.save_checkpoint(file);
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E>::with_solver<PetscKrylov<3>>> resumed(read_checkpoint_mesh<3>(file),
                                                                                     FlowOptions{1.0, 1.0});
  resumed.set_velocity(1, [&](const alefsi::Vec<3>& x, Real) { return alefsi::Vec<3>(gamma * x[1], 0.0, 0.0); });
  resumed.add_body(sphere_body(5, alefsi::Vec<3>::Zero(), a, 1.0));
  resumed.load_checkpoint(file);
  std::filesystem::remove(file);
  serial.step(0.05), resumed.step(0.05);
  CHECK((resumed.field() - serial.field()).norm() <= 1e-7 * serial.field().norm());
  CHECK((resumed.body_centre(0) - serial.body_centre(0)).norm() <= 1e-9 * a);
}

TEST_CASE("a sphere settling in a spherical container: 10 steps through run() on N ranks follow the serial "
          "trajectory, rank 0 writes, each rank its VTU piece, and the checkpoint continues in a serial flow",
          "[petsc][settling][quick]") {
  // examples/sphere_settling.cpp's scene: Navier–Stokes, a free sphere under gravity, the mesh
  // moved by elasticity. Every rank runs the PETSc flow through the driver (rank 0 writing into
  // one shared folder), then the serial flow with SaddlePointGmres, and compares the two
  // trajectories step by step. Newton (to 1e-10) removes the solvers' differences (1e-8).
  const scenes::SettlingSphere scene;
  const Real dt = 0.005;
  const int steps = 10;
  const auto dir = std::filesystem::temp_directory_path() /
                   ("alefsi_test_settling_" + std::to_string(PetscSession::size()) + "_ranks");
  if (PetscSession::rank() == 0) std::filesystem::remove_all(dir);
  MPI_Barrier(PETSC_COMM_WORLD);
  auto trajectory = [&](auto& flow, RunOptions opt) {
    std::vector<alefsi::Vec<3>> centre;
    std::vector<alefsi::Vec<6>> velocity;
    opt.dt = dt, opt.tolerance = 0, opt.log = nullptr;
    opt.on_step = [&] {
      centre.push_back(flow.body_centre(0));
      velocity.push_back(flow.body_velocity(0));
    };
    run(flow, opt);
    return std::pair(centre, velocity);
  };
  using Cfg = FlowConfig<3, TaylorHood, BDF2_BDF2E, NavierStokes>;
  AleFlow<Cfg::with_solver<PetscKrylov<3>>> distributed(scene.mesh(), scene.flow_options());
  scene.configure(distributed);
  RunOptions opt;
  opt.t_end = steps * dt, opt.output = dir, opt.checkpoint_every = steps / 2, opt.writer = PetscSession::rank() == 0;
  opt.vtu_every = steps / 2;
  const auto [x_mpi, v_mpi] = trajectory(distributed, opt);
  MPI_Barrier(PETSC_COMM_WORLD);  // rank 0's files are complete

  // the VTU series: steps 0, 5, 10; in parts, one piece per rank holding its cells and the
  // .pvtu that joins them (the pieces' contents are checked by VTK in tests/mesh/test_vtu.cpp)
  {
    const int ranks = PetscSession::size();
    CHECK(distributed.in_parts() == (ranks > 1));
    auto text = [](const std::filesystem::path& f) {
      std::ifstream in(f, std::ios::binary);
      std::ostringstream s;
      s << in.rdbuf();
      return s.str();
    };
    auto count = [](const std::string& s, const std::string& what) {
      int n = 0;
      for (auto at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
      return n;
    };
    const std::string pvd = text(dir / "flow.pvd");
    CHECK(count(pvd, "<DataSet ") == 3);
    for (int k = 0; k < 3; ++k) {
      const std::string step = "flow_00000" + std::to_string(k);
      if (ranks == 1) {
        CHECK(std::filesystem::is_regular_file(dir / "flow" / (step + ".vtu")));
        continue;
      }
      CHECK(count(pvd, "file=\"flow/" + step + ".pvtu\"") == 1);
      CHECK(count(text(dir / "flow" / (step + ".pvtu")), "<Piece Source=") == ranks);
      long cells = 0;  // the pieces' cells: every cell once
      for (int r = 0; r < ranks; ++r) {
        const std::string head = text(dir / "flow" / (step + "_p000" + std::to_string(r) + ".vtu")).substr(0, 400);
        const auto at = head.find("NumberOfCells=\"");
        REQUIRE(at != std::string::npos);
        cells += std::stol(head.substr(at + 15));
      }
      CHECK(cells == distributed.mesh().n_cells());
    }
    CHECK(long(distributed.own_cells().size()) == (ranks > 1 ? long(distributed.assembled_cells()) : 0L));
    // processes that disagree on the pieces are refused on every process, before any step
    if (ranks > 1) {
      RunOptions odd = opt;
      odd.t_end = 2 * steps * dt, odd.vtu_every = PetscSession::rank() == 1 ? 0 : 1, odd.log = nullptr;
      CHECK_THROWS_AS(run(distributed, odd), InvalidArgument);
      CHECK(distributed.time() == Approx(steps * dt));
      // rank 0 cannot create its folder (a file is in the way): every rank stops, none waits
      RunOptions blocked = odd;
      blocked.vtu_every = 0, blocked.output = dir / "bodies.csv" / "sub";
      if (PetscSession::rank() == 0) CHECK_THROWS_AS(run(distributed, blocked), std::filesystem::filesystem_error);
      else CHECK_THROWS_AS(run(distributed, blocked), IoError);
      CHECK(distributed.time() == Approx(steps * dt));
    }
  }

  AleFlow<Cfg::with_solver<SaddlePointGmres<3>>> serial(scene.mesh(), scene.flow_options());
  scene.configure(serial);
  RunOptions serial_opt;
  serial_opt.t_end = steps * dt;
  const auto [x, v] = trajectory(serial, serial_opt);
  REQUIRE(x_mpi.size() == std::size_t(steps));
  REQUIRE(x.size() == std::size_t(steps));
  const Real depth = std::abs(x.back()[2]), speed = v.back().norm();
  CHECK(depth > 0.02);  // it has moved: 0.024 cm down at t = 0.05
  for (int n = 0; n < steps; ++n) {
    CHECK((x_mpi[std::size_t(n)] - x[std::size_t(n)]).norm() <= 1e-9 * depth);
    CHECK((v_mpi[std::size_t(n)] - v[std::size_t(n)]).norm() <= 1e-9 * speed);
  }
  // rank 0's time series: a header and one row per step
  {
    std::ifstream csv(dir / "bodies.csv");
    int lines = 0;
    for (std::string line; std::getline(csv, line);) ++lines;
    CHECK(lines == steps + 1);
  }
  // the checkpoint of step 10 (written by rank 0 under N ranks), continued serially for 2 steps,
  // is the N-rank run continued (the state is the same on every rank)
  const auto file = dir / "checkpoint.bin";
  AleFlow<Cfg::with_solver<SaddlePointGmres<3>>> continued(read_checkpoint_mesh<3>(file), scene.flow_options());
  scene.configure(continued);
  continued.load_checkpoint(file);
  CHECK(continued.time() == Approx(steps * dt));
  CHECK((continued.body_centre(0) - x_mpi.back()).norm() == 0);
  continued.step(dt), serial.step(dt);
  CHECK((continued.body_centre(0) - serial.body_centre(0)).norm() <= 1e-9 * depth);
  MPI_Barrier(PETSC_COMM_WORLD);
  if (PetscSession::rank() == 0) std::filesystem::remove_all(dir);
}

// Catch2 reads the arguments before "--"; PETSc reads them all (its options go after "--").
int main(int argc, char** argv) {
  PetscSession petsc(argc, argv);
  int catch_argc = argc;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--") {
      catch_argc = i;
      break;
    }
  return Catch::Session().run(catch_argc, argv);
}
