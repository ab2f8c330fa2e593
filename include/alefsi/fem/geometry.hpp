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
///
/// Moving meshes: a curved edge's point is stored in a frame of mesh nodes and computed from the
/// mesh's current nodes whenever it is asked for (so it follows `Mesh::set_coordinates` with
/// nothing to update; `edge_point(e, X)` at other positions), and its velocity follows from
/// theirs (`edge_velocities`). With d = X_b - X_a and m = (X_a + X_b) / 2,
///   2D:  P = m + alpha d + beta d^perp                    (linear in X)
///   3D:  P = m + alpha d + beta f + gamma (d x f) / |d|,   f = X_c - m,
/// X_c the third vertex of a boundary facet through the edge (of any cell through it when the
/// edge is on no boundary facet). The coefficients are fixed when the point is set. Both rules
/// commute with rotations, translations and scaling, so a point whose frame nodes move rigidly
/// (a body's surface) moves rigidly with them, and its velocity is the rigid velocity there.
#include <algorithm>
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
    if constexpr (D == 3) {  // each edge's third frame vertex: from a boundary facet if it has one
      partner_.assign(std::size_t(mesh.n_edges()), -1);
      for (Index f : mesh.boundary_facets()) {
        const auto& fv = mesh.facet(f);
        const Index c = mesh.facet_cells(f)[0];
        for (int le = 0; le < Shape::n_edge_dofs; ++le) {
          const Index e = mesh.cell_edges(c)[le];
          const auto& ev = mesh.edge(e);
          int on = 0;
          Index other = -1;
          for (Index v : fv) {
            if (v == ev[0] || v == ev[1]) ++on;
            else other = v;
          }
          if (on == 2 && partner_[std::size_t(e)] < 0) partner_[std::size_t(e)] = other;
        }
      }
      for (Index e = 0; e < mesh.n_edges(); ++e) {
        if (partner_[std::size_t(e)] >= 0) continue;
        for (Index v : mesh.cell(edge_cells_[std::size_t(start_[std::size_t(e)])]))
          if (v != mesh.edge(e)[0] && v != mesh.edge(e)[1]) {
            partner_[std::size_t(e)] = v;
            break;
          }
      }
    }
    coef_.assign(std::size_t(mesh.n_edges()), Vec<D>::Zero());
    moved_.assign(std::size_t(mesh.n_edges()), 0);
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
  /// The point of edge e at the mesh's current nodes (its midpoint unless curved).
  Vec<D> edge_point(Index e) const { return edge_point(e, mesh_->coordinates()); }
  /// Every edge's point (e.g. for `write_vtu`'s quadratic cells).
  std::vector<Vec<D>> edge_points() const {
    std::vector<Vec<D>> out(std::size_t(mesh_->n_edges()));
    for (Index e = 0; e < mesh_->n_edges(); ++e) out[std::size_t(e)] = edge_point(e);
    return out;
  }
  /// The geometry nodes of facet f: its corners, then the points of its edges (2D the facet
  /// itself; 3D the edges 01, 12, 20 of its corners): the facet's P2 map, as
  /// `curved_surface_flux` takes it.
  std::array<Vec<D>, D*(D + 1) / 2> facet_nodes(Index f) const {
    const auto& fv = mesh_->facet(f);
    std::array<Vec<D>, D*(D + 1) / 2> x;
    for (int a = 0; a < D; ++a) x[std::size_t(a)] = mesh_->node(fv[std::size_t(a)]);
    for (Index e : mesh_->cell_edges(mesh_->facet_cells(f)[0])) {
      const auto& ev = mesh_->edge(e);
      for (int a = 0; a < D * (D - 1) / 2; ++a) {
        const Index p = fv[std::size_t(a)], q = fv[std::size_t((a + 1) % D)];
        if ((ev[0] == p && ev[1] == q) || (ev[0] == q && ev[1] == p)) x[std::size_t(D + a)] = edge_point(e);
      }
    }
    return x;
  }
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
  /// Its coordinates in the edge's frame (class comment) are fixed from the current nodes.
  void set_edge_point(Index e, const Vec<D>& x) {
    ALEFSI_CHECK_ARG(e >= 0 && e < mesh_->n_edges(), "e", "edge ", e, " out of range [0, ", mesh_->n_edges(), ")");
    const Frame F = frame(e, mesh_->coordinates());
    coef_[std::size_t(e)] = F.axes.inverse() * (x - F.origin);
    mark_moved(e);
  }

  /// Whether edge e's point was set (else it is the midpoint), and its coordinates in the edge's
  /// frame: what places it. A checkpoint keeps them, and `set_frame_coefficients` puts a point
  /// back bit for bit (through `set_edge_point` it would pass through a frame's inverse).
  bool point_set(Index e) const { return moved_.at(std::size_t(e)) != 0; }
  const Vec<D>& frame_coefficients(Index e) const { return coef_.at(std::size_t(e)); }
  void set_frame_coefficients(Index e, const Vec<D>& k) {
    ALEFSI_CHECK_ARG(e >= 0 && e < mesh_->n_edges(), "e", "edge ", e, " out of range [0, ", mesh_->n_edges(), ")");
    ALEFSI_CHECK_ARG(k.allFinite(), "k", "edge ", e, ": the frame coefficients must be finite");
    coef_[std::size_t(e)] = k;
    mark_moved(e);
  }

  /// Puts edge e's point back at its midpoint; a cell around it stays curved only through
  /// another set edge.
  void straighten(Index e) {
    ALEFSI_CHECK_ARG(e >= 0 && e < mesh_->n_edges(), "e", "edge ", e, " out of range [0, ", mesh_->n_edges(), ")");
    moved_[std::size_t(e)] = 0;
    coef_[std::size_t(e)] = Vec<D>::Zero();
    for (Index k = start_[std::size_t(e)]; k < start_[std::size_t(e) + 1]; ++k) {
      const Index c = edge_cells_[std::size_t(k)];
      char any = 0;
      for (Index f : mesh_->cell_edges(c)) any |= moved_[std::size_t(f)];
      curved_[std::size_t(c)] = any;
    }
  }
  /// Straightens every set edge of each curved cell whose `jacobian_ratio` is below `floor`,
  /// until none is (a straight cell's ratio is 1); returns the number of edges straightened.
  /// Where a mesh is too coarse for a thin gap beside a curve (a body near a wall), its cells
  /// fall back to the chord there instead of folding.
  Index straighten_below(Real floor) {
    Index n = 0;
    for (bool again = true; again;) {  // (a neighbour's ratio may change with a shared edge)
      again = false;
      for (Index c = 0; c < mesh_->n_cells(); ++c)
        if (curved(c) && jacobian_ratio(c) < floor)
          for (Index e : mesh_->cell_edges(c))
            if (moved_[std::size_t(e)]) straighten(e), ++n, again = true;
    }
    return n;
  }

  /// The point of edge e when the mesh nodes are at X (one position per node).
  Vec<D> edge_point(Index e, const std::vector<Vec<D>>& X) const {
    if (!moved_[std::size_t(e)]) {  // the midpoint, without the frame (most edges)
      const auto& ev = mesh_->edge(e);
      return 0.5 * (X[std::size_t(ev[0])] + X[std::size_t(ev[1])]);
    }
    const Frame F = frame(e, X);
    return F.origin + F.axes * coef_[std::size_t(e)];
  }
  /// The velocity of every edge point when the mesh nodes, at their current positions, move at
  /// V (one velocity per node): the derivative of the frame rule; the midpoint average on
  /// straight edges.
  std::vector<Vec<D>> edge_velocities(const std::vector<Vec<D>>& V) const {
    ALEFSI_CHECK_ARG(Index(V.size()) == mesh_->n_nodes(), "V", "has ", V.size(), " entries, the mesh has ",
                     mesh_->n_nodes(), " nodes");
    const auto& X = mesh_->coordinates();
    std::vector<Vec<D>> W(std::size_t(mesh_->n_edges()));
    for (Index e = 0; e < mesh_->n_edges(); ++e) {
      const auto& ev = mesh_->edge(e);
      const Vec<D>&va = V[std::size_t(ev[0])], &vb = V[std::size_t(ev[1])];
      Vec<D> w = 0.5 * (va + vb);
      if (moved_[std::size_t(e)]) {
        const Vec<D>& k = coef_[std::size_t(e)];
        const Vec<D> d = X[std::size_t(ev[1])] - X[std::size_t(ev[0])], dd = vb - va;
        if constexpr (D == 2) {
          w += k[0] * dd + k[1] * Vec<D>(-dd[1], dd[0]);
        } else {
          const Index c = partner_[std::size_t(e)];
          const Vec<D> f = X[std::size_t(c)] - 0.5 * (X[std::size_t(ev[0])] + X[std::size_t(ev[1])]);
          const Vec<D> df = V[std::size_t(c)] - 0.5 * (va + vb);
          const Real L = d.norm();
          const Vec<D> n = d.cross(f);
          const Vec<D> dn = (dd.cross(f) + d.cross(df)) / L - n * (d.dot(dd) / (L * L * L));
          w += k[0] * dd + k[1] * df + k[2] * dn;
        }
      }
      W[std::size_t(e)] = w;
    }
    return W;
  }

  /// The geometry nodes of cell c: its vertices, then its edge points (local edge order).
  Nodes cell_nodes(Index c) const {
    Nodes X;
    const auto& v = mesh_->cell(c);
    for (int i = 0; i <= D; ++i) X[i] = mesh_->node(v[i]);
    const auto& e = mesh_->cell_edges(c);
    for (int k = 0; k < Shape::n_edge_dofs; ++k) X[D + 1 + k] = edge_point(e[k]);
    return X;
  }

  /// Where scalar DOF i of a P1 or P2 Lagrange DOF map sits (node DOFs first, then one per
  /// edge): a node, or the edge point.
  Vec<D> dof_point(Index i) const {
    if (i < mesh_->n_nodes()) return mesh_->node(i);
    return edge_point(i - mesh_->n_nodes());
  }
  /// ... when the mesh nodes are at X.
  Vec<D> dof_point(Index i, const std::vector<Vec<D>>& X) const {
    if (i < mesh_->n_nodes()) return X[std::size_t(i)];
    return edge_point(i - mesh_->n_nodes(), X);
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
  /// The smallest `jacobian_ratio` over the curved cells (1 with none): how near the map of the
  /// worst curved cell is to folding. A motion that flattens a curved cell (its edge point kept
  /// on the curve, the opposite node brought towards the chord) lowers it.
  Real worst_ratio() const {
    Real r = 1;
    for (Index c = 0; c < mesh_->n_cells(); ++c)
      if (curved(c)) r = std::min(r, jacobian_ratio(c));
    return r;
  }

 private:
  // Edge e's point is set: the cells around it are curved.
  void mark_moved(Index e) {
    moved_[std::size_t(e)] = 1;
    for (Index k = start_[std::size_t(e)]; k < start_[std::size_t(e) + 1]; ++k) curved_[std::size_t(edge_cells_[std::size_t(k)])] = 1;
  }
  Vec<D> midpoint(Index e) const { return 0.5 * (mesh_->node(mesh_->edge(e)[0]) + mesh_->node(mesh_->edge(e)[1])); }

  // The frame of edge e at node positions X: origin m, axes (d, d^perp) or (d, f, d x f / |d|).
  struct Frame {
    Vec<D> origin;
    Mat<D> axes;
  };
  Frame frame(Index e, const std::vector<Vec<D>>& X) const {
    const auto& ev = mesh_->edge(e);
    const Vec<D>&a = X[std::size_t(ev[0])], &b = X[std::size_t(ev[1])];
    Frame F{0.5 * (a + b), Mat<D>::Zero()};
    const Vec<D> d = b - a;
    F.axes.col(0) = d;
    if constexpr (D == 2) {
      F.axes.col(1) = Vec<D>(-d[1], d[0]);
    } else {
      const Vec<D> f = X[std::size_t(partner_[std::size_t(e)])] - F.origin;
      F.axes.col(1) = f;
      F.axes.col(2) = d.cross(f) / d.norm();
    }
    return F;
  }

  const Mesh<D>* mesh_;
  std::vector<char> curved_;
  std::vector<Index> start_, edge_cells_;
  std::vector<Index> partner_;  // 3D: each edge's third frame vertex
  std::vector<Vec<D>> coef_;    // a moved edge point's coordinates in its frame
  std::vector<char> moved_;     // the edge point was set (else: the midpoint)
};

/// Places the point of every edge lying on a boundary facet with tag `tag` at onto(midpoint)
/// (a projection onto the exact curve or surface), then checks the cells it curved (unless
/// `check` is false: the caller checks later). Returns the number of edges moved. Throws
/// InvalidArgument when no facet has the tag.
template <int D, class Projector>
Index project_boundary_edges(QuadraticGeometry<D>& g, int tag, Projector&& onto, bool check = true) {
  const auto& mesh = g.mesh();
  const std::vector<Index> edges = mesh.boundary_edges(tag);
  ALEFSI_CHECK_ARG(!edges.empty(), "tag", "no boundary facet has tag ", tag);
  for (Index e : edges) {
    const Vec<D> m = 0.5 * (mesh.node(mesh.edge(e)[0]) + mesh.node(mesh.edge(e)[1]));
    g.set_edge_point(e, onto(m));
  }
  if (check) g.check_all();
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

/// The nearest point on the axis-aligned ellipsoid (ellipse in 2D) about `centre` with semi-axes
/// s: y_i = c_i + s_i^2 d_i / (s_i^2 + t), d = x - c, where t is the root of
///     f(t) = sum_i (s_i d_i / (s_i^2 + t))^2 - 1
/// on t > -min_i s_i^2, where f falls monotonically (the largest root: the nearest of the
/// critical points). A curved edge's point has to move along the normal: a radial projection
/// moves the midpoint of a chord of a slender body along it as well, by as much as the chord's
/// sagitta over the cosine between the ray and the normal, and that tangential part folds the
/// cells beside it. Deep inside, where the root is not in that range (near the part of the
/// plane of the larger axes whose points have no unique nearest point: on a prolate
/// spheroid's axis farther than a radius of curvature from the tips), the radial projection is
/// returned. Undefined at the centre.
template <int D>
auto onto_ellipsoid(const Vec<D>& centre, const Vec<D>& semi_axes) {
  ALEFSI_CHECK_ARG(semi_axes.minCoeff() > 0 && semi_axes.allFinite(), "semi_axes", "must be positive and finite");
  return [centre, s = semi_axes](const Vec<D>& x) -> Vec<D> {
    const Vec<D> d = x - centre;
    const Real l = d.cwiseQuotient(s).norm();
    ALEFSI_CHECK_ARG(l > 0, "x", "the projection onto an ellipsoid is undefined at its centre");
    const Vec<D> s2 = s.cwiseProduct(s), sd = s.cwiseProduct(d);
    const auto f = [&](Real t, Real* df) {
      Real v = -1, dv = 0;
      for (int i = 0; i < D; ++i) {
        const Real q = sd[i] / (s2[i] + t);
        v += q * q;
        dv -= 2 * q * q / (s2[i] + t);
      }
      if (df) *df = dv;
      return v;
    };
    // the bracket: f(lo) > 0 just right of the pole, f(hi) <= 0 at hi = max_i s_i |d|
    Real lo = -s2.minCoeff() * (1 - 1e-12), hi = s.maxCoeff() * d.norm();
    if (!(f(lo, nullptr) > 0)) return Vec<D>(centre + d / l);  // deep inside a thin body
    Real t = std::clamp(Real(0), lo, hi);                      // near the surface t is near 0
    for (int it = 0; it < 200; ++it) {
      Real df = 0;
      const Real v = f(t, &df);
      if (v == 0) break;
      (v > 0 ? lo : hi) = t;
      const Real step = v / df;
      if (std::abs(step) <= 1e-14 * s2.maxCoeff()) {  // converged (before the safeguard: at the
        t -= step;                                     // root, round-off may put t - step outside)
        break;
      }
      t = t - step > lo && t - step < hi ? t - step : (lo + hi) / 2;  // Newton, kept in the bracket
    }
    const Vec<D> y = s2.cwiseProduct(d).cwiseQuotient((s2.array() + t).matrix());
    return Vec<D>(centre + y / y.cwiseQuotient(s).norm());  // on the surface to round-off
  };
}

/// The nearest point on a turned ellipsoid (ellipse): the axis-aligned one's (`onto_ellipsoid`)
/// in the frame whose columns `axes` (orthonormal) are the directions of the semi-axes s:
/// x -> c + A onto(A^T (x - c)).
template <int D>
auto onto_ellipsoid(const Vec<D>& centre, const Vec<D>& semi_axes, const Mat<D, D>& axes) {
  ALEFSI_CHECK_ARG(axes.allFinite() && (axes.transpose() * axes - Mat<D, D>::Identity()).norm() < 1e-12, "axes",
                   "must be orthonormal columns");
  return [centre, axes, onto = onto_ellipsoid<D>(Vec<D>::Zero(), semi_axes)](const Vec<D>& x) -> Vec<D> {
    return centre + axes * onto(Vec<D>(axes.transpose() * (x - centre)));
  };
}

}  // namespace alefsi
