#pragma once
/// \file time/stepper.hpp
/// The coefficients of one ALE step, computed from a scheme (time/schemes.hpp) and the
/// step-size history (time/history.hpp), and the scheme's start-up.
///
/// `step_coefficients<S>(dt, history)` gives everything the step loop reads:
///   - the flow's BDF weights a_k: delta_l u^{n+1} = sum_{k=0}^{l} a_k u^{n+1-k}, the time
///     derivative delta_l u^{n+1} / dt (l = S::flow_bdf);
///   - the positions' BDF weights b_k (lg = S::position_bdf): sum_k b_k X^{n+1-k} = dt V;
///   - the extrapolation weights e_k of X^ and U^ (and the bodies' state) from levels n, n-1,
///     n-2 to the level where the mesh velocity is solved (S::velocity_level);
///   - the weights of the convecting velocity u* at t^{n+theta} (order 2 to t^{n+1/2} for
///     theta < 1, order l to t^{n+1} otherwise) and of a body's velocity at t^{n+1} (order 2);
///   - theta, the mesh-velocity level and what the flow sees of it.
/// With equal steps these are the constant-step tables of the scheme (exactly, so constant-step
/// results do not depend on this file's arithmetic). With unequal steps they are the
/// variable-step formulas: Lagrange interpolation on the actual times,
///     a_k = dt L_k'(t^{n+1}),  e_k = L_k(t_target),
/// with L_k the Lagrange basis on t^{n+1}, t^n, ..., resp. on t^n, t^{n-1}, ... (for BDF2,
/// with w = dt_n / dt_{n-1}: a = ((1 + 2w)/(1 + w), -(1 + w), w^2/(1 + w))).
///
/// `Stepper<S>` decides how the next step is taken: with the scheme's own coefficients, or, while
/// the history holds fewer levels than the scheme reads, with start-up coefficients (self-starting;
/// the very first one back-fills level n-1, `StepCoefficients::backfill`): MR/AB's
/// (`StartUp::midpoint`), or for the BDF schemes BDF of the order the history allows, BSS then
/// BDF2/BDF2E (`StartUp::bdf`: L-stable, so a start that is not smooth is damped), or
/// as a damped start (m backward-Euler substeps, Richardson-extrapolated for design order >= 3;
/// sim/ale_flow.hpp carries it out). With constant steps (the default) a change of dt restarts
/// the history; with variable steps (`Stepper(m, true)`) the variable-step formulas take it,
/// unless the step grows by more than the scheme's `max_step_ratio` (`restarts`).
///
///     Stepper<BDF3_BDF3E> stepper;
///     StepPlan plan = stepper.plan(history, 0.01);   // plan.kind, plan.coefficients
#include <array>
#include <string>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/time/history.hpp"
#include "alefsi/time/schemes.hpp"

namespace alefsi {

/// Everything one step reads from its scheme (see the file comment).
struct StepCoefficients {
  const char* scheme = "";  ///< name of the scheme whose formulas are used
  Real dt = 0;
  Real theta = 1;
  int flow_order = 1;                ///< l
  std::array<Real, 4> flow_bdf{};    ///< a_0..a_l
  int position_order = 1;            ///< lg
  std::array<Real, 4> position_bdf{};  ///< b_0..b_lg
  std::array<Real, 3> extrapolation{};  ///< e: X^ = sum_k e_k X^{n-k}, at the mesh-velocity level
  VelocityLevel velocity_level = VelocityLevel::n_one;
  FlowMeshVelocity flow_velocity = FlowMeshVelocity::solved;
  std::array<Real, 3> convection{};     ///< u* at t^{n+theta}
  std::array<Real, 3> body_velocity{};  ///< a body's Z at t^{n+1} (theta < 1: the link's offset)
  /// The first step after a (re)start of a scheme that reads level n-1: the step back-fills it
  /// (X^{n-1} = X^n - dt V^n, U^{n-1} = U^n, the bodies likewise).
  bool backfill = false;

  /// t^n + dt times the mesh-velocity level (0, 1/2 or 1): t_V.
  Real velocity_time(Real tn) const {
    return velocity_level == VelocityLevel::n ? tn : velocity_level == VelocityLevel::n_half ? tn + dt / 2 : tn + dt;
  }
};

namespace detail {

/// Lagrange weights at `target` of the nodes s[0..m-1] (offsets, any origin): L_k(target).
inline std::array<Real, 3> lagrange_weights(const std::array<Real, 3>& s, int m, Real target) {
  std::array<Real, 3> w{};
  for (int k = 0; k < m; ++k) {
    Real num = 1, den = 1;
    for (int j = 0; j < m; ++j)
      if (j != k) num *= target - s[j], den *= s[k] - s[j];
    w[k] = num / den;
  }
  return w;
}

/// BDF weights of order l on the nodes 0 (= t^{n+1}) and s[1..l] (< 0: t^{n+1-k} - t^{n+1}),
/// scaled by dt: a_k = dt L_k'(0).
inline std::array<Real, 4> bdf_weights(const std::array<Real, 4>& s, int l, Real dt) {
  std::array<Real, 4> a{};
  for (int k = 0; k <= l; ++k) {
    if (k == 0) {
      Real d = 0;
      for (int j = 1; j <= l; ++j) d += 1 / (0 - s[j]);
      a[0] = dt * d;
      continue;
    }
    Real num = 1, den = 1;
    for (int j = 0; j <= l; ++j) {
      if (j == k) continue;
      den *= s[k] - s[j];
      if (j != 0) num *= 0 - s[j];
    }
    a[k] = dt * num / den;
  }
  return a;
}

/// Number of levels (1..3) an extrapolation table reads.
inline int extrapolation_points(const std::array<Real, 3>& e) { return e[2] != 0 ? 3 : e[1] != 0 ? 2 : 1; }

}  // namespace detail

/// The BDF weights of order l for a step dt after the past steps `past` (past[0] = dt_{n-1},
/// past[1] = dt_{n-2}); the constant-step table when they equal dt.
inline std::array<Real, 4> variable_bdf_coefficients(int l, Real dt, const std::array<Real, 3>& past) {
  bool uniform = true;
  for (int k = 0; k + 1 < l; ++k) uniform &= past[std::size_t(k)] == dt;
  if (uniform) return bdf_coefficients(l);
  std::array<Real, 4> s{0, -dt, -dt - past[0], -dt - past[0] - past[1]};
  return detail::bdf_weights(s, l, dt);
}

/// Weights of the m-point extrapolation from t^n, t^{n-1}, t^{n-2} to t^n + frac dt, for a step
/// dt after the past steps `past`; the constant-step table `uniform_table` when they equal dt.
inline std::array<Real, 3> variable_extrapolation_weights(int m, Real frac, Real dt, const std::array<Real, 3>& past,
                                                          const std::array<Real, 3>& uniform_table) {
  bool uniform = true;
  for (int k = 0; k + 1 < m; ++k) uniform &= past[std::size_t(k)] == dt;
  if (uniform) return uniform_table;
  const std::array<Real, 3> s{0, -past[0], -past[0] - past[1]};
  return detail::lagrange_weights(s, m, frac * dt);
}

/// The coefficients of a step of dt with scheme S after the history h (the past steps it reads
/// are h's; missing ones, before a start-up completes, count as dt).
template <TimeScheme S>
StepCoefficients step_coefficients(Real dt, const TimeHistory& h) {
  std::array<Real, 3> past{dt, dt, dt};
  for (int k = 0; k < TimeHistory::depth && k < h.levels(); ++k) past[std::size_t(k)] = h.step(k);
  StepCoefficients c;
  c.scheme = S::name;
  c.dt = dt;
  c.theta = S::theta;
  c.flow_order = S::flow_bdf;
  c.flow_bdf = variable_bdf_coefficients(S::flow_bdf, dt, past);
  c.position_order = S::position_bdf;
  c.position_bdf = variable_bdf_coefficients(S::position_bdf, dt, past);
  const Real frac = S::velocity_level == VelocityLevel::n ? 0.0 : S::velocity_level == VelocityLevel::n_half ? 0.5 : 1.0;
  c.extrapolation =
      variable_extrapolation_weights(detail::extrapolation_points(S::extrapolation), frac, dt, past, S::extrapolation);
  c.velocity_level = S::velocity_level;
  c.flow_velocity = S::flow_velocity;
  const bool half = S::theta < 1;
  const int m = half ? 2 : S::flow_bdf;
  c.convection = variable_extrapolation_weights(m, half ? 0.5 : 1.0, dt, past, extrapolation_weights(m, half));
  c.body_velocity = variable_extrapolation_weights(2, 1.0, dt, past, extrapolation_weights(2, false));
  return c;
}

/// How the next step is taken.
enum class StepKind {
  regular,       ///< the scheme's own formulas
  startup,       ///< MR/AB start-up formulas (the history is still short)
  damped_start,  ///< backward-Euler substeps (FlowOptions::damped_start)
};

struct StepPlan {
  StepKind kind = StepKind::regular;
  StepCoefficients coefficients;  ///< regular, startup: the step's; damped_start: one substep's
  int substeps = 0;               ///< damped_start: m
  bool richardson = false;        ///< damped_start: extrapolate m and m/2 substeps (order >= 3)
};

/// The formulas of the start-up steps, taken while the history is shorter than the scheme reads.
enum class StartUp {
  midpoint,  ///< MR/AB's (second order; not L-stable: |R(inf)| = 1)
  bdf,       ///< BDF schemes only: BSS, then BDF2/BDF2E (L-stable; first, then second order)
};

/// The scheme's driver: which formulas the next step uses (see the file comment).
template <TimeScheme S>
class Stepper {
 public:
  using Scheme = S;
  /// `damped_start` = m (even, 2..64), or 0 for the multistep start-up; `variable_steps`: a
  /// change of dt keeps the history (within the scheme's step-ratio bound); `start_up`: the
  /// multistep start-up's formulas (StartUp::bdf needs a BDF scheme, theta = 1).
  explicit Stepper(int damped_start = 0, bool variable_steps = false, StartUp start_up = StartUp::midpoint)
      : damped_start_(damped_start), variable_(variable_steps), start_up_(start_up) {
    ALEFSI_CHECK_ARG(damped_start == 0 || (damped_start >= 2 && damped_start <= 64 && damped_start % 2 == 0),
                     "damped_start", "must be 0 (off) or an even number of substeps in 2..64, got ", damped_start);
    ALEFSI_CHECK_ARG(start_up == StartUp::midpoint || S::theta == 1, "start_up",
                     "BDF start-up steps need a BDF scheme (theta = 1); ", S::name, " starts with its own formulas");
  }
  StartUp start_up() const { return start_up_; }
  int damped_start() const { return damped_start_; }

  bool variable_steps() const { return variable_; }

  /// Whether a step of dt after history h restarts it: with constant steps when dt differs from
  /// the last step; with variable steps when it exceeds the last one by more than the scheme's
  /// step-ratio bound (max_step_ratio<S>).
  bool restarts(const TimeHistory& h, Real dt) const {
    if (h.levels() == 0 || dt == h.last_step()) return false;
    return !variable_ || dt > max_step_ratio<S>() * h.last_step();
  }

  /// The plan of a step of dt after history h (already restarted if `restarts` said so).
  StepPlan plan(const TimeHistory& h, Real dt) const {
    StepPlan p;
    if (h.levels() == 0 && damped_start_ > 0) {
      p.kind = StepKind::damped_start;
      p.substeps = damped_start_;
      p.richardson = S::order >= 3;
      p.coefficients = step_coefficients<BSS>(dt / damped_start_, h);
    } else if (h.levels() < history_levels<S>()) {
      p.kind = StepKind::startup;
      p.coefficients = start_up_ == StartUp::midpoint ? step_coefficients<MR_AB>(dt, h)
                       : h.levels() == 0             ? step_coefficients<BSS>(dt, h)
                                                     : step_coefficients<BDF2_BDF2E>(dt, h);
      p.coefficients.backfill = h.levels() == 0;
    } else {
      p.coefficients = step_coefficients<S>(dt, h);
    }
    return p;
  }
  /// The coefficients of one substep of size dt_sub of a damped start (backward Euler).
  static StepCoefficients substep(Real dt_sub, const TimeHistory& h) { return step_coefficients<BSS>(dt_sub, h); }

 private:
  int damped_start_ = 0;
  bool variable_ = false;
  StartUp start_up_ = StartUp::midpoint;
};

}  // namespace alefsi
