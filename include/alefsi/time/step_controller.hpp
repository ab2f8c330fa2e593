#pragma once
/// \file time/step_controller.hpp
/// The step-size controller of adaptive runs: Söderlind's PI.3.4 (G. Söderlind, Digital filters
/// in adaptive time-stepping, ACM TOMS 29 (2003) 1-26, the controller PETSc's TSADAPTDSP
/// offers and ARKODE's PI follows), from the scaled error estimates r_n (time/error_estimate.hpp;
/// r <= 1 keeps a step) of a scheme of order q, k = q + 1:
///     dt_{n+1} = dt_n * (safety / r_n)^(kI/k) * (r_{n-1} / r_n)^(kP/k),   kI = 0.3, kP = 0.4,
/// the integral part steering r toward safety = 0.9 and the proportional part damping the
/// oscillation that the elementary controller (safety / r_n)^(1/k) (used for the first estimate,
/// when there is no r_{n-1}) shows on stiff problems. The ratio is clipped to
/// [shrink_min, grow_max] and to the scheme's zero-stability bound (max_step_ratio: 2 for BDF2,
/// 1.5 for BDF3), never above 1 right after a rejection. A rejected step is retried with
/// dt * clip((safety / r)^(1/k), shrink_min, 0.9). A step without estimate (start-up) keeps dt.
///
///     PiStepController pi(2, max_step_ratio<BDF2_BDF2E>());
///     dt = pi.accepted(dt, report.error.available, r);
#include <algorithm>
#include <cmath>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

class PiStepController {
 public:
  static constexpr Real safety = 0.9, shrink_min = 0.2, grow_max = 5, k_integral = 0.3, k_proportional = 0.4;

  /// `order`: the scheme's q; `max_ratio`: its step-ratio bound (infinity for one-step
  /// schemes); `last_error`: r_{n-1} of a run that is continued (0: none).
  PiStepController(int order, Real max_ratio, Real last_error = 0)
      : k_(order + 1), max_ratio_(max_ratio), last_(last_error) {
    ALEFSI_CHECK_ARG(order >= 1, "order", "must be >= 1, got ", order);
    ALEFSI_CHECK_ARG(max_ratio > 1, "max_ratio", "must exceed 1, got ", max_ratio);
  }

  /// The next step after an accepted step of dt with scaled error r (`estimated` false: no
  /// estimate, dt is kept); `after_rejection`: this step was retried after a rejection.
  Real accepted(Real dt, bool estimated, Real r, bool after_rejection = false) {
    if (!estimated) return dt;
    r = std::max(r, min_error);
    const Real f = last_ > 0 ? std::pow(safety / r, k_integral / k_) * std::pow(last_ / r, k_proportional / k_)
                             : std::pow(safety / r, Real(1) / k_);
    last_ = r;
    const Real grow = after_rejection ? 1.0 : std::min(grow_max, ratio_below_bound());
    return dt * std::clamp(f, shrink_min, grow);
  }
  /// The retry of a step of dt rejected with scaled error r > 1.
  Real rejected(Real dt, Real r) const {
    return dt * std::clamp(std::pow(safety / r, Real(1) / k_), shrink_min, Real(0.9));
  }
  /// r of the last accepted step with an estimate (0: none yet).
  Real last_error() const { return last_; }

 private:
  static constexpr Real min_error = 1e-10;  // an estimate of 0 (a steady flow) grows dt at the cap
  // a margin below the bound, so that rounding in dt_{n+1} = f dt_n never crosses it
  Real ratio_below_bound() const { return std::isfinite(max_ratio_) ? max_ratio_ * (1 - 1e-9) : max_ratio_; }

  int k_;
  Real max_ratio_;
  Real last_;
};

}  // namespace alefsi
