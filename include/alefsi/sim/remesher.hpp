#pragma once
/// \file sim/remesher.hpp
/// The seam between the flow and mesh adaptation: `Remesher<D>`, and the transfer of a flow's
/// whole state to a new mesh.
///
/// After each step the flow asks its remesher `needed(mesh, bodies, memory)`: whether the mesh
/// must be adapted, given what the last remesh left (`RemeshMemory`, kept in the flow state and
/// checkpointed, so that a trigger with hysteresis restarts bit for bit). If so,
/// `adapt(mesh, bodies, velocity_degree)` returns the new mesh and a `MeshTransfer<D>` from the
/// old one (or nothing if the adaptation changed nothing), and the flow:
///   1. interpolates every history level in the current configuration (`transfer_levels`:
///      positions X^{n-1}, X^{n-2} (as displacements from X^n) and the mesh velocity V^n by P1,
///      the fields U^{n-k} by the velocity and pressure degrees; the new X^n is the new mesh's
///      nodes);
///   2. rebuilds the discretisation on the new topology;
///   3. resets each body's surface nodes and surface velocity DOFs, at every level, from its
///      exact rigid motion (sim/body_system.hpp), so bodies keep their shape;
///   4. stores `measure(new mesh)` as the memory.
/// Bodies are given as `RemeshBody<D>` (tag, centre at t^n, radius > 0 for a disk / sphere,
/// whose surface the remesher keeps exact).
///
/// Remeshers: `Remesher2D` (sim/remesher2d.hpp: split / collapse / flip / smoothing with disks on
/// their exact circles) and `Remesher3D` (sim/remesher3d.hpp: a new mesh of the box with its
/// spheres from gmsh, when alefsi::gmsh is linked). Both transfer by `LagrangeTransfer<D>`.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/adapt/transfer.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

/// A body as the remesher sees it, at t^n.
template <int D>
struct RemeshBody {
  int tag = 0;
  Vec<D> centre = Vec<D>::Zero();
  Real radius = 0;  ///< > 0: a disk / sphere, kept exact
  Real r_out = 0;   ///< the largest distance from the centre to the surface (a disk's radius)
};

/// What the trigger remembers of the last remesh: the quantities `measure` returned then.
struct RemeshMemory {
  Real quality = 1;    ///< worst cell quality
  Real deviation = 0;  ///< worst relative deviation of an edge from the size function
  Real curved = 1;     ///< smallest det J ratio of the curved cells (the flow's own trigger)
};

/// Interpolation from the old mesh's Lagrange spaces to the new mesh's.
template <int D>
class MeshTransfer {
 public:
  virtual ~MeshTransfer() = default;
  /// A field of the degree-`degree` Lagrange space with `components` interleaved components
  /// per DOF (DofMap numbering: nodes, then edges).
  virtual std::vector<Real> apply(const std::vector<Real>& values, int components, int degree) const = 0;
};

/// The MeshTransfer of both remeshers: interpolation (FieldTransfer<D>) by P1 and by the
/// velocity degree, the plans built once per remesh. With curved cells (isoparametric P2), the
/// edge points of both meshes: the old cells are mapped back through their quadratic maps and
/// the new P2 DOFs sit at the new edge points (mesh/adapt/transfer.hpp).
template <int D>
class LagrangeTransfer final : public MeshTransfer<D> {
 public:
  LagrangeTransfer(const Mesh<D>& from, const Mesh<D>& to, int velocity_degree,
                   const std::vector<Vec<D>>& from_edge_points = {}, const std::vector<Vec<D>>& to_edge_points = {})
      : p1_(from, to, 1, {}, OutsidePolicy::clamp, from_edge_points) {
    if (velocity_degree != 1) pk_.emplace(from, to, velocity_degree, to_edge_points, OutsidePolicy::clamp, from_edge_points);
  }
  std::vector<Real> apply(const std::vector<Real>& values, int components, int degree) const override {
    if (degree == 1) return p1_.apply(values, components);
    ALEFSI_ASSERT(pk_ && pk_->degree() == degree);
    return pk_->apply(values, components);
  }

 private:
  FieldTransfer<D> p1_;
  std::optional<FieldTransfer<D>> pk_;
};

template <int D>
struct Remeshed {
  Mesh<D> mesh;
  std::unique_ptr<MeshTransfer<D>> transfer;
};

template <int D>
class Remesher {
 public:
  virtual ~Remesher() = default;
  /// False: the flow never remeshes by itself (an explicit `AleFlow::remesh()` still does).
  virtual bool enabled() const = 0;
  /// The trigger's quantities on `mesh` (remembered after a remesh).
  virtual RemeshMemory measure(const Mesh<D>& mesh, const std::vector<RemeshBody<D>>& bodies) const = 0;
  /// Whether the mesh should be adapted now, given the memory of the last remesh.
  virtual bool needed(const Mesh<D>& mesh, const std::vector<RemeshBody<D>>& bodies, const RemeshMemory& last) const = 0;
  /// The adapted mesh and the transfer to it, or nothing when the mesh did not change.
  virtual std::optional<Remeshed<D>> adapt(const Mesh<D>& mesh, const std::vector<RemeshBody<D>>& bodies,
                                           int velocity_degree) = 0;
};

/// Worst relative deviation |L - h| / h of an edge's length L from the size function h at its
/// midpoint (the size trigger of both remeshers).
template <int D, class SizeFn>
Real size_deviation(const Mesh<D>& mesh, const SizeFn& h) {
  Real dev = 0;
  for (const auto& e : mesh.edges()) {
    const Vec<D> a = mesh.node(e[0]), c = mesh.node(e[1]);
    const Real E = h(0.5 * (a + c));
    dev = std::max(dev, std::abs((a - c).norm() - E) / E);
  }
  return dev;
}

/// The trigger of both remeshers, with hysteresis: the worst quality below `trigger_quality`,
/// or (`sized`: there is a size function) an edge off its band |L - h| / h > `tolerance`; what
/// the last remesh left (`last`) triggers again only once it got worse by 10 %.
inline bool remesh_due(const RemeshMemory& now, const RemeshMemory& last, Real trigger_quality, Real tolerance,
                       bool sized) {
  return now.quality < std::min(trigger_quality, 0.9 * last.quality) ||
         (sized && now.deviation > std::max(tolerance, 1.1 * last.deviation));
}

/// Smallest Mesh::quality over the cells.
template <int D>
Real worst_quality(const Mesh<D>& mesh) {
  Real q = 1;
  for (Index c = 0; c < mesh.n_cells(); ++c) q = std::min(q, mesh.quality(c));
  return q;
}

/// Step 1 above: every history level of `state` interpolated from `old_space`'s mesh by `T`,
/// in place. Levels not yet taken (empty) stay empty. X^n is left to the caller (the new
/// mesh's nodes, `new_nodes`). The past positions are transferred as displacements from the
/// nodes at t^n, X^{n-k} = x + T(X^{n-k} - X^n)(x) at a new node x: a node that does not move
/// (a wall's) keeps X^{n-k} = x, where the positions themselves would give a new node on a
/// curved wall the point of the old chord (or of the old cell's P2 map of its vertices), which
/// the position formula would then take for a motion towards it and follow.
template <class State, class Space>
void transfer_levels(State& state, const Space& old_space, const MeshTransfer<Space::dim>& T,
                     const std::vector<Vec<Space::dim>>& new_nodes) {
  constexpr int D = Space::dim;
  const int kv = Space::VelocityElement::degree, kp = Space::PressureElement::degree;
  const std::vector<Vec<D>>& old_nodes = old_space.mesh().coordinates();
  // x_new + T(x - base) (base: the old nodes) or T(x) (no base)
  auto move_points = [&](std::vector<Vec<D>>& x, bool displacement) {
    if (x.empty()) return;
    ALEFSI_ASSERT(!displacement || x.size() == old_nodes.size());
    std::vector<Real> flat(D * x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
      for (int c = 0; c < D; ++c) flat[D * i + c] = x[i][c] - (displacement ? old_nodes[i][c] : Real(0));
    flat = T.apply(flat, D, 1);
    ALEFSI_ASSERT(flat.size() == D * new_nodes.size());
    x.resize(flat.size() / D);
    for (std::size_t i = 0; i < x.size(); ++i)
      for (int c = 0; c < D; ++c) x[i][c] = flat[D * i + c] + (displacement ? new_nodes[i][c] : Real(0));
  };
  for (int k = 1; k < state.X.size(); ++k) move_points(state.X[k], true);
  move_points(state.V, false);
  for (int k = 0; k < state.U.size(); ++k) {
    VecX& u = state.U[k];
    if (u.size() == 0) continue;
    u = Space::join(T.apply(old_space.velocity_values(u), D, kv), T.apply(old_space.pressure_values(u), 1, kp));
  }
}

}  // namespace alefsi
