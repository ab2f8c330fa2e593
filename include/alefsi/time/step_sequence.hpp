#pragma once
/// \file time/step_sequence.hpp
/// A graded start for fixed-dt runs: the first steps grow geometrically from a small one up to
/// dt, so that a multistep scheme's start-up steps (lower order: StartUp::bdf's BSS and BDF2,
/// or the midpoint rule) and a start that is not smooth (an impulsive wall) are resolved, while
/// the run afterwards keeps dt on the grid t0 + k dt (convergence studies compare levels there).
///
/// With first step f < dt and growth bound rho (the scheme's step-ratio bound, times a margin),
/// m = ceil(log(dt / f) / log rho) steps of ratio r = (dt / f)^(1/m) would end just below dt and
/// sum to S = (dt - f) / (r - 1); they are scaled by c = K dt / S >= 1, K = ceil(S / dt), so
/// that the start ends on the grid point t0 + K dt. Every ratio inside the start is r <= rho,
/// the ratio into the first regular step dt is r / c <= r, and the first step is c f.
///
///     for (Real h : graded_start(dt, 1e-3 * dt, max_step_ratio<BDF3_BDF3E>())) flow.step(h);
///     // then flow.step(dt) on the grid t0 + K dt, K = round(sum / dt)
#include <cmath>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

/// The steps of a graded start from `first` up to `dt` (see the file comment), with ratios at
/// most min(max_ratio, 2) * 0.9; they sum to an integer multiple of dt (the last one absorbs
/// the rounding). `first` >= dt: none (the run starts with dt).
inline std::vector<Real> graded_start(Real dt, Real first, Real max_ratio) {
  ALEFSI_CHECK_ARG(dt > 0 && std::isfinite(dt), "dt", "must be positive and finite, got ", dt);
  ALEFSI_CHECK_ARG(first > 0 && std::isfinite(first), "first", "the first step must be positive, got ", first);
  ALEFSI_CHECK_ARG(max_ratio > 1, "max_ratio", "must exceed 1, got ", max_ratio);
  std::vector<Real> steps;
  if (first >= dt) return steps;
  const Real rho = 0.9 * std::min(max_ratio, Real(2));
  const int m = std::max(1, int(std::ceil(std::log(dt / first) / std::log(rho))));
  const Real r = std::pow(dt / first, Real(1) / m);
  const Real S = (dt - first) / (r - 1);
  const Real K = std::ceil(S / dt * (1 - 1e-12));
  const Real c = K * dt / S;
  Real sum = 0;
  for (int j = 0; j < m; ++j) {
    steps.push_back(c * first * std::pow(r, j));
    sum += steps.back();
  }
  steps.back() += K * dt - sum;
  return steps;
}

}  // namespace alefsi
