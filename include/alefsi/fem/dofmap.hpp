#pragma once
/// \file fem/dofmap.hpp
/// Global DOF numbering of scalar Lagrange spaces and of velocity/pressure spaces.
///
/// Scalar space (`DofMap<E, D>`): the DOF on mesh node v is v; the DOF on mesh edge e is
/// n_nodes + e. Cell c's DOFs come in the element's local order. An edge DOF sits at the edge's
/// midpoint, or at its point of a `QuadraticGeometry` given by `set_geometry` (isoparametric
/// P2: `point` then follows the curved edges, for every user of the space).
///
/// Mixed space (`MixedSpace<D, Pair>`): the *field* vector holds every velocity component at
/// every velocity DOF, interleaved (field index i*D + c for component c of scalar DOF i), then
/// every pressure DOF (field index D*n_u + k). A cell's local field DOFs are ordered the same
/// way: local velocity node a, component c -> a*D + c, then the pressure nodes.
///
///     alefsi::MixedSpace<2, alefsi::TaylorHood> space(mesh);
///     auto dofs = space.cell_field_dofs(c);        // 15 field indices for a P2/P1 triangle
///     Vec<2> x = space.velocity().point(i);        // where scalar velocity DOF i sits
///     Vec<2> y = space.velocity().point(i, X);     // ... when the mesh nodes are at X
#include <algorithm>
#include <array>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/concepts.hpp"
#include "alefsi/fem/element_pair.hpp"
#include "alefsi/fem/geometry.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

template <ScalarElement E, int D = E::dim>
class DofMap {
 public:
  static constexpr int n_local = E::n_dofs;
  using CellDofs = std::array<Index, n_local>;

  explicit DofMap(const Mesh<D>& mesh) : mesh_(&mesh) {
    n_dofs_ = mesh.n_nodes() + (E::n_edge_dofs > 0 ? mesh.n_edges() : 0);
    cell_dofs_.resize(mesh.n_cells());
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      for (int i = 0; i <= D; ++i) cell_dofs_[c][i] = mesh.cell(c)[i];
      for (int e = 0; e < E::n_edge_dofs; ++e) cell_dofs_[c][D + 1 + e] = mesh.n_nodes() + mesh.cell_edges(c)[e];
    }
  }

  Index n_dofs() const { return n_dofs_; }
  const CellDofs& cell_dofs(Index c) const { return cell_dofs_[c]; }
  /// Physical location of global DOF i (node, or the edge's midpoint or geometry point).
  Vec<D> point(Index i) const {
    if (i < mesh_->n_nodes()) return mesh_->node(i);
    if (geometry_) return geometry_->edge_point(i - mesh_->n_nodes());
    const auto& e = mesh_->edge(i - mesh_->n_nodes());
    return 0.5 * (mesh_->node(e[0]) + mesh_->node(e[1]));
  }
  /// Location of global DOF i when the mesh nodes are at `x` (one position per node, e.g. a
  /// past or predicted configuration of a moving mesh).
  Vec<D> point(Index i, const std::vector<Vec<D>>& x) const {
    if (i < mesh_->n_nodes()) return x[std::size_t(i)];
    if (geometry_) return geometry_->edge_point(i - mesh_->n_nodes(), x);
    const auto& e = mesh_->edge(i - mesh_->n_nodes());
    return 0.5 * (x[std::size_t(e[0])] + x[std::size_t(e[1])]);
  }
  /// Edge DOFs at the points of `g` (null: the midpoints); g must be on this map's mesh and
  /// outlive the map's use of it.
  void set_geometry(const QuadraticGeometry<D>* g) {
    ALEFSI_CHECK_ARG(!g || &g->mesh() == mesh_, "geometry", "is on another mesh than the DOF map's");
    geometry_ = g;
  }
  const QuadraticGeometry<D>* geometry() const { return geometry_; }
  /// The DOF on mesh node v (vertex DOFs come first, in node order).
  Index node_dof(Index v) const { return v; }
  /// Global DOFs on boundary facets with the given tag (sorted).
  std::vector<Index> boundary_dofs(int tag) const {
    std::vector<Index> out = mesh_->boundary_nodes(tag);
    if constexpr (E::n_edge_dofs > 0)
      for (Index e : mesh_->boundary_edges(tag)) out.push_back(mesh_->n_nodes() + e);
    return out;
  }
  const Mesh<D>& mesh() const { return *mesh_; }

 private:
  const Mesh<D>* mesh_;
  const QuadraticGeometry<D>* geometry_ = nullptr;
  Index n_dofs_ = 0;
  std::vector<CellDofs> cell_dofs_;
};

template <int D, ElementPair Pair>
class MixedSpace {
 public:
  using VelocityElement = typename Pair::template Velocity<D>;
  using PressureElement = typename Pair::template Pressure<D>;
  static constexpr int dim = D;
  static constexpr int n_velocity_local = VelocityElement::n_dofs;
  static constexpr int n_pressure_local = PressureElement::n_dofs;
  static constexpr int n_local = D * n_velocity_local + n_pressure_local;
  using CellDofs = std::array<Index, n_local>;

  explicit MixedSpace(const Mesh<D>& mesh) : velocity_(mesh), pressure_(mesh) {}

  const Mesh<D>& mesh() const { return velocity_.mesh(); }
  /// Isoparametric P2: the velocity's edge DOFs at the points of `g` (null: the midpoints).
  void set_geometry(const QuadraticGeometry<D>* g) { velocity_.set_geometry(g); }
  const QuadraticGeometry<D>* geometry() const { return velocity_.geometry(); }
  const DofMap<VelocityElement, D>& velocity() const { return velocity_; }
  const DofMap<PressureElement, D>& pressure() const { return pressure_; }
  Index n_field() const { return D * velocity_.n_dofs() + pressure_.n_dofs(); }
  Index velocity_field(Index scalar_dof, int component) const { return D * scalar_dof + component; }
  Index pressure_field(Index scalar_dof) const { return D * velocity_.n_dofs() + scalar_dof; }

  /// The velocity part of a field vector: D interleaved components per velocity DOF (component
  /// c of DOF i at D i + c), as a Lagrange field with D components.
  std::vector<Real> velocity_values(const VecX& field) const {
    ALEFSI_CHECK_ARG(field.size() == n_field(), "field", "has ", field.size(), " entries, expected ", n_field());
    return std::vector<Real>(field.data(), field.data() + D * velocity_.n_dofs());
  }
  /// The pressure part of a field vector, one value per pressure DOF.
  std::vector<Real> pressure_values(const VecX& field) const {
    ALEFSI_CHECK_ARG(field.size() == n_field(), "field", "has ", field.size(), " entries, expected ", n_field());
    return std::vector<Real>(field.data() + D * velocity_.n_dofs(), field.data() + field.size());
  }
  /// The field vector of a velocity and a pressure part (the inverse of velocity_values and
  /// pressure_values; the sizes must be those of one space).
  static VecX join(const std::vector<Real>& velocity, const std::vector<Real>& pressure) {
    VecX u(Index(velocity.size() + pressure.size()));
    std::copy(velocity.begin(), velocity.end(), u.data());
    std::copy(pressure.begin(), pressure.end(), u.data() + velocity.size());
    return u;
  }

  CellDofs cell_field_dofs(Index c) const {
    CellDofs out;
    const auto& v = velocity_.cell_dofs(c);
    for (int a = 0; a < n_velocity_local; ++a)
      for (int k = 0; k < D; ++k) out[D * a + k] = velocity_field(v[a], k);
    const auto& p = pressure_.cell_dofs(c);
    for (int b = 0; b < n_pressure_local; ++b) out[D * n_velocity_local + b] = pressure_field(p[b]);
    return out;
  }

 private:
  DofMap<VelocityElement, D> velocity_;
  DofMap<PressureElement, D> pressure_;
};

}  // namespace alefsi
