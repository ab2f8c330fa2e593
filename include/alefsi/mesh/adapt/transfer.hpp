#pragma once
/// \file mesh/adapt/transfer.hpp
/// Transfer of P1 / P2 finite-element fields from one triangle (2D) or tetrahedron (3D) mesh to
/// another (after mesh adaptation) by interpolation at the new DOF points.
///
/// Algorithm: every DOF point of the target space (P1: the nodes; P2: the nodes, then one
/// point per edge, by default the straight midpoint) is located in the source mesh
/// (`PointLocator<D>`: walk from the cell found for a neighbouring point, bucket grid as
/// fall-back); the source field is evaluated there with the P1 / P2 shape functions of
/// the containing cell. The located cells and weights are stored once (`FieldTransfer<D>`)
/// and applied to any number of fields / history levels / components.
///
/// Exactness: a field in the source FE space is reproduced exactly (to round-off) at
/// every target DOF point inside the source mesh; in particular P1 transfer is exact for
/// affine fields and P2 transfer for quadratic fields, and the error for a smooth field
/// is the interpolation error, O(h^2) for P1 and O(h^3) for P2 (max norm).
///
/// Curved source cells: with `from_edge_points` (one point per edge of the source mesh, e.g.
/// `QuadraticGeometry::edge_points()`) a source cell whose edge points are off their midpoints is
/// the image of the P2 (isoparametric) map of its vertices and edge points, and a source field
/// is a polynomial of the reference coordinates there. A target point in such a cell is then
/// mapped back by Newton's method on that map (from the straight cell's coordinates; 2-4
/// iterations), walking to the neighbour across a facet while the coordinates leave the cell;
/// a field of the source's isoparametric space is then reproduced exactly (in P2 the affine
/// functions of x are such fields; in P1 on a curved cell they are not).
/// Without it the straight cell's coordinates are used, an O(h^2) error in the reference
/// point beside a curved boundary and so an O(h^2) error in the value.
///
/// Points outside the source mesh (a new boundary node put on a circle arc / a sphere lies
/// outside the inscribed polygon / polyhedron of the old mesh, at a distance O(h^2 / radius)): by default
/// (`OutsidePolicy::clamp`) the value at the point of the nearest source cell closest to
/// it (clamped barycentric coordinates: bounded, no overshoot, error O(|grad f| * distance)
/// = O(h^2)); with `OutsidePolicy::extrapolate` the nearest cell's polynomial evaluated
/// at the point (exact for fields of the source space, but it may overshoot far away).
/// `n_outside()` and `max_outside_distance()` report how many points were concerned.
///
/// Layout: a field with k components per DOF is stored interleaved, value of component j
/// at DOF i at index i * k + j (as MixedSpace interleaves velocity components); the
/// matrix overloads take one row per DOF and one column per component / field.
///
/// Cost: construction O(n_source + n_target) (walks of O(1) steps when the meshes are
/// close, as after an adaptation); each application O(n_target * k).
///
///     alefsi::FieldTransfer2D T(old_mesh, new_mesh, 2);          // P2 plan (FieldTransfer<3>: tets)
///     std::vector<Real> u_new = T.apply(u_old, 2);               // 2 components per DOF
///     auto p_new = alefsi::transfer<1>(old_mesh, p_old, 1, new_mesh);
#include <algorithm>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/adapt/locate.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

/// What to do with target DOF points outside the source mesh.
enum class OutsidePolicy { clamp, extrapolate };

namespace detail {

/// P1 / P2 shape function values at barycentric coordinates l (local order of lagrange.hpp:
/// vertices, then the edges of SimplexTopology<D>).
template <int D>
std::array<Real, 10> lagrange_weights(int degree, const Vec<D + 1>& l) {
  std::array<Real, 10> w{};
  for (int i = 0; i <= D; ++i) w[i] = degree == 1 ? l[i] : l[i] * (2 * l[i] - 1);
  if (degree == 2)
    for (std::size_t e = 0; e < SimplexTopology<D>::edges.size(); ++e) {
      const auto [a, b] = SimplexTopology<D>::edges[e];
      w[D + 1 + e] = 4 * l[a] * l[b];
    }
  return w;
}

/// The P2 map of a cell with nodes X (vertices, then edge points in SimplexTopology<D>'s edge
/// order), at barycentric coordinates l: the point x(l), and J = dx/dxi, xi = (l_1, .., l_D).
template <int D>
Vec<D> quadratic_map(const std::array<Vec<D>, 10>& X, const Vec<D + 1>& l, Mat<D>* J) {
  Vec<D> x = Vec<D>::Zero();
  Mat<D> dx = Mat<D>::Zero();
  // d/dxi_j = d/dl_{j+1} - d/dl_0
  auto add = [&](const Vec<D>& Xk, Real value, const Vec<D + 1>& dl) {
    x += value * Xk;
    for (int j = 0; j < D; ++j) dx.col(j) += (dl[j + 1] - dl[0]) * Xk;
  };
  for (int i = 0; i <= D; ++i) {
    Vec<D + 1> dl = Vec<D + 1>::Zero();
    dl[i] = 4 * l[i] - 1;
    add(X[std::size_t(i)], l[i] * (2 * l[i] - 1), dl);
  }
  for (std::size_t e = 0; e < SimplexTopology<D>::edges.size(); ++e) {
    const auto [a, b] = SimplexTopology<D>::edges[e];
    Vec<D + 1> dl = Vec<D + 1>::Zero();
    dl[a] = 4 * l[b];
    dl[b] = 4 * l[a];
    add(X[D + 1 + e], 4 * l[a] * l[b], dl);
  }
  if (J) *J = dx;
  return x;
}

/// Number of DOFs of the scalar P1 / P2 space on a mesh (numbering of DofMap).
template <int D>
Index lagrange_dofs(const Mesh<D>& m, int degree) { return m.n_nodes() + (degree == 2 ? m.n_edges() : 0); }

}  // namespace detail

/// Precomputed interpolation from the P`degree` space of `from` to that of `to`.
template <int D>
class FieldTransfer {
  static constexpr int ne = static_cast<int>(SimplexTopology<D>::edges.size());

 public:
  /// `to_edge_points` (P2 only, optional): the DOF point of each edge of `to` (indexed as
  /// to.edges()), e.g. the arc midpoint for edges on a circle; default: straight midpoints.
  /// `from_edge_points` (optional, any degree): the point of each edge of `from`, which makes
  /// the cells with displaced points curved (file comment); default: straight cells.
  FieldTransfer(const Mesh<D>& from, const Mesh<D>& to, int degree, const std::vector<Vec<D>>& to_edge_points = {},
                OutsidePolicy outside = OutsidePolicy::clamp, const std::vector<Vec<D>>& from_edge_points = {})
      : degree_(degree) {
    ALEFSI_CHECK_ARG(degree == 1 || degree == 2, "degree", "must be 1 or 2, got ", degree);
    ALEFSI_CHECK_ARG(to_edge_points.empty() || (degree == 2 && to_edge_points.size() == std::size_t(to.n_edges())),
                     "to_edge_points", "must be empty or (P2) have one point per edge of 'to' (", to.n_edges(), "), got ",
                     to_edge_points.size());
    ALEFSI_CHECK_ARG(from_edge_points.empty() || from_edge_points.size() == std::size_t(from.n_edges()),
                     "from_edge_points", "must be empty or have one point per edge of 'from' (", from.n_edges(),
                     "), got ", from_edge_points.size());
    const std::vector<char> curved = curved_cells(from, from_edge_points);
    n_from_ = detail::lagrange_dofs(from, degree);
    n_to_ = detail::lagrange_dofs(to, degree);
    nl_ = degree == 1 ? D + 1 : D + 1 + ne;
    idx_.resize(std::size_t(n_to_) * nl_);
    w_.resize(std::size_t(n_to_) * nl_);
    const PointLocator<D> loc(from);

    // a neighbour with a smaller index for each target node: its cell is the walk's start
    std::vector<Index> nb(std::size_t(to.n_nodes()), -1);
    for (const auto& e : to.edges())
      if (nb[e[1]] < 0 || e[0] < nb[e[1]]) nb[e[1]] = e[0];
    std::vector<Index> found(std::size_t(to.n_nodes()), -1);
    Index prev = -1;
    auto store = [&](Index dof, const Vec<D>& x, Index hint) {
      PointLocation<D> l = loc.find(x, hint);
      if (!curved.empty()) l = on_curved_cells(from, from_edge_points, curved, x, l);
      if (l.distance > 0) ++n_outside_, max_outside_ = std::max(max_outside_, l.distance);
      const auto w = detail::lagrange_weights<D>(degree, outside == OutsidePolicy::extrapolate ? l.raw : l.lambda);
      const auto& cv = from.cell(l.cell);
      for (int i = 0; i <= D; ++i) idx_[std::size_t(dof) * nl_ + i] = cv[i];
      if (degree == 2)
        for (int e = 0; e < ne; ++e) idx_[std::size_t(dof) * nl_ + D + 1 + e] = from.n_nodes() + from.cell_edges(l.cell)[e];
      for (int i = 0; i < nl_; ++i) w_[std::size_t(dof) * nl_ + i] = w[i];
      return l.cell;
    };
    for (Index v = 0; v < to.n_nodes(); ++v) {
      const Index hint = nb[v] >= 0 && nb[v] < v ? found[nb[v]] : prev;
      prev = found[v] = store(v, to.node(v), hint);
    }
    if (degree == 2)
      for (Index e = 0; e < to.n_edges(); ++e) {
        const auto& ev = to.edge(e);
        const Vec<D> x = to_edge_points.empty() ? Vec<D>(0.5 * (to.node(ev[0]) + to.node(ev[1]))) : to_edge_points[e];
        store(to.n_nodes() + e, x, found[ev[0]]);
      }
  }

  int degree() const { return degree_; }
  Index n_source_dofs() const { return n_from_; }
  Index n_target_dofs() const { return n_to_; }
  /// Number of target DOF points outside the source mesh, and their largest distance to it.
  Index n_outside() const { return n_outside_; }
  Real max_outside_distance() const { return max_outside_; }

  /// One field with `components` interleaved components per DOF.
  std::vector<Real> apply(const std::vector<Real>& values, int components = 1) const {
    ALEFSI_CHECK_ARG(components >= 1, "components", "must be >= 1, got ", components);
    ALEFSI_CHECK_ARG(values.size() == std::size_t(n_from_) * std::size_t(components), "values", "has ", values.size(),
                     " entries, expected ", n_from_, " DOFs x ", components, " components");
    const std::size_t k = std::size_t(components);
    std::vector<Real> out(std::size_t(n_to_) * k, 0.0);
    for (std::size_t i = 0; i < std::size_t(n_to_); ++i)
      for (int j = 0; j < nl_; ++j) {
        const Real w = w_[i * nl_ + j];
        const std::size_t src = std::size_t(idx_[i * nl_ + j]) * k;
        for (std::size_t c = 0; c < k; ++c) out[i * k + c] += w * values[src + c];
      }
    return out;
  }

  /// Several fields (e.g. the history levels of a multistep scheme), same layout each.
  std::vector<std::vector<Real>> apply(const std::vector<std::vector<Real>>& fields, int components = 1) const {
    std::vector<std::vector<Real>> out;
    out.reserve(fields.size());
    for (const auto& f : fields) out.push_back(apply(f, components));
    return out;
  }

  /// One row per source DOF, any number of columns (components / fields).
  MatX apply(const MatX& values) const {
    ALEFSI_CHECK_ARG(values.rows() == n_from_, "values", "has ", values.rows(), " rows, expected ", n_from_, " DOFs");
    MatX out = MatX::Zero(n_to_, values.cols());
    for (Index i = 0; i < n_to_; ++i)
      for (int j = 0; j < nl_; ++j)
        out.row(i) += w_[std::size_t(i) * nl_ + j] * values.row(idx_[std::size_t(i) * nl_ + j]);
    return out;
  }

 private:
  // Per source cell, whether an edge point is off its midpoint (empty: none is).
  static std::vector<char> curved_cells(const Mesh<D>& from, const std::vector<Vec<D>>& points) {
    if (points.empty()) return {};
    std::vector<char> curved(std::size_t(from.n_cells()), 0);
    bool any = false;
    for (Index c = 0; c < from.n_cells(); ++c)
      for (Index e : from.cell_edges(c)) {
        const auto& ev = from.edge(e);
        const Vec<D> m = 0.5 * (from.node(ev[0]) + from.node(ev[1]));
        if ((points[std::size_t(e)] - m).norm() > 1e-12 * from.edge_length(e)) {
          curved[std::size_t(c)] = 1;
          any = true;
        }
      }
    return any ? curved : std::vector<char>{};
  }

  // The location of x among curved cells (file comment): Newton on the P2 map of the cell the
  // straight location found, then of its neighbours while the coordinates leave the cell. A
  // straight cell's image is its own (curved cells meet straight ones on flat facets): kept.
  static PointLocation<D> on_curved_cells(const Mesh<D>& from, const std::vector<Vec<D>>& points,
                                          const std::vector<char>& curved, const Vec<D>& x,
                                          const PointLocation<D>& found) {
    if (found.distance == 0 && !curved[std::size_t(found.cell)]) return found;
    PointLocation<D> best;
    Real best_out = 1e300;
    Index c = found.cell, previous = -1;
    for (int walk = 0; walk < 8; ++walk) {
      Vec<D + 1> raw = affine_coordinates(from, c, x);
      if (curved[std::size_t(c)]) {
        const auto X = cell_nodes(from, points, c);
        Vec<D + 1> lam = raw.cwiseMax(Real(0));  // inside its straight cell the map is near affine
        lam /= lam.sum();
        const Real scale = from.jacobian(c).norm();
        bool converged = false;
        for (int it = 0; it < 20 && !converged; ++it) {
          Mat<D> J;
          const Vec<D> r = x - detail::quadratic_map<D>(X, lam, &J);
          if (r.norm() <= 1e-14 * scale) {
            converged = true;
            break;
          }
          const Vec<D> dxi = J.inverse() * r;
          if (!dxi.allFinite()) break;
          lam.template tail<D>() += dxi;
          lam[0] -= dxi.sum();
          converged = dxi.norm() <= 1e-15;
        }
        if (converged) raw = lam;  // else: the straight coordinates, to choose the walk's way
      }
      const Real out = std::max(Real(0), -raw.minCoeff());
      if (out < best_out) {
        best_out = out;
        best.cell = c;
        best.raw = raw;
        best.lambda = raw;
      }
      if (out <= 1e-12) return best;  // inside, to round-off
      int k = 0;  // across the facet opposite the most negative coordinate
      for (int i = 1; i <= D; ++i)
        if (raw[i] < raw[k]) k = i;
      const auto& fc = from.facet_cells(from.cell_facets(c)[k]);
      const Index next = fc[0] == c ? fc[1] : fc[0];
      if (next < 0 || next == previous) break;
      previous = c;
      c = next;
    }
    // outside every cell tried (beyond the curved boundary): the nearest one's clamped point
    best.lambda = best.raw.cwiseMax(Real(0));
    best.lambda /= best.lambda.sum();
    const Vec<D> y = curved[std::size_t(best.cell)]
                         ? detail::quadratic_map<D>(cell_nodes(from, points, best.cell), best.lambda, nullptr)
                         : Vec<D>(from.node(from.cell(best.cell)[0]) +
                                  from.jacobian(best.cell) * Vec<D>(best.lambda.template tail<D>()));
    best.distance = std::max((x - y).norm(), std::numeric_limits<Real>::min());
    return best;
  }
  static Vec<D + 1> affine_coordinates(const Mesh<D>& from, Index c, const Vec<D>& x) {
    const Vec<D> xi = from.jacobian(c).inverse() * (x - from.node(from.cell(c)[0]));
    Vec<D + 1> l;
    l[0] = 1 - xi.sum();
    l.template tail<D>() = xi;
    return l;
  }
  static std::array<Vec<D>, 10> cell_nodes(const Mesh<D>& from, const std::vector<Vec<D>>& points, Index c) {
    std::array<Vec<D>, 10> X;
    const auto& cv = from.cell(c);
    for (int i = 0; i <= D; ++i) X[std::size_t(i)] = from.node(cv[i]);
    for (int e = 0; e < ne; ++e) X[std::size_t(D + 1 + e)] = points[std::size_t(from.cell_edges(c)[e])];
    return X;
  }

  int degree_;
  int nl_ = D + 1;
  Index n_from_ = 0, n_to_ = 0, n_outside_ = 0;
  Real max_outside_ = 0;
  std::vector<Index> idx_;
  std::vector<Real> w_;
};

using FieldTransfer2D = FieldTransfer<2>;

/// One-shot transfer of a P`K` field (K = 1 or 2) with `components` interleaved
/// components per DOF; see FieldTransfer<D>.
template <int K, int D>
std::vector<Real> transfer(const Mesh<D>& from, const std::vector<Real>& values, int components, const Mesh<D>& to,
                           const std::vector<Vec<D>>& to_edge_points = {}, OutsidePolicy outside = OutsidePolicy::clamp) {
  static_assert(K == 1 || K == 2, "transfer<K>: K is the Lagrange degree, 1 or 2");
  return FieldTransfer<D>(from, to, K, to_edge_points, outside).apply(values, components);
}

}  // namespace alefsi
