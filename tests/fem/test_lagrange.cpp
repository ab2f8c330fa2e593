// Generic conformance test run on every Lagrange element (Dune testFE style), plus the
// concept checks of the fem module.
#include <catch2/catch.hpp>

#include <type_traits>

#include "alefsi/fem/concepts.hpp"
#include "alefsi/fem/element_pair.hpp"
#include "alefsi/fem/lagrange.hpp"

using namespace alefsi;

namespace {
template <int D>
Vec<D> sample_point(int k) {  // deterministic points inside the simplex
  Vec<D> x;
  for (int i = 0; i < D; ++i) x[i] = 0.11 + 0.07 * ((k * (i + 3)) % 5);
  return x / (x.sum() + 0.15 * (1 + k % 3));
}
}  // namespace

TEMPLATE_TEST_CASE("Lagrange element conformance", "[fem][lagrange][quick]", (Lagrange<2, 1>), (Lagrange<2, 2>),
                   (Lagrange<3, 1>), (Lagrange<3, 2>)) {
  using E = TestType;
  constexpr int D = E::dim;
  SECTION("basis is dual to nodal interpolation (Kronecker property)") {
    for (int j = 0; j < E::n_dofs; ++j) {
      const auto v = E::values(E::node(j));
      for (int i = 0; i < E::n_dofs; ++i) CHECK(v[i] == Approx(i == j ? 1.0 : 0.0).margin(1e-15));
    }
  }
  SECTION("partition of unity; gradients sum to zero") {
    for (int k = 0; k < 10; ++k) {
      const auto x = sample_point<D>(k);
      CHECK(E::values(x).sum() == Approx(1.0).epsilon(1e-15));
      CHECK(E::gradients(x).colwise().sum().norm() < 1e-14);
    }
  }
  SECTION("reproduces every polynomial of its degree exactly") {
    // p(x) = 1 + sum_i (i+2) x_i [+ sum_ij x_i x_j (i+j+1) for P2]
    auto p = [](const Vec<D>& x) {
      Real s = 1;
      for (int i = 0; i < D; ++i) s += (i + 2) * x[i];
      if (E::degree == 2)
        for (int i = 0; i < D; ++i)
          for (int j = 0; j < D; ++j) s += (i + j + 1) * x[i] * x[j];
      return s;
    };
    Eigen::Matrix<Real, E::n_dofs, 1> coef;
    for (int i = 0; i < E::n_dofs; ++i) coef[i] = p(E::node(i));
    for (int k = 0; k < 10; ++k) {
      const auto x = sample_point<D>(k);
      CHECK(E::values(x).dot(coef) == Approx(p(x)).epsilon(1e-14));
    }
  }
  SECTION("gradients and Hessians agree with central finite differences") {
    const Real h = 1e-6;
    for (int k = 0; k < 5; ++k) {
      const auto x = sample_point<D>(k);
      const auto g = E::gradients(x);
      for (int d = 0; d < D; ++d) {
        Vec<D> e = Vec<D>::Zero();
        e[d] = h;
        const auto fd = ((E::values(x + e) - E::values(x - e)) / (2 * h)).eval();
        for (int i = 0; i < E::n_dofs; ++i) CHECK(g(i, d) == Approx(fd[i]).margin(1e-8));
        const auto fdg = ((E::gradients(x + e) - E::gradients(x - e)) / (2 * h)).eval();
        for (int i = 0; i < E::n_dofs; ++i)
          for (int d2 = 0; d2 < D; ++d2) CHECK(E::hessian(i)(d2, d) == Approx(fdg(i, d2)).margin(1e-7));
      }
    }
  }
  SECTION("DOF entities: vertices first, then edges in local edge order") {
    for (int i = 0; i < E::n_dofs; ++i) {
      const auto ent = E::entity(i);
      if (i <= D) {
        CHECK(ent.kind == DofEntity::vertex);
        CHECK(E::node(i) == reference_vertex<D>(i));
      } else {
        CHECK(ent.kind == DofEntity::edge);
        const auto& ab = SimplexTopology<D>::edges[ent.local];
        CHECK((E::node(i) - 0.5 * (reference_vertex<D>(ab[0]) + reference_vertex<D>(ab[1]))).norm() < 1e-15);
      }
    }
  }
}

namespace {
struct NotAnElement {
  static constexpr int dim = 2;
};
struct NotAPair {  // the elements, no name, no stabilisation tag (the former `stabilised` flag)
  template <int D>
  using Velocity = Lagrange<D, 2>;
  template <int D>
  using Pressure = Lagrange<D, 1>;
  static constexpr bool stabilised = false;
};
struct PairWithFlagNotTag : NotAPair {  // a name, but `Stabilisation` is not a tag
  static constexpr const char* name = "P2/P1";
  using Stabilisation = bool;
};
struct TagWithoutName {};
struct PairWithUnnamedTag : LagrangePair<1, 1> {  // LagrangePair constrains its tag; this does not
  static constexpr const char* name = "P1/P1-?";
  using Stabilisation = TagWithoutName;
};
struct MyPair : LagrangePair<2, 1> {  // the minimal model of fem/concepts.hpp
  static constexpr const char* name = "P2/P1";
};
}  // namespace

TEST_CASE("concepts accept the models and reject wrong types", "[fem][concepts][quick]") {
  STATIC_REQUIRE(ScalarElement<Lagrange<2, 2>>);
  STATIC_REQUIRE(!ScalarElement<NotAnElement>);
  STATIC_REQUIRE(ElementPair<TaylorHood>);
  STATIC_REQUIRE(ElementPair<P1P1Gls>);
  STATIC_REQUIRE(ElementPair<MyPair>);
  STATIC_REQUIRE(!ElementPair<NotAPair>);
  STATIC_REQUIRE(!ElementPair<PairWithFlagNotTag>);
  STATIC_REQUIRE(!ElementPair<PairWithUnnamedTag>);
  STATIC_REQUIRE(!ElementPair<Lagrange<2, 1>>);
  STATIC_REQUIRE(StabilisationTag<NoStabilisation>);
  STATIC_REQUIRE(StabilisationTag<GlsStabilisation>);
  STATIC_REQUIRE(!StabilisationTag<TagWithoutName>);
  STATIC_REQUIRE(!StabilisationTag<bool>);
  // the pairs are compositions: the same P1 element, GLS on top for P1P1Gls only
  STATIC_REQUIRE(std::is_same_v<TaylorHood::Stabilisation, NoStabilisation>);
  STATIC_REQUIRE(std::is_same_v<P1P1Gls::Stabilisation, GlsStabilisation>);
  STATIC_REQUIRE(std::is_same_v<P1P1Gls::Velocity<3>, TaylorHood::Pressure<3>>);
}
