// The time layer alone: the step-size history, the stepper's coefficients (constant-step tables,
// variable-step formulas against their defining property), the start-up plan, and the
// scheme-name dispatch.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include "alefsi/time.hpp"

using namespace alefsi;

namespace {
TimeHistory history(std::initializer_list<Real> steps) {  // oldest first
  TimeHistory h;
  for (Real dt : steps) h.advance(dt);
  return h;
}
}  // namespace

TEST_CASE("TimeHistory keeps t^n, the step sizes as taken and the levels since the last restart", "[time][quick]") {
  TimeHistory h(1.0);
  CHECK(h.levels() == 0);
  CHECK(h.last_step() == 0);
  h.advance(0.1);
  h.advance(0.2);
  h.advance(0.3);
  h.advance(0.4);
  CHECK(h.now() == Approx(2.0).epsilon(1e-15));
  CHECK(h.levels() == 4);
  CHECK(h.step(0) == 0.4);
  CHECK(h.step(1) == 0.3);
  CHECK(h.step(2) == 0.2);
  h.restart();
  CHECK(h.levels() == 0);
  CHECK(h.now() == Approx(2.0).epsilon(1e-15));
  Levels<int> l;
  l.fill(0);
  l.push(1), l.push(2), l.push(3), l.push(4);
  CHECK((l[0] == 4 && l[1] == 3 && l[2] == 2));
}

TEMPLATE_TEST_CASE("constant steps: the coefficients are the scheme's tables, to the last bit", "[time][stepper][quick]",
                   MR_AB, BDF2_BDF2E, BDF2_AB, BDF3_BDF3E, BSS) {
  using S = TestType;
  const TimeHistory h = history({0.01, 0.01, 0.01});
  const StepCoefficients c = step_coefficients<S>(0.01, h);
  CHECK(c.flow_bdf == bdf_coefficients(S::flow_bdf));
  CHECK(c.position_bdf == bdf_coefficients(S::position_bdf));
  CHECK(c.extrapolation == S::extrapolation);
  CHECK(c.convection == extrapolation_weights(S::theta < 1 ? 2 : S::flow_bdf, S::theta < 1));
  CHECK(c.theta == S::theta);
  CHECK(c.velocity_level == S::velocity_level);
  CHECK(c.flow_velocity == S::flow_velocity);
  CHECK(std::string(c.scheme) == S::name);
}

TEST_CASE("variable steps: BDF2 weights are the closed form with w = dt_n / dt_{n-1}", "[time][stepper][quick]") {
  const Real dt = 0.03, prev = 0.02, w = dt / prev;
  const auto a = step_coefficients<BDF2_BDF2E>(dt, history({0.05, prev})).flow_bdf;
  CHECK(a[0] == Approx((1 + 2 * w) / (1 + w)).epsilon(1e-14));
  CHECK(a[1] == Approx(-(1 + w)).epsilon(1e-14));
  CHECK(a[2] == Approx(w * w / (1 + w)).epsilon(1e-14));
  CHECK(a[3] == 0);
}

TEST_CASE("variable steps: BDF-l differentiates degree-l polynomials exactly, extrapolations reproduce degree m-1",
          "[time][stepper][quick]") {
  // times t^{n+1} = 0.37, steps dt = 0.11 after 0.05, 0.08 (levels t^n, t^{n-1}, t^{n-2})
  const Real dt = 0.11, t1 = 0.37;
  const TimeHistory h = history({0.07, 0.08, 0.05});  // last step 0.05, before it 0.08
  const std::array<Real, 4> t{t1, t1 - dt, t1 - dt - 0.05, t1 - dt - 0.05 - 0.08};
  for (int l = 1; l <= 3; ++l) {
    const auto a = variable_bdf_coefficients(l, dt, {0.05, 0.08, 0.07});
    for (int p = 0; p <= l; ++p) {  // d/dt t^p at t1, times dt
      Real sum = 0;
      for (int k = 0; k <= l; ++k) sum += a[k] * std::pow(t[k], p);
      const Real exact = p == 0 ? 0.0 : dt * p * std::pow(t1, p - 1);
      CHECK(sum == Approx(exact).margin(1e-13));
    }
  }
  // extrapolation from t^n, t^{n-1}, t^{n-2} to t^n + dt / 2 (MR/AB's level) and to t^{n+1}
  const StepCoefficients mr = step_coefficients<MR_AB>(dt, h), b3 = step_coefficients<BDF3_BDF3E>(dt, h);
  for (int p = 0; p <= 2; ++p) {
    Real e2 = 0, e3 = 0, u3 = 0;
    for (int k = 0; k < 3; ++k) {
      e2 += mr.extrapolation[k] * std::pow(t[k + 1], p);
      e3 += b3.extrapolation[k] * std::pow(t[k + 1], p);
      u3 += b3.convection[k] * std::pow(t[k + 1], p);
    }
    if (p <= 1) CHECK(e2 == Approx(std::pow(t1 - dt / 2, p)).margin(1e-14));
    CHECK(e3 == Approx(std::pow(t1, p)).margin(1e-14));
    CHECK(u3 == Approx(std::pow(t1, p)).margin(1e-14));
  }
  // the body velocity extrapolation to t^{n+1} is linear
  CHECK(b3.body_velocity[0] * t[1] + b3.body_velocity[1] * t[2] == Approx(t1).epsilon(1e-14));
}

TEST_CASE("Stepper: start-up while the history is short, a damped start when asked, restarts on a dt change",
          "[time][stepper][quick]") {
  const Stepper<BDF3_BDF3E> bdf3;
  TimeHistory h;
  StepPlan p = bdf3.plan(h, 0.01);
  CHECK(p.kind == StepKind::startup);
  CHECK(p.coefficients.backfill);
  CHECK(std::string(p.coefficients.scheme) == MR_AB::name);
  h.advance(0.01);
  p = bdf3.plan(h, 0.01);
  CHECK(p.kind == StepKind::startup);
  CHECK(!p.coefficients.backfill);
  h.advance(0.01);
  CHECK(bdf3.plan(h, 0.01).kind == StepKind::regular);
  CHECK(bdf3.restarts(h, 0.005));
  CHECK(!bdf3.restarts(h, 0.01));
  // variable steps: any shrinking, and growth up to the scheme's ratio bound, keep the history
  const Stepper<BDF3_BDF3E> var3(0, true);
  CHECK(!var3.restarts(h, 0.001));
  CHECK(!var3.restarts(h, 0.015));
  CHECK(var3.restarts(h, 0.0151));
  CHECK(var3.plan(h, 0.013).kind == StepKind::regular);
  const Stepper<BDF2_BDF2E> var2(0, true);
  CHECK(!var2.restarts(h, 0.02));
  CHECK(var2.restarts(h, 0.0201));
  CHECK(!Stepper<MR_AB>(0, true).restarts(h, 1.0));  // one-step flow and positions: no bound
  CHECK(Stepper<BSS>().plan(TimeHistory{}, 0.1).kind == StepKind::regular);  // BSS reads no past level

  const Stepper<BDF3_BDF3E> damped3(4);
  p = damped3.plan(TimeHistory{}, 0.02);
  CHECK(p.kind == StepKind::damped_start);
  CHECK(p.substeps == 4);
  CHECK(p.richardson);  // order 3: extrapolated
  CHECK(p.coefficients.dt == 0.005);
  CHECK(!Stepper<BDF2_BDF2E>(2).plan(TimeHistory{}, 0.02).richardson);
  CHECK_THROWS_WITH(Stepper<MR_AB>(3), Catch::Contains("damped_start"));

  // BDF start-up: BSS (back-filling), then BDF2/BDF2E, then the scheme's own; not for MR/AB
  const Stepper<BDF3_BDF3E> bdf_start(0, true, StartUp::bdf);
  TimeHistory g;
  p = bdf_start.plan(g, 1e-4);
  CHECK((p.kind == StepKind::startup && p.coefficients.backfill));
  CHECK(std::string(p.coefficients.scheme) == BSS::name);
  g.advance(1e-4);
  p = bdf_start.plan(g, 1.3e-4);
  CHECK((p.kind == StepKind::startup && !p.coefficients.backfill));
  CHECK(std::string(p.coefficients.scheme) == BDF2_BDF2E::name);
  g.advance(1.3e-4);
  CHECK(bdf_start.plan(g, 1.6e-4).kind == StepKind::regular);
  CHECK(std::string(Stepper<BDF2_AB>(2, false, StartUp::bdf).plan(history({0.01}), 0.01).coefficients.scheme) ==
        BDF2_AB::name);
  CHECK_THROWS_WITH(Stepper<MR_AB>(0, true, StartUp::bdf), Catch::Contains("start_up"));
}

TEST_CASE("graded_start: geometric growth within the ratio bound, ending on the grid k dt", "[time][stepper][quick]") {
  for (Real bound : {1.5, 2.0}) {
    for (Real first : {1e-6, 1e-3, 0.3}) {
      const Real dt = 0.01;
      const std::vector<Real> s = graded_start(dt, first * dt, bound);
      REQUIRE(!s.empty());
      Real sum = 0;
      for (std::size_t j = 0; j < s.size(); ++j) {
        sum += s[j];
        if (j > 0) CHECK(s[j] / s[j - 1] <= 0.9 * bound * (1 + 1e-12));
      }
      CHECK(s.front() >= first * dt);
      CHECK(s.front() < 2 * first * dt);                  // scaled up by c <= 1 + dt / S < 2
      CHECK(dt / s.back() <= 0.9 * bound * (1 + 1e-12));  // into the first regular step
      const Real k = std::round(sum / dt);
      CHECK(k >= 1);
      CHECK(std::abs(sum - k * dt) <= 1e-15);
    }
  }
  CHECK(graded_start(0.01, 0.01, 1.5).empty());
  CHECK_THROWS_WITH(graded_start(0.01, 0, 1.5), Catch::Contains("first"));
}

namespace {
/// The largest modulus of the roots of sum_k a_k z^{l-k} other than z = 1 (which every
/// consistent BDF has), for the BDF-l weights a_k with a constant step ratio w.
Real spurious_root(int l, Real w) {
  const Real dt = 1;
  const auto a = variable_bdf_coefficients(l, dt, {dt / w, dt / (w * w), 0});
  // deflate (z - 1): q has degree l - 1
  std::array<Real, 3> q{a[0], 0, 0};
  for (int k = 1; k < l; ++k) q[std::size_t(k)] = a[std::size_t(k)] + q[std::size_t(k - 1)];
  if (l == 2) return std::abs(q[1] / q[0]);
  const std::complex<Real> d = std::sqrt(std::complex<Real>(q[1] * q[1] - 4 * q[0] * q[2]));
  return std::max(std::abs((-q[1] + d) / (2 * q[0])), std::abs((-q[1] - d) / (2 * q[0])));
}
}  // namespace

TEST_CASE("variable-step BDF: zero-stable for constant ratios below 1 + sqrt(2) (BDF2), (1 + sqrt(5))/2 (BDF3)",
          "[time][stepper][quick]") {
  const Real r2 = 1 + std::sqrt(2.0), r3 = (1 + std::sqrt(5.0)) / 2;
  CHECK(spurious_root(2, 1.0) == Approx(1.0 / 3));  // the constant-step BDF2 root
  for (Real w : {0.01, 0.1, 0.5, 1.0, 1.5, 2.0, 0.999 * r2}) CHECK(spurious_root(2, w) < 1);
  CHECK(spurious_root(2, 1.001 * r2) > 1);
  for (Real w : {0.01, 0.1, 0.5, 1.0, 1.3, 1.5, 0.999 * r3}) CHECK(spurious_root(3, w) < 1);
  CHECK(spurious_root(3, 1.001 * r3) > 1);
  // the enforced bounds lie inside, with a margin
  CHECK(max_step_ratio<BDF2_BDF2E>() == 2.0);
  CHECK(max_step_ratio<BDF2_AB>() == 2.0);
  CHECK(max_step_ratio<BDF3_BDF3E>() == 1.5);
  CHECK(std::isinf(max_step_ratio<MR_AB>()));
  CHECK(spurious_root(2, max_step_ratio<BDF2_BDF2E>()) <= 0.8 + 1e-12);
  CHECK(spurious_root(3, max_step_ratio<BDF3_BDF3E>()) < 0.9);
}

TEST_CASE("dispatch_scheme: display or type name to the scheme type, unknown names listed", "[time][quick]") {
  CHECK(dispatch_scheme("BDF2/BDF2E", []<class S>() { return S::order; }) == 2);
  CHECK(dispatch_scheme("BDF3_BDF3E", []<class S>() { return S::order; }) == 3);
  CHECK(dispatch_scheme("BSS", []<class S>() { return std::string(S::name); }) == "BSS");
  int calls = 0;
  dispatch_scheme("MR_AB", [&]<class S>() { calls += S::theta == 0.5; });
  CHECK(calls == 1);
  CHECK_THROWS_WITH(dispatch_scheme("BDF4", []<class S>() {}, "--scheme"),
                    Catch::Contains("--scheme") && Catch::Contains("MR/AB, BDF2/BDF2E, BDF2/AB, BDF3/BDF3E, BSS"));
  CHECK(scheme_names() == "MR/AB, BDF2/BDF2E, BDF2/AB, BDF3/BDF3E, BSS");
}

namespace {
// One step of scheme S for u' = lambda u from exact past values e^{lambda t} on the history h
// (BDF of order l: sum_k a_k u^{n+1-k} = dt lambda u^{n+1}; MR/AB: the trapezoidal rule).
template <TimeScheme S>
Real one_step(const TimeHistory& h, Real dt, Real lambda, Real t0) {
  if constexpr (S::theta == 0.5) {
    return std::exp(lambda * t0) * (1 + dt * lambda / 2) / (1 - dt * lambda / 2);
  } else {
    const StepCoefficients c = step_coefficients<S>(dt, h);
    Real rhs = 0, t = t0;
    for (int k = 1; k <= c.flow_order; ++k) {
      rhs -= c.flow_bdf[std::size_t(k)] * std::exp(lambda * t);
      if (k < c.flow_order) t -= h.step(k - 1);
    }
    return rhs / (c.flow_bdf[0] - dt * lambda);
  }
}
// The ratio of the estimate to the true local error of that step.
template <TimeScheme S>
Real estimate_ratio(std::initializer_list<Real> past, Real dt, Real lambda) {
  const TimeHistory h = history(past);
  const Real t0 = h.now(), u1 = one_step<S>(h, dt, lambda, t0);
  const ErrorWeights w = error_weights<S>(dt, h);
  REQUIRE(w.available());
  Real p = 0, t = t0;
  for (int k = 0; k < w.points; ++k) {
    p += w.predictor[std::size_t(k)] * std::exp(lambda * t);
    if (k + 1 < w.points) t -= h.step(k);
  }
  return w.constant * (u1 - p) / (std::exp(lambda * (t0 + dt)) - u1);
}
}  // namespace

TEST_CASE("error estimate: the constants C / (E - C) with equal steps", "[time][error][quick]") {
  const TimeHistory h = history({0.1, 0.1, 0.1});
  CHECK(error_weights<BDF2_BDF2E>(0.1, h).constant == Approx(-2.0 / 11));
  CHECK(error_weights<BDF2_AB>(0.1, h).constant == Approx(-2.0 / 11));
  CHECK(error_weights<BDF3_BDF3E>(0.1, h).constant == Approx(-3.0 / 25));
  CHECK(error_weights<BSS>(0.1, h).constant == Approx(-1.0 / 3));
  // MR/AB: the predictor that reproduces quadratics and ignores the (-1)^j mode, 2, 0, -2, 1
  const ErrorWeights mr = error_weights<MR_AB>(0.1, h);
  CHECK(mr.constant == Approx(-1.0 / 25));
  CHECK(mr.predictor[0] == Approx(2));
  CHECK(std::abs(mr.predictor[1]) < 1e-12);
  CHECK(mr.predictor[2] == Approx(-2));
  CHECK(mr.predictor[3] == Approx(1));
  CHECK(!error_weights<MR_AB>(0.1, history({0.1, 0.1})).available());
  // the predictor of BDF3 reads four levels: 4, -6, 4, -1
  const ErrorWeights w = error_weights<BDF3_BDF3E>(0.1, h);
  CHECK(w.points == 4);
  CHECK(w.predictor[0] == Approx(4));
  CHECK(w.predictor[1] == Approx(-6));
  CHECK(w.predictor[2] == Approx(4));
  CHECK(w.predictor[3] == Approx(-1));
  // too few levels: no estimate
  CHECK(!error_weights<BDF3_BDF3E>(0.1, history({0.1, 0.1})).available());
  CHECK(error_weights<BSS>(0.1, history({0.1})).available());
}

TEMPLATE_TEST_CASE("error estimate: the estimate over the true local error tends to 1, equal and unequal steps",
                   "[time][error][quick]", MR_AB, BDF2_BDF2E, BDF2_AB, BDF3_BDF3E, BSS) {
  for (Real lambda : {1.0, -2.0}) {
    Real prev = 1, prev_equal = 1;
    for (Real dt : {0.04, 0.02, 0.01}) {
      const Real equal = estimate_ratio<TestType>({dt, dt, dt, dt}, dt, lambda);
      const Real unequal = estimate_ratio<TestType>({dt, 1.3 * dt, 0.8 * dt, 1.1 * dt}, 0.7 * dt, lambda);
      INFO(TestType::name << " lambda " << lambda << " dt " << dt << ": ratio " << equal << " (equal), " << unequal
                          << " (unequal)");
      // the ratio is 1 + O(dt): its distance from 1 halves with dt
      CHECK(std::abs(equal - 1) < 0.2);
      CHECK(std::abs(unequal - 1) < 0.2);
      if (dt < 0.04) CHECK(std::abs(unequal - 1) < 0.6 * prev);
      if (dt < 0.04) CHECK(std::abs(equal - 1) < 0.6 * prev_equal);
      prev = std::abs(unequal - 1), prev_equal = std::abs(equal - 1);
    }
  }
}

TEST_CASE("PI step controller: converges to the step that meets the tolerance, clips, shrinks on rejection",
          "[time][error][quick]") {
  // a model error r = (dt / dt*)^k, k = q + 1 = 3 (dt* meets the tolerance exactly): the
  // controller settles at r = safety, dt = safety^(1/k) dt*
  PiStepController pi(2, max_step_ratio<BDF2_BDF2E>());
  const Real dt_star = 1e-2;
  Real dt = 1e-4;
  for (int n = 0; n < 80; ++n) dt = pi.accepted(dt, true, std::pow(dt / dt_star, 3.0));
  CHECK(dt / dt_star == Approx(std::cbrt(PiStepController::safety)).epsilon(1e-6));
  CHECK(pi.last_error() == Approx(PiStepController::safety).epsilon(1e-5));
  // growth clipped at the zero-stability bound (2 for BDF2), never above 1 after a rejection
  PiStepController fresh(2, 2.0);
  CHECK(fresh.accepted(1.0, true, 1e-12) < 2.0);
  CHECK(fresh.accepted(1.0, true, 1e-12) == Approx(2.0).epsilon(1e-8));
  CHECK(fresh.accepted(1.0, true, 1e-12, true) <= 1.0);
  PiStepController bdf3(3, max_step_ratio<BDF3_BDF3E>());
  CHECK(bdf3.accepted(1.0, true, 1e-12) < 1.5);
  // no estimate: dt kept; rejection: shrink by safety r^(-1/k), at least to 0.2
  CHECK(pi.accepted(0.5, false, 0) == 0.5);
  CHECK(pi.rejected(1.0, 8.0) == Approx(std::cbrt(0.9 / 8)));
  CHECK(pi.rejected(1.0, 1e6) == Approx(0.2));
  CHECK_THROWS_AS(PiStepController(0, 2.0), InvalidArgument);
}
