#pragma once
/// \file la/saddle_point_blocks.hpp
/// What the space knows about a flow system's unknowns [u | p | z] — the block split, the
/// velocity components, the pressure mass matrix and the lumped velocity mass — for solvers that
/// precondition the saddle point by blocks (`SaddlePointGmres`, la/krylov.hpp, whose file
/// comment has the preconditioner). Separate from la/krylov.hpp so that a flow (sim/
/// discretisation.hpp) can hand the blocks to any solver that takes them without compiling GMRES
/// and AMG when its solver is direct.
///
///     alefsi::SaddlePointBlocks b = alefsi::saddle_point_blocks(space, cons, mu, rho * a0 / dt);
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/fem/quadrature.hpp"
#include "alefsi/la/assembler.hpp"  // SparseMatrix

namespace alefsi {

/// A solver that can take a closed domain's system unpinned, with the constant pressure as its
/// null space (SaddlePointGmres, la/krylov.hpp, whose file comment says why: a pin would leave
/// it a near-null vector). The flows (sim/discretisation.hpp) and `Stokes` then pin nothing.
template <class S>
concept SolvesPressureNullSpace = requires(S s) { s.set_pressure_null_space(true); };

/// The pressure constant of a closed domain (`closed`: every boundary velocity given) in the
/// constraints `cons` of a system that `solver` will solve: the pressure field DOF `pressure0`
/// pinned to 0, or, for a SolvesPressureNullSpace solver, nothing pinned and the solver told.
/// Returns whether the solver takes the null space. Before `cons.finalize()`.
template <class Solver>
bool constrain_pressure_constant(Solver& solver, bool closed, DofConstraints& cons, Index pressure0) {
  bool null_space = false;
  if constexpr (SolvesPressureNullSpace<Solver>) {
    null_space = closed;
    solver.set_pressure_null_space(null_space);
  }
  if (closed && !null_space) cons.fix(pressure0, 0.0);
  return null_space;
}

/// What the space knows about a flow system's unknowns [u | p | z] (see the file comment).
struct SaddlePointBlocks {
  Index n_pressure = 0;                 ///< free pressure unknowns, after the velocity ones
  Index n_extra = 0;                    ///< trailing extra (body) unknowns
  std::vector<int> velocity_component;  ///< per velocity unknown, 0..D-1 (empty: interleaved)
  SparseMatrix pressure_mass;           ///< M_p on the pressure unknowns (empty: algebraic S~)
  Real mu = 1;                          ///< viscosity: S ~ M_p / mu
  VecX velocity_mass;                   ///< lumped M_u per velocity unknown (for Cahouet–Chabard)
  Real mass_coefficient = 0;            ///< gamma: A_uu holds gamma M_u (rho a_0 / dt; 0: steady)
};

/// The sizes of the blocks [u | p | z] of a flow system K: from the space's blocks when given
/// (checked against K's size), otherwise from K's diagonal: the pressures are the contiguous
/// range of unknowns whose diagonal entry is <= 0 (zero for Taylor–Hood, -C_ii < 0 for GLS; every
/// velocity and body diagonal is > 0). `solver` names the caller in the errors.
struct SaddlePointSplit {
  Index n_velocity = 0, n_pressure = 0, n_extra = 0;
};
inline SaddlePointSplit saddle_point_split(const SparseMatrix& K, const SaddlePointBlocks* blocks,
                                           const char* solver) {
  ALEFSI_CHECK_ARG(K.rows() == K.cols(), "A", "must be square");
  const Index n = K.rows();
  SaddlePointSplit s;
  if (blocks) {
    s.n_pressure = blocks->n_pressure, s.n_extra = blocks->n_extra;
    s.n_velocity = n - s.n_pressure - s.n_extra;
    ALEFSI_CHECK_ARG(s.n_velocity > 0 && s.n_pressure > 0 && s.n_extra >= 0, "A", "size ", n,
                     " does not match the blocks (", s.n_pressure, " pressures, ", s.n_extra, " extras)");
    return s;
  }
  Index first = -1, last = -1;
  for (Index j = 0; j < n; ++j)
    if (!(K.coeff(j, j) > 0)) {
      if (first < 0) first = j;
      last = j;
    }
  if (first < 0) throw SolverError(std::string(solver) + ": no unknown with a diagonal <= 0: not a saddle-point system");
  for (Index j = first; j <= last; ++j)
    if (K.coeff(j, j) > 0)
      throw SolverError(std::string(solver) +
                        ": the unknowns with a diagonal <= 0 are not contiguous; pass the blocks (set_blocks)");
  s.n_velocity = first, s.n_pressure = last + 1 - first, s.n_extra = n - last - 1;
  return s;
}

/// The blocks of the system assembled on `space` through `cons`: pressure mass matrix
/// (quadrature exact for the pressure element), HRZ-lumped velocity mass (diagonal of the
/// consistent mass, scaled per cell to the cell's measure: positive for P2, whose row sums are
/// not) when mass_coefficient > 0.
template <int D, ElementPair Pair>
SaddlePointBlocks saddle_point_blocks(const MixedSpace<D, Pair>& space, const DofConstraints& cons, Real mu,
                                      Real mass_coefficient = 0) {
  ALEFSI_CHECK_ARG(cons.finalized(), "cons", "must be finalized");
  ALEFSI_CHECK_ARG(cons.n_field() == space.n_field(), "cons", "was built for another space");
  ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "must be positive and finite, got ", mu);
  ALEFSI_CHECK_ARG(mass_coefficient >= 0, "mass_coefficient", "must be >= 0, got ", mass_coefficient);
  using P = typename Pair::template Pressure<D>;
  using V = typename Pair::template Velocity<D>;
  const Index nvf = D * space.velocity().n_dofs();
  SaddlePointBlocks blk;
  blk.mu = mu;
  blk.mass_coefficient = mass_coefficient;
  Index nu = 0;
  for (Index f = 0; f < nvf; ++f)
    if (cons.kind(f) == DofConstraints::Kind::free) {
      ALEFSI_ASSERT(cons.indices(f)[0] == nu);
      blk.velocity_component.push_back(int(f % D));
      ++nu;
    }
  for (Index k = 0; k < space.pressure().n_dofs(); ++k)
    if (cons.kind(space.pressure_field(k)) == DofConstraints::Kind::free) ++blk.n_pressure;
  blk.n_extra = cons.n_unknowns() - nu - blk.n_pressure;
  ALEFSI_CHECK_ARG(blk.n_extra == cons.n_unknowns() - cons.n_free(), "cons",
                   "constrains pressure DOFs by links: not a [u | p | z] system");
  const auto& mesh = space.mesh();
  // pressure mass
  {
    const auto& rule = simplex_quadrature<D>(2 * P::degree);
    Eigen::Matrix<Real, P::n_dofs, P::n_dofs> ref = Eigen::Matrix<Real, P::n_dofs, P::n_dofs>::Zero();
    for (int q = 0; q < rule.size(); ++q) {
      const auto phi = P::values(rule.points[q]);
      for (int a = 0; a < P::n_dofs; ++a)
        for (int b = 0; b < P::n_dofs; ++b) ref(a, b) += rule.weights[q] * phi[a] * phi[b];
    }
    std::vector<Eigen::Triplet<Real, Index>> t;
    t.reserve(std::size_t(mesh.n_cells()) * P::n_dofs * P::n_dofs);
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      const Real m = mesh.measure(c) / reference_measure<D>;
      const auto& dofs = space.pressure().cell_dofs(c);
      std::array<Index, P::n_dofs> u{};
      for (int a = 0; a < P::n_dofs; ++a) {
        const Index f = space.pressure_field(dofs[a]);
        u[a] = cons.kind(f) == DofConstraints::Kind::free ? cons.indices(f)[0] - nu : -1;
      }
      for (int a = 0; a < P::n_dofs; ++a)
        for (int b = 0; b < P::n_dofs; ++b)
          if (u[a] >= 0 && u[b] >= 0) t.emplace_back(u[a], u[b], m * ref(a, b));
    }
    blk.pressure_mass.resize(blk.n_pressure, blk.n_pressure);
    blk.pressure_mass.setFromTriplets(t.begin(), t.end());
  }
  // lumped velocity mass
  if (mass_coefficient > 0) {
    const auto& rule = simplex_quadrature<D>(2 * V::degree);
    std::array<Real, V::n_dofs> diag{};
    for (int q = 0; q < rule.size(); ++q) {
      const auto phi = V::values(rule.points[q]);
      for (int a = 0; a < V::n_dofs; ++a) diag[a] += rule.weights[q] * phi[a] * phi[a];
    }
    Real sum = 0;
    for (Real d : diag) sum += d;
    VecX scalar = VecX::Zero(space.velocity().n_dofs());
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      const auto& dofs = space.velocity().cell_dofs(c);
      for (int a = 0; a < V::n_dofs; ++a) scalar[dofs[a]] += mesh.measure(c) * diag[a] / sum;
    }
    blk.velocity_mass.resize(nu);
    for (Index f = 0; f < nvf; ++f)
      if (cons.kind(f) == DofConstraints::Kind::free) blk.velocity_mass[cons.indices(f)[0]] = scalar[f / D];
  }
  return blk;
}

}  // namespace alefsi
