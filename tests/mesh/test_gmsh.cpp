// Tests of the gmsh .msh reader (mesh/io/gmsh.hpp) on the files under tests/data/gmsh:
// gmsh-generated meshes in MSH 4.1 ASCII / binary and 2.2 ASCII, first and second order,
// hand-written small files, and malformed files (tests/data/gmsh/README.md).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "alefsi/mesh/io/gmsh.hpp"

using namespace alefsi;

namespace {

const std::string kDir = ALEFSI_TEST_DATA_DIR "/gmsh/";

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

/// Matches a ParseError on the given line whose message contains `part`.
class ParseErrorIs : public Catch::MatcherBase<ParseError> {
 public:
  ParseErrorIs(std::string part, std::size_t line) : part_(std::move(part)), line_(line) {}
  bool match(const ParseError& e) const override {
    return e.line() == line_ && std::string(e.what()).find(part_) != std::string::npos;
  }
  std::string describe() const override {
    return "is a ParseError on line " + std::to_string(line_) + " containing \"" + part_ + "\"";
  }

 private:
  std::string part_;
  std::size_t line_;
};

/// Matches a MeshError about the given entity whose message contains `part`.
class MeshErrorIs : public Catch::MatcherBase<MeshError> {
 public:
  MeshErrorIs(MeshError::Entity entity, Index index, std::string part)
      : entity_(entity), index_(index), part_(std::move(part)) {}
  bool match(const MeshError& e) const override {
    return e.entity() == entity_ && e.index() == index_ && std::string(e.what()).find(part_) != std::string::npos;
  }
  std::string describe() const override {
    return "is a MeshError about entity " + std::to_string(index_) + " containing \"" + part_ + "\"";
  }

 private:
  MeshError::Entity entity_;
  Index index_;
  std::string part_;
};

template <int D>
Vec<D> midpoint(const Mesh<D>& m, Index e) {
  return 0.5 * (m.node(m.edge(e)[0]) + m.node(m.edge(e)[1]));
}

template <int D>
Real boundary_measure(const Mesh<D>& m, int tag) {
  Real s = 0;
  for (Index f : m.boundary_facets())
    if (m.facet_tag(f) == tag) s += m.facet_measure(f);
  return s;
}

template <int D>
Real region_measure(const Mesh<D>& m, int tag) {
  Real s = 0;
  for (Index c = 0; c < m.n_cells(); ++c)
    if (m.cell_tag(c) == tag) s += m.measure(c);
  return s;
}

/// Measure of the region between `centre` and the boundary facets with `tag` (the polygon /
/// polyhedron the mesh uses for a hole around `centre`).
template <int D>
Real hole_measure(const Mesh<D>& m, int tag, const Vec<D>& centre) {
  Real s = 0;
  for (Index f : m.boundary_facets()) {
    if (m.facet_tag(f) != tag) continue;
    Mat<D> J;
    for (int k = 0; k < D; ++k) J.col(k) = m.node(m.facet(f)[std::size_t(k)]) - centre;
    s += std::abs(J.determinant()) * reference_measure<D>;
  }
  return s;
}

template <int D>
void require_same_mesh(const GmshMesh<D>& a, const GmshMesh<D>& b) {
  REQUIRE(a.mesh.n_nodes() == b.mesh.n_nodes());
  REQUIRE(a.mesh.n_cells() == b.mesh.n_cells());
  REQUIRE(a.mesh.n_facets() == b.mesh.n_facets());
  // ASCII files print 16 significant digits, binary files hold the exact doubles
  for (Index v = 0; v < a.mesh.n_nodes(); ++v) REQUIRE((a.mesh.node(v) - b.mesh.node(v)).norm() <= 1e-15 * D);
  CHECK(a.mesh.cells() == b.mesh.cells());
  CHECK(a.mesh.cell_tags() == b.mesh.cell_tags());
  for (Index f = 0; f < a.mesh.n_facets(); ++f) REQUIRE(a.mesh.facet_tag(f) == b.mesh.facet_tag(f));
  CHECK(a.physical_names == b.physical_names);
}

/// Second-order check: each mid node is on its circle / sphere for edges of the curved
/// boundary `curved_tag`, and exactly at the edge midpoint for every other edge.
template <int D>
void check_midpoints(const GmshMesh<D>& g, int curved_tag, const Vec<D>& centre, Real r) {
  const Mesh<D>& m = g.mesh;
  REQUIRE(g.edge_midpoints.size() == std::size_t(m.n_edges()));
  const auto curved = m.boundary_edges(curved_tag);
  const std::set<Index> on_curve(curved.begin(), curved.end());
  int n_curved = 0, n_straight = 0;
  for (Index e = 0; e < m.n_edges(); ++e) {
    const Vec<D> a = m.node(m.edge(e)[0]), b = m.node(m.edge(e)[1]);
    const Vec<D>& mid = g.edge_midpoints[std::size_t(e)];
    if (on_curve.count(e)) {
      ++n_curved;
      CHECK((mid - centre).norm() == Approx(r).epsilon(1e-12));
      const Real off = (mid - 0.5 * (a + b)).norm();
      CHECK(off > 1e-6);                    // off the chord, towards the curve
      CHECK(off < 0.25 * (b - a).norm());   // but still next to its own edge
    } else {
      ++n_straight;
      CHECK((mid - 0.5 * (a + b)).norm() <= 1e-12);
    }
  }
  CHECK(n_curved > 0);
  CHECK(n_straight > n_curved);
}

}  // namespace

TEST_CASE("gmsh: the 2D channel is the same mesh in every format and order", "[mesh][gmsh][quick]") {
  const auto ref = read_gmsh<2>(kDir + "channel2d_o1_msh41.msh");
  CHECK(ref.edge_midpoints.empty());
  for (const char* name : {"channel2d_o1_msh41bin.msh", "channel2d_o1_msh22.msh", "channel2d_o2_msh41.msh",
                           "channel2d_o2_msh41bin.msh", "channel2d_o2_msh22.msh",
                           "channel2d_o2_msh41bin_bigendian.msh"}) {
    CAPTURE(name);
    const auto g = read_gmsh<2>(kDir + name);
    require_same_mesh(g, ref);
    CHECK(g.edge_midpoints.empty() == (std::string(name).find("_o1_") != std::string::npos));
  }
}

TEST_CASE("gmsh: the 2D channel has the geometry, tags and names of its .geo", "[mesh][gmsh][quick]") {
  const auto g = read_gmsh<2>(kDir + "channel2d_o1_msh41.msh");
  const Mesh<2>& m = g.mesh;
  const Vec<2> c(0.5, 0.5);
  const Real r = 0.2;
  CHECK(m.n_cells() < 2000);
  // physical names: unnamed group 11 has none; both dimensions are kept
  const std::map<int, std::string> names{{1, "inlet"}, {2, "outlet"}, {3, "walls"}, {4, "hole"}, {10, "left"}};
  CHECK(g.physical_names == names);
  // region tags: the left square minus the hole, and the right square (written with negative
  // orientation by gmsh, reoriented by the reader)
  CHECK(std::set<int>(m.cell_tags().begin(), m.cell_tags().end()) == std::set<int>{10, 11});
  const Real hole = hole_measure(m, 4, c);
  CHECK(hole == Approx(std::numbers::pi * r * r).epsilon(0.01));
  CHECK(hole < std::numbers::pi * r * r);
  CHECK(region_measure(m, 11) == Approx(1.0).epsilon(1e-12));
  CHECK(region_measure(m, 10) == Approx(1.0 - hole).epsilon(1e-12));
  CHECK(m.total_measure() == Approx(2.0 - hole).epsilon(1e-12));
  for (Index k = 0; k < m.n_cells(); ++k) REQUIRE(m.signed_measure(k) > 0);
  // boundary tags and measures: straight sides exact, the hole a polygon inscribed in the circle
  for (Index f : m.boundary_facets()) REQUIRE(m.facet_tag(f) >= 1);
  CHECK(boundary_measure(m, 1) == Approx(1.0).epsilon(1e-12));
  CHECK(boundary_measure(m, 2) == Approx(1.0).epsilon(1e-12));
  CHECK(boundary_measure(m, 3) == Approx(4.0).epsilon(1e-12));
  const Real circumference = boundary_measure(m, 4);
  CHECK(circumference < 2 * std::numbers::pi * r);
  CHECK(circumference > 0.99 * 2 * std::numbers::pi * r);
  for (Index v : m.boundary_nodes(4)) CHECK((m.node(v) - c).norm() == Approx(r).epsilon(1e-12));
  for (Index v : m.boundary_nodes(1)) CHECK(m.node(v)[0] == 0.0);
  for (Index f : m.boundary_facets())
    if (m.facet_tag(f) == 1) CHECK((m.facet_normal(f) - Vec<2>(-1, 0)).norm() < 1e-12);
  // interior facets carry no tag (the x = 1 interface has no physical group)
  for (Index f = 0; f < m.n_facets(); ++f)
    if (!m.on_boundary(f)) REQUIRE(m.facet_tag(f) == 0);
}

TEST_CASE("gmsh: second-order 2D mid nodes land on their edges", "[mesh][gmsh][quick]") {
  // straight edges: mid node at the midpoint; hole edges: mid node on the circle
  const auto o1 = read_gmsh<2>(kDir + "channel2d_o1_msh41.msh");
  for (const char* name : {"channel2d_o2_msh41.msh", "channel2d_o2_msh41bin.msh", "channel2d_o2_msh22.msh",
                           "channel2d_o2_msh41bin_bigendian.msh"}) {
    CAPTURE(name);
    const auto g = read_gmsh<2>(kDir + name);
    CHECK(g.mesh.cells() == o1.mesh.cells());
    check_midpoints(g, 4, Vec<2>(0.5, 0.5), 0.2);
  }
}

TEST_CASE("gmsh: the 3D box with a spherical hole in every format and order", "[mesh][gmsh][quick]") {
  const auto ref = read_gmsh<3>(kDir + "box3d_o1_msh41.msh");
  const Mesh<3>& m = ref.mesh;
  const Vec<3> c(0.5, 0.5, 0.5);
  const Real r = 0.25;
  CHECK(m.n_cells() < 2000);
  const std::map<int, std::string> names{{1, "xmin"}, {2, "xmax"}, {5, "zmin"},
                                         {6, "zmax"}, {7, "sphere"}, {20, "solid"}};
  CHECK(ref.physical_names == names);
  CHECK(std::set<int>(m.cell_tags().begin(), m.cell_tags().end()) == std::set<int>{20});
  const Real hole = hole_measure(m, 7, c);
  CHECK(hole < 4.0 / 3.0 * std::numbers::pi * r * r * r);  // an inscribed polyhedron, coarse
  CHECK(hole > 0.85 * 4.0 / 3.0 * std::numbers::pi * r * r * r);
  CHECK(m.total_measure() == Approx(1.0 - hole).epsilon(1e-12));
  for (int tag = 1; tag <= 6; ++tag) CHECK(boundary_measure(m, tag) == Approx(1.0).epsilon(1e-12));
  const Real area = boundary_measure(m, 7);
  CHECK(area < 4 * std::numbers::pi * r * r);
  CHECK(area > 0.9 * 4 * std::numbers::pi * r * r);
  for (Index v : m.boundary_nodes(7)) CHECK((m.node(v) - c).norm() == Approx(r).epsilon(1e-12));
  for (Index f : m.boundary_facets()) REQUIRE(m.facet_tag(f) >= 1);
  for (Index f : m.boundary_facets())
    if (m.facet_tag(f) == 6) CHECK((m.facet_normal(f) - Vec<3>(0, 0, 1)).norm() < 1e-12);

  for (const char* name : {"box3d_o1_msh41bin.msh", "box3d_o1_msh22.msh", "box3d_o2_msh41.msh",
                           "box3d_o2_msh41bin.msh", "box3d_o2_msh22.msh"}) {
    CAPTURE(name);
    const auto g = read_gmsh<3>(kDir + name);
    require_same_mesh(g, ref);
    if (std::string(name).find("_o2_") != std::string::npos) check_midpoints(g, 7, c, r);
    else CHECK(g.edge_midpoints.empty());
  }
}

TEST_CASE("gmsh: sparse tags, unused nodes, orientation and unknown sections", "[mesh][gmsh][quick]") {
  // hand-written MSH 4.1: tags up to 1e9, two unused nodes, a parametric node block, a point
  // element, a negatively oriented triangle, $Comments and $NodeData sections
  const auto g = read_gmsh<2>(kDir + "tiny_sparse_v41.msh");
  const Mesh<2>& m = g.mesh;
  REQUIRE(m.n_nodes() == 4);  // tags 10, 20, 40, 30 in file order; 1e9 and 77 dropped
  CHECK(m.node(0) == Vec<2>(0, 0));
  CHECK(m.node(1) == Vec<2>(1, 0));
  CHECK(m.node(2) == Vec<2>(0, 1));
  CHECK(m.node(3) == Vec<2>(1, 1));
  REQUIRE(m.n_cells() == 2);
  CHECK(m.cell(0) == Mesh<2>::Cell{0, 1, 3});
  CHECK(m.cell(1) == Mesh<2>::Cell{0, 3, 2});  // written as (10, 40, 30): vertices 1, 2 swapped
  CHECK(m.cell_tags() == std::vector<int>{5, 5});
  CHECK(g.physical_names == std::map<int, std::string>{{1, "bottom wall"}, {2, "rest"}, {5, "square"}});
  CHECK(g.edge_midpoints.empty());
  for (Index f : m.boundary_facets()) {
    const bool bottom = m.facet(f) == Mesh<2>::Facet{0, 1};
    CHECK(m.facet_tag(f) == (bottom ? 1 : 2));
  }
  CHECK(m.total_measure() == Approx(1.0));
}

TEST_CASE("gmsh: mid nodes follow reoriented triangle6 and tet10 cells", "[mesh][gmsh][quick]") {
  SECTION("triangle6, MSH 4.1") {
    const auto g = read_gmsh<2>(kDir + "tiny_tri6_v41.msh");
    REQUIRE(g.mesh.n_cells() == 2);
    CHECK(g.mesh.cell(1) == Mesh<2>::Cell{0, 2, 3});  // written as (1, 4, 3)
    REQUIRE(g.edge_midpoints.size() == 5);
    for (Index e = 0; e < g.mesh.n_edges(); ++e)
      CHECK(g.edge_midpoints[std::size_t(e)] == midpoint(g.mesh, e));
    CHECK(g.mesh.cell_tags() == std::vector<int>{8, 8});
    CHECK(boundary_measure(g.mesh, 3) == Approx(4.0));
  }
  SECTION("tet10, MSH 2.2") {
    const auto g = read_gmsh<3>(kDir + "tiny_tet10_v22.msh");
    REQUIRE(g.mesh.n_cells() == 1);
    CHECK(g.mesh.cell(0) == Mesh<3>::Cell{0, 1, 2, 3});  // written as (1, 3, 2, 4)
    REQUIRE(g.edge_midpoints.size() == 6);
    for (Index e = 0; e < g.mesh.n_edges(); ++e)
      CHECK(g.edge_midpoints[std::size_t(e)] == midpoint(g.mesh, e));
    CHECK(g.mesh.cell_tag(0) == 7);
    for (int tag = 1; tag <= 3; ++tag) CHECK(boundary_measure(g.mesh, tag) == Approx(0.5));
    CHECK(boundary_measure(g.mesh, 4) == Approx(std::sqrt(3.0) / 2));
    CHECK(g.physical_names.empty());
  }
}

TEST_CASE("gmsh: reading from a stream", "[mesh][gmsh][quick]") {
  std::ifstream in(kDir + "channel2d_o2_msh41bin.msh", std::ios::binary);
  const auto g = read_gmsh<2>(in, "channel.msh");
  require_same_mesh(g, read_gmsh<2>(kDir + "channel2d_o1_msh22.msh"));
  CHECK(g.edge_midpoints.size() == std::size_t(g.mesh.n_edges()));

  std::istringstream bad("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n");
  try {
    read_gmsh<2>(bad, "from-memory");
    FAIL("no exception");
  } catch (const ParseError& e) {
    CHECK(e.file() == "from-memory");
    CHECK(e.line() == 5);
    CHECK_THAT(e.what(), Catch::Contains("truncated"));
  }
}

TEST_CASE("gmsh: malformed files throw ParseError naming the problem and the line", "[mesh][gmsh][quick]") {
  struct Case {
    const char* file;
    int dim;
    const char* message;
    std::size_t line;
  };
  const Case cases[] = {
      {"truncated_nodes_v41.msh", 2, "unexpected end of file in the $Nodes section", 29},
      {"truncated_elements_v22.msh", 2, "unexpected end of file in the $Elements section", 23},
      {"truncated_binary_v41.msh", 2, "truncated file or corrupt count", 52},
      {"truncated_binary_header_v41.msh", 2, "truncated file: the binary data of the $Elements section", 44},
      {"missing_endnodes_v22.msh", 2, "missing $EndNodes before '$Elements'", 15},
      {"missing_elements_v22.msh", 2, "missing $Elements section", 15},
      {"unterminated_section_v22.msh", 2, "missing $EndPeriodic", 25},
      {"node_count_too_big_v22.msh", 2, "found '$EndNodes' where a node tag was expected", 15},
      {"node_count_too_small_v22.msh", 2, "expected $EndNodes, found '4'", 14},
      {"negative_count_v22.msh", 2, "negative number of nodes -4", 10},
      {"huge_count_v41.msh", 2, "bad number of nodes 1000000000000000000", 10},
      {"bad_block_count_bin_v41.msh", 2, "bad number of nodes in the block 1000000000000", 21},
      {"non_numeric_coordinate_v22.msh", 2, "non-numeric token '1x' where a y coordinate was expected", 13},
      {"extra_value_v22.msh", 2, "unexpected extra value '7'", 12},
      {"short_element_line_v22.msh", 2, "the line ends before the node tag", 22},
      {"undefined_node_v22.msh", 2, "node tag 99, which $Nodes does not define", 23},
      {"duplicate_node_tag_v22.msh", 2, "duplicate node tag 3 (first defined on line 13)", 14},
      {"duplicate_node_tag_v41.msh", 2, "duplicate node tag 7 (first defined on line 15)", 18},
      {"duplicate_sparse_tag_v41.msh", 2, "duplicate node tag 1000000000 (first defined on line 34)", 35},
      {"unknown_element_type_v22.msh", 2, "unknown element type 99", 22},
      {"quad_in_2d_v22.msh", 2, "unsupported element type 3 (4-node quadrangle)", 22},
      {"tet_in_2d_v22.msh", 2, "element type 4 (4-node tetrahedron) is 3-dimensional", 23},
      {"square_v22.msh", 3, "no 3-dimensional cells (tetrahedra)", 16},
      {"mixed_order_v22.msh", 2, "mixes first- and second-order cells", 23},
      {"missing_physical_v22.msh", 2, "missing physical groups: no triangle belongs to a physical group", 22},
      {"missing_boundary_v41.msh", 2, "missing physical groups on the boundary", 31},
      {"duplicate_triangle_v22.msh", 2, "this triangle repeats the one on line 22 with the same physical tag 5", 24},
      {"duplicate_boundary_v22.msh", 2, "this line repeats the one on line 18 with the same physical tag 1", 24},
      {"boundary_node_not_in_cell_v22.msh", 2, "uses node 5, which is not a vertex of any triangle", 25},
      {"nonplanar_v22.msh", 2, "not planar", 13},
      {"unsupported_version.msh", 2, "unsupported MSH format version 3.0 ASCII", 2},
      {"v22_binary.msh", 2, "unsupported MSH format version 2.2 binary", 2},
      {"data_size4_bin.msh", 2, "unsupported data size 4", 2},
      {"bad_endianness_bin.msh", 2, "bad endianness check int 2", 2},
      {"empty.msh", 2, "empty file", 1},
      {"not_msh.msh", 2, "not a gmsh .msh file", 1},
  };
  for (const Case& c : cases) {
    const std::string dir = std::string(c.file) == "square_v22.msh" ? kDir : kDir + "bad/";
    const std::string path = dir + c.file;
    CAPTURE(path);
    if (c.dim == 2) REQUIRE_THROWS_MATCHES(read_gmsh<2>(path), ParseError, ParseErrorIs(c.message, c.line));
    else REQUIRE_THROWS_MATCHES(read_gmsh<3>(path), ParseError, ParseErrorIs(c.message, c.line));
    try {
      if (c.dim == 2) read_gmsh<2>(path);
      else read_gmsh<3>(path);
    } catch (const ParseError& e) {
      CHECK(e.file() == path);
      CHECK_THAT(e.what(), Catch::StartsWith(path + ":" + std::to_string(c.line) + ": "));
    }
  }
  // a 3D file read as 2D: its nodes are not in the plane z = 0
  auto not_planar = [](const ParseError& e) { return std::string(e.what()).find("not planar") != std::string::npos; };
  REQUIRE_THROWS_MATCHES(read_gmsh<2>(kDir + "box3d_o1_msh41.msh"), ParseError,
                         Catch::Matchers::Predicate<ParseError>(not_planar, "says the mesh is not planar"));
}

TEST_CASE("gmsh: invalid meshes throw MeshError naming the cell or facet", "[mesh][gmsh][quick]") {
  // cell 1 = (0,0), (1,1), (0.5,0.5): collinear
  REQUIRE_THROWS_MATCHES(read_gmsh<2>(kDir + "bad/degenerate_cell_v22.msh"), MeshError,
                         MeshErrorIs(MeshError::Entity::cell, 1, "degenerate"));
  // a tagged line from (1,0) to (0,1) crosses the square's diagonal: (D-1)-element 4 is no edge
  REQUIRE_THROWS_MATCHES(read_gmsh<2>(kDir + "bad/not_a_facet_v22.msh"), MeshError,
                         MeshErrorIs(MeshError::Entity::facet, 4, "not a facet of the mesh"));
  // and the message says which file, and the line of the element
  try {
    (void)read_gmsh<2>(kDir + "bad/degenerate_cell_v22.msh");
    FAIL("no MeshError");
  } catch (const MeshError& e) {
    CHECK(std::string(e.what()).rfind(kDir + "bad/degenerate_cell_v22.msh:" + std::to_string(23) + ": cell 1: ", 0) == 0);
  }
}

TEST_CASE("gmsh: a missing file is a ParseError on line 0", "[mesh][gmsh][quick]") {
  const std::string path = kDir + "no_such_file.msh";
  REQUIRE_THROWS_MATCHES(read_gmsh<2>(path), ParseError, ParseErrorIs("cannot open", 0));
  REQUIRE_THROWS_MATCHES(read_gmsh<3>(path), ParseError, ParseErrorIs(path, 0));
}

TEST_CASE("gmsh: truncated and corrupted files throw alefsi errors, never crash", "[mesh][gmsh][quick]") {
  // Every outcome must be a mesh, a ParseError or a MeshError; anything else (a crash, a
  // bad_alloc from a huge count, another exception type) fails the test.
  std::mt19937 rng(20240607);
  int parse_errors = 0;
  auto attempt = [&](int dim, const std::string& text) {
    std::istringstream in(text);
    try {
      if (dim == 2) read_gmsh<2>(in, "fuzz");
      else read_gmsh<3>(in, "fuzz");
    } catch (const ParseError&) {
      ++parse_errors;
    } catch (const MeshError&) {
    }
  };
  const std::string noise = "0123456789-+.eE $\n\t\"x";
  struct Input {
    const char* file;
    int dim;
    int tries;
  };
  for (const Input& f : {Input{"channel2d_o1_msh41.msh", 2, 120}, Input{"channel2d_o2_msh41bin.msh", 2, 120},
                         Input{"channel2d_o2_msh22.msh", 2, 60}, Input{"tiny_sparse_v41.msh", 2, 200},
                         Input{"box3d_o1_msh41bin.msh", 3, 40}, Input{"tiny_tet10_v22.msh", 3, 100}}) {
    CAPTURE(f.file);
    const std::string data = slurp(kDir + f.file);
    REQUIRE(!data.empty());
    for (int i = 0; i < f.tries; ++i) {
      attempt(f.dim, data.substr(0, rng() % data.size()));
      std::string t = data;
      for (int k = 1 + int(rng() % 4); k > 0; --k) {
        const std::size_t at = rng() % t.size();
        t[at] = rng() % 2 ? noise[rng() % noise.size()] : static_cast<char>(rng() % 256);
      }
      attempt(f.dim, t);
    }
  }
  CHECK(parse_errors > 0);
}

namespace {

template <int D>
Real facets_measure(const Mesh<D>& m, const std::vector<Index>& facets) {
  Real s = 0;
  for (Index f : facets) s += m.facet_measure(f);
  return s;
}

template <int D>
Real cells_measure(const Mesh<D>& m, const std::vector<Index>& cells) {
  Real s = 0;
  for (Index c : cells) s += m.measure(c);
  return s;
}

/// Cell centroids, sorted: the same mesh read from files that number it differently.
template <int D>
std::vector<std::array<Real, D>> sorted_centroids(const Mesh<D>& m) {
  std::vector<std::array<Real, D>> out;
  for (Index c = 0; c < m.n_cells(); ++c) {
    const Vec<D> g = m.centroid(c);
    std::array<Real, D> a;
    for (int k = 0; k < D; ++k) a[std::size_t(k)] = std::round(g[k] * 1e9) / 1e9;
    out.push_back(a);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE("gmsh: an entity in two physical groups is in both (gmsh t14)", "[mesh][gmsh][quick]") {
  const auto g41 = read_gmsh<2>(kDir + "groups2d_msh41.msh");
  const auto g22 = read_gmsh<2>(kDir + "groups2d_msh22.msh");  // writes each element once per group
  require_same_mesh(g22, g41);
  for (const auto* g : {&g41, &g22}) {
    const Mesh<2>& m = g->mesh;
    CHECK(g->cell_groups.size() == 2);
    std::vector<Index> all(std::size_t(m.n_cells()));
    std::iota(all.begin(), all.end(), Index(0));
    CHECK(g->cell_groups.at(10) == all);
    CHECK(g->cell_groups.at(11) == all);
    for (Index c = 0; c < m.n_cells(); ++c) REQUIRE(m.cell_tag(c) == 10);  // the first group
    CHECK(m.total_measure() == Approx(1.0).epsilon(1e-14));
    // `walls` is the whole boundary, `bottom` its part y = 0, which keeps tag 1 (its first group)
    CHECK(g->facet_groups.at(1).size() == m.boundary_facets().size());
    CHECK(facets_measure(m, g->facet_groups.at(1)) == Approx(4.0).epsilon(1e-14));
    CHECK(facets_measure(m, g->facet_groups.at(2)) == Approx(1.0).epsilon(1e-14));
    for (Index f : g->facet_groups.at(2)) {
      CHECK(m.on_boundary(f));
      CHECK(m.facet_tag(f) == 1);
      for (Index v : m.facet(f)) CHECK(m.node(v)[1] == 0.0);
    }
  }
  // gmsh writes a negative physical tag for an entity in a group with reversed orientation
  // (t14's `Physical Surface(80) = bnd()`): the group is 80
  std::string text = slurp(kDir + "groups2d_msh41.msh");
  const std::string bottom = "1 0 0 0 1 0 0 2 1 2 2 1 -2 \n";
  REQUIRE(text.find(bottom) != std::string::npos);
  text.replace(text.find(bottom), bottom.size(), "1 0 0 0 1 0 0 2 -1 -2 2 1 -2 \n");
  std::istringstream in(text);
  const auto neg = read_gmsh<2>(in, "negative tags");
  CHECK(neg.facet_groups.at(1) == g41.facet_groups.at(1));
  CHECK(neg.facet_groups.at(2) == g41.facet_groups.at(2));
  CHECK(neg.facet_groups.count(-2) == 0);
}

TEST_CASE("gmsh: embedded curves and surfaces are tagged interior facets (gmsh t15)", "[mesh][gmsh][quick]") {
  {  // 2D: the sensor line y = 0.5, 0.25 <= x <= 0.75
    const auto g = read_gmsh<2>(kDir + "groups2d_msh41.msh");
    const Mesh<2>& m = g.mesh;
    const auto inner = m.tagged_interior_facets();
    CHECK(inner == g.facet_groups.at(5));
    CHECK(facets_measure(m, inner) == Approx(0.5).epsilon(1e-14));
    for (Index f : inner) {
      CHECK_FALSE(m.on_boundary(f));
      CHECK(m.facet_tag(f) == 5);
      for (Index v : m.facet(f)) CHECK(m.node(v)[1] == 0.5);
    }
    for (Index f : m.boundary_facets()) REQUIRE(m.facet_tag(f) == 1);
    CHECK(m.boundary_nodes(5).empty());  // boundary queries see boundary facets only
  }
  for (const char* name : {"embedded3d_msh41.msh", "embedded3d_msh22.msh"}) {
    CAPTURE(name);
    const auto g = read_gmsh<3>(kDir + name);
    const Mesh<3>& m = g.mesh;
    const auto inner = m.tagged_interior_facets();
    REQUIRE(inner.size() >= 2);
    CHECK(inner == g.facet_groups.at(7));
    CHECK(facets_measure(m, inner) == Approx(0.25).epsilon(1e-12));
    for (Index f : inner) {
      CHECK(m.facet_tag(f) == 7);
      for (Index v : m.facet(f)) {
        CHECK(m.node(v)[2] == Approx(0.5).epsilon(1e-14));
        CHECK(std::max(std::abs(m.node(v)[0] - 0.5), std::abs(m.node(v)[1] - 0.5)) <= 0.25 + 1e-12);
      }
    }
    CHECK(boundary_measure(m, 1) == Approx(6.0).epsilon(1e-12));
    CHECK(m.total_measure() == Approx(1.0).epsilon(1e-12));
  }
}

TEST_CASE("gmsh: partitioned MSH 4.1 files read as the whole mesh with each cell's partition (gmsh t21)",
          "[mesh][gmsh][quick]") {
  const auto plain = read_gmsh<2>(kDir + "channel2d_o1_msh41.msh");
  CHECK(plain.n_partitions == 0);
  CHECK(plain.cell_partitions.empty());
  for (const char* name :
       {"channel2d_part3_msh41.msh", "channel2d_part3_msh41bin.msh", "channel2d_part3_ghosts_msh41.msh"}) {
    CAPTURE(name);
    const auto g = read_gmsh<2>(kDir + name);
    const Mesh<2>& m = g.mesh;
    // the same mesh, numbered partition by partition; ghost cells are not read twice
    REQUIRE(m.n_nodes() == plain.mesh.n_nodes());
    REQUIRE(m.n_cells() == plain.mesh.n_cells());
    CHECK(sorted_centroids(m) == sorted_centroids(plain.mesh));
    for (int tag : {10, 11}) CHECK(region_measure(m, tag) == Approx(region_measure(plain.mesh, tag)).epsilon(1e-14));
    for (int tag : {1, 2, 3, 4})
      CHECK(boundary_measure(m, tag) == Approx(boundary_measure(plain.mesh, tag)).epsilon(1e-14));
    // the partition interfaces' lines are not kept: no tagged interior facet
    CHECK(m.tagged_interior_facets().empty());
    // three partitions, each a nonempty set of cells
    CHECK(g.n_partitions == 3);
    REQUIRE(g.cell_partitions.size() == std::size_t(m.n_cells()));
    std::array<int, 3> count{};
    for (int p : g.cell_partitions) {
      REQUIRE(p >= 1);
      REQUIRE(p <= 3);
      ++count[std::size_t(p - 1)];
    }
    for (int n : count) CHECK(n > m.n_cells() / 6);
  }
}
