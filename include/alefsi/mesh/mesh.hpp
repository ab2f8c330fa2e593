#pragma once
/// \file mesh/mesh.hpp
/// Conforming simplex meshes in 2D (triangles) and 3D (tetrahedra).
///
/// A `Mesh<D>` owns node coordinates, cells (D+1 node indices, positively oriented),
/// an integer region tag per cell and tagged facets: boundary facets carry the tags boundary
/// conditions and bodies refer to; interior facets may carry tags too (an embedded surface
/// for output or sensors; nothing in the solver reads them). On construction it checks
/// that the mesh is valid and builds its topology: unique edges, unique facets, the cells
/// on each side of a facet, and the edges and facets of each cell in the local order of
/// `SimplexTopology<D>`. Invalid input throws `MeshError` naming the offending entity:
/// out-of-range node index, degenerate or inverted cell, dangling (unused) node,
/// non-manifold facet (shared by more than two cells), tagged facet that is not a facet of the mesh.
///
/// Coordinates may change (moving meshes) through `set_coordinates`, which rechecks the
/// orientation of every cell; the topology stays.
///
///     auto mesh = alefsi::rectangle_mesh(8, 8);          // unit square, 128 triangles
///     for (Index c = 0; c < mesh.n_cells(); ++c) area += mesh.measure(c);
///     auto wall = mesh.boundary_nodes(alefsi::tags::left);
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/simplex.hpp"

namespace alefsi {

template <int D>
class Mesh {
  static_assert(D == 2 || D == 3, "alefsi meshes are triangles (D = 2) or tetrahedra (D = 3)");

 public:
  static constexpr int dim = D;
  static constexpr int nv = D + 1;              ///< vertices per cell
  static constexpr int ne = simplex_edges<D>;   ///< edges per cell
  static constexpr int nf = D + 1;              ///< facets per cell
  using Point = Vec<D>;
  using Cell = std::array<Index, D + 1>;
  using Facet = std::array<Index, D>;  ///< facet vertices, sorted increasingly
  using Edge = std::array<Index, 2>;   ///< edge vertices, sorted increasingly

  Mesh() = default;

  /// Builds and validates a mesh. `tagged_facets[i]` (any vertex order; a boundary or an
  /// interior facet) gets tag `facet_tags[i]`; facets not listed get tag 0. `cell_tags` may be
  /// empty (all 0).
  Mesh(std::vector<Point> nodes, std::vector<Cell> cells,
       const std::vector<Facet>& tagged_facets = {}, const std::vector<int>& facet_tags = {},
       std::vector<int> cell_tags = {})
      : x_(std::move(nodes)), cells_(std::move(cells)), cell_tags_(std::move(cell_tags)) {
    if (cell_tags_.empty()) cell_tags_.assign(cells_.size(), 0);
    if (cell_tags_.size() != cells_.size())
      throw MeshError(MeshError::Entity::mesh, -1, "cell_tags has " + std::to_string(cell_tags_.size()) +
                                                       " entries for " + std::to_string(cells_.size()) + " cells");
    if (tagged_facets.size() != facet_tags.size())
      throw MeshError(MeshError::Entity::mesh, -1, "tagged_facets and facet_tags differ in size");
    if (cells_.empty()) throw MeshError(MeshError::Entity::mesh, -1, "no cells");
    check_cells();
    build_edges();
    build_facets();
    tag_facets(tagged_facets, facet_tags);
  }

  // --- sizes -------------------------------------------------------------------------
  Index n_nodes() const { return static_cast<Index>(x_.size()); }
  Index n_cells() const { return static_cast<Index>(cells_.size()); }
  Index n_edges() const { return static_cast<Index>(edges_.size()); }
  Index n_facets() const { return static_cast<Index>(facets_.size()); }

  // --- entities ----------------------------------------------------------------------
  const Point& node(Index i) const { return x_[i]; }
  const std::vector<Point>& coordinates() const { return x_; }
  const Cell& cell(Index c) const { return cells_[c]; }
  const std::vector<Cell>& cells() const { return cells_; }
  int cell_tag(Index c) const { return cell_tags_[c]; }
  const std::vector<int>& cell_tags() const { return cell_tags_; }
  const Edge& edge(Index e) const { return edges_[e]; }
  const std::vector<Edge>& edges() const { return edges_; }
  /// Global edge indices of cell c in the local edge order of SimplexTopology<D>.
  const std::array<Index, ne>& cell_edges(Index c) const { return cell_edges_[c]; }
  const Facet& facet(Index f) const { return facets_[f]; }
  /// The cells on both sides of facet f; the second is -1 on the boundary.
  const std::array<Index, 2>& facet_cells(Index f) const { return facet_cells_[f]; }
  /// Global facet indices of cell c; local facet i is opposite local vertex i.
  const std::array<Index, nf>& cell_facets(Index c) const { return cell_facets_[c]; }
  bool on_boundary(Index f) const { return facet_cells_[f][1] < 0; }
  /// Physical tag of a facet (0 if untagged).
  int facet_tag(Index f) const { return facet_tags_[f]; }
  /// Indices of all boundary facets.
  const std::vector<Index>& boundary_facets() const { return boundary_facets_; }
  /// Indices of the interior facets with a nonzero tag (an embedded curve or surface).
  std::vector<Index> tagged_interior_facets() const {
    std::vector<Index> out;
    for (Index f = 0; f < n_facets(); ++f)
      if (facet_tags_[f] != 0 && !on_boundary(f)) out.push_back(f);
    return out;
  }

  /// Sorted, unique nodes on boundary facets with the given tag.
  std::vector<Index> boundary_nodes(int tag) const {
    std::vector<Index> out;
    for (Index f : boundary_facets_)
      if (facet_tags_[f] == tag) out.insert(out.end(), facets_[f].begin(), facets_[f].end());
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
  /// Sorted, unique edges lying on boundary facets with the given tag.
  std::vector<Index> boundary_edges(int tag) const {
    std::vector<Index> out;
    for (Index f : boundary_facets_) {
      if (facet_tags_[f] != tag) continue;
      const Index c = facet_cells_[f][0];
      for (int le = 0; le < ne; ++le) {
        const auto [a, b] = edges_[cell_edges_[c][le]];
        if (contains(facets_[f], a) && contains(facets_[f], b)) out.push_back(cell_edges_[c][le]);
      }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // --- geometry ----------------------------------------------------------------------
  /// Jacobian of the affine map from the reference simplex: columns x_i - x_0.
  Mat<D> jacobian(Index c) const {
    Mat<D> J;
    for (int i = 0; i < D; ++i) J.col(i) = x_[cells_[c][i + 1]] - x_[cells_[c][0]];
    return J;
  }
  /// Signed measure (area / volume); positive for a valid cell.
  Real signed_measure(Index c) const { return jacobian(c).determinant() * reference_measure<D>; }
  Real measure(Index c) const { return std::abs(signed_measure(c)); }
  Point centroid(Index c) const {
    Point g = Point::Zero();
    for (Index v : cells_[c]) g += x_[v];
    return g / Real(nv);
  }
  Real edge_length(Index e) const { return (x_[edges_[e][1]] - x_[edges_[e][0]]).norm(); }
  /// Largest edge length of cell c.
  Real diameter(Index c) const {
    Real h = 0;
    for (Index e : cell_edges_[c]) h = std::max(h, edge_length(e));
    return h;
  }
  /// Shape quality in [0, 1]: 1 for the equilateral triangle / regular tetrahedron, 0 for a
  /// degenerate cell, negative for an inverted one.
  /// 2D: 4 sqrt(3) A / sum l^2;  3D: 12 (3 V)^(2/3) / sum l^2 (sign of V kept).
  Real quality(Index c) const {
    Real l2 = 0;
    for (Index e : cell_edges_[c]) l2 += (x_[edges_[e][1]] - x_[edges_[e][0]]).squaredNorm();
    const Real v = signed_measure(c);
    if constexpr (D == 2) {
      return 4.0 * std::sqrt(3.0) * v / l2;
    } else {
      return std::copysign(12.0 * std::pow(3.0 * std::abs(v), 2.0 / 3.0) / l2, v);
    }
  }
  /// Measure of facet f (length in 2D, area in 3D).
  Real facet_measure(Index f) const { return facet_normal_scaled(f).norm(); }
  /// Unit normal of facet f pointing out of its first cell (out of the domain on the boundary).
  Point facet_normal(Index f) const {
    const Point n = facet_normal_scaled(f);
    return n / n.norm();
  }
  /// Total measure of the mesh.
  Real total_measure() const {
    Real s = 0;
    for (Index c = 0; c < n_cells(); ++c) s += measure(c);
    return s;
  }

  /// Moves the nodes; throws MeshError (naming the cell) if a cell would be inverted or
  /// degenerate, leaving the mesh unchanged.
  void set_coordinates(std::vector<Point> x) {
    if (x.size() != x_.size())
      throw InvalidArgument("x", "expected " + std::to_string(x_.size()) + " coordinates, got " +
                                     std::to_string(x.size()));
    std::swap(x_, x);
    for (Index c = 0; c < n_cells(); ++c) {
      const Real v = signed_measure(c);
      const Real h = diameter(c);
      if (!(v > degenerate_tolerance * std::pow(h, D))) {
        const bool inverted = v < 0;
        std::swap(x_, x);
        throw MeshError(MeshError::Entity::cell, c, inverted ? "inverted by the motion" : "degenerate after the motion");
      }
    }
  }

  /// Relative volume below which a cell counts as degenerate (|K| <= tol * h^D).
  static constexpr Real degenerate_tolerance = 1e-12;

 private:
  template <class A>
  static bool contains(const A& a, Index v) {
    return std::find(a.begin(), a.end(), v) != a.end();
  }

  Point facet_normal_scaled(Index f) const {
    const Index c = facet_cells_[f][0];
    const auto& fv = facets_[f];
    Point n;
    if constexpr (D == 2) {
      const Point t = x_[fv[1]] - x_[fv[0]];
      n = Point(t[1], -t[0]);
    } else {
      const Point a = x_[fv[1]] - x_[fv[0]], b = x_[fv[2]] - x_[fv[0]];
      n = 0.5 * a.cross(b);
    }
    // orient outwards from cell c: away from the vertex opposite the facet
    Index opp = -1;
    for (Index v : cells_[c])
      if (!contains(fv, v)) opp = v;
    if (n.dot(x_[fv[0]] - x_[opp]) < 0) n = -n;
    return n;
  }

  void check_cells() {
    const Index nn = n_nodes();
    std::vector<char> used(x_.size(), 0);
    for (Index c = 0; c < n_cells(); ++c) {
      for (Index v : cells_[c]) {
        if (v < 0 || v >= nn)
          throw MeshError(MeshError::Entity::cell, c, "node index " + std::to_string(v) + " out of range [0, " +
                                                          std::to_string(nn) + ")");
        used[v] = 1;
      }
      for (int i = 0; i < nv; ++i)
        for (int j = i + 1; j < nv; ++j)
          if (cells_[c][i] == cells_[c][j])
            throw MeshError(MeshError::Entity::cell, c, "degenerate: node " + std::to_string(cells_[c][i]) + " repeated");
      const Real v = signed_measure(c);
      Real h = 0;
      for (int i = 0; i < nv; ++i)
        for (int j = i + 1; j < nv; ++j) h = std::max(h, (x_[cells_[c][i]] - x_[cells_[c][j]]).norm());
      if (!std::isfinite(v)) throw MeshError(MeshError::Entity::cell, c, "non-finite coordinates");
      if (std::abs(v) <= degenerate_tolerance * std::pow(h, D))
        throw MeshError(MeshError::Entity::cell, c, "degenerate (zero measure)");
      if (v < 0) throw MeshError(MeshError::Entity::cell, c, "inverted (negative orientation)");
    }
    for (Index i = 0; i < nn; ++i)
      if (!used[i]) throw MeshError(MeshError::Entity::node, i, "dangling (belongs to no cell)");
  }

  // Vertex-bucketed construction of unique sub-entities (edges or facets): each entity is
  // filed under its smallest vertex, so lookups scan a handful of candidates.
  template <int K, class LocalList, class OnEntity>
  Index unique_entities(const LocalList& local, std::vector<std::array<Index, K>>& out, OnEntity&& on_entity) {
    const Index nn = n_nodes();
    std::vector<Index> start(nn + 1, 0);
    auto key = [&](Index c, int l) {
      std::array<Index, K> k;
      for (int i = 0; i < K; ++i) k[i] = cells_[c][local[l][i]];
      std::sort(k.begin(), k.end());
      return k;
    };
    const int nl = static_cast<int>(local.size());
    for (Index c = 0; c < n_cells(); ++c)
      for (int l = 0; l < nl; ++l) ++start[key(c, l)[0] + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<Index> bucket(start.back(), -1), fill(start.begin(), start.end() - 1);
    out.clear();
    out.reserve(start.back() / 2 + 16);
    for (Index c = 0; c < n_cells(); ++c) {
      for (int l = 0; l < nl; ++l) {
        const auto k = key(c, l);
        Index id = -1;
        for (Index p = start[k[0]]; p < fill[k[0]]; ++p)
          if (out[bucket[p]] == k) { id = bucket[p]; break; }
        if (id < 0) {
          id = static_cast<Index>(out.size());
          out.push_back(k);
          bucket[fill[k[0]]++] = id;
        }
        on_entity(c, l, id);
      }
    }
    return static_cast<Index>(out.size());
  }

  void build_edges() {
    cell_edges_.resize(cells_.size());
    unique_entities<2>(SimplexTopology<D>::edges, edges_, [&](Index c, int l, Index id) { cell_edges_[c][l] = id; });
  }

  void build_facets() {
    cell_facets_.resize(cells_.size());
    std::vector<std::array<Index, 2>> fc;
    unique_entities<D>(SimplexTopology<D>::facets, facets_, [&](Index c, int l, Index id) {
      cell_facets_[c][l] = id;
      if (id >= static_cast<Index>(fc.size())) fc.push_back({c, -1});
      else if (fc[id][1] < 0) fc[id][1] = c;
      else
        throw MeshError(MeshError::Entity::cell, c,
                        "non-manifold facet shared by cells " + std::to_string(fc[id][0]) + ", " +
                            std::to_string(fc[id][1]) + " and " + std::to_string(c));
    });
    facet_cells_ = std::move(fc);
    facet_tags_.assign(facets_.size(), 0);
    boundary_facets_.clear();
    for (Index f = 0; f < n_facets(); ++f)
      if (facet_cells_[f][1] < 0) boundary_facets_.push_back(f);
  }

  void tag_facets(const std::vector<Facet>& bf, const std::vector<int>& tags) {
    if (bf.empty()) return;
    // index facets by smallest vertex
    std::vector<std::vector<Index>> by_node(x_.size());
    for (Index f = 0; f < n_facets(); ++f) by_node[facets_[f][0]].push_back(f);
    for (std::size_t i = 0; i < bf.size(); ++i) {
      Facet k = bf[i];
      for (Index v : k)
        if (v < 0 || v >= n_nodes())
          throw MeshError(MeshError::Entity::facet, static_cast<Index>(i),
                          "tagged facet has node index " + std::to_string(v) + " out of range");
      std::sort(k.begin(), k.end());
      Index found = -1;
      for (Index f : by_node[k[0]])
        if (facets_[f] == k) found = f;
      if (found < 0)
        throw MeshError(MeshError::Entity::facet, static_cast<Index>(i),
                        "tagged facet (tag " + std::to_string(tags[i]) + ") is not a facet of the mesh");
      facet_tags_[found] = tags[i];
    }
  }

  std::vector<Point> x_;
  std::vector<Cell> cells_;
  std::vector<int> cell_tags_;
  std::vector<Edge> edges_;
  std::vector<std::array<Index, ne>> cell_edges_;
  std::vector<Facet> facets_;
  std::vector<std::array<Index, 2>> facet_cells_;
  std::vector<std::array<Index, nf>> cell_facets_;
  std::vector<int> facet_tags_;
  std::vector<Index> boundary_facets_;
};

}  // namespace alefsi
