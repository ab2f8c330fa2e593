// alefsi: the 2D P2/P1 Stokes matrix on the unit square cut into 2 N^2 triangles, timed by phase,
// for the side-by-side comparison with the peers (bench/peers/side_by_side.sh builds and runs it).
//
//   alefsi_stokes N [repetitions = 3] [threads = 1]
//
// Same problem as bench/peers/stokes_p2p1.edp (FreeFEM) and bench/peers/dealii/stokes_p2p1.cc
// (deal.II): 2 mu (D(u), D(v)) - (p, div v) - (q, div u), mu = 1, every velocity DOF on the
// boundary fixed (u = (1, 0) on the top side, 0 elsewhere, eliminated from the unknowns) and
// pressure DOF 0 pinned, as Stokes::solve does. Phases:
//   dofs     the constraints (boundary DOFs fixed) and their finalisation
//   pattern  Assembler construction: CSR pattern, scatter positions, thread schedule
//   fill     Assembler::assemble of the matrix and the residual (zero, kernel, scatter)
// Times are the minimum over the repetitions of the process CPU time and of the wall time.
// Prints one line:
//   alefsi N cells unknowns nnz dofs_cpu pattern_cpu fill_cpu pattern_wall fill_wall threads
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/stokes.hpp"

namespace {
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

int main(int argc, char** argv) {
  using namespace alefsi;
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s N [repetitions] [threads]\n", argv[0]);
    return 2;
  }
  const int n = std::atoi(argv[1]);
  const int reps = argc > 2 ? std::atoi(argv[2]) : 3;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 1;
  using Space = MixedSpace<2, TaylorHood>;
  const auto mesh = rectangle_mesh(n, n);
  const Space space(mesh);
  const StokesKernel<2, TaylorHood> kernel(space, 1.0);
  double best_dofs = 1e30, best_pattern = 1e30, best_fill = 1e30, wall_pattern = 1e30, wall_fill = 1e30;
  Index unknowns = 0, nnz = 0;
  for (int rep = 0; rep < reps; ++rep) {
    double c0 = cpu_seconds();
    DofConstraints cons(space.n_field());
    const auto& vel = space.velocity();
    std::vector<char> done(vel.n_dofs(), 0);
    for (int tag : {tags::top, tags::bottom, tags::left, tags::right})  // the lid first
      for (Index i : vel.boundary_dofs(tag)) {
        if (done[i]) continue;
        done[i] = 1;
        for (int k = 0; k < 2; ++k) cons.fix(space.velocity_field(i, k), (tag == tags::top && k == 0) ? 1.0 : 0.0);
      }
    cons.fix(space.pressure_field(0), 0.0);
    cons.finalize();
    best_dofs = std::min(best_dofs, cpu_seconds() - c0);
    c0 = cpu_seconds();
    double w0 = wall_seconds();
    Assembler<Space::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
    asmb.set_threads(threads);
    best_pattern = std::min(best_pattern, cpu_seconds() - c0);
    wall_pattern = std::min(wall_pattern, wall_seconds() - w0);
    const VecX field = cons.expand(VecX::Zero(cons.n_unknowns()));
    SparseMatrix J;
    VecX r;
    asmb.assemble(kernel, field, &J, &r);  // first assembly: allocates J (not timed)
    c0 = cpu_seconds();
    w0 = wall_seconds();
    asmb.assemble(kernel, field, &J, &r);
    best_fill = std::min(best_fill, cpu_seconds() - c0);
    wall_fill = std::min(wall_fill, wall_seconds() - w0);
    unknowns = cons.n_unknowns();
    nnz = J.nonZeros();
  }
  std::printf("alefsi %d %ld %ld %ld %.6f %.6f %.6f %.6f %.6f %d\n", n, long(mesh.n_cells()), long(unknowns), long(nnz),
              best_dofs, best_pattern, best_fill, wall_pattern, wall_fill, threads);
  return 0;
}
