// deal.II: the 2D P2/P1 Stokes matrix on the unit square cut into 2 N^2 triangles, timed by
// phase, for bench/peers/side_by_side.sh (same problem as bench/peers/alefsi_stokes.cpp).
//
//   stokes_p2p1_dealii N [repetitions = 3]
//
// FE_SimplexP(2)^2 x FE_SimplexP(1), MappingFE(P1), QGaussSimplex<2>(2) (4 points: exact for this
// form), 2 mu (D(u), D(v)) - (p, div v) - (q, div u) with mu = 1; velocity on the boundary
// fixed (1, 0) on the top side (boundary id 3), 0 elsewhere; one pressure DOF
// pinned. Constraints are eliminated by AffineConstraints::distribute_local_to_global (rows of
// the constrained DOFs keep a diagonal entry). The textbook deal.II assembly (FEValues with
// extractors, shape values cached per quadrature point), not tuned further.
// Phases:
//   dofs      distribute_dofs + the boundary/pressure constraints
//   pattern   DynamicSparsityPattern from the DoFs and constraints, SparsityPattern, matrix reinit
//   fill      the cell loop (FEValues, local matrix, distribute_local_to_global), matrix zeroed first
// Times: minimum over the repetitions of the process CPU time and of the wall time.
// Prints one line:
//   dealii N cells dofs nnz dofs_cpu pattern_cpu fill_cpu pattern_wall fill_wall
#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/numerics/vector_tools.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// (1, 0, 0) on the lid: velocity x-component 1, the pressure component unused
class Lid : public dealii::Function<2> {
 public:
  Lid() : dealii::Function<2>(3) {}
  double value(const dealii::Point<2>&, const unsigned int component) const override { return component == 0 ? 1.0 : 0.0; }
};
}  // namespace

int main(int argc, char** argv) {
  using namespace dealii;
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s N [repetitions]\n", argv[0]);
    return 2;
  }
  const unsigned n = unsigned(std::atoi(argv[1]));
  const int reps = argc > 2 ? std::atoi(argv[2]) : 3;
  Triangulation<2> tria;
  GridGenerator::subdivided_hyper_cube_with_simplices(tria, n, 0.0, 1.0);
  // boundary ids 0..3: x = 0, x = 1, y = 0, y = 1 (colorize is not implemented for simplices)
  for (const auto& cell : tria.active_cell_iterators())
    for (const auto f : cell->face_indices())
      if (cell->face(f)->at_boundary()) {
        const Point<2> c = cell->face(f)->center();
        cell->face(f)->set_boundary_id(c[0] < 1e-12 ? 0 : c[0] > 1 - 1e-12 ? 1 : c[1] < 1e-12 ? 2 : 3);
      }
  const FESystem<2> fe(FE_SimplexP<2>(2), 2, FE_SimplexP<2>(1), 1);
  const MappingFE<2> mapping(FE_SimplexP<2>(1));
  const QGaussSimplex<2> quad(2);
  const FEValuesExtractors::Vector velocities(0);
  const FEValuesExtractors::Scalar pressure(2);
  double best_dofs = 1e30, best_pattern = 1e30, best_fill = 1e30, wall_pattern = 1e30, wall_fill = 1e30;
  std::size_t n_dofs = 0, nnz = 0;
  for (int rep = 0; rep < reps; ++rep) {
    double c0 = cpu_seconds();
    DoFHandler<2> dof(tria);
    dof.distribute_dofs(fe);
    AffineConstraints<double> cons;
    const Lid lid;
    const Functions::ZeroFunction<2> zero(3);
    VectorTools::interpolate_boundary_values(mapping, dof, 3, lid, cons, fe.component_mask(velocities));
    for (types::boundary_id b : {0, 1, 2})
      VectorTools::interpolate_boundary_values(mapping, dof, b, zero, cons, fe.component_mask(velocities));
    const IndexSet pdofs = DoFTools::extract_dofs(dof, fe.component_mask(pressure));
    const auto p0 = *pdofs.begin();
    if (!cons.is_constrained(p0)) cons.add_line(p0);
    cons.close();
    best_dofs = std::min(best_dofs, cpu_seconds() - c0);

    c0 = cpu_seconds();
    double w0 = wall_seconds();
    DynamicSparsityPattern dsp(dof.n_dofs());
    DoFTools::make_sparsity_pattern(dof, dsp, cons, false);
    SparsityPattern sp;
    sp.copy_from(dsp);
    SparseMatrix<double> A;
    A.reinit(sp);
    best_pattern = std::min(best_pattern, cpu_seconds() - c0);
    wall_pattern = std::min(wall_pattern, wall_seconds() - w0);

    c0 = cpu_seconds();
    w0 = wall_seconds();
    A = 0;
    FEValues<2> fev(mapping, fe, quad, update_values | update_gradients | update_JxW_values);
    const unsigned nd = fe.n_dofs_per_cell(), nq = quad.size();
    FullMatrix<double> local(nd, nd);
    std::vector<types::global_dof_index> ldofs(nd);
    std::vector<SymmetricTensor<2, 2>> eps(nd);
    std::vector<double> div(nd), psi(nd);
    for (const auto& cell : dof.active_cell_iterators()) {
      fev.reinit(cell);
      local = 0;
      for (unsigned q = 0; q < nq; ++q) {
        for (unsigned k = 0; k < nd; ++k) {
          eps[k] = fev[velocities].symmetric_gradient(k, q);
          div[k] = fev[velocities].divergence(k, q);
          psi[k] = fev[pressure].value(k, q);
        }
        const double w = fev.JxW(q);
        for (unsigned i = 0; i < nd; ++i)
          for (unsigned j = 0; j < nd; ++j)
            local(i, j) += (2.0 * (eps[i] * eps[j]) - div[i] * psi[j] - psi[i] * div[j]) * w;
      }
      cell->get_dof_indices(ldofs);
      cons.distribute_local_to_global(local, ldofs, A);
    }
    best_fill = std::min(best_fill, cpu_seconds() - c0);
    wall_fill = std::min(wall_fill, wall_seconds() - w0);
    n_dofs = dof.n_dofs();
    nnz = sp.n_nonzero_elements();
  }
  std::printf("dealii %u %u %zu %zu %.6f %.6f %.6f %.6f %.6f\n", n, tria.n_active_cells(), n_dofs, nnz, best_dofs,
              best_pattern, best_fill, wall_pattern, wall_fill);
  return 0;
}
