#pragma once
/// \file fem/geometry.hpp
/// Quadratic (isoparametric P2) cell geometry: cells whose edges may be curved.
///
/// A simplex mesh stores straight cells: the map from the reference simplex is affine. On a
/// curved boundary (a cylinder, a sphere) that replaces the domain by a polygon / polyhedron,
/// an O(h^2) geometric error that caps Taylor–Hood at L2 rate 2 and H1 rate 1.5. A
/// `QuadraticGeometry` gives each mesh edge a point — its midpoint, or a point on the exact
/// curve — and maps cell c by the P2 interpolant of its D + 1 vertices and its edge points:
///   x(xi) = sum_k N_k(xi) X_k,   J(xi) = dx/dxi = sum_k X_k grad N_k(xi)^T,
/// N_k the P2 shape functions, X_k the vertices then the edge points in the local edge order
/// of simplex.hpp. Cells with no displaced edge point stay affine (`curved(c)` false: kernels
/// keep their fast affine path there); on a curved cell J varies and integrals are taken by
/// quadrature with weights |det J(xi)|. With P2 velocities the edge DOF sits at the edge point
/// (`dof_point`): the element is isoparametric.
///
///     alefsi::QuadraticGeometry<2> g(mesh);
///     alefsi::project_boundary_edges(g, tags::inner, alefsi::onto_sphere<2>(centre, radius));
///     stokes.set_geometry(g);          // the kernel integrates curved cells by quadrature
///
/// A cell's map must stay invertible: `project_boundary_edges` checks det J > 0 at the points
/// of a degree-4 rule on every cell it curves and throws MeshError naming the cell otherwise
/// (an edge point too far from the chord for the cell's size). The geometry refers to the mesh:
/// the mesh must outlive it.
#include <array>
#include <cmath>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/fem/lagrange.hpp"
#include "alefsi/fem/quadrature.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

template <int D>
class QuadraticGeometry {
 public:
  using Shape = Lagrange<D, 2>;
  static constexpr int n_nodes = Shape::n_dofs;  ///< geometry nodes per cell: vertices, then edges
  using Nodes = std::array<Vec<D>, n_nodes>;

  /// Straight edges: every edge point at its midpoint (the affine geometry).
  explicit QuadraticGeometry(const Mesh<D>& mesh) : mesh_(&mesh) {
    points_.resize(std::size_t(mesh.n_edges()));
    for (Index e = 0; e < mesh.n_edges(); ++e) points_[std::size_t(e)] = midpoint(e);
    curved_.assign(std::size_t(mesh.n_cells()), 0);
    // the cells around each edge, compressed: cells of e at edge_cells_[start_[e] .. start_[e + 1])
    start_.assign(std::size_t(mesh.n_edges()) + 1, 0);
    for (Index c = 0; c < mesh.n_cells(); ++c)
      for (Index e : mesh.cell_edges(c)) ++start_[std::size_t(e) + 1];
    for (std::size_t e = 0; e < std::size_t(mesh.n_edges()); ++e) start_[e + 1] += start_[e];
    edge_cells_.resize(std::size_t(start_.back()));
    std::vector<Index> fill(start_.begin(), start_.end() - 1);
    for (Index c = 0; c < mesh.n_cells(); ++c)
      for (Index e : mesh.cell_edges(c)) edge_cells_[std::size_t(fill[std::size_t(e)]++)] = c;
  }

  /// Edge points given for every edge (e.g. gmsh's second-order mid nodes,
  /// `GmshMesh::edge_midpoints`, or `curved_edge_midpoints`): cells with an edge point off its
  /// midpoint by more than 1e-12 of the edge length are curved. Checks every curved cell.
  QuadraticGeometry(const Mesh<D>& mesh, const std::vector<Vec<D>>& edge_points) : QuadraticGeometry(mesh) {
    ALEFSI_CHECK_ARG(Index(edge_points.size()) == mesh.n_edges(), "edge_points", "has ", edge_points.size(),
                     " entries, the mesh has ", mesh.n_edges(), " edges");
    for (Index e = 0; e < mesh.n_edges(); ++e)
      if ((edge_points[std::size_t(e)] - midpoint(e)).norm() > 1e-12 * mesh.edge_length(e))
        set_edge_point(e, edge_points[std::size_t(e)]);
    check_all();
  }

  const Mesh<D>& mesh() const { return *mesh_; }
  /// The point of edge e (its midpoint unless curved).
  const Vec<D>& edge_point(Index e) const { return points_[std::size_t(e)]; }
  const std::vector<Vec<D>>& edge_points() const { return points_; }
  /// True when cell c has a displaced edge point (its map is not affine).
  bool curved(Index c) const { return curved_[std::size_t(c)] != 0; }
  /// Number of curved cells.
  Index n_curved() const {
    Index n = 0;
    for (char k : curved_) n += k;
    return n;
  }

  /// Moves the point of edge e to x and marks the cells around it curved. Call `check(c)` (or
  /// `check_all`) after the last move.
  void set_edge_point(Index e, const Vec<D>& x) {
    ALEFSI_CHECK_ARG(e >= 0 && e < mesh_->n_edges(), "e", "edge ", e, " out of range [0, ", mesh_->n_edges(), ")");
    points_[std::size_t(e)] = x;
    for (Index k = start_[std::size_t(e)]; k < start_[std::size_t(e) + 1]; ++k) curved_[std::size_t(edge_cells_[std::size_t(k)])] = 1;
  }

  /// The geometry nodes of cell c: its vertices, then its edge points (local edge order).
  Nodes cell_nodes(Index c) const {
    Nodes X;
    const auto& v = mesh_->cell(c);
    for (int i = 0; i <= D; ++i) X[i] = mesh_->node(v[i]);
    const auto& e = mesh_->cell_edges(c);
    for (int k = 0; k < Shape::n_edge_dofs; ++k) X[D + 1 + k] = points_[std::size_t(e[k])];
    return X;
  }

  /// Where scalar DOF i of a P1 or P2 Lagrange DOF map sits (node DOFs first, then one per
  /// edge): a node, or the edge point.
  Vec<D> dof_point(Index i) const {
    if (i < mesh_->n_nodes()) return mesh_->node(i);
    return points_[std::size_t(i - mesh_->n_nodes())];
  }

  /// x(xi) on cell nodes X.
  static Vec<D> map(const Nodes& X, const typename Shape::Values& N) {
    Vec<D> x = Vec<D>::Zero();
    for (int k = 0; k < n_nodes; ++k) x += N[k] * X[k];
    return x;
  }
  /// J(xi) = dx/dxi on cell nodes X, from the reference shape gradients at xi.
  static Mat<D> jacobian(const Nodes& X, const typename Shape::Gradients& G) {
    Mat<D> J = Mat<D>::Zero();
    for (int k = 0; k < n_nodes; ++k) J.noalias() += X[k] * G.row(k);
    return J;
  }

  /// Smallest det J(xi) / det J_affine over the points of a degree-4 rule on cell c (1 on a
  /// straight cell; the map folds when it reaches 0).
  Real jacobian_ratio(Index c) const {
    const Real det0 = mesh_->jacobian(c).determinant();
    if (!curved(c)) return 1;
    const auto X = cell_nodes(c);
    const auto& rule = simplex_quadrature<D>(4);
    Real worst = 1e300;
    for (int q = 0; q < rule.size(); ++q)
      worst = std::min(worst, jacobian(X, Shape::gradients(rule.points[q])).determinant() / det0);
    for (int i = 0; i < n_nodes; ++i)  // and at the nodes, where folding shows first
      worst = std::min(worst, jacobian(X, Shape::gradients(Shape::node(i))).determinant() / det0);
    return worst;
  }
  /// Throws MeshError naming cell c when its map is not invertible (ratio <= 0.1 counts as
  /// folded: quadrature on a nearly singular map is meaningless).
  void check(Index c) const {
    const Real r = jacobian_ratio(c);
    if (!(r > 0.1))
      throw MeshError(MeshError::Entity::cell, c, "curved cell's map is nearly singular: min det J / det J_affine = " + detail::sci(r) +
                                     " (an edge point too far from its chord for the cell's size)");
  }
  void check_all() const {
    for (Index c = 0; c < mesh_->n_cells(); ++c)
      if (curved(c)) check(c);
  }

 private:
  Vec<D> midpoint(Index e) const { return 0.5 * (mesh_->node(mesh_->edge(e)[0]) + mesh_->node(mesh_->edge(e)[1])); }

  const Mesh<D>* mesh_;
  std::vector<Vec<D>> points_;
  std::vector<char> curved_;
  std::vector<Index> start_, edge_cells_;
};

/// Places the point of every edge lying on a boundary facet with tag `tag` at onto(midpoint)
/// (a projection onto the exact curve or surface), then checks the cells it curved.
/// Returns the number of edges moved. Throws InvalidArgument when no facet has the tag.
template <int D, class Projector>
Index project_boundary_edges(QuadraticGeometry<D>& g, int tag, Projector&& onto) {
  const auto& mesh = g.mesh();
  const std::vector<Index> edges = mesh.boundary_edges(tag);
  ALEFSI_CHECK_ARG(!edges.empty(), "tag", "no boundary facet has tag ", tag);
  for (Index e : edges) {
    const Vec<D> m = 0.5 * (mesh.node(mesh.edge(e)[0]) + mesh.node(mesh.edge(e)[1]));
    g.set_edge_point(e, onto(m));
  }
  g.check_all();
  return Index(edges.size());
}

/// The radial projection onto the circle (D = 2) or sphere (D = 3) of the given centre and
/// radius: x -> centre + radius (x - centre) / |x - centre|.
template <int D>
auto onto_sphere(const Vec<D>& centre, Real radius) {
  ALEFSI_CHECK_ARG(radius > 0 && std::isfinite(radius), "radius", "must be positive and finite, got ", radius);
  return [centre, radius](const Vec<D>& x) -> Vec<D> {
    const Vec<D> d = x - centre;
    const Real n = d.norm();
    ALEFSI_CHECK_ARG(n > 0, "x", "the projection onto a sphere is undefined at its centre");
    return centre + (radius / n) * d;
  };
}

}  // namespace alefsi
