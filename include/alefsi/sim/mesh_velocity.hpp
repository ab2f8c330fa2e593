#pragma once
/// \file sim/mesh_velocity.hpp
/// The boundary data of the mesh-velocity problem (eq. 15-16) and its solution on a geometry.
///
/// The mesh velocity of a node on the boundary is, in this order: the rigid velocity of the
/// body it belongs to (given per step by sim/body_system.hpp as `NodeVelocities`), the
/// function set for its boundary tag (`set_boundary`), or 0 (walls stay in place). Interior
/// nodes follow the elasticity problem (physics/mesh_motion.hpp) on the geometry passed to
/// `solve` (the scheme's extrapolated positions). For verification an analytic field can
/// replace all of it (`set_prescribed`).
///
///     MeshVelocityData<2> data;
///     data.set_boundary(tags::top, [](const Vec<2>& x, Real t) { return Vec<2>(0, std::sin(t)); });
///     auto v = data.solve(motion, mesh, X_hat, t, body_nodes);
#include <functional>
#include <map>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

/// Prescribed node velocities for the mesh-velocity problem (the bodies' surface nodes).
template <int D>
struct NodeVelocities {
  std::vector<Vec<D>> value;  ///< per mesh node (empty: none given)
  std::vector<char> given;    ///< per mesh node
};

template <int D>
class MeshVelocityData {
 public:
  using TimeFunction = std::function<Vec<D>(const Vec<D>&, Real)>;

  /// The mesh velocity g(x, t) of the boundary nodes tagged `tag` (default 0).
  void set_boundary(const Mesh<D>& mesh, int tag, TimeFunction g) {
    ALEFSI_CHECK_ARG(g != nullptr, "g", "mesh velocity function is empty");
    ALEFSI_CHECK_ARG(!mesh.boundary_nodes(tag).empty(), "tag", "no boundary facet has tag ", tag);
    boundary_[tag] = std::move(g);
  }
  /// An analytic mesh velocity v(x, t) everywhere (verification), instead of the elasticity problem.
  void set_prescribed(TimeFunction v) { prescribed_ = std::move(v); }

  /// The mesh velocity on geometry x (one position per node of `mesh`) at time t, with the
  /// bodies' surface node velocities `bodies`.
  template <class Motion>
  std::vector<Vec<D>> solve(Motion& motion, const Mesh<D>& mesh, const std::vector<Vec<D>>& x, Real t,
                            const NodeVelocities<D>& bodies) const {
    if (prescribed_) {
      std::vector<Vec<D>> v(x.size());
      for (std::size_t i = 0; i < x.size(); ++i) v[i] = prescribed_(x[i], t);
      return v;
    }
    std::vector<const TimeFunction*> node_fn(std::size_t(mesh.n_nodes()), nullptr);
    for (const auto& [tag, g] : boundary_)
      for (Index v : mesh.boundary_nodes(tag)) node_fn[std::size_t(v)] = &g;
    return motion.solve(x, [&](Index v, const Vec<D>& xv) {
      if (!bodies.value.empty() && bodies.given[v]) return bodies.value[v];
      return node_fn[v] ? (*node_fn[v])(xv, t) : Vec<D>(Vec<D>::Zero());
    });
  }

 private:
  std::map<int, TimeFunction> boundary_;
  TimeFunction prescribed_;
};

}  // namespace alefsi
