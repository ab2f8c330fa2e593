#pragma once
/// \file sim/remesher2d.hpp
/// The 2D remesher behind the `Remesher<2>` seam (sim/remesher.hpp): mesh/adapt/adapt2d.hpp's
/// split / collapse / flip / smoothing adaptation, disks kept on their exact circles (other
/// bodies' surfaces kept as they are: their nodes move with the body), and LagrangeTransfer<2>
/// for the state.
///
/// Trigger (RemeshOptions): the worst cell quality (Mesh::quality) below `trigger_quality`, or,
/// with a size function, an edge off its size band (|L - h| / h > adapt.tolerance); with
/// hysteresis: what the last adaptation could not bring inside the band (e.g. the cells in a
/// gap narrower than h) triggers again only once it got worse by 10 %.
///
///     flow.set_remeshing({.walls = {channel_outline(2, 6)},
///                         .size = [](const auto& disks) { return graded_size(disks, 0.02, 0.2); }});
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/mesh/adapt/adapt2d.hpp"
#include "alefsi/mesh/adapt/transfer.hpp"
#include "alefsi/sim/remesher.hpp"

namespace alefsi {

/// Remeshing in the time loop (2D).
struct RemeshOptions {
  bool enabled = true;
  Real trigger_quality = 0.35;  ///< in [0, 1)
  /// The fixed outer boundary (walls) as curves, at their place (mesh/generate/mesher2d.hpp).
  std::vector<BoundaryCurve> walls;
  /// Target edge length for the bodies' current circles, e.g.
  /// `[](const auto& disks) { return graded_size(disks, 0.02, 0.2); }`: a disk body's own
  /// circle, any other body's bounding circle (centre of mass, largest distance to its
  /// surface), each with the body's tag. Empty: the paper's comparative value (adapt2d.hpp)
  /// and the quality trigger only.
  std::function<SizeFunction(const std::vector<Circle>& disks)> size;
  AdaptOptions adapt;  ///< tolerance T, min_quality, smoothing (adapt.size is set from `size`)

  void validate() const {
    ALEFSI_CHECK_ARG(trigger_quality >= 0 && trigger_quality < 1, "remesh.trigger_quality",
                     "must be in [0, 1), got ", trigger_quality);
  }
};

class Remesher2D final : public Remesher<2> {
 public:
  explicit Remesher2D(RemeshOptions opt) : opt_(std::move(opt)) { opt_.validate(); }

  bool enabled() const override { return opt_.enabled; }
  const RemeshOptions& options() const { return opt_; }
  /// The report of the last adaptation.
  const AdaptReport& last_report() const { return last_; }

  RemeshMemory measure(const Mesh<2>& mesh, const std::vector<RemeshBody<2>>& bodies) const override {
    return {worst_quality(mesh), opt_.size ? size_deviation(mesh, opt_.size(circles(bodies))) : Real(0)};
  }

  bool needed(const Mesh<2>& mesh, const std::vector<RemeshBody<2>>& bodies, const RemeshMemory& last) const override {
    return remesh_due(measure(mesh, bodies), last, opt_.trigger_quality, opt_.adapt.tolerance, bool(opt_.size));
  }

  std::optional<Remeshed<2>> adapt(const Mesh<2>& mesh, const std::vector<RemeshBody<2>>& bodies,
                                   int velocity_degree) override {
    std::vector<BoundaryCurve> curves = opt_.walls;
    for (const auto& b : bodies)  // only disks slide on a curve: other surfaces stay fixed
      if (b.radius > 0) curves.push_back(Circle{b.centre, b.radius, b.tag});
    AdaptOptions ao = opt_.adapt;
    if (opt_.size) ao.size = opt_.size(circles(bodies));
    Mesh<2> m2 = alefsi::adapt(mesh, curves, ao, &last_);
    if (!last_.changed) return std::nullopt;
    auto T = std::make_unique<LagrangeTransfer<2>>(mesh, m2, velocity_degree);
    return Remeshed<2>{std::move(m2), std::move(T)};
  }

 private:
  // the size function's circles at t^n: a disk's own, another body's bounding circle
  static std::vector<Circle> circles(const std::vector<RemeshBody<2>>& bodies) {
    std::vector<Circle> out;
    for (const auto& b : bodies) out.push_back(Circle{b.centre, b.radius > 0 ? b.radius : b.r_out, b.tag});
    return out;
  }

  RemeshOptions opt_;
  AdaptReport last_;
};

}  // namespace alefsi
