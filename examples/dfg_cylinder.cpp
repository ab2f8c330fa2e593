// dfg_cylinder — flow around a cylinder in a channel: the DFG benchmark of Schäfer & Turek (1996),
// cases 2D-1 (steady, Re = 20) and 2D-2 (periodic vortex shedding, Re = 100).
//
// What it shows: drag and lift on a body held fixed (a driven body with zero velocity), computed
// from the residual of the rows the body would have if it were free (BodySystem::driven_loads):
// the quantity the benchmark asks for, with the same code that couples free bodies.
//
// Set-up (the benchmark's): channel [0, 2.2] x [0, 0.41], cylinder of diameter D = 0.1 centred at
// (0.2, 0.2); rho = 1, nu = 1e-3; parabolic inflow u = 4 U y (0.41 - y) / 0.41^2 on the left,
// no-slip walls and cylinder, do-nothing outflow on the right. Case 1: U = 0.3 (mean 0.2,
// Re = 20), solved to steady state by backward-Euler steps. Case 2: U = 1.5 (mean 1, Re = 100),
// the inflow ramped over the first second, then run until the shedding is periodic.
// Reported: c_D = 2 F_x / (rho Um^2 D), c_L = 2 F_y / (rho Um^2 D) (Um the mean inflow speed),
// Delta p = p(0.15, 0.2) - p(0.25, 0.2); case 2: c_D,max and c_L,max over the last period, the
// Strouhal number St = D f / Um (f from the lift's zero crossings) and Delta p half a period after
// the lift's maximum.
// How to run: `dfg_cylinder --case 1` (seconds), `dfg_cylinder --case 2` (minutes); `--help` lists
// the options (pair, mesh sizes, dt, scheme, CSV of the time series).
// Expected: within the benchmark's reference intervals (docs/results.md): 2D-1 c_D in
// [5.57, 5.59], c_L in [0.0104, 0.0110], Delta p in [0.1172, 0.1176] (high-accuracy values
// 5.57953523384, 0.010618948146, 0.11752016697, John & Matthies 2001); 2D-2 c_D,max in
// [3.22, 3.24], c_L,max in [0.99, 1.01], St in [0.295, 0.305], Delta p in [2.46, 2.50].
#include <alefsi/alefsi.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using namespace alefsi;

namespace {

struct Sample {
  Real t, cd, cl, dp;
};

template <class Pair, class Scheme>
int simulate(int which, Real h_body, Real h_far, Real dt, Real t_end, const std::string& csv_path, bool newton) {
  const scenes::DfgCylinder scene{.U = which == 1 ? 0.3 : 1.5, .ramp_time = which == 1 ? 0.0 : 1.0};
  const Mesh<2> mesh = scene.mesh(h_body, h_far);
  using Flow = AleFlow<FlowConfig<2, Pair, Scheme>>;
  Flow flow(mesh, FlowOptions{.rho = 1, .mu = scene.nu, .linearisation = newton ? Linearisation::newton : Linearisation::semi_implicit});
  std::printf("DFG 2D-%d (Re = %g): %s, %s, %s; %ld nodes, %ld triangles, %ld unknowns; h at the cylinder %g\n", which,
              scene.reynolds(), Pair::name, Scheme::name, newton ? "Newton" : "semi-implicit", long(mesh.n_nodes()),
              long(mesh.n_cells()), long(flow.space().n_field()), h_body);
  scene.configure(flow);
  const PointLocator2D loc(flow.mesh());  // the mesh does not move
  std::vector<Sample> s;
  const auto wall0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  const int n = int(std::lround(t_end / dt));
  for (int k = 1; k <= n; ++k) {
    flow.step(dt);
    const Vec<2> c = scene.coefficients(flow.body_hydrodynamic_load(0));
    s.push_back({flow.time(), c[0], c[1], scenes::DfgCylinder::pressure_difference(flow, loc)});
    if (k % 100 == 0 || k == n)
      std::printf("  t %7.3f  c_D %.6f  c_L %+.6f  dp %.6f\n", s.back().t, s.back().cd, s.back().cl, s.back().dp);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const double cpu = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  if (!csv_path.empty()) {
    std::ofstream csv(csv_path);
    csv.precision(12);
    csv << "t,c_D,c_L,dp\n";
    for (const auto& x : s) csv << x.t << ',' << x.cd << ',' << x.cl << ',' << x.dp << '\n';
  }
  if (which == 1) {
    const Sample& e = s.back();
    const Sample& prev = s[s.size() - 2];
    std::printf("\n2D-1 | c_D %.6f | c_L %.6f | dp %.6f | (reference 5.57953523384, 0.010618948146, 0.11752016697) | change "
                "in the last step %.1e | %.1f s wall, %.1f s CPU\n",
                e.cd, e.cl, e.dp, std::abs(e.cd - prev.cd), wall, cpu);
    return 0;
  }
  // the last full periods: upward zero crossings of c_L
  std::vector<Real> up;
  for (std::size_t i = 1; i < s.size(); ++i)
    if (s[i - 1].cl < 0 && s[i].cl >= 0) up.push_back(s[i - 1].t + (s[i].t - s[i - 1].t) * (-s[i - 1].cl) / (s[i].cl - s[i - 1].cl));
  if (up.size() < 4) {
    std::printf("not periodic yet: %zu lift zero crossings; run longer (--t-end)\n", up.size());
    return 1;
  }
  const Real T = (up.back() - up[up.size() - 4]) / 3, f = 1 / T;
  const Real t0 = up[up.size() - 2], t1 = up.back();
  // maxima over [t0, t1], refined by the parabola through the largest sample and its neighbours
  auto peak = [&](auto get, Real* at) {
    std::size_t best = 0;
    for (std::size_t i = 1; i + 1 < s.size(); ++i)
      if (s[i].t >= t0 && s[i].t <= t1 && (best == 0 || get(s[i]) > get(s[best]))) best = i;
    const Real a = get(s[best - 1]), b = get(s[best]), c = get(s[best + 1]);
    const Real den = a - 2 * b + c, off = den != 0 ? 0.5 * (a - c) / den : 0;
    if (at) *at = s[best].t + off * (s[best + 1].t - s[best].t);
    return b - 0.25 * (a - c) * off;
  };
  Real t_lmax = 0;
  const Real cdmax = peak([](const Sample& x) { return x.cd; }, nullptr);
  const Real clmax = peak([](const Sample& x) { return x.cl; }, &t_lmax);
  const Real t_half = t_lmax + T / 2;
  Real dp = NAN;
  for (std::size_t i = 1; i < s.size(); ++i)
    if (s[i - 1].t <= t_half && s[i].t >= t_half) dp = s[i - 1].dp + (s[i].dp - s[i - 1].dp) * (t_half - s[i - 1].t) / (s[i].t - s[i - 1].t);
  std::printf("\n2D-2 | c_D,max %.5f | c_L,max %.5f | St %.5f | dp(t0 + T/2) %.5f | (intervals [3.22, 3.24], [0.99, 1.01], "
              "[0.295, 0.305], [2.46, 2.50]) | period %.5f | %.1f s wall, %.1f s CPU\n",
              cdmax, clmax, scene.diameter * f / scene.mean_speed(), dp, T, wall, cpu);
  return 0;
}

}  // namespace

int main(int argc, char** argv) try {
  int which = 1;
  std::string pair = "th", scheme, csv;
  Real h_body = 0.005, h_far = 0.04, dt = 0, t_end = 0;
  bool newton = false;
  Options opt("dfg_cylinder", "Flow around a cylinder (Schäfer & Turek 1996): case 1 (steady, Re = 20) or 2 (periodic, Re = 100).");
  opt.add("case", which, "1 (2D-1, steady) or 2 (2D-2, periodic)")
      .add("pair", pair, "th (P2/P1) or gls (P1/P1-GLS)")
      .add("h-body", h_body, "mesh size at the cylinder")
      .add("h-far", h_far, "largest mesh size")
      .add("dt", dt, "time step (0: 0.5 for case 1, 0.005 for case 2)")
      .add("t-end", t_end, "final time (0: 10 for case 1, 12 for case 2)")
      .add("scheme", scheme, "time scheme: BSS, BDF2/BDF2E or BDF3/BDF3E (default: BSS for case 1, BDF2/BDF2E for case 2)")
      .add("csv", csv, "CSV file of c_D, c_L and Delta p against t")
      .flag("newton", newton, "Newton's method (case 1 always uses it)");
  if (!opt.parse(argc, argv, std::cout)) return 0;
  opt.print(std::cout);
  ALEFSI_CHECK_ARG(which == 1 || which == 2, "--case", "1 or 2, got ", which);
  if (dt <= 0) dt = which == 1 ? 0.5 : 0.005;
  if (t_end <= 0) t_end = which == 1 ? 10 : 12;
  if (scheme.empty()) scheme = which == 1 ? "BSS" : "BDF2_BDF2E";
  if (which == 1) newton = true;
  // the schemes this benchmark is run with (each is a flow compiled for both pairs)
  using Schemes = SchemeList<BSS, BDF2_BDF2E, BDF3_BDF3E>;
  return dispatch_scheme<Schemes>(scheme, [&]<class S>() {
    if (pair == "th") return simulate<TaylorHood, S>(which, h_body, h_far, dt, t_end, csv, newton);
    if (pair == "gls") return simulate<P1P1Gls, S>(which, h_body, h_far, dt, t_end, csv, newton);
    throw InvalidArgument("--pair", "th or gls, got " + pair);
  }, "--scheme");
} catch (const std::exception& e) {
  std::fprintf(stderr, "dfg_cylinder: %s\n", e.what());
  return 1;
}
