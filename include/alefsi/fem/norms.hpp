#pragma once
/// \file fem/norms.hpp
/// Errors of a discrete velocity/pressure field against exact functions, and the net flux of a
/// discrete velocity (`divergence_integral`).
///
/// L2 and H1-seminorm errors of the velocity and the L2 error of the pressure *modulo
/// constants* (the mean of p_h - p is removed first, so the error does not depend on how the
/// pressure constant was fixed). Integrals use a rule exact to degree 2k + 4 (k the velocity
/// degree), well above the discretisation error. With a `QuadraticGeometry` the curved cells
/// are integrated through their quadratic map (the discrete field lives on the curved cells:
/// integrating it over the straight ones would add an O(h^2) error of its own).
///
///     auto e = alefsi::flow_errors(space, field, u_exact, grad_u_exact, p_exact);
///     // e.u_l2, e.u_h1, e.p_l2
#include <cmath>
#include <functional>

#include "alefsi/fem/dofmap.hpp"
#include "alefsi/fem/geometry.hpp"
#include "alefsi/fem/quadrature.hpp"

namespace alefsi {

struct FlowErrors {
  Real u_l2 = 0, u_h1 = 0, p_l2 = 0;
};

namespace detail {
/// Calls f(q, x, Jinv, detJ) at each point q of `rule` in cell c: the physical point, the
/// inverse Jacobian and |det J|, of the affine map (J^-1 and det J once for the cell) or, on a
/// curved cell of `geometry`, of its quadratic map at that point.
template <int D, class F>
void for_each_point(const Mesh<D>& mesh, const QuadraticGeometry<D>* geometry, const QuadratureRule<D>& rule,
                    Index c, F&& f) {
  using Geometry = QuadraticGeometry<D>;
  const bool curved = geometry && geometry->curved(c);
  const auto X = curved ? geometry->cell_nodes(c) : typename Geometry::Nodes{};
  Mat<D> J = mesh.jacobian(c), Jinv = J.inverse();
  Real detJ = std::abs(J.determinant());
  const Vec<D> x0 = mesh.node(mesh.cell(c)[0]);
  for (int q = 0; q < rule.size(); ++q) {
    Vec<D> x = x0 + J * rule.points[q];
    if (curved) {
      J = Geometry::jacobian(X, Geometry::Shape::gradients(rule.points[q]));
      Jinv = J.inverse();
      detJ = std::abs(J.determinant());
      x = Geometry::map(X, Geometry::Shape::values(rule.points[q]));
    }
    f(q, static_cast<const Vec<D>&>(x), static_cast<const Mat<D>&>(Jinv), detJ);
  }
}
}  // namespace detail

template <int D, ElementPair Pair>
FlowErrors flow_errors(const MixedSpace<D, Pair>& space, const VecX& field,
                       const std::function<Vec<D>(const Vec<D>&)>& u,
                       const std::function<Mat<D>(const Vec<D>&)>& grad_u,  // (i, j) = d u_i / d x_j
                       const std::function<Real(const Vec<D>&)>& p,
                       const QuadraticGeometry<D>* geometry = nullptr) {
  using V = typename Pair::template Velocity<D>;
  using P = typename Pair::template Pressure<D>;
  const auto& mesh = space.mesh();
  const auto& rule = simplex_quadrature<D>(2 * V::degree + 4);
  Real eu = 0, eg = 0, ep = 0, ep_mean = 0, vol = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      const auto& vd = space.velocity().cell_dofs(c);
      const auto& pd = space.pressure().cell_dofs(c);
      detail::for_each_point(mesh, geometry, rule, c, [&](int q, const Vec<D>& x, const Mat<D>& Jinv, Real detJ) {
        const Real w = rule.weights[q] * detJ;
        const auto php = P::values(rule.points[q]);
        Real ph = 0;
        for (int b = 0; b < P::n_dofs; ++b) ph += php[b] * field[space.pressure_field(pd[b])];
        const Real dp = ph - p(x);
        if (pass == 0) {
          const auto phv = V::values(rule.points[q]);
          const Eigen::Matrix<Real, V::n_dofs, D> G = V::gradients(rule.points[q]) * Jinv;
          Vec<D> uh = Vec<D>::Zero();
          Mat<D> gh = Mat<D>::Zero();
          for (int a = 0; a < V::n_dofs; ++a)
            for (int i = 0; i < D; ++i) {
              const Real ua = field[space.velocity_field(vd[a], i)];
              uh[i] += phv[a] * ua;
              gh.row(i) += ua * G.row(a);
            }
          eu += w * (uh - u(x)).squaredNorm();
          eg += w * (gh - grad_u(x)).squaredNorm();
          ep_mean += w * dp;
          vol += w;
        } else {
          ep += w * std::pow(dp - ep_mean / vol, 2);
        }
      });
    }
  }
  return {std::sqrt(eu), std::sqrt(eg), std::sqrt(ep)};
}

/// The integral of div u_h over the domain, through the curved cells' quadratic map if
/// `geometry` is given: the net flux of u_h out of the domain, which the discrete continuity
/// equations (their sum: the test function 1) set to zero in a closed domain unless one of
/// them is left out (a pinned pressure DOF then takes it up as a point source). The rule is of
/// degree 2k + 2, exact for det J div u_h on a curved cell (degree 3 in 3D).
template <int D, ElementPair Pair>
Real divergence_integral(const MixedSpace<D, Pair>& space, const VecX& field,
                         const QuadraticGeometry<D>* geometry = nullptr) {
  using V = typename Pair::template Velocity<D>;
  const auto& mesh = space.mesh();
  const auto& rule = simplex_quadrature<D>(2 * V::degree + 2);
  Real total = 0;
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    const auto& vd = space.velocity().cell_dofs(c);
    detail::for_each_point(mesh, geometry, rule, c, [&](int q, const Vec<D>&, const Mat<D>& Jinv, Real detJ) {
      const Eigen::Matrix<Real, V::n_dofs, D> G = V::gradients(rule.points[q]) * Jinv;
      Real div = 0;
      for (int a = 0; a < V::n_dofs; ++a)
        for (int i = 0; i < D; ++i) div += field[space.velocity_field(vd[a], i)] * G(a, i);
      total += rule.weights[q] * detJ * div;
    });
  }
  return total;
}

/// Observed convergence rate from two (DOF count, error) pairs: log(e1/e2) / ((1/D) log(N2/N1)).
inline Real observed_rate(Real n1, Real e1, Real n2, Real e2, int dim) {
  return std::log(e1 / e2) / (std::log(n2 / n1) / dim);
}

}  // namespace alefsi
