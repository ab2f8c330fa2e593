#pragma once
// Saddle-point systems for the solver tests (tests/fem/test_solvers.cpp, tests/petsc/
// test_petsc.cpp): the 3D lid-driven cavity, assembled once. Not part of the library (not
// installed); namespace alefsi::testing.
#include <vector>

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/saddle_point_blocks.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/stokes.hpp"

namespace alefsi::testing {

struct SaddleSystem {
  SparseMatrix A;
  VecX b;
  SaddlePointBlocks blocks;
};

// 3D lid-driven cavity on box_mesh(n, n, n): every boundary velocity fixed (lid z = 1:
// (1, 0, 0)), pressure DOF 0 pinned, mu = 1; b = -r at the zero field.
template <class Pair>
inline SaddleSystem cavity3d(int n) {
  const Mesh<3> mesh = box_mesh(n, n, n);
  MixedSpace<3, Pair> space(mesh);
  StokesKernel<3, Pair> kernel(space, 1.0);
  DofConstraints cons(space.n_field());
  const auto& vel = space.velocity();
  std::vector<char> done(vel.n_dofs(), 0);
  for (int t : {tags::zmax, 1, 2, 3, 4, 5})
    for (Index i : vel.boundary_dofs(t)) {
      if (done[i]) continue;
      done[i] = 1;
      for (int k = 0; k < 3; ++k) cons.fix(space.velocity_field(i, k), (t == tags::zmax && k == 0) ? 1.0 : 0.0);
    }
  cons.fix(space.pressure_field(0), 0.0);
  cons.finalize();
  Assembler<MixedSpace<3, Pair>::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
  SaddleSystem s;
  VecX r;
  asmb.assemble(kernel, cons.expand(VecX::Zero(cons.n_unknowns())), &s.A, &r);
  s.b = -r;
  s.blocks = saddle_point_blocks(space, cons, 1.0);
  return s;
}

}  // namespace alefsi::testing
