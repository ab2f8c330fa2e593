// Tests of fem/quadrature.hpp: exactness on monomials, true degree, positivity, inclusion.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <thread>
#include <vector>

#include "alefsi/fem/quadrature.hpp"

using namespace alefsi;

namespace {

Real factorial(int n) {
  Real f = 1;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

/// Exponent tuples of total degree exactly p in D variables.
template <int D>
std::vector<std::array<int, D>> exponents(int p) {
  std::vector<std::array<int, D>> out;
  std::array<int, D> e{};
  auto rec = [&](auto&& self, int k, int left) -> void {
    if (k == D - 1) {
      e[k] = left;
      out.push_back(e);
      return;
    }
    for (int i = 0; i <= left; ++i) {
      e[k] = i;
      self(self, k + 1, left - i);
    }
  };
  rec(rec, 0, p);
  return out;
}

/// Integral of x^e over the reference simplex: prod e_i! / (|e| + D)!.
template <int D>
Real exact_monomial(const std::array<int, D>& e) {
  Real num = 1;
  int sum = 0;
  for (int i = 0; i < D; ++i) num *= factorial(e[i]), sum += e[i];
  return num / factorial(sum + D);
}

/// Largest relative error over all monomials of total degree exactly p.
template <int D>
Real max_relative_error(const QuadratureRule<D>& q, int p) {
  // powers[point][dim][k] = x^k
  std::vector<std::array<std::vector<Real>, D>> pw(q.size());
  for (int i = 0; i < q.size(); ++i)
    for (int d = 0; d < D; ++d) {
      pw[i][d].resize(p + 1);
      pw[i][d][0] = 1;
      for (int k = 1; k <= p; ++k) pw[i][d][k] = pw[i][d][k - 1] * q.points[i][d];
    }
  Real worst = 0;
  for (const auto& e : exponents<D>(p)) {
    Real s = 0;
    for (int i = 0; i < q.size(); ++i) {
      Real m = q.weights[i];
      for (int d = 0; d < D; ++d) m *= pw[i][d][e[d]];
      s += m;
    }
    const Real ref = exact_monomial<D>(e);
    worst = std::max(worst, std::abs(s - ref) / ref);
  }
  return worst;
}

template <int D>
void check_rule(const QuadratureRule<D>& q) {
  INFO("D = " << D << ", rule degree " << q.degree << ", " << q.size() << " points");
  REQUIRE(q.size() > 0);
  REQUIRE(q.weights.size() == q.points.size());
  Real wsum = 0;
  for (int i = 0; i < q.size(); ++i) {
    CHECK(q.weights[i] > 0);
    wsum += q.weights[i];
    Real csum = 0;
    for (int d = 0; d < D; ++d) {
      CHECK(q.points[i][d] >= 0);
      csum += q.points[i][d];
    }
    CHECK(csum <= 1 + 1e-15);
  }
  CHECK(std::abs(wsum - reference_measure<D>) <= 1e-14 * reference_measure<D>);
  for (int p = 0; p <= q.degree; ++p) {
    INFO("monomials of degree " << p);
    CHECK(max_relative_error<D>(q, p) <= 1e-13);
  }
  // The claimed degree is the true one: some monomial of degree + 1 is not integrated exactly.
  // (In 1D that error of Gauss-Legendre falls towards round-off, ~3e-11 at 10 points, so there
  // the check stops at degree 15; on triangles and tetrahedra it stays >= 1e-8 up to degree 23.)
  if (D > 1 || q.degree <= 15) CHECK(max_relative_error<D>(q, q.degree + 1) > 1e-11);
}

template <int D>
void check_all_degrees(int max_degree) {
  for (int degree = 0; degree <= max_degree; ++degree) {
    INFO("requested degree " << degree);
    const QuadratureRule<D>& q = simplex_quadrature<D>(degree);
    CHECK(q.degree >= degree);
    check_rule<D>(q);
    // Same cached object on every call.
    CHECK(&simplex_quadrature<D>(degree) == &q);
  }
}

}  // namespace

TEST_CASE("interval rules are exact to their degree", "[fem][quadrature]") {
  check_all_degrees<1>(20);
  CHECK(simplex_quadrature<1>(0).size() == 1);
  CHECK(simplex_quadrature<1>(5).size() == 3);
  CHECK(simplex_quadrature<1>(20).size() == 11);
}

TEST_CASE("triangle rules are exact to their degree", "[fem][quadrature]") {
  check_all_degrees<2>(20);
}

TEST_CASE("tetrahedron rules are exact to their degree", "[fem][quadrature]") {
  check_all_degrees<3>(20);
}

TEST_CASE("point counts of the tabulated rules", "[fem][quadrature]") {
  const std::array<int, 11> tri{1, 1, 3, 6, 6, 7, 12, 12, 16, 19, 25};
  for (int d = 0; d <= 10; ++d) {
    INFO("triangle degree " << d);
    CHECK(simplex_quadrature<2>(d).size() == tri[d]);
  }
  CHECK(simplex_quadrature<2>(11).size() == 36);
  const std::array<int, 8> tet{1, 1, 4, 8, 14, 14, 24, 64};
  for (int d = 0; d <= 7; ++d) {
    INFO("tetrahedron degree " << d);
    CHECK(simplex_quadrature<3>(d).size() == tet[d]);
  }
}

TEST_CASE("explicit Gauss-Legendre and collapsed Gauss-Jacobi rules", "[fem][quadrature]") {
  for (int n = 1; n <= 16; ++n) {
    INFO("n = " << n);
    const auto g = gauss_legendre(n);
    CHECK(g.size() == n);
    CHECK(g.degree == 2 * n - 1);
    check_rule<1>(g);
  }
  for (int n = 1; n <= 12; ++n) {
    INFO("n = " << n);
    const auto t = collapsed_gauss_jacobi<2>(n);
    CHECK(t.size() == n * n);
    check_rule<2>(t);
  }
  for (int n = 1; n <= 8; ++n) {
    INFO("n = " << n);
    const auto t = collapsed_gauss_jacobi<3>(n);
    CHECK(t.size() == n * n * n);
    check_rule<3>(t);
  }
  // Known values: 2-point Gauss-Legendre on [0,1].
  const auto g2 = gauss_legendre(2);
  CHECK(g2.points[0][0] == Approx(0.5 - 0.5 / std::sqrt(3.0)).epsilon(1e-15));
  CHECK(g2.weights[1] == Approx(0.5).epsilon(1e-15));
}

TEST_CASE("bad degrees and point counts throw InvalidArgument", "[fem][quadrature]") {
  CHECK_THROWS_AS(simplex_quadrature<2>(-1), InvalidArgument);
  CHECK_THROWS_AS(simplex_quadrature<3>(max_quadrature_degree + 1), InvalidArgument);
  CHECK_THROWS_AS(simplex_quadrature<1>(1000), InvalidArgument);
  try {
    simplex_quadrature<2>(-3);
    FAIL("no exception");
  } catch (const InvalidArgument& e) {
    CHECK(e.parameter() == "degree");
  }
  CHECK_THROWS_AS(gauss_legendre(0), InvalidArgument);
  CHECK_THROWS_AS(collapsed_gauss_jacobi<2>(0), InvalidArgument);
  CHECK_NOTHROW(simplex_quadrature<3>(max_quadrature_degree));
}

TEST_CASE("concurrent first use returns one cached rule", "[fem][quadrature]") {
  const QuadratureRule<3>* seen[2] = {nullptr, nullptr};
  std::thread t0([&] { seen[0] = &simplex_quadrature<3>(13); });
  std::thread t1([&] { seen[1] = &simplex_quadrature<3>(13); });
  t0.join();
  t1.join();
  CHECK(seen[0] == seen[1]);
  CHECK(seen[0]->size() == 7 * 7 * 7);
}
