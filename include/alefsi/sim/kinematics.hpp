#pragma once
/// \file sim/kinematics.hpp
/// The mesh kinematics of one ALE step (section 4 of the paper), on plain node arrays:
///   - `extrapolate`: X^ = sum_k e_k X^{n-k}, where the mesh velocity is solved;
///   - `advance_nodes`: X^{n+1} from the position formula sum_k b_k X^{n+1-k} = dt V, the mesh
///     velocity the flow sees (the solved one, or 2 V^{n+1/2} - V^n for BDF2/AB) and V^{n+1}
///     for the next step, and the flow geometry X^{n+theta} = theta X^{n+1} + (1 - theta) X^n.
/// The bodies' surface nodes of X^{n+1} are then overwritten by their exact rigid map
/// (sim/body_system.hpp) before X^{n+theta} is formed, so `advance_nodes` leaves it to
/// `flow_geometry`.
///
///     auto Xh = extrapolate(state.X, c.extrapolation);
///     StepNodes<2> g = advance_nodes(state.X, state.V, Vs, c);
#include <array>
#include <vector>

#include "alefsi/core/types.hpp"
#include "alefsi/time/history.hpp"
#include "alefsi/time/stepper.hpp"

namespace alefsi {

/// Node positions and mesh velocities of one step.
template <int D>
struct StepNodes {
  std::vector<Vec<D>> Xn1;    ///< X^{n+1}
  std::vector<Vec<D>> Vflow;  ///< the mesh velocity in the flow residual
  std::vector<Vec<D>> Vnext;  ///< V^{n+1}
};

/// sum_k e_k X^{n-k} over the levels with e_k != 0.
template <int D>
std::vector<Vec<D>> extrapolate(const Levels<std::vector<Vec<D>>>& X, const std::array<Real, 3>& e) {
  std::vector<Vec<D>> out(X[0].size(), Vec<D>::Zero());
  for (int k = 0; k < 3; ++k)
    if (e[k] != 0)
      for (std::size_t i = 0; i < out.size(); ++i) out[i] += e[k] * X[k][i];
  return out;
}

/// X^{n+1} from the position formula with the mesh velocity Vs (solved at the scheme's level),
/// the mesh velocity the flow sees and V^{n+1}; Vn is V^n.
template <int D>
StepNodes<D> advance_nodes(const Levels<std::vector<Vec<D>>>& X, const std::vector<Vec<D>>& Vn,
                           const std::vector<Vec<D>>& Vs, const StepCoefficients& c) {
  const auto& b = c.position_bdf;
  StepNodes<D> g;
  g.Xn1.resize(Vs.size());
  for (std::size_t i = 0; i < Vs.size(); ++i) {
    Vec<D> x = c.dt * Vs[i];
    for (int k = 1; k <= c.position_order; ++k) x -= b[k] * X[k - 1][i];
    g.Xn1[i] = x / b[0];
  }
  g.Vflow = Vs, g.Vnext = Vs;
  if (c.velocity_level == VelocityLevel::n_half)
    for (std::size_t i = 0; i < Vs.size(); ++i) g.Vnext[i] = 2 * Vs[i] - Vn[i];
  if (c.flow_velocity == FlowMeshVelocity::ab2) g.Vflow = g.Vnext;
  return g;
}

/// X^{n+theta} = theta X^{n+1} + (1 - theta) X^n.
template <int D>
std::vector<Vec<D>> flow_geometry(const std::vector<Vec<D>>& Xn1, const std::vector<Vec<D>>& Xn, Real theta) {
  std::vector<Vec<D>> out(Xn1.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = theta * Xn1[i] + (1 - theta) * Xn[i];
  return out;
}

}  // namespace alefsi
