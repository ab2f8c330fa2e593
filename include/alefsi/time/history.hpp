#pragma once
/// \file time/history.hpp
/// The step-size history of a multistep run: the current time t^n and the sizes of the last
/// steps, dt_{n-1} = t^n - t^{n-1}, dt_{n-2}, dt_{n-3}, as they were taken (not recomputed
/// from differences of times, which would round), and how many steps were taken since the
/// last (re)start of the history.
///
/// Time does not drift: a run of equal steps computes t^n = t_a + k dt from the time t_a at
/// which the step size last changed and the count k of steps of that size since, not by adding
/// dt k times (after 900 steps of 5e-4 from 0, t is the double nearest 0.45, not 0.45 - 1e-13;
/// a loop that stops at t_end then takes no sliver step).
///
/// The stepper (time/stepper.hpp) computes each step's coefficients from it; the flow state
/// (sim/flow_state.hpp) keeps it beside the solution levels it describes, level k (k = 0 is
/// t^n) lying at t^n - (dt_{n-1} + ... + dt_{n-k}).
///
///     TimeHistory h(0.0);
///     h.advance(0.01);              // t^1 = 0.01, one level back
///     Real w = h.step(0) / 0.005;   // ratio of the last step to a new one of 0.005
#include <array>
#include <cmath>
#include <cstdint>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

class TimeHistory {
 public:
  /// Past steps remembered (enough for the three-level schemes and their start-up).
  static constexpr int depth = 3;

  explicit TimeHistory(Real t0 = 0) : t_(t0) {}

  /// t^n.
  Real now() const { return t_; }
  /// Steps taken since the last (re)start: past levels n-1, n-2, ... exist for k <= levels().
  int levels() const { return levels_; }
  /// dt_{n-1-k}, the size of the k-th last step (k = 0: the last one); k < min(levels(), depth).
  Real step(int k) const {
    ALEFSI_ASSERT(k >= 0 && k < depth && k < levels_);
    return steps_[std::size_t(k)];
  }
  /// The size of the last step, 0 before any.
  Real last_step() const { return levels_ > 0 ? steps_[0] : 0.0; }

  /// After a step of dt: t^{n+1} = t^n + dt (counted, see the file comment), one more level.
  void advance(Real dt) {
    if (dt != run_dt_ || run_count_ == 0) anchor_ = t_, run_dt_ = dt, run_count_ = 0;
    ++run_count_;
    t_ = anchor_ + Real(run_count_) * run_dt_;
    steps_ = {dt, steps_[0], steps_[1]};
    ++levels_;
  }
  /// Forgets the past levels (the next step starts the scheme anew from t^n).
  void restart() { levels_ = 0; }
  /// Sets the whole history (checkpoint restart, or a start-up procedure that built levels
  /// by other means): t^n, the number of valid levels and the last step sizes.
  void assign(Real t, int levels, const std::array<Real, depth>& steps) {
    ALEFSI_CHECK_ARG(std::isfinite(t), "t", "must be finite, got ", t);
    ALEFSI_CHECK_ARG(levels >= 0, "levels", "must be >= 0, got ", levels);
    t_ = t, levels_ = levels, steps_ = steps;
    anchor_ = t, run_dt_ = steps[0], run_count_ = 0;
  }
  const std::array<Real, depth>& steps() const { return steps_; }

  /// The counter behind t^n (checkpoints store it, so a restart counts on exactly): the time
  /// the step size last changed, the step size and the number of such steps since.
  struct Count {
    Real anchor = 0, dt = 0;
    std::int64_t steps = 0;
  };
  Count count() const { return {anchor_, run_dt_, run_count_}; }
  void set_count(const Count& c) {
    ALEFSI_CHECK_ARG(std::isfinite(c.anchor) && std::isfinite(c.dt) && c.steps >= 0, "count",
                     "invalid time counter (anchor ", c.anchor, ", dt ", c.dt, ", steps ", c.steps, ")");
    anchor_ = c.anchor, run_dt_ = c.dt, run_count_ = c.steps;
  }

 private:
  Real t_ = 0;
  int levels_ = 0;
  std::array<Real, depth> steps_{};
  Real anchor_ = 0, run_dt_ = 0;  // t^n = anchor_ + run_count_ run_dt_
  std::int64_t run_count_ = 0;
};

/// The levels n, n-1, n-2, n-3 of a quantity (positions, a field, a body's velocity): `at[k]`
/// is level n-k (the three-level schemes read n ... n-2; the error estimate of BDF3 reads n-3,
/// time/error_estimate.hpp). `push` shifts them back and makes `x` level n.
template <class T, int N = TimeHistory::depth + 1>
struct Levels {
  std::array<T, N> at{};

  T& operator[](int k) { return at[std::size_t(k)]; }
  const T& operator[](int k) const { return at[std::size_t(k)]; }
  void push(T x) {
    for (int k = N - 1; k > 0; --k) at[std::size_t(k)] = std::move(at[std::size_t(k - 1)]);
    at[0] = std::move(x);
  }
  void fill(const T& x) { at.fill(x); }
  static constexpr int size() { return N; }
};

}  // namespace alefsi
