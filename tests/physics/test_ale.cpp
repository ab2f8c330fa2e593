// ALE Navier-Stokes on moving meshes: geometric conservation, Newton's quadratic convergence
// and the temporal order of the five schemes, measured against exact solutions that lie in the
// finite-element space (so the spatial error is zero and only the time error remains).
#include <catch2/catch.hpp>

#include <cmath>
#include <iostream>
#include <numbers>

#include "alefsi/fem/norms.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/sim/ale_flow.hpp"
#include "alefsi/sim/driver.hpp"

using namespace alefsi;
using std::numbers::pi;

namespace {
constexpr Real rho = 1.3, mu = 0.4;

template <int D>
Mesh<D> unit_mesh(int n) {
  if constexpr (D == 2) return rectangle_mesh(n, n);
  else return box_mesh(n, n, n);
}

// Interior mesh motion, zero on the boundary of the unit square/cube.
template <int D>
Vec<D> wobble(const Vec<D>& x, Real t) {
  Real s = 1;
  for (int i = 0; i < D; ++i) s *= std::sin(pi * x[i]);
  Vec<D> v;
  v[0] = std::cos(pi * t);
  v[1] = std::sin(pi * t);
  if constexpr (D == 3) v[2] = 0.5 * std::cos(2 * pi * t);
  return 0.25 * s * v;
}

// Exact solutions in the FE space: g(t) times a quadratic (Taylor-Hood) or linear (P1/P1) field.
inline Real g(Real t) { return std::cos(2 * t) + 0.5; }
inline Real dg(Real t) { return -2 * std::sin(2 * t); }

template <int D, class Pair>
struct Exact {
  static constexpr bool quad = std::is_same_v<Pair, TaylorHood>;
  static Vec<D> shape(const Vec<D>& x) {  // divergence-free
    if constexpr (D == 2) return quad ? Vec<2>(x[1] * x[1], x[0] * x[0]) : Vec<2>(x[0], -x[1]);
    else return quad ? Vec<3>(x[1] * x[1], x[2] * x[2], x[0] * x[0]) : Vec<3>(x[0], x[1], -2 * x[2]);
  }
  static Mat<D> shape_grad(const Vec<D>& x) {
    Mat<D> G = Mat<D>::Zero();
    if constexpr (D == 2) {
      if (quad) G(0, 1) = 2 * x[1], G(1, 0) = 2 * x[0];
      else G(0, 0) = 1, G(1, 1) = -1;
    } else {
      if (quad) G(0, 1) = 2 * x[1], G(1, 2) = 2 * x[2], G(2, 0) = 2 * x[0];
      else G(0, 0) = 1, G(1, 1) = 1, G(2, 2) = -2;
    }
    return G;
  }
  static Vec<D> lap_shape() {
    Vec<D> l = Vec<D>::Zero();
    if (quad) l.setConstant(2.0);
    return l;
  }
  static Vec<D> u(const Vec<D>& x, Real t) { return g(t) * shape(x); }
  static Real p(const Vec<D>& x, Real t) { return g(t) * (x.sum() - 0.5 * D); }
  static Vec<D> f(const Vec<D>& x, Real t) {
    const Vec<D> s = shape(x);
    return rho * (dg(t) * s + g(t) * g(t) * shape_grad(x) * s) - mu * g(t) * lap_shape() + Vec<D>::Constant(g(t));
  }
};

// t_n of a grid of `steps` steps on [0, T]: uniform, or (`varied`) t = T phi(n / steps) with
// phi(s) = s + 0.3 sin(2 pi s) / (2 pi): steps between 0.7 and 1.3 times T / steps whose ratio
// tends to 1 as steps grows (a smoothly varying step sequence).
inline Real grid_time(int n, int steps, Real T, bool varied) {
  const Real s = Real(n) / steps;
  return varied ? T * (s + 0.3 * std::sin(2 * pi * s) / (2 * pi)) : T * s;
}

template <int D, class Pair, class Scheme>
Real run_mms(int steps, Real T, bool elastic, int n_mesh = 4, Linearisation lin = Linearisation::newton,
             bool varied = false) {
  using Ex = Exact<D, Pair>;
  FlowOptions opt{rho, mu, lin, 25, 1e-13};
  opt.variable_steps = varied;
  AleFlow<FlowConfig<D, Pair, Scheme>> flow(unit_mesh<D>(n_mesh), opt);
  for (int t = 1; t <= 2 * D; ++t) flow.set_velocity(t, Ex::u);
  if (elastic) {
    // the bottom wall's nodes slide along it; the interior follows by elasticity
    flow.set_mesh_velocity(tags::bottom, [](const Vec<D>& x, Real t) {
      Vec<D> v = Vec<D>::Zero();
      v[0] = 0.3 * std::sin(pi * x[0]) * std::cos(t);
      return v;
    });
  } else {
    flow.set_prescribed_mesh_velocity(wobble<D>);
  }
  flow.set_force(Ex::f);
  flow.set_initial_velocity([](const Vec<D>& x) { return Ex::u(x, 0.0); });
  // constant steps: the same dt every step (differences of t_n would differ in the last bit, and
  // each change of dt restarts the constant-step history)
  for (int n = 0; n < steps; ++n)
    flow.step(varied ? grid_time(n + 1, steps, T, true) - grid_time(n, steps, T, true) : T / steps);
  if (varied) CHECK(flow.stats().history_restarts == 0);
  const auto e = flow_errors<D, Pair>(
      flow.space(), flow.field(), [&](const Vec<D>& x) { return Ex::u(x, T); },
      [&](const Vec<D>& x) { return Mat<D>(g(T) * Ex::shape_grad(x)); }, [&](const Vec<D>& x) { return Ex::p(x, T); });
  return e.u_l2;
}

// The same flow, run adaptively to T by run() with the error tolerance `tol` from a first step
// of 1e-3; returns the L2 velocity error at T and the number of steps.
template <class Pair, class Scheme>
std::pair<Real, int> run_mms_adaptive(Real tol, Real T = 1.0) {
  constexpr int D = 2;
  using Ex = Exact<D, Pair>;
  AleFlow<FlowConfig<D, Pair, Scheme>> flow(unit_mesh<D>(4), FlowOptions{rho, mu, Linearisation::newton, 25, 1e-13});
  for (int t = 1; t <= 2 * D; ++t) flow.set_velocity(t, Ex::u);
  flow.set_prescribed_mesh_velocity(wobble<D>);
  flow.set_force(Ex::f);
  flow.set_initial_velocity([](const Vec<D>& x) { return Ex::u(x, 0.0); });
  RunOptions ro;
  ro.dt = 1e-5, ro.t_end = T, ro.tolerance = tol, ro.progress_every = 0, ro.log = nullptr;
  const RunSummary sum = run(flow, ro);
  CHECK(flow.time() == Approx(T).epsilon(1e-14));
  CHECK(flow.stats().history_restarts == 0);
  const auto e = flow_errors<D, Pair>(
      flow.space(), flow.field(), [&](const Vec<D>& x) { return Ex::u(x, T); },
      [&](const Vec<D>& x) { return Mat<D>(g(T) * Ex::shape_grad(x)); }, [&](const Vec<D>& x) { return Ex::p(x, T); });
  return {e.u_l2, sum.steps};
}

template <int D, class Pair, class Scheme>
void check_order(bool elastic, std::vector<int> steps, Real T = 1.0, int n_mesh = 4, bool varied = false) {
  std::vector<Real> err;
  for (int s : steps) err.push_back(run_mms<D, Pair, Scheme>(s, T, elastic, n_mesh, Linearisation::newton, varied));
  std::cout << D << "D " << Pair::name << " " << Scheme::name << (elastic ? " (elastic mesh)" : " (prescribed mesh)")
            << (varied ? ", variable steps" : "") << ": ";
  for (std::size_t k = 0; k < err.size(); ++k) {
    std::cout << "dt=T/" << steps[k] << " e=" << err[k];
    if (k > 0) std::cout << " (" << std::log(err[k - 1] / err[k]) / std::log(Real(steps[k]) / steps[k - 1]) << ")";
    std::cout << "  ";
  }
  std::cout << "\n";
  const std::size_t m = err.size();
  const Real rate = std::log(err[m - 2] / err[m - 1]) / std::log(Real(steps[m - 1]) / steps[m - 2]);
  CHECK(rate == Approx(Scheme::order).margin(0.15));
}
}  // namespace

TEMPLATE_TEST_CASE("geometric conservation: a uniform flow stays exact on a moving mesh", "[ale][quick]", MR_AB,
                   BDF2_BDF2E, BDF2_AB, BDF3_BDF3E, BSS) {
  const Vec<2> U(1.0, -0.5);
  auto run = [&](auto pair_tag, bool elastic, bool variable = false) {
    using Pair = decltype(pair_tag);
    AleFlow<FlowConfig<2, Pair, TestType>> flow(rectangle_mesh(5, 5),
                                                FlowOptions{.rho = rho, .mu = mu, .variable_steps = variable});
    for (int t = 1; t <= 4; ++t) flow.set_velocity(t, [&](const Vec<2>&, Real) { return U; });
    if (elastic)
      flow.set_mesh_velocity(tags::bottom, [](const Vec<2>& x, Real t) { return Vec<2>(0.4 * std::sin(pi * x[0]) * std::cos(3 * t), 0); });
    else
      flow.set_prescribed_mesh_velocity(wobble<2>);
    flow.set_initial_velocity([&](const Vec<2>&) { return U; });
    Real moved = 0;
    for (int n = 0; n < 12; ++n) flow.step(0.05);
    if (variable) {  // then steps that shrink and grow within the ratio bound, keeping the history
      for (Real dt : {0.03, 0.02, 0.029, 0.04, 0.05, 0.06, 0.045}) flow.step(dt);
      CHECK(flow.stats().history_restarts == 0);
    }
    for (Index i = 0; i < flow.mesh().n_nodes(); ++i) moved = std::max(moved, (flow.mesh().node(i) - rectangle_mesh(5, 5).node(i)).norm());
    CHECK(moved > 0.01);  // the mesh really moved
    Real err = 0, perr = 0;
    for (Index i = 0; i < flow.space().velocity().n_dofs(); ++i)
      for (int k = 0; k < 2; ++k) err = std::max(err, std::abs(flow.field()[flow.space().velocity_field(i, k)] - U[k]));
    for (Index i = 0; i < flow.space().pressure().n_dofs(); ++i)
      perr = std::max(perr, std::abs(flow.field()[flow.space().pressure_field(i)]));
    CHECK(err < 1e-12);
    CHECK(perr < 1e-11);
  };
  run(TaylorHood{}, false);
  run(TaylorHood{}, true);
  run(P1P1Gls{}, false);
  run(P1P1Gls{}, true);
  run(TaylorHood{}, true, true);
  run(P1P1Gls{}, false, true);
}

TEST_CASE("Newton converges quadratically with the exact Jacobian", "[ale][quick]") {
  using Ex = Exact<2, TaylorHood>;
  for (int pass = 0; pass < 2; ++pass) {
    auto check = [&](auto& flow) {
      for (int t = 1; t <= 4; ++t) flow.set_velocity(t, Ex::u);
      flow.set_prescribed_mesh_velocity(wobble<2>);
      flow.set_force([](const Vec<2>& x, Real t) { return Vec<2>(40 * Ex::f(x, t)); });
      flow.set_initial_velocity([](const Vec<2>& x) { return Ex::u(x, 0.0); });
      const auto rep = flow.step(0.2);
      const auto& r = rep.residuals;
      INFO("residuals: " << r[0] << " " << (r.size() > 1 ? r[1] : 0) << " " << (r.size() > 2 ? r[2] : 0) << " "
                         << (r.size() > 3 ? r[3] : 0));
      // order of convergence from the last three residuals above round-off:
      // q = log(r_{k+1} / r_k) / log(r_k / r_{k-1}) -> 2 for Newton with the exact Jacobian
      std::size_t m = 0;
      while (m < r.size() && r[m] > 1e-9 * r[0]) ++m;
      REQUIRE(m >= 3);
      const Real q = std::log(r[m - 1] / r[m - 2]) / std::log(r[m - 2] / r[m - 3]);
      CHECK(q > 1.8);
    };
    if (pass == 0) {
      AleFlow<FlowConfig<2, TaylorHood, BDF2_BDF2E>> flow(rectangle_mesh(4, 4), FlowOptions{rho, 0.01, Linearisation::newton, 25, 1e-14});
      check(flow);
    } else {
      AleFlow<FlowConfig<2, P1P1Gls, BDF2_BDF2E>> flow(rectangle_mesh(6, 6), FlowOptions{rho, 0.01, Linearisation::newton, 25, 1e-14});
      check(flow);
    }
  }
}

// Temporal order within 0.15 of the design order over the last two refinements of dt.
TEMPLATE_TEST_CASE("2D Taylor-Hood: every scheme reaches its design order in time", "[ale][convergence]", MR_AB,
                   BDF2_BDF2E, BDF2_AB, BDF3_BDF3E, BSS) {
  check_order<2, TaylorHood, TestType>(false, {10, 20, 40, 80});
  check_order<2, TaylorHood, TestType>(true, {10, 20, 40, 80});
}
// P1/P1-GLS, on an 8 x 8 mesh. tau = [(2 rho/dt)^2 + ...]^(-1/2) -> dt / (2 rho) as dt -> 0, so
// the stabilised spatial operator changes with dt: the velocity error at T is dt^p F(tau(dt)),
// F(tau) the error constant of the same scheme with tau frozen, and the measured rate is
// p + dlnF/dlntau. (Without the 2 rho/dt term in tau the rates are p +- 0.003 at dt = T/1280 on
// 4 x 4; there, for BDF2/BDF2E, e N^2 equals F(tau_N) from frozen-tau runs to 3 digits for
// N = 40..5120.) As tau -> 0 the method tends to Galerkin P1/P1, whose discretely divergence-free
// interior velocities on this n x n mesh span (n - 3)^2 dimensions. On 4 x 4 the velocity locks:
// F(tau) ~ tau for tau < 1e-7, the rates of the theta = 1 schemes lie above p and tend to p + 1
// (BDF2/BDF2E 2.24 at dt = T/640, 2.57 at T/5120; BSS 1.13), so the design order is not the
// asymptotic rate there. On 8 x 8 (25 dimensions) F(0) != 0 and dlnF/dlntau < 0.06 for
// tau < 1e-2: every scheme is within 0.06 of its design order at dt = T/320, with the prescribed
// and with the elastic mesh motion. (MR/AB's F hardly depends on tau: 2.00 on either mesh.)
TEMPLATE_TEST_CASE("2D P1/P1-GLS: every scheme reaches its design order in time", "[ale][convergence]", MR_AB,
                   BDF2_BDF2E, BDF2_AB, BDF3_BDF3E, BSS) {
  check_order<2, P1P1Gls, TestType>(false, {20, 40, 80, 160, 320}, 1.0, 8);
  check_order<2, P1P1Gls, TestType>(true, {20, 40, 80, 160, 320}, 1.0, 8);
}
// Variable steps (FlowOptions::variable_steps): the step sizes follow a smooth function of
// time (grid_time: 0.7..1.3 times T/N, changing every step), the history is never restarted,
// and the variable-step formulas (time/stepper.hpp) keep every scheme's design order.
TEMPLATE_TEST_CASE("2D Taylor-Hood: every scheme keeps its design order with smoothly varying steps",
                   "[ale][convergence]", MR_AB, BDF2_BDF2E, BDF2_AB, BDF3_BDF3E, BSS) {
  check_order<2, TaylorHood, TestType>(false, {10, 20, 40, 80, 160}, 1.0, 4, true);
  check_order<2, TaylorHood, TestType>(true, {10, 20, 40, 80, 160}, 1.0, 4, true);
}
TEMPLATE_TEST_CASE("3D Taylor-Hood: design order in time", "[ale][convergence]", BDF2_BDF2E, BDF3_BDF3E) {
  check_order<3, TaylorHood, TestType>(false, {10, 20, 40, 80}, 1.0, 2);
}

TEMPLATE_TEST_CASE("semi-implicit (extrapolated convection, one solve per step) keeps the design order",
                   "[ale][convergence]", MR_AB, BDF2_BDF2E, BDF3_BDF3E, BSS) {
  std::vector<int> steps{10, 20, 40, 80};
  std::vector<Real> err;
  for (int s : steps) err.push_back(run_mms<2, TaylorHood, TestType>(s, 1.0, false, 4, Linearisation::semi_implicit));
  std::cout << "2D P2/P1 " << TestType::name << " semi-implicit:";
  for (std::size_t k = 0; k < err.size(); ++k) std::cout << " " << err[k];
  const Real rate = std::log(err[2] / err[3]) / std::log(2.0);
  std::cout << "  rate " << rate << "\n";
  CHECK(rate == Approx(TestType::order).margin(0.15));
}

namespace {
// Kovasznay flow (steady Navier-Stokes), Re = rho / mu = 40 on [-0.5, 1] x [-0.5, 1.5].
constexpr Real kov_re = 40;
inline Real kov_lambda() { return kov_re / 2 - std::sqrt(kov_re * kov_re / 4 + 4 * pi * pi); }
Vec<2> kov_u(const Vec<2>& x) {
  const Real l = kov_lambda(), e = std::exp(l * x[0]);
  return {1 - e * std::cos(2 * pi * x[1]), l / (2 * pi) * e * std::sin(2 * pi * x[1])};
}
Mat<2> kov_grad(const Vec<2>& x) {
  const Real l = kov_lambda(), e = std::exp(l * x[0]), c = std::cos(2 * pi * x[1]), s = std::sin(2 * pi * x[1]);
  Mat<2> g;
  g << -l * e * c, 2 * pi * e * s, l * l / (2 * pi) * e * s, l * e * c;
  return g;
}
Real kov_p(const Vec<2>& x) { return 0.5 * (1 - std::exp(2 * kov_lambda() * x[0])); }

template <class Pair>
std::pair<Real, FlowErrors> kovasznay(int n) {
  // one backward-Euler step with dt -> infinity is Newton's method for the steady problem
  AleFlow<FlowConfig<2, Pair, BSS>> flow(rectangle_mesh(n, n * 4 / 3, -0.5, 1.0, -0.5, 1.5),
                             FlowOptions{1.0, 1.0 / kov_re, Linearisation::newton, 30, 1e-12});
  for (int t = 1; t <= 4; ++t) flow.set_velocity(t, [](const Vec<2>& x, Real) { return kov_u(x); });
  flow.step(1e14);
  return {Real(flow.field().size()), flow_errors<2, Pair>(flow.space(), flow.field(), kov_u, kov_grad, kov_p)};
}
}  // namespace

TEMPLATE_TEST_CASE("steady Navier-Stokes (Kovasznay, Re = 40): spatial rates", "[ale][convergence]", TaylorHood, P1P1Gls) {
  constexpr bool th = std::is_same_v<TestType, TaylorHood>;
  const std::vector<int> ns = th ? std::vector<int>{12, 24, 48} : std::vector<int>{24, 48, 96};
  std::vector<std::pair<Real, FlowErrors>> runs;
  for (int n : ns) runs.push_back(kovasznay<TestType>(n));
  for (std::size_t k = 0; k < runs.size(); ++k) {
    std::cout << "Kovasznay " << TestType::name << " n=" << ns[k] << " dofs=" << runs[k].first << " u_L2=" << runs[k].second.u_l2
              << " u_H1=" << runs[k].second.u_h1 << " p_L2=" << runs[k].second.p_l2;
    if (k > 0)
      std::cout << "  rates " << observed_rate(runs[k - 1].first, runs[k - 1].second.u_l2, runs[k].first, runs[k].second.u_l2, 2)
                << " " << observed_rate(runs[k - 1].first, runs[k - 1].second.u_h1, runs[k].first, runs[k].second.u_h1, 2)
                << " " << observed_rate(runs[k - 1].first, runs[k - 1].second.p_l2, runs[k].first, runs[k].second.p_l2, 2);
    std::cout << "\n";
  }
  const auto& [N0, e0] = runs[1];
  const auto& [N1, e1] = runs[2];
  CHECK(observed_rate(N0, e0.u_l2, N1, e1.u_l2, 2) == Approx(th ? 3.0 : 2.0).margin(0.2));
  CHECK(observed_rate(N0, e0.u_h1, N1, e1.u_h1, 2) == Approx(th ? 2.0 : 1.0).margin(0.15));
  CHECK(observed_rate(N0, e0.p_l2, N1, e1.p_l2, 2) >= (th ? 1.85 : 1.4));
}

TEST_CASE("a step whose Newton iteration fails is rejected and leaves the state at t^n", "[ale][quick]") {
  using Ex = Exact<2, TaylorHood>;
  AleFlow<FlowConfig<2, TaylorHood, BDF2_BDF2E>> flow(rectangle_mesh(4, 4), FlowOptions{rho, 0.01, Linearisation::newton, 1, 1e-14});
  for (int t = 1; t <= 4; ++t) flow.set_velocity(t, Ex::u);
  flow.set_prescribed_mesh_velocity(wobble<2>);
  flow.set_force([](const Vec<2>& x, Real t) { return Vec<2>(40 * Ex::f(x, t)); });
  flow.set_initial_velocity([](const Vec<2>& x) { return Ex::u(x, 0.0); });
  const auto x0 = flow.mesh().coordinates();
  const VecX u0 = flow.field();
  REQUIRE_THROWS_WITH(flow.step(0.2), Catch::Contains("Newton did not converge"));
  CHECK(flow.time() == 0.0);
  CHECK(flow.field() == u0);
  for (Index i = 0; i < flow.mesh().n_nodes(); ++i) CHECK(flow.mesh().node(i) == x0[i]);
  REQUIRE_THROWS_AS(flow.step(-1.0), InvalidArgument);
}

// Adaptive steps (run() with RunOptions::tolerance): the controller holds the estimated local
// error per step at the tolerance, so the steps scale as tol^(1/(q+1)) and the error at T as
// tol^(q/(q+1)) (tolerance proportionality, Hairer, Norsett & Wanner I, II.4): the estimate
// (time/error_estimate.hpp) measures the scheme's real local error.
TEMPLATE_TEST_CASE("adaptive steps: the error at T is proportional to tol^(q/(q+1)), the step count to tol^(-1/(q+1))",
                   "[ale][adaptive][convergence]", BDF2_BDF2E, BDF2_AB, BDF3_BDF3E, BSS) {
  constexpr int q = TestType::order;
  const std::vector<Real> tols = q == 1 ? std::vector<Real>{1e-3, 1e-4, 1e-5} : std::vector<Real>{1e-5, 1e-6, 1e-7};
  std::vector<Real> err;
  std::vector<int> steps;
  for (Real tol : tols) {
    const auto [e, n] = run_mms_adaptive<TaylorHood, TestType>(tol);
    err.push_back(e), steps.push_back(n);
  }
  std::cout << "adaptive " << TestType::name << ":";
  for (std::size_t k = 0; k < tols.size(); ++k) std::cout << " tol " << tols[k] << " e " << err[k] << " steps " << steps[k];
  const Real p_err = std::log10(err[1] / err[2]), p_steps = std::log10(Real(steps[2]) / steps[1]);
  std::cout << "; error ~ tol^" << p_err << ", steps ~ tol^-" << p_steps << "\n";
  CHECK(p_err == Approx(Real(q) / (q + 1)).margin(0.1));
  CHECK(p_steps == Approx(1.0 / (q + 1)).margin(0.1));
}

// MR/AB under steps that jump (1.2, 0.8, 1.2, ... times T/N, not a smooth sequence): the jumps
// excite the midpoint rule's undamped (-1)^n mode and the scheme is only first order (BDF2 keeps
// its second order on the same sequence); run() refuses it for adaptive steps.
TEST_CASE("MR/AB is first order when the steps jump; adaptive runs refuse it", "[ale][adaptive][convergence]") {
  auto jumpy = [](auto scheme, int N) {
    using S = decltype(scheme);
    using Ex = Exact<2, TaylorHood>;
    AleFlow<FlowConfig<2, TaylorHood, S>> flow(unit_mesh<2>(4), FlowOptions{rho, mu, Linearisation::newton, 25, 1e-13});
    for (int t = 1; t <= 4; ++t) flow.set_velocity(t, Ex::u);
    flow.set_prescribed_mesh_velocity(wobble<2>);
    flow.set_force(Ex::f);
    flow.set_initial_velocity([](const Vec<2>& x) { return Ex::u(x, 0.0); });
    for (int n = 0; n < N; ++n) flow.step((n % 2 ? 0.8 : 1.2) / N);
    const Real T = flow.time();
    return flow_errors<2, TaylorHood>(
               flow.space(), flow.field(), [&](const Vec<2>& x) { return Ex::u(x, T); },
               [&](const Vec<2>& x) { return Mat<2>(g(T) * Ex::shape_grad(x)); }, [&](const Vec<2>& x) { return Ex::p(x, T); })
        .u_l2;
  };
  const Real mr = std::log2(jumpy(MR_AB{}, 40) / jumpy(MR_AB{}, 80));
  const Real bdf2 = std::log2(jumpy(BDF2_BDF2E{}, 40) / jumpy(BDF2_BDF2E{}, 80));
  std::cout << "jumping steps: MR/AB rate " << mr << ", BDF2/BDF2E rate " << bdf2 << "\n";
  CHECK(mr == Approx(1.0).margin(0.15));
  CHECK(bdf2 > 1.7);
  AleFlow<FlowConfig<2, TaylorHood, MR_AB>> flow(unit_mesh<2>(2), FlowOptions{rho, mu});
  RunOptions ro;
  ro.t_end = 0.1, ro.tolerance = 1e-4, ro.log = nullptr;
  CHECK_THROWS_WITH(run(flow, ro), Catch::Contains("tolerance") && Catch::Contains("not L-stable"));
}
