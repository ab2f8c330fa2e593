#pragma once
/// \file sim/remesher3d.hpp
/// The 3D remesher behind the `Remesher<3>` seam (sim/remesher.hpp): when the mesh has
/// degraded, a new mesh of the box with the spheres where they are now (gmsh_box_mesh, from
/// gmsh: needs alefsi::gmsh), and LagrangeTransfer<3> for the state. The spheres' surfaces
/// stay exact: the new mesh's sphere nodes are on the spheres, and the flow places them from
/// each body's rigid motion at every level after the transfer.
///
/// Trigger (Remesh3DOptions): the worst cell quality (Mesh::quality, the normalised
/// volume-to-edge ratio) below `trigger_quality`, or, with a size function, an edge off its
/// size band (|L - h| / h > `tolerance`), with the 2D remesher's hysteresis: what the last new
/// mesh had already triggers again only once it got worse by 10 %. gmsh's new meshes measure
/// 0.95-1.1 in |L - h| / h and 0.32-0.42 in worst quality (tests/gmsh, examples/ten_cate), so
/// that the default band, 1.5, leaves a new mesh alone and the hysteresis decides: with
/// `tolerance = 1`, the test's sphere is remeshed each time it has moved about 1.5 h_body.
/// Each remesh interpolates the state (O(h^3) for P2 velocities), so fewer remeshes are better
/// while the elasticity keeps the cells good.
///
/// Every body must be a sphere (sphere_body): other shapes are refused by name. A new mesh
/// below `mesher.quality_floor` is refused (MeshError naming the quality) before anything of
/// the flow changed: the flow, its mesh and its checkpoints stay as they were.
///
///     flow.set_remesher(std::make_unique<alefsi::Remesher3D>(alefsi::Remesh3DOptions{
///         .box = box, .size = [](const auto& spheres) { return alefsi::graded_size(spheres, 0.1, 1.0); }}));
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/mesh/generate/gmsh_mesher.hpp"
#include "alefsi/mesh/generate/spheres_in_box.hpp"
#include "alefsi/mesh/quality.hpp"
#include "alefsi/sim/remesher.hpp"

namespace alefsi {

/// Remeshing in the time loop (3D).
struct Remesh3DOptions {
  bool enabled = true;
  Real trigger_quality = 0.1;  ///< in [0, 1)
  BoxDomain box;               ///< the walls
  /// Target edge length for the spheres where they are now, e.g.
  /// `[](const auto& s) { return graded_size(s, 0.1, 1.0); }` (required).
  std::function<SizeFunction3D(const std::vector<Sphere>& spheres)> size;
  Real tolerance = 1.5;     ///< the size band of the trigger: |L - h| / h
  GmshMeshOptions mesher;   ///< the quality floor of a new mesh, Netgen's optimiser

  void validate() const {
    ALEFSI_CHECK_ARG(trigger_quality >= 0 && trigger_quality < 1, "remesh.trigger_quality", "must be in [0, 1), got ",
                     trigger_quality);
    ALEFSI_CHECK_ARG(tolerance > 0 && std::isfinite(tolerance), "remesh.tolerance", "must be positive, got ",
                     tolerance);
    ALEFSI_CHECK_ARG(static_cast<bool>(size), "remesh.size", "a size function is needed");
    box.validate();
    mesher.validate();
  }
};

/// What one remesh did: the mesher's report (wall time, cells, quality after) and the
/// quality of the mesh it replaced.
struct Remesh3DReport {
  GmshMeshReport mesher;
  QualityStats before;
};

class Remesher3D final : public Remesher<3> {
 public:
  explicit Remesher3D(Remesh3DOptions opt) : opt_(std::move(opt)) { opt_.validate(); }

  bool enabled() const override { return opt_.enabled; }
  const Remesh3DOptions& options() const { return opt_; }
  /// The reports of every remesh so far, in order.
  const std::vector<Remesh3DReport>& reports() const { return reports_; }

  RemeshMemory measure(const Mesh<3>& mesh, const std::vector<RemeshBody<3>>& bodies) const override {
    return {worst_quality(mesh), size_deviation(mesh, opt_.size(spheres(bodies)))};
  }

  bool needed(const Mesh<3>& mesh, const std::vector<RemeshBody<3>>& bodies, const RemeshMemory& last) const override {
    return remesh_due(measure(mesh, bodies), last, opt_.trigger_quality, opt_.tolerance, true);
  }

  std::optional<Remeshed<3>> adapt(const Mesh<3>& mesh, const std::vector<RemeshBody<3>>& bodies,
                                   int velocity_degree) override {
    Remesh3DReport rep;
    rep.before = quality_stats(mesh);
    const std::vector<Sphere> s = spheres(bodies);
    Mesh<3> m2 = gmsh_box_mesh(opt_.box, s, opt_.size(s), opt_.mesher, &rep.mesher);
    auto T = std::make_unique<LagrangeTransfer<3>>(mesh, m2, velocity_degree);
    reports_.push_back(rep);
    return Remeshed<3>{std::move(m2), std::move(T)};
  }

 private:
  static std::vector<Sphere> spheres(const std::vector<RemeshBody<3>>& bodies) {
    std::vector<Sphere> out;
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      ALEFSI_CHECK_ARG(bodies[k].radius > 0, "bodies[" + std::to_string(k) + "]", "(tag ", bodies[k].tag,
                       ") is not a sphere: Remesher3D remeshes around spheres only");
      out.push_back({bodies[k].centre, bodies[k].radius, bodies[k].tag});
    }
    return out;
  }

  Remesh3DOptions opt_;
  std::vector<Remesh3DReport> reports_;
};

}  // namespace alefsi
