// Mesh data structure, topology, geometry, validation and the structured generators.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/mesh/mesh.hpp"

using namespace alefsi;
using Catch::Matchers::Contains;

TEST_CASE("rectangle mesh: counts, Euler characteristic, area, tags", "[mesh][quick]") {
  const int nx = GENERATE(1, 3, 7), ny = GENERATE(1, 4);
  const auto m = rectangle_mesh(nx, ny, -1.0, 2.0, 0.5, 1.5);
  CHECK(m.n_nodes() == (nx + 1) * (ny + 1));
  CHECK(m.n_cells() == 2 * nx * ny);
  // Euler: V - E + F = 1 for a disk
  CHECK(m.n_nodes() - m.n_edges() + m.n_cells() == 1);
  CHECK(m.n_facets() == m.n_edges());
  CHECK(m.total_measure() == Approx(3.0).epsilon(1e-14));
  CHECK(m.boundary_facets().size() == std::size_t(2 * (nx + ny)));
  Real len[5] = {0, 0, 0, 0, 0};
  for (Index f : m.boundary_facets()) len[m.facet_tag(f)] += m.facet_measure(f);
  CHECK(len[0] == 0);
  CHECK(len[tags::bottom] == Approx(3.0));
  CHECK(len[tags::top] == Approx(3.0));
  CHECK(len[tags::left] == Approx(1.0));
  CHECK(len[tags::right] == Approx(1.0));
  for (Index c = 0; c < m.n_cells(); ++c) CHECK(m.signed_measure(c) > 0);
}

TEST_CASE("outward normals integrate to zero over a closed boundary", "[mesh][quick]") {
  const auto m2 = annulus_mesh(0.3, 1.0, 3, 40);
  Vec<2> s2 = Vec<2>::Zero();
  for (Index f : m2.boundary_facets()) s2 += m2.facet_measure(f) * m2.facet_normal(f);
  CHECK(s2.norm() < 1e-13);
  // on the outer circle the normal points away from the centre, on the inner towards it
  for (Index f : m2.boundary_facets()) {
    const Vec<2> mid = 0.5 * (m2.node(m2.facet(f)[0]) + m2.node(m2.facet(f)[1]));
    const Real s = mid.dot(m2.facet_normal(f));
    CHECK((m2.facet_tag(f) == tags::outer ? s > 0 : s < 0));
  }
  const auto m3 = box_mesh(2, 3, 2);
  Vec<3> s3 = Vec<3>::Zero();
  Real area = 0;
  for (Index f : m3.boundary_facets()) s3 += m3.facet_measure(f) * m3.facet_normal(f), area += m3.facet_measure(f);
  CHECK(s3.norm() < 1e-13);
  CHECK(area == Approx(6.0));
}

TEST_CASE("box mesh: Kuhn split is conforming and tagged", "[mesh][quick]") {
  const auto m = box_mesh(3, 2, 4, Vec<3>(0, 0, 0), Vec<3>(3, 2, 4));
  CHECK(m.n_cells() == 6 * 24);
  CHECK(m.total_measure() == Approx(24.0));
  // Euler characteristic of a ball: V - E + F - C = 1
  CHECK(m.n_nodes() - m.n_edges() + m.n_facets() - m.n_cells() == 1);
  for (int t = 1; t <= 6; ++t) {
    Real a = 0;
    for (Index f : m.boundary_facets())
      if (m.facet_tag(f) == t) a += m.facet_measure(f);
    const Real expected[7] = {0, 8, 8, 12, 12, 6, 6};
    CHECK(a == Approx(expected[t]));
  }
  // facet-to-cell adjacency: each interior facet's cells share exactly D vertices
  for (Index f = 0; f < m.n_facets(); ++f) {
    const auto [c0, c1] = m.facet_cells(f);
    if (c1 < 0) continue;
    int shared = 0;
    for (Index a : m.cell(c0))
      for (Index b : m.cell(c1)) shared += a == b;
    CHECK(shared == 3);
  }
}

TEST_CASE("annulus mesh: nodes on circles, area approaches pi (r2^2 - r1^2)", "[mesh][quick]") {
  const auto m = annulus_mesh(0.25, 1.0, 4, 256);
  for (Index i : m.boundary_nodes(tags::inner)) CHECK(m.node(i).norm() == Approx(0.25).epsilon(1e-15));
  for (Index i : m.boundary_nodes(tags::outer)) CHECK(m.node(i).norm() == Approx(1.0).epsilon(1e-15));
  const Real exact = std::numbers::pi * (1.0 - 0.0625);
  // polygon area: (n/2) sin(2 pi / n) (r2^2 - r1^2)
  const Real poly = 128 * std::sin(2 * std::numbers::pi / 256) * (1.0 - 0.0625);
  CHECK(m.total_measure() == Approx(poly).epsilon(1e-13));
  CHECK(std::abs(m.total_measure() - exact) < 1e-3);
}

TEST_CASE("spherical shell mesh: conforming, nodes on the spheres, no cell flat on a sphere", "[mesh][quick]") {
  const Real r1 = 0.5, r2 = 1.0;
  for (int n : {1, 2}) {
    const auto m = spherical_shell_mesh(r1, r2, n, Vec<3>(0.1, 0.2, 0.3));
    CHECK(m.n_cells() == 336 * n * n * n);
    // the boundary: two spheres of 48 n^2 and 192 n^2 triangles (each cube face's boxes halved)
    Index n_in = 0, n_out = 0;
    for (Index f : m.boundary_facets()) (m.facet_tag(f) == tags::inner ? n_in : n_out) += 1;
    CHECK(n_in == 48 * n * n);
    CHECK(n_out == 192 * n * n);
    for (Index i : m.boundary_nodes(tags::inner)) CHECK((m.node(i) - Vec<3>(0.1, 0.2, 0.3)).norm() == Approx(r1).epsilon(1e-14));
    for (Index i : m.boundary_nodes(tags::outer)) CHECK((m.node(i) - Vec<3>(0.1, 0.2, 0.3)).norm() == Approx(r2).epsilon(1e-14));
    // every cell has a vertex off each sphere it touches: none of them is a flat sliver on it
    Real worst = 1;
    for (Index c = 0; c < m.n_cells(); ++c) {
      CHECK(m.signed_measure(c) > 0);
      worst = std::min(worst, m.quality(c));
    }
    CHECK(worst > 0.2);
    // the polyhedral volume approaches the shell's from below at O(h^2)
    const Real exact = 4 * std::numbers::pi / 3 * (r2 * r2 * r2 - r1 * r1 * r1);
    CHECK(m.total_measure() < exact);
    CHECK(m.total_measure() > (n == 1 ? 0.9 : 0.97) * exact);
  }
}

TEST_CASE("cell edges and facets follow the local conventions", "[mesh][quick]") {
  const auto m = box_mesh(1, 1, 1);
  for (Index c = 0; c < m.n_cells(); ++c) {
    for (int le = 0; le < 6; ++le) {
      const auto& ab = SimplexTopology<3>::edges[le];
      auto e = m.edge(m.cell_edges(c)[le]);
      Index a = m.cell(c)[ab[0]], b = m.cell(c)[ab[1]];
      CHECK(std::min(a, b) == e[0]);
      CHECK(std::max(a, b) == e[1]);
    }
    for (int lf = 0; lf < 4; ++lf) {
      const auto& fv = m.facet(m.cell_facets(c)[lf]);
      CHECK(std::find(fv.begin(), fv.end(), m.cell(c)[lf]) == fv.end());  // opposite vertex lf
    }
  }
}

TEST_CASE("quality: 1 for the equilateral triangle and the regular tetrahedron", "[mesh][quick]") {
  Mesh<2> t({Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(0.5, std::sqrt(3.0) / 2)}, {{0, 1, 2}});
  CHECK(t.quality(0) == Approx(1.0).epsilon(1e-14));
  Mesh<3> k({Vec<3>(1, 1, 1), Vec<3>(1, -1, -1), Vec<3>(-1, 1, -1), Vec<3>(-1, -1, 1)}, {{0, 2, 1, 3}});
  CHECK(k.quality(0) == Approx(1.0).epsilon(1e-14));
  Mesh<2> flat({Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(0.5, 1e-3)}, {{0, 1, 2}});
  CHECK(flat.quality(0) < 0.01);
}

TEST_CASE("invalid meshes are rejected with the offending entity named", "[mesh][quick]") {
  const std::vector<Vec<2>> x{Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(1, 1), Vec<2>(0, 1)};
  SECTION("inverted cell") {
    try {
      Mesh<2>(x, {{0, 1, 2}, {0, 3, 2}});
      FAIL("no exception");
    } catch (const MeshError& e) {
      CHECK(e.entity() == MeshError::Entity::cell);
      CHECK(e.index() == 1);
      CHECK_THAT(e.what(), Contains("inverted"));
    }
  }
  SECTION("degenerate cell (collinear)") {
    std::vector<Vec<2>> y = x;
    y.push_back(Vec<2>(2, 0));
    REQUIRE_THROWS_WITH((Mesh<2>(y, {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}})), Contains("cell 2") && Contains("degenerate"));
  }
  SECTION("repeated vertex") {
    REQUIRE_THROWS_WITH((Mesh<2>(x, {{0, 1, 2}, {0, 2, 2}})), Contains("cell 1") && Contains("repeated"));
  }
  SECTION("node index out of range") {
    REQUIRE_THROWS_WITH((Mesh<2>(x, {{0, 1, 2}, {0, 2, 7}})), Contains("cell 1") && Contains("out of range"));
  }
  SECTION("dangling node") {
    REQUIRE_THROWS_WITH((Mesh<2>(x, {{0, 1, 2}})), Contains("node 3") && Contains("dangling"));
  }
  SECTION("non-manifold facet") {
    // edge (0,1) is shared by three positively oriented triangles
    std::vector<Vec<2>> z{Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(0.5, 1), Vec<2>(0.5, 2), Vec<2>(0.5, -1)};
    REQUIRE_THROWS_WITH((Mesh<2>(z, {{0, 1, 2}, {0, 1, 3}, {1, 0, 4}})), Contains("non-manifold"));
  }
  SECTION("tagged facet that is not a facet of the mesh") {
    // (1, 3) crosses the diagonal (0, 2); a tagged interior facet such as (0, 2) is fine
    REQUIRE_THROWS_WITH((Mesh<2>(x, {{0, 1, 2}, {0, 2, 3}}, {{1, 3}}, {7})), Contains("not a facet of the mesh"));
    const Mesh<2> m(x, {{0, 1, 2}, {0, 2, 3}}, {{2, 0}}, {7});
    REQUIRE(m.tagged_interior_facets().size() == 1);
    const Index f = m.tagged_interior_facets()[0];
    CHECK(m.facet(f) == Mesh<2>::Facet{0, 2});
    CHECK(m.facet_tag(f) == 7);
    CHECK_FALSE(m.on_boundary(f));
    for (Index b : m.boundary_facets()) CHECK(m.facet_tag(b) == 0);
  }
  SECTION("moving a node through a cell inverts it: refused, mesh unchanged") {
    Mesh<2> m(x, {{0, 1, 2}, {0, 2, 3}});
    auto y = x;
    y[1] = Vec<2>(-1, 2);
    REQUIRE_THROWS_AS(m.set_coordinates(y), MeshError);
    CHECK(m.node(1) == x[1]);
  }
}
