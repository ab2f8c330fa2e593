// Steady Stokes: exactness on polynomial solutions, matrix properties, and manufactured-solution
// convergence rates in 2D and 3D for Taylor–Hood and P1/P1-GLS (rates from DOF counts).
#include <catch2/catch.hpp>

#include <cmath>
#include <iostream>
#include <numbers>

#include "alefsi/fem/norms.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/stokes.hpp"

using namespace alefsi;
using std::numbers::pi;

namespace {
constexpr Real mu = 0.7;

// 2D: u = curl(sin(pi x) sin(pi y) / pi), p = cos(pi x) cos(pi y); -lap u = 2 pi^2 u.
struct Exact2 {
  static Vec<2> u(const Vec<2>& x) {
    return {std::sin(pi * x[0]) * std::cos(pi * x[1]), -std::cos(pi * x[0]) * std::sin(pi * x[1])};
  }
  static Mat<2> grad(const Vec<2>& x) {
    const Real sx = std::sin(pi * x[0]), cx = std::cos(pi * x[0]), sy = std::sin(pi * x[1]), cy = std::cos(pi * x[1]);
    Mat<2> g;
    g << pi * cx * cy, -pi * sx * sy, pi * sx * sy, -pi * cx * cy;
    return g;
  }
  static Real p(const Vec<2>& x) { return std::cos(pi * x[0]) * std::cos(pi * x[1]); }
  static Vec<2> f(const Vec<2>& x) {
    const Vec<2> gp(-pi * std::sin(pi * x[0]) * std::cos(pi * x[1]), -pi * std::cos(pi * x[0]) * std::sin(pi * x[1]));
    return 2 * pi * pi * mu * u(x) + gp;
  }
};

// 3D: u = (s c c, c s c, -2 c c s), div u = 0, -lap u = 3 pi^2 u; p = c c c.
struct Exact3 {
  static Vec<3> u(const Vec<3>& x) {
    const Real s0 = std::sin(pi * x[0]), c0 = std::cos(pi * x[0]), s1 = std::sin(pi * x[1]), c1 = std::cos(pi * x[1]),
               s2 = std::sin(pi * x[2]), c2 = std::cos(pi * x[2]);
    return {s0 * c1 * c2, c0 * s1 * c2, -2 * c0 * c1 * s2};
  }
  static Mat<3> grad(const Vec<3>& x) {
    const Real s0 = std::sin(pi * x[0]), c0 = std::cos(pi * x[0]), s1 = std::sin(pi * x[1]), c1 = std::cos(pi * x[1]),
               s2 = std::sin(pi * x[2]), c2 = std::cos(pi * x[2]);
    Mat<3> g;
    g << c0 * c1 * c2, -s0 * s1 * c2, -s0 * c1 * s2,  //
        -s0 * s1 * c2, c0 * c1 * c2, -c0 * s1 * s2,   //
        2 * s0 * c1 * s2, 2 * c0 * s1 * s2, -2 * c0 * c1 * c2;
    return pi * g;
  }
  static Real p(const Vec<3>& x) { return std::cos(pi * x[0]) * std::cos(pi * x[1]) * std::cos(pi * x[2]); }
  static Vec<3> f(const Vec<3>& x) {
    const Real s0 = std::sin(pi * x[0]), c0 = std::cos(pi * x[0]), s1 = std::sin(pi * x[1]), c1 = std::cos(pi * x[1]),
               s2 = std::sin(pi * x[2]), c2 = std::cos(pi * x[2]);
    const Vec<3> gp = -pi * Vec<3>(s0 * c1 * c2, c0 * s1 * c2, c0 * c1 * s2);
    return 3 * pi * pi * mu * u(x) + gp;
  }
};

template <int D>
Mesh<D> unit_mesh(int n) {
  if constexpr (D == 2) return rectangle_mesh(n, n);
  else return box_mesh(n, n, n);
}

template <int D, class Pair, class Ex>
std::pair<Real, FlowErrors> solve_mms(int n) {
  const auto mesh = unit_mesh<D>(n);
  Stokes<D, Pair> stokes(mesh, mu, Ex::f);
  for (Index f : mesh.boundary_facets()) stokes.set_velocity(mesh.facet_tag(f), Ex::u);
  const VecX field = stokes.solve();
  const auto e = flow_errors<D, Pair>(stokes.space(), field, Ex::u, Ex::grad, Ex::p);
  return {Real(field.size()), e};
}

template <int D, class Pair, class Ex>
void convergence(std::vector<int> ns, Real ru, Real tol_u, Real rh1, Real tol_h1, Real rp_min) {
  std::vector<std::pair<Real, FlowErrors>> runs;
  for (int n : ns) runs.push_back(solve_mms<D, Pair, Ex>(n));
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const auto& [N, e] = runs[k];
    std::cout << D << "D " << Pair::name << " n=" << ns[k] << " dofs=" << N << "  |u-uh|_L2=" << e.u_l2
              << "  |u-uh|_H1=" << e.u_h1 << "  |p-ph|_L2=" << e.p_l2;
    if (k > 0) {
      const auto& [N0, e0] = runs[k - 1];
      std::cout << "  rates: " << observed_rate(N0, e0.u_l2, N, e.u_l2, D) << " " << observed_rate(N0, e0.u_h1, N, e.u_h1, D)
                << " " << observed_rate(N0, e0.p_l2, N, e.p_l2, D);
    }
    std::cout << "\n";
  }
  // asserted over the last two refinements
  const auto& [N0, e0] = runs[runs.size() - 2];
  const auto& [N1, e1] = runs.back();
  CHECK(observed_rate(N0, e0.u_l2, N1, e1.u_l2, D) == Approx(ru).margin(tol_u));
  CHECK(observed_rate(N0, e0.u_h1, N1, e1.u_h1, D) == Approx(rh1).margin(tol_h1));
  const Real rp = observed_rate(N0, e0.p_l2, N1, e1.p_l2, D);
  CHECK(rp >= rp_min);
}
}  // namespace

TEST_CASE("manufactured body forces match the exact solutions (finite-difference check)", "[stokes][quick]") {
  // -mu lap u + grad p = f, with lap by central differences
  const Real h = 1e-4;
  const Vec<2> x2(0.31, 0.77);
  Vec<2> lap2 = -4 * Exact2::u(x2);
  for (int d = 0; d < 2; ++d) {
    Vec<2> e = Vec<2>::Zero();
    e[d] = h;
    lap2 += Exact2::u(x2 + e) + Exact2::u(x2 - e);
  }
  lap2 /= h * h;
  const Vec<2> gp2((Exact2::p(x2 + Vec<2>(h, 0)) - Exact2::p(x2 - Vec<2>(h, 0))) / (2 * h),
                   (Exact2::p(x2 + Vec<2>(0, h)) - Exact2::p(x2 - Vec<2>(0, h))) / (2 * h));
  CHECK((-mu * lap2 + gp2 - Exact2::f(x2)).norm() < 1e-5);
  CHECK(Exact2::grad(x2).trace() == Approx(0).margin(1e-14));
  const Vec<3> x3(0.31, 0.77, 0.12);
  Vec<3> lap3 = -6 * Exact3::u(x3), gp3;
  for (int d = 0; d < 3; ++d) {
    Vec<3> e = Vec<3>::Zero();
    e[d] = h;
    lap3 += Exact3::u(x3 + e) + Exact3::u(x3 - e);
    gp3[d] = (Exact3::p(x3 + e) - Exact3::p(x3 - e)) / (2 * h);
    const Vec<3> fdg = (Exact3::u(x3 + e) - Exact3::u(x3 - e)) / (2 * h);
    CHECK((Exact3::grad(x3).col(d) - fdg).norm() < 1e-6);
  }
  lap3 /= h * h;
  CHECK((-mu * lap3 + gp3 - Exact3::f(x3)).norm() < 1e-5);
  CHECK(Exact3::grad(x3).trace() == Approx(0).margin(1e-14));
}

TEST_CASE("Taylor-Hood reproduces Poiseuille flow exactly (P2 velocity, P1 pressure)", "[stokes][quick]") {
  // u = (y (1 - y), 0), p = -2 mu x + c, f = 0 on a rectangle; walls, inflow and outflow given
  const auto mesh = rectangle_mesh(5, 3, 0.0, 2.0, 0.0, 1.0);
  Stokes<2, TaylorHood> stokes(mesh, mu);
  auto u = [](const Vec<2>& x) { return Vec<2>(x[1] * (1 - x[1]), 0.0); };
  for (int t = 1; t <= 4; ++t) stokes.set_velocity(t, u);
  const VecX field = stokes.solve();
  CHECK(stokes.pressure_pinned());
  const auto e = flow_errors<2, TaylorHood>(
      stokes.space(), field, u, [](const Vec<2>& x) { Mat<2> g; g << 0, 1 - 2 * x[1], 0, 0; return g; },
      [](const Vec<2>& x) { return -2 * mu * x[0]; });
  CHECK(e.u_l2 < 1e-12);
  CHECK(e.u_h1 < 1e-11);
  CHECK(e.p_l2 < 1e-11);
}

TEMPLATE_TEST_CASE("both pairs reproduce a linear flow exactly, 2D and 3D", "[stokes][quick]", TaylorHood, P1P1Gls) {
  SECTION("2D: u = (x, -y), p = 0") {
    const auto mesh = rectangle_mesh(4, 4);
    Stokes<2, TestType> s(mesh, mu);
    for (int t = 1; t <= 4; ++t) s.set_velocity(t, [](const Vec<2>& x) { return Vec<2>(x[0], -x[1]); });
    const VecX field = s.solve();
    const auto e = flow_errors<2, TestType>(
        s.space(), field, [](const Vec<2>& x) { return Vec<2>(x[0], -x[1]); },
        [](const Vec<2>&) { Mat<2> g; g << 1, 0, 0, -1; return g; }, [](const Vec<2>&) { return 0.0; });
    CHECK(e.u_l2 < 1e-12);
    CHECK(e.p_l2 < 1e-11);
  }
  SECTION("3D: u = (x, y, -2z), p = 0") {
    const auto mesh = box_mesh(2, 2, 2);
    Stokes<3, TestType> s(mesh, mu);
    auto u = [](const Vec<3>& x) { return Vec<3>(x[0], x[1], -2 * x[2]); };
    for (int t = 1; t <= 6; ++t) s.set_velocity(t, u);
    const VecX field = s.solve();
    const auto e = flow_errors<3, TestType>(
        s.space(), field, u, [](const Vec<3>&) { return Vec<3>(1, 1, -2).asDiagonal().toDenseMatrix().eval(); },
        [](const Vec<3>&) { return 0.0; });
    CHECK(e.u_l2 < 1e-12);
    CHECK(e.p_l2 < 1e-11);
  }
}

TEMPLATE_TEST_CASE("Stokes matrix is symmetric; velocity block positive definite", "[stokes][quick]", TaylorHood, P1P1Gls) {
  const auto mesh = rectangle_mesh(3, 3);
  MixedSpace<2, TestType> space(mesh);
  StokesKernel<2, TestType> k(space, mu);
  DofConstraints cons(space.n_field());
  for (Index f : mesh.boundary_facets())
    for (Index v : mesh.facet(f))
      if (cons.kind(space.velocity_field(v, 0)) == DofConstraints::Kind::free)
        for (int d = 0; d < 2; ++d) cons.fix(space.velocity_field(v, d), 0.0);
  cons.finalize();
  Assembler<MixedSpace<2, TestType>::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
  SparseMatrix J;
  VecX r;
  asmb.assemble(k, cons.expand(VecX::Zero(cons.n_unknowns())), &J, &r);
  const MatX A(J);
  CHECK((A - A.transpose()).norm() <= 1e-13 * A.norm());
  // the velocity-velocity block (first unknowns are velocity, pressure last) is SPD
  Index nvel = 0;
  for (Index f = 0; f < 2 * space.velocity().n_dofs(); ++f) nvel += cons.kind(f) == DofConstraints::Kind::free;
  Eigen::SelfAdjointEigenSolver<MatX> eig(A.topLeftCorner(nvel, nvel));
  CHECK(eig.eigenvalues().minCoeff() > 0);
}

TEST_CASE("BiCGSTAB+ILUT and SparseLU agree on a P1/P1-GLS problem", "[stokes][quick]") {
  const auto mesh = rectangle_mesh(12, 12);
  Stokes<2, P1P1Gls> s(mesh, mu, Exact2::f);
  for (int t = 1; t <= 4; ++t) s.set_velocity(t, Exact2::u);
  const VecX a = s.solve(SparseLu<>{});
  const VecX b = s.solve(BiCgStabIlut(1e-12));
  CHECK((a - b).norm() <= 1e-8 * a.norm());
}

TEST_CASE("bad Stokes input is rejected with the parameter named", "[stokes][quick]") {
  const auto mesh = rectangle_mesh(2, 2);
  REQUIRE_THROWS_WITH((Stokes<2, TaylorHood>(mesh, -1.0)), Catch::Contains("'mu'"));
  REQUIRE_THROWS_WITH((Stokes<2, TaylorHood>(mesh, std::nan(""))), Catch::Contains("'mu'"));
  Stokes<2, TaylorHood> s(mesh, 1.0);
  REQUIRE_THROWS_WITH(s.set_velocity(99, Exact2::u), Catch::Contains("'tag'"));
}

// Rates asserted over the last two refinements, with the bands stated here:
//   Taylor-Hood: |u|_L2 3 +- 0.2, |u|_H1 2 +- 0.15, |p|_L2 >= 1.85
//   P1/P1-GLS:   |u|_L2 2 +- 0.2, |u|_H1 1 +- 0.15, |p|_L2 >= 1.4
// The pressure gets a lower bound only: on these uniform meshes it superconverges before the
// asymptotic range (3D Taylor-Hood, n = 4, 8, 12: rates 3.71 then 2.83, falling towards 2;
// 3D P1/P1-GLS, n = 8, 16, 24: 1.32 then 1.62), which is no defect.
TEST_CASE("2D Taylor-Hood converges at rates 3 / 2 / 2", "[stokes][convergence]") {
  convergence<2, TaylorHood, Exact2>({8, 16, 32}, 3.0, 0.2, 2.0, 0.15, 1.85);
}
TEST_CASE("2D P1/P1-GLS converges at rates 2 / 1 / >= 1.4", "[stokes][convergence]") {
  convergence<2, P1P1Gls, Exact2>({16, 32, 64}, 2.0, 0.2, 1.0, 0.15, 1.4);
}
TEST_CASE("3D Taylor-Hood converges at rates 3 / 2 / 2", "[stokes][convergence]") {
  convergence<3, TaylorHood, Exact3>({4, 8, 12}, 3.0, 0.2, 2.0, 0.15, 1.85);
}
TEST_CASE("3D P1/P1-GLS converges at rates 2 / 1 / >= 1.4", "[stokes][convergence]") {
  convergence<3, P1P1Gls, Exact3>({8, 16, 24}, 2.0, 0.2, 1.0, 0.15, 1.4);
}
