#pragma once
/// \file time/error_estimate.hpp
/// The local error of a step, estimated for free from what the step has anyway: the levels the
/// scheme keeps (Milne's device; Hairer, Nørsett & Wanner, Solving ODEs I, III.7; the
/// predictor-corrector estimate of CVODE, Hindmarsh et al. 2005).
///
/// For a scheme of order q, let P be the polynomial extrapolation of the levels t^n ... t^{n-q}
/// (q + 1 points) to t^{n+1}. For a smooth solution u,
///     u(t^{n+1}) - P       = E u^(q+1) + ...,  E = prod_{j=0..q} (t^{n+1} - t^{n-j}) / (q+1)!
///     u(t^{n+1}) - u^{n+1} = C u^(q+1) + ...   (the scheme's local error)
/// so u^{n+1} - P = (E - C) u^(q+1) and the local error is estimated by
///     est = C / (E - C) (u^{n+1} - P).
/// C, on the actual step sizes:
///   - BDF of order l (theta = 1): the residual of the exact solution in the BDF formula,
///     sum_k a_k u(t^{n+1-k}) - dt u'(t^{n+1}) = R u^(l+1), gives a_0 (u(t^{n+1}) - u^{n+1}) = R
///     (to leading order, for the non-stiff part), C = R / a_0 with
///     R = sum_{k>=1} a_k (t^{n+1-k} - t^{n+1})^{l+1} / (l+1)!;
///     with equal steps C = -2/9 dt^3 (BDF2), -3/22 dt^4 (BDF3), -1/2 dt^2 (BDF1);
///   - the midpoint rule with theta-interpolated residuals (theta = 1/2, MR/AB): the trapezoidal
///     rule's C = -dt^3 / 12.
/// With equal steps C / (E - C) is -2/11 (BDF2), -3/25 (BDF3), -1/3 (BDF1).
///
/// The midpoint rule is not L-stable: a mode that is algebraic (the velocity's part that the
/// moving mesh's divergence constraint does not fix) or stiff is multiplied by R(inf) = -1 at
/// every step and keeps its size, so the levels carry an undamped (-1)^j oscillation of the
/// size of the start-up and step-change errors. Through Lagrange extrapolation it would enter
/// the estimate at every dt, which then stops vanishing as dt -> 0 (a controller shrinks the
/// step to nothing). For MR/AB the predictor therefore reads four levels n ... n-3 with the
/// weights that reproduce quadratics exactly AND the oscillation (-1)^j:
///     sum_k p_k (t^{n-k} - t^n)^m = dt^m (m = 0, 1, 2),  sum_k p_k (-1)^k = -1,
/// so that u^{n+1} - P does not see it; E is then -sum_k p_k (t^{n-k} - t^{n+1})^3 / 3!, and
/// with equal steps P = 2 u^n - 2 u^{n-2} + u^{n-3}, E = 2 dt^3, C / (E - C) = -1/25.
/// The estimate needs q past levels (MR/AB: 3; history.levels() >= q); before that (start-up)
/// there is none.
///
///     ErrorWeights w = error_weights<BDF2_BDF2E>(dt, history);
///     if (w.available()) est = w.constant * (u1 - (w.predictor[0] u0 + w.predictor[1] u_1 + ...));
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/time/history.hpp"
#include "alefsi/time/schemes.hpp"
#include "alefsi/time/stepper.hpp"

namespace alefsi {

struct ErrorWeights {
  int points = 0;                  ///< levels read (n ... n-points+1); 0: no estimate
  std::array<Real, 4> predictor{}; ///< P = sum_k predictor[k] u^{n-k}
  Real constant = 0;               ///< C / (E - C)
  bool available() const { return points > 0; }
};

/// What is controlled: a tolerance on the step's local error relative to the flow's velocity
/// scale (0: no control, the step is always kept), and a floor for that scale (a velocity the
/// user considers small, for flows that start from rest; 0: none).
struct ErrorControl {
  Real tolerance = 0;
  Real velocity_scale = 0;
};

/// The size of a step's estimated local error (max norms), against the flow's velocity scale.
/// Velocities are what is controlled: the flow's (the free velocity DOFs: not the pressure, an
/// algebraic variable, nor prescribed values such as a wall's data, whose extrapolation error
/// is not the scheme's, nor a body's surface, given by its Z) and the free bodies' Z, a body's
/// angular part weighted by its radius L (the largest distance of a surface node from its
/// centre), so that it is a surface velocity.
/// Positions are their integrals and follow.
struct ErrorEstimate {
  bool available = false;  ///< false for start-up steps (too few levels)
  Real velocity = 0;       ///< max over the velocity DOFs of |est|
  Real body = 0;           ///< max over the free bodies of |est V| + L |est omega|
  Real scale = 0;          ///< max |u^{n+1}| over the velocity DOFs and the free bodies' |V| + L |omega|

  /// The error in units of the tolerance, max(velocity, body) / (tolerance max(scale, floor));
  /// a step is kept when it is <= 1 (0 when there is no estimate).
  Real scaled(const ErrorControl& c) const {
    if (!available || c.tolerance <= 0) return 0;
    const Real err = std::max(velocity, body), ref = c.tolerance * std::max(scale, c.velocity_scale);
    return ref > 0 ? err / ref : err > 0 ? std::numeric_limits<Real>::infinity() : 0;
  }
};

/// A step whose estimated local error exceeds the tolerance (AleFlow::step with an
/// ErrorControl): the flow is still at t^n; retry with a smaller step.
class StepRejected : public Error {
 public:
  StepRejected(const std::string& what, Real scaled_error) : Error(what), scaled_error_(scaled_error) {}
  /// The error in units of the tolerance (> 1).
  Real scaled_error() const { return scaled_error_; }

 private:
  Real scaled_error_;
};

/// The leading coefficient C of a scheme's local error u(t^{n+1}) - u^{n+1} = C u^(q+1), for a
/// step dt after the past steps `past` (see the file comment).
template <TimeScheme S>
Real local_error_constant(Real dt, const std::array<Real, 3>& past) {
  static_assert(S::theta == 1 || (S::theta == 0.5 && S::flow_bdf == 1),
                "the error constant is known for BDF (theta = 1) and the midpoint rule");
  if constexpr (S::theta == 0.5) {
    return -dt * dt * dt / 12;
  } else {
    constexpr int l = S::flow_bdf;
    const std::array<Real, 4> a = variable_bdf_coefficients(l, dt, past);
    Real s = -dt, R = 0, factorial = 1;
    for (int j = 2; j <= l + 1; ++j) factorial *= j;
    for (int k = 1; k <= l; ++k) {
      Real p = 1;
      for (int j = 0; j <= l; ++j) p *= s;
      R += a[std::size_t(k)] * p;
      if (k < l) s -= past[std::size_t(k - 1)];
    }
    return R / factorial / a[0];
  }
}

/// The predictor and the constant of the error estimate of a step of dt with scheme S after
/// the history h (none while h holds fewer than S::order past levels).
template <TimeScheme S>
ErrorWeights error_weights(Real dt, const TimeHistory& h) {
  constexpr int q = S::order;
  constexpr bool midpoint = S::theta == 0.5;  // the oscillation-blind predictor (file comment)
  constexpr int points = midpoint ? 4 : q + 1, past_levels = points - 1;
  static_assert(points <= TimeHistory::depth + 1, "the predictor reads at most depth + 1 levels");
  ErrorWeights w;
  if (h.levels() < past_levels) return w;
  std::array<Real, 3> past{};
  for (int k = 0; k < past_levels; ++k) past[std::size_t(k)] = h.step(k);
  // nodes relative to t^n: 0, -dt_{n-1}, -(dt_{n-1} + dt_{n-2}), ...; target dt
  std::array<Real, 4> s{};
  for (int k = 1; k < points; ++k) s[std::size_t(k)] = s[std::size_t(k - 1)] - past[std::size_t(k - 1)];
  if constexpr (midpoint) {
    Eigen::Matrix4d A;
    Eigen::Vector4d b(1, dt, dt * dt, -1);
    for (int k = 0; k < 4; ++k) {
      const Real x = s[std::size_t(k)];
      A(0, k) = 1, A(1, k) = x, A(2, k) = x * x, A(3, k) = k % 2 == 0 ? 1 : -1;
    }
    const Eigen::Vector4d p = A.fullPivLu().solve(b);
    for (int k = 0; k < 4; ++k) w.predictor[std::size_t(k)] = p[k];
  } else {
    for (int k = 0; k < points; ++k) {
      Real num = 1, den = 1;
      for (int j = 0; j < points; ++j)
        if (j != k) num *= dt - s[std::size_t(j)], den *= s[std::size_t(k)] - s[std::size_t(j)];
      w.predictor[std::size_t(k)] = num / den;
    }
  }
  // E: u(t^{n+1}) - P for u = (t - t^{n+1})^{q+1} / (q+1)!
  Real E = 0, factorial = 1;
  for (int j = 2; j <= q + 1; ++j) factorial *= j;
  for (int k = 0; k < points; ++k) E -= w.predictor[std::size_t(k)] * std::pow(s[std::size_t(k)] - dt, q + 1);
  E /= factorial;
  const Real C = local_error_constant<S>(dt, past);
  w.constant = C / (E - C);
  w.points = points;
  return w;
}

}  // namespace alefsi
