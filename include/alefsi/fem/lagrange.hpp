#pragma once
/// \file fem/lagrange.hpp
/// Lagrange P1 and P2 shape functions on the reference triangle and tetrahedron.
///
/// Local DOF order: the D+1 vertices (reference vertex 0 at the origin, vertex i at e_i),
/// then, for P2, one DOF per edge in the local edge order of `SimplexTopology<D>`
/// (VTK's quadratic-cell order). With barycentric coordinates l_0 = 1 - sum x_i, l_i = x_i:
///   P1: phi_i = l_i;   P2: phi_i = l_i (2 l_i - 1) at vertices, phi_(a,b) = 4 l_a l_b at edges.
///
///     using P2 = alefsi::Lagrange<2, 2>;
///     auto phi = P2::values(Vec<2>(0.2, 0.3));     // 6 values, sum 1
///     auto dphi = P2::gradients(Vec<2>(0.2, 0.3)); // 6 x 2 reference gradients
#include <array>

#include "alefsi/core/types.hpp"
#include "alefsi/mesh/simplex.hpp"

namespace alefsi {

/// Where a DOF sits: on a vertex or an edge of the cell (local index of that entity).
struct DofEntity {
  enum Kind { vertex, edge } kind;
  int local;
};

template <int D, int K>
struct Lagrange {
  static_assert(D == 2 || D == 3, "Lagrange elements are provided on triangles and tetrahedra");
  static_assert(K == 1 || K == 2, "Lagrange elements are provided for degrees 1 and 2");
  static constexpr int dim = D;
  static constexpr int degree = K;
  static constexpr int n_vertex_dofs = D + 1;
  static constexpr int n_edge_dofs = K == 2 ? simplex_edges<D> : 0;
  static constexpr int n_dofs = n_vertex_dofs + n_edge_dofs;
  using Values = Eigen::Matrix<Real, n_dofs, 1>;
  using Gradients = Eigen::Matrix<Real, n_dofs, D>;

  static constexpr DofEntity entity(int i) {
    return i < n_vertex_dofs ? DofEntity{DofEntity::vertex, i} : DofEntity{DofEntity::edge, i - n_vertex_dofs};
  }

  /// Interpolation node of local DOF i on the reference simplex.
  static Vec<D> node(int i) {
    if (i < n_vertex_dofs) return reference_vertex<D>(i);
    const auto& e = SimplexTopology<D>::edges[i - n_vertex_dofs];
    return 0.5 * (reference_vertex<D>(e[0]) + reference_vertex<D>(e[1]));
  }

  static Values values(const Vec<D>& x) {
    const auto l = barycentric(x);
    Values v;
    if constexpr (K == 1) {
      for (int i = 0; i <= D; ++i) v[i] = l[i];
    } else {
      for (int i = 0; i <= D; ++i) v[i] = l[i] * (2 * l[i] - 1);
      for (int e = 0; e < n_edge_dofs; ++e) {
        const auto& ab = SimplexTopology<D>::edges[e];
        v[n_vertex_dofs + e] = 4 * l[ab[0]] * l[ab[1]];
      }
    }
    return v;
  }

  /// Reference gradients, row i = grad phi_i.
  static Gradients gradients(const Vec<D>& x) {
    const auto l = barycentric(x);
    Gradients g;
    for (int i = 0; i <= D; ++i) {
      const Vec<D> dl = grad_l(i);
      if constexpr (K == 1) g.row(i) = dl.transpose();
      else g.row(i) = ((4 * l[i] - 1) * dl).transpose();
    }
    if constexpr (K == 2) {
      for (int e = 0; e < n_edge_dofs; ++e) {
        const auto& ab = SimplexTopology<D>::edges[e];
        g.row(n_vertex_dofs + e) = (4 * (l[ab[0]] * grad_l(ab[1]) + l[ab[1]] * grad_l(ab[0]))).transpose();
      }
    }
    return g;
  }

  /// Second derivatives are constant on a cell for P2 and zero for P1: hessian(i) of phi_i.
  static Mat<D> hessian(int i) {
    if constexpr (K == 1) {
      (void)i;
      return Mat<D>::Zero();
    } else {
      if (i < n_vertex_dofs) return 4 * grad_l(i) * grad_l(i).transpose();
      const auto& ab = SimplexTopology<D>::edges[i - n_vertex_dofs];
      const Vec<D> ga = grad_l(ab[0]), gb = grad_l(ab[1]);
      return 4 * (ga * gb.transpose() + gb * ga.transpose());
    }
  }

 private:
  static std::array<Real, D + 1> barycentric(const Vec<D>& x) {
    std::array<Real, D + 1> l;
    l[0] = 1 - x.sum();
    for (int i = 0; i < D; ++i) l[i + 1] = x[i];
    return l;
  }
  static Vec<D> grad_l(int i) { return i == 0 ? Vec<D>(-Vec<D>::Ones()) : Vec<D>(reference_vertex<D>(i)); }
};

template <int D>
using P1 = Lagrange<D, 1>;
template <int D>
using P2 = Lagrange<D, 2>;

}  // namespace alefsi
