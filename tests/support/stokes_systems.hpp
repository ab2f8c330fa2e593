#pragma once
// Saddle-point systems for the solver tests and benchmarks (tests/fem/test_solvers.cpp,
// tests/petsc/test_petsc.cpp, bench/bench_krylov3d.cpp): the 3D lid-driven cavity, assembled
// once, optionally with a time step's velocity mass. Not part of the library (not installed);
// namespace alefsi::testing.
#include <vector>

#include "alefsi/fem/quadrature.hpp"

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/partition.hpp"
#include "alefsi/la/saddle_point_blocks.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/stokes.hpp"

namespace alefsi::testing {

struct SaddleSystem {
  SparseMatrix A;
  VecX b;
  SaddlePointBlocks blocks;
  SparseMatrix part;  // with parts > 1: the matrix of part `part`'s cells (la/partition.hpp)
};

// consistent scalar velocity mass, added as gamma * M to every component of the free velocities
template <class Pair>
inline void add_velocity_mass(const MixedSpace<3, Pair>& space, const DofConstraints& cons, Real gamma, SparseMatrix& A) {
  using V = typename Pair::template Velocity<3>;
  const auto& rule = simplex_quadrature<3>(2 * V::degree);
  Eigen::Matrix<Real, V::n_dofs, V::n_dofs> ref = Eigen::Matrix<Real, V::n_dofs, V::n_dofs>::Zero();
  for (int q = 0; q < rule.size(); ++q) {
    const auto phi = V::values(rule.points[q]);
    for (int a = 0; a < V::n_dofs; ++a)
      for (int c = 0; c < V::n_dofs; ++c) ref(a, c) += rule.weights[q] * phi[a] * phi[c];
  }
  const auto& mesh = space.mesh();
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    const Real m = gamma * mesh.measure(c) / reference_measure<3>;
    const auto& dofs = space.velocity().cell_dofs(c);
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < V::n_dofs; ++a) {
        const Index fa = space.velocity_field(dofs[a], k);
        if (cons.kind(fa) != DofConstraints::Kind::free) continue;
        for (int e = 0; e < V::n_dofs; ++e) {
          const Index fe = space.velocity_field(dofs[e], k);
          if (cons.kind(fe) != DofConstraints::Kind::free) continue;
          A.coeffRef(cons.indices(fa)[0], cons.indices(fe)[0]) += m * ref(a, e);  // in the pattern
        }
      }
  }
}

// 3D lid-driven cavity on box_mesh(n, n, n): every boundary velocity fixed (lid z = 1:
// (1, 0, 0)), pressure DOF 0 pinned (pin = false: not, the constant pressure is then K's null
// space), mu = 1; b = -r at the zero field. gamma > 0 adds gamma M_u to the velocity block (the
// rho a0 / dt part of a time step) and hands it to the blocks. parts > 1 (gamma 0): also the
// matrix of the cells of Morton part `part` of `parts`.
template <class Pair>
inline SaddleSystem cavity3d(int n, Real gamma = 0, int parts = 1, int part = 0, bool pin = true) {
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
  if (pin) cons.fix(space.pressure_field(0), 0.0);
  cons.finalize();
  Assembler<MixedSpace<3, Pair>::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
  SaddleSystem s;
  VecX r;
  asmb.assemble(kernel, cons.expand(VecX::Zero(cons.n_unknowns())), &s.A, &r);
  s.b = -r;
  if (gamma > 0) add_velocity_mass(space, cons, gamma, s.A);
  s.blocks = saddle_point_blocks(space, cons, 1.0, gamma);
  if (parts > 1) {
    const std::vector<Index> cells = cells_of_part(partition_cells(mesh, parts), part);
    Assembler<MixedSpace<3, Pair>::n_local> mine(
        Index(cells.size()), [&](Index i) { return space.cell_field_dofs(cells[std::size_t(i)]); }, cons,
        AssembledCells::part);
    mine.assemble(PartKernel<StokesKernel<3, Pair>>{&kernel, &cells}, cons.expand(VecX::Zero(cons.n_unknowns())),
                  &s.part, nullptr);
  }
  return s;
}

}  // namespace alefsi::testing
