#pragma once
/// \file physics/stokes.hpp
/// Steady Stokes flow with Taylor–Hood (P2/P1) or P1/P1 + PSPG/GLS elements.
///
/// Weak form (mu: dynamic viscosity [Pa s], f: body force per unit volume [N/m^3]):
///   find (u, p):  2 mu (D(u), D(v)) - (p, div v) - (q, div u) + S_h((u, p), (v, q)) = (f, v) + L_h(q)
/// for all (v, q), where S_h and L_h are the terms of the pair's stabilisation policy
/// (`StokesStabilisation<D, Pair>`, physics/stabilisation.hpp): none for TaylorHood; for
/// P1P1Gls the PSPG terms -sum_K tau_K (grad p - mu lap u - f, grad q)_K (lap u_h = 0 on each
/// cell) with tau_K = h_K^2 / (c1 mu), c1 = 4, h_K = the longest edge of K (`gls_tau`, steady:
/// Codina 2001 with the convective and transient parts absent). The pressure block is then -C,
/// C SPD, and the system is symmetric.
///
/// The residual form r(u) = A u - F is assembled at the current field (Dirichlet values
/// included through `DofConstraints` offsets); one Newton step from any state solves the
/// linear problem. When every boundary facet carries a Dirichlet condition the pressure is
/// defined up to a constant: pressure DOF 0 is pinned to 0 during the solve (a solver that takes
/// the constant as its null space, SolvesPressureNullSpace, gets the system unpinned) and the
/// computed pressure is then shifted to zero mean over the domain.
///
///     alefsi::Stokes<2, alefsi::TaylorHood> stokes(mesh, /*mu=*/1.0, f);
///     for (int t : {1, 2, 3, 4}) stokes.set_velocity(t, u_exact);
///     VecX field = stokes.solve();          // layout: see MixedSpace
#include <cmath>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/fem/geometry.hpp"
#include "alefsi/fem/quadrature.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/saddle_point_blocks.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/physics/affine_forms.hpp"
#include "alefsi/physics/stabilisation.hpp"

namespace alefsi {

template <int D>
using VectorFunction = std::function<Vec<D>(const Vec<D>&)>;

/// The Stokes element kernel (affine cells): A from precomputed reference integrals
/// (`AffineStokesForms`: viscous and divergence blocks), no quadrature loop; the body-force
/// load (if any) by quadrature of degree 2k + 2; the stabilisation's block of A and its part
/// of F from the pair's policy `Stabilisation` (PSPG for P1/P1-GLS). r = A u - F. Equal to
/// the quadrature oracle (tests/support/oracle_kernels.hpp) to round-off.
/// With a `QuadraticGeometry` (P2 velocity pairs), curved cells are integrated by the same
/// rule of degree 2k + 2 through the isoparametric map (`curved_cell`), straight ones as above.
/// `cell` is const and touches only its arguments: safe to call from several threads (the
/// force function must then be too).
template <int D, ElementPair Pair>
class StokesKernel {
 public:
  using Space = MixedSpace<D, Pair>;
  using V = typename Space::VelocityElement;
  using P = typename Space::PressureElement;
  using Forms = AffineStokesForms<D, Pair>;
  using Stabilisation = StokesStabilisation<D, Pair>;
  static constexpr int nv = V::n_dofs, np = P::n_dofs, n_local = Space::n_local;
  using LocalVec = Eigen::Matrix<Real, n_local, 1>;
  using LocalMat = Eigen::Matrix<Real, n_local, n_local>;

  /// `force` may be empty (no body force). c1: the constant of tau (`gls_tau`).
  StokesKernel(const Space& space, Real mu, VectorFunction<D> force = {}, Real c1 = 4.0)
      : space_(&space), mu_(mu), f_(std::move(force)), forms_(&Forms::get()), stab_(mu, c1),
        tab_(2 * V::degree + 2) {
    ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "viscosity must be positive and finite, got ", mu);
    ALEFSI_CHECK_ARG(c1 > 0, "c1", "GLS constant must be positive");
  }

  /// Stabilisation parameter tau_K of cell c (0 for stable pairs).
  Real tau(Index c) const { return stab_.tau(space_->mesh(), c); }

  /// Integrates the curved cells of `g` through their quadratic map (null: every cell affine).
  /// The geometry must be on this kernel's mesh and outlive the kernel.
  void set_geometry(const QuadraticGeometry<D>* g)
    requires(V::degree == 2)
  {
    ALEFSI_CHECK_ARG(!g || &g->mesh() == &space_->mesh(), "geometry", "is on another mesh than the space's");
    geom_ = g;
    if (g && geo_dN_.empty())
      for (int q = 0; q < tab_.rule->size(); ++q) {
        geo_N_.push_back(QuadraticGeometry<D>::Shape::values(tab_.rule->points[q]));
        geo_dN_.push_back(QuadraticGeometry<D>::Shape::gradients(tab_.rule->points[q]));
      }
  }
  const QuadraticGeometry<D>* geometry() const { return geom_; }

  void cell(Index c, const LocalVec& u, LocalMat& A, LocalVec& r) const {
    if (geom_ && geom_->curved(c)) return curved_cell(c, u, A, r);
    const Mat<D> J = space_->mesh().jacobian(c);
    const Mat<D> Jinv = J.inverse();
    const Real detJ = J.determinant();
    A.setZero();
    forms_->add_viscous(Jinv, detJ, mu_, A);
    forms_->add_divergence(Jinv, detJ, -1.0, -1.0, A);
    const Real tau_c = tau(c);
    stab_.add_matrix(*forms_, Jinv, detJ, tau_c, A);
    r.noalias() = A * u;
    if (f_) r -= load(c, J, Jinv, detJ, tau_c);
  }

  /// The load vector F of cell c (body force, and the stabilisation's part with tau_c).
  LocalVec load(Index c, const Mat<D>& J, const Mat<D>& Jinv, Real detJ, Real tau_c) const {
    LocalVec F = LocalVec::Zero();
    const auto& mesh = space_->mesh();
    const Vec<D> x0 = mesh.node(mesh.cell(c)[0]);
    const auto& rule = *tab_.rule;
    for (int q = 0; q < rule.size(); ++q) {
      const Real w = rule.weights[q] * detJ;
      const Vec<D> fq = f_(x0 + J * rule.points[q]);
      const auto& phv = tab_.phi_v[q];
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < D; ++i) F[D * a + i] += w * fq[i] * phv[a];
      stab_.add_load(tab_, q, Jinv, w, tau_c, fq, F);
    }
    return F;
  }

  /// Cell c through the isoparametric map x(xi) = sum_k N_k(xi) X_k: at each point of the
  /// rule, J(xi), physical gradients dphi J^-1 and weights w det J(xi);
  ///   A(D a + i, D b + j) += w mu (g_a . g_b delta_ij + g_a,j g_b,i)   (2 mu (D(u), D(v)))
  ///   A(D a + i, D nv + b) = A(D nv + b, D a + i) -= w psi_b g_a,i    (-(p, div v) - (q, div u))
  /// and the load w f(x(xi)) phi_a. Equal to the affine path when the edge points are the
  /// midpoints (tested).
  void curved_cell(Index c, const LocalVec& u, LocalMat& A, LocalVec& r) const {
    using Geometry = QuadraticGeometry<D>;
    const auto X = geom_->cell_nodes(c);
    const auto& rule = *tab_.rule;
    A.setZero();
    LocalVec F = LocalVec::Zero();
    for (int q = 0; q < rule.size(); ++q) {
      const Mat<D> J = Geometry::jacobian(X, geo_dN_[std::size_t(q)]);
      const Real w = rule.weights[q] * J.determinant();
      const Eigen::Matrix<Real, nv, D> g = tab_.dphi_v[q] * J.inverse();
      const Eigen::Matrix<Real, nv, nv> gg = (w * mu_) * (g * g.transpose());
      for (int a = 0; a < nv; ++a)
        for (int b = 0; b < nv; ++b)
          for (int i = 0; i < D; ++i) {
            A(D * a + i, D * b + i) += gg(a, b);
            for (int j = 0; j < D; ++j) A(D * a + i, D * b + j) += w * mu_ * g(a, j) * g(b, i);
          }
      const auto& psi = tab_.phi_p[q];
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < D; ++i)
          for (int b = 0; b < np; ++b) {
            const Real v = w * psi[b] * g(a, i);
            A(D * a + i, D * nv + b) -= v;
            A(D * nv + b, D * a + i) -= v;
          }
      if (f_) {
        const Vec<D> fq = f_(Geometry::map(X, geo_N_[std::size_t(q)]));
        const auto& phv = tab_.phi_v[q];
        for (int a = 0; a < nv; ++a)
          for (int i = 0; i < D; ++i) F[D * a + i] += w * fq[i] * phv[a];
      }
    }
    r.noalias() = A * u;
    if (f_) r -= F;
  }

 private:
  const Space* space_;
  Real mu_;
  VectorFunction<D> f_;
  const Forms* forms_;
  [[no_unique_address]] Stabilisation stab_;  // empty without stabilisation
  ReferenceTables<D, Pair> tab_;
  const QuadraticGeometry<D>* geom_ = nullptr;
  std::vector<typename QuadraticGeometry<D>::Shape::Values> geo_N_;        // geometry shape values at tab_'s points
  std::vector<typename QuadraticGeometry<D>::Shape::Gradients> geo_dN_;   // ... and their reference gradients
};

/// Adds a constant to the pressure part of `field` so that the pressure has zero mean over
/// the domain (the pressure of a flow with every boundary velocity prescribed); over the
/// curved cells of `geometry` if given.
template <int D, ElementPair Pair>
void shift_pressure_to_zero_mean(const MixedSpace<D, Pair>& space, VecX& field,
                                 const QuadraticGeometry<D>* geometry = nullptr) {
  using P = typename Pair::template Pressure<D>;
  using Geometry = QuadraticGeometry<D>;
  const auto& mesh = space.mesh();
  const auto& rule = simplex_quadrature<D>(geometry ? P::degree + 2 : P::degree);
  Real integral = 0, volume = 0;
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    const bool curved = geometry && geometry->curved(c);
    const Real m = mesh.measure(c) / reference_measure<D>;
    const auto X = curved ? geometry->cell_nodes(c) : typename Geometry::Nodes{};
    const auto& dofs = space.pressure().cell_dofs(c);
    for (int q = 0; q < rule.size(); ++q) {
      const auto phi = P::values(rule.points[q]);
      Real p = 0;
      for (int b = 0; b < P::n_dofs; ++b) p += phi[b] * field[space.pressure_field(dofs[b])];
      const Real w =
          rule.weights[q] *
          (curved ? Geometry::jacobian(X, Geometry::Shape::gradients(rule.points[q])).determinant() : m);
      integral += w * p;
      volume += w;
    }
  }
  const Real mean = integral / volume;
  for (Index k = 0; k < space.pressure().n_dofs(); ++k) field[space.pressure_field(k)] -= mean;
}

/// Fixes every velocity component on the boundary facets of each tag in `tags` (a map or set
/// keyed by tag), to 0: set the values with `DofConstraints::set_fixed_value`. DOFs already
/// marked in `taken` (size n_u) are skipped and the fixed ones are marked. Returns the
/// (scalar velocity DOF, tag) pairs, the first tag winning where tags meet.
template <int D, ElementPair Pair, class Tags>
std::vector<std::pair<Index, int>> fix_velocity_on_tags(const MixedSpace<D, Pair>& space, const Tags& tags,
                                                        DofConstraints& cons, std::vector<char>& taken) {
  std::vector<std::pair<Index, int>> fixed;
  for (const auto& entry : tags) {
    const int tag = entry.first;
    for (Index i : space.velocity().boundary_dofs(tag)) {
      if (taken[i]) continue;
      taken[i] = 1;
      fixed.emplace_back(i, tag);
      for (int k = 0; k < D; ++k) cons.fix(space.velocity_field(i, k), 0.0);
    }
  }
  return fixed;
}

/// True when every boundary facet's tag satisfies `prescribed(tag)`: the velocity is then given
/// on the whole boundary and the pressure is defined up to a constant only.
template <int D, class Pred>
bool whole_boundary_prescribed(const Mesh<D>& mesh, Pred&& prescribed) {
  for (Index f : mesh.boundary_facets())
    if (!prescribed(mesh.facet_tag(f))) return false;
  return true;
}

/// A steady Stokes problem on a fixed mesh: Dirichlet conditions by boundary tag, then solve.
template <int D, ElementPair Pair>
class Stokes {
 public:
  using Space = MixedSpace<D, Pair>;
  using Kernel = StokesKernel<D, Pair>;

  Stokes(const Mesh<D>& mesh, Real mu, VectorFunction<D> force = {})
      : space_(mesh), kernel_(space_, mu, std::move(force)) {}

  /// Isoparametric P2 (Taylor–Hood): the curved cells of `g` are integrated through their
  /// quadratic map and the boundary values are taken at the edge points. `g` must be on this
  /// problem's mesh and outlive it.
  void set_geometry(const QuadraticGeometry<D>& g)
    requires(Space::VelocityElement::degree == 2)
  {
    kernel_.set_geometry(&g);
    space_.set_geometry(&g);
  }

  /// Prescribes the velocity on the boundary facets with tag `tag`.
  void set_velocity(int tag, VectorFunction<D> g) {
    ALEFSI_CHECK_ARG(g != nullptr, "g", "boundary velocity function is empty");
    ALEFSI_CHECK_ARG(!space_.velocity().boundary_dofs(tag).empty(), "tag", "no boundary facet has tag ", tag);
    dirichlet_[tag] = std::move(g);
  }

  const Space& space() const { return space_; }
  const Kernel& kernel() const { return kernel_; }
  /// True when every boundary velocity is prescribed, so that the pressure is defined up to a
  /// constant: pressure DOF 0 was pinned (or, for a SolvesPressureNullSpace solver, the
  /// constant was its null space) and the pressure shifted to zero mean.
  bool pressure_pinned() const { return pinned_; }

  /// Assembles and solves; returns the field vector (velocity interleaved, then pressure).
  template <LinearSolver Solver = SparseLu<>>
  VecX solve(Solver solver = Solver{}) {
    DofConstraints cons(space_.n_field());
    const auto& vel = space_.velocity();
    std::vector<char> taken(vel.n_dofs(), 0);
    for (const auto& [i, tag] : fix_velocity_on_tags(space_, dirichlet_, cons, taken)) {
      const Vec<D> val = dirichlet_.at(tag)(vel.point(i));
      for (int k = 0; k < D; ++k) cons.set_fixed_value(space_.velocity_field(i, k), val[k]);
    }
    pinned_ = whole_boundary_prescribed(space_.mesh(), [&](int tag) { return dirichlet_.count(tag) > 0; });
    constrain_pressure_constant(solver, pinned_, cons, space_.pressure_field(0));
    cons.finalize();
    Assembler<Space::n_local> asmb(space_.mesh().n_cells(), [&](Index c) { return space_.cell_field_dofs(c); }, cons);
    VecX field = cons.expand(VecX::Zero(cons.n_unknowns()));
    SparseMatrix J;
    VecX r;
    asmb.assemble(kernel_, field, &J, &r);
    solver.analyze(J);
    solver.factorize(J);
    const VecX du = solver.solve(-r);
    field = cons.expand(du);
    if (pinned_) shift_pressure_to_zero_mean(field);
    return field;
  }

  /// Adds a constant to the pressure so that its mean over the domain is zero.
  void shift_pressure_to_zero_mean(VecX& field) const {
    alefsi::shift_pressure_to_zero_mean(space_, field, space_.geometry());
  }
  /// The geometry set by `set_geometry` (null: affine cells).
  const QuadraticGeometry<D>* geometry() const { return space_.geometry(); }

 private:
  Space space_;
  Kernel kernel_;
  std::map<int, VectorFunction<D>> dirichlet_;
  bool pinned_ = false;
};

}  // namespace alefsi
