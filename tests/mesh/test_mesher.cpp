// Tests of the built-in 2D triangle mesher (mesh/generate/mesher2d.hpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "alefsi/mesh/generate/mesher2d.hpp"

using namespace alefsi;

namespace {

constexpr double pi = std::numbers::pi;

double angle_at(const Vec<2>& p, const Vec<2>& q, const Vec<2>& r) {  // angle at p, degrees
  const Vec<2> a = q - p, b = r - p;
  return std::atan2(std::abs(a[0] * b[1] - a[1] * b[0]), a.dot(b)) * 180 / pi;
}

double cell_min_angle(const Mesh<2>& m, Index c) {
  const auto& v = m.cell(c);
  return std::min({angle_at(m.node(v[0]), m.node(v[1]), m.node(v[2])), angle_at(m.node(v[1]), m.node(v[2]), m.node(v[0])),
                   angle_at(m.node(v[2]), m.node(v[0]), m.node(v[1]))});
}

bool on_circle(const Vec<2>& x, const Circle& c, double rel = 1e-14) {
  return std::abs((x - c.centre).norm() - c.radius) <= rel * c.radius;
}

/// Area of the polygon through the boundary nodes with the given tag, ordered by angle
/// around `centre` (the inscribed polygon actually used for a circle).
double tagged_polygon_area(const Mesh<2>& m, int tag, const Vec<2>& centre) {
  std::vector<Vec<2>> p;
  for (Index v : m.boundary_nodes(tag)) p.push_back(m.node(v) - centre);
  std::sort(p.begin(), p.end(), [](const Vec<2>& a, const Vec<2>& b) { return std::atan2(a[1], a[0]) < std::atan2(b[1], b[0]); });
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) a += p[i][0] * p[(i + 1) % p.size()][1] - p[(i + 1) % p.size()][0] * p[i][1];
  return 0.5 * a;
}

/// Ratios edge length / h(edge midpoint): {min, max}.
std::pair<double, double> size_band(const Mesh<2>& m, const SizeFunction& h) {
  double lo = 1e300, hi = 0;
  for (Index e = 0; e < m.n_edges(); ++e) {
    const Vec<2> mid = 0.5 * (m.node(m.edge(e)[0]) + m.node(m.edge(e)[1]));
    const double r = m.edge_length(e) / h(mid);
    lo = std::min(lo, r), hi = std::max(hi, r);
  }
  return {lo, hi};
}

/// Checks shared by the rectangle-with-disks scenes: angles, area, tags, nodes on circles.
void check_channel(const Mesh<2>& m, double w, double H, const std::vector<Circle>& disks) {
  double worst = 180;
  for (Index c = 0; c < m.n_cells(); ++c) worst = std::min(worst, cell_min_angle(m, c));
  CHECK(worst >= 25.0);
  double area = w * H;
  for (const Circle& d : disks) area -= tagged_polygon_area(m, d.tag, d.centre);
  CHECK(m.total_measure() == Approx(area).epsilon(1e-12));
  for (Index f : m.boundary_facets()) {
    const auto& fv = m.facet(f);
    const Vec<2>&a = m.node(fv[0]), &b = m.node(fv[1]);
    const int tag = m.facet_tag(f);
    INFO("facet " << f << " tag " << tag << " from (" << a.transpose() << ") to (" << b.transpose() << ")");
    switch (tag) {
      case tags::bottom: CHECK((a[1] == 0 && b[1] == 0)); break;
      case tags::right: CHECK((a[0] == w && b[0] == w)); break;
      case tags::top: CHECK((a[1] == H && b[1] == H)); break;
      case tags::left: CHECK((a[0] == 0 && b[0] == 0)); break;
      default: {
        const auto it = std::find_if(disks.begin(), disks.end(), [&](const Circle& d) { return d.tag == tag; });
        REQUIRE(it != disks.end());
        CHECK(on_circle(a, *it));
        CHECK(on_circle(b, *it));
      }
    }
  }
}

bool near_polyline(const Vec<2>& x, const std::vector<Vec<2>>& poly) {
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec<2> a = poly[i], d = poly[(i + 1) % poly.size()] - a;
    const double t = std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    if ((a + t * d - x).norm() < 1e-15) return true;
  }
  return false;
}

template <class F>
std::string invalid_parameter(F&& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.parameter();
  }
  return "<no InvalidArgument>";
}

}  // namespace

TEST_CASE("robust predicates are exact on near-degenerate input", "[mesh][mesher]") {
  using detail::XY;
  // a = (0.5 + i ulp, 0.5 + j ulp), b = (12, 12), c = (24, 24): orient = 12 (ay - ax) exactly
  const double u = std::nextafter(0.5, 1.0) - 0.5;
  int wrong_naive = 0;
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j) {
      const XY a{0.5 + i * u, 0.5 + j * u}, b{12, 12}, c{24, 24};
      const double o = detail::orient2d(a, b, c);
      CHECK(((o > 0) - (o < 0)) == ((j > i) - (j < i)));
      const double naive = (a.x - c.x) * (b.y - c.y) - (a.y - c.y) * (b.x - c.x);
      wrong_naive += ((naive > 0) - (naive < 0)) != ((j > i) - (j < i));
    }
  CHECK(wrong_naive > 0);  // the test does exercise the exact stage
  // cocircular points (Pythagorean triples on the circle of radius 5), shifted by 1e6
  for (double s : {0.0, 1e6}) {
    const XY a{s + 5, s}, b{s, s + 5}, c{s - 5, s};
    CHECK(detail::incircle(a, b, c, XY{s + 3, s - 4}) == 0);
    CHECK(detail::incircle(a, b, c, XY{s - 4, s + 3}) == 0);
    CHECK(detail::incircle(a, b, c, XY{s + 3, std::nextafter(s - 4, s)}) > 0);        // one ulp inside
    CHECK(detail::incircle(a, b, c, XY{std::nextafter(s + 3, s + 4), s - 4}) < 0);    // one ulp outside
    // on the line x + y = 2 s + 5, and one ulp off it on either side
    CHECK(detail::orient2d(a, b, XY{s + 2.5, s + 2.5}) == 0);
    CHECK(detail::orient2d(a, b, XY{s + 2.5, std::nextafter(s + 2.5, s)}) > 0);
    CHECK(detail::orient2d(a, b, XY{s + 2.5, std::nextafter(s + 2.5, s + 5)}) < 0);
  }
}

TEST_CASE("channel with two disks: angles, area, tags, nodes on circles, sizes", "[mesh][mesher]") {
  const std::vector<Circle> disks{{Vec<2>(1, 4), 0.125, 5}, {Vec<2>(1.1, 4.5), 0.125, 6}};
  for (double h_body : {0.02, 0.005}) {
    MesherReport rep;
    const Mesh<2> m = channel_with_disks(2, 6, disks, h_body, 10 * h_body, &rep);
    INFO("h_body " << h_body << ": " << m.n_cells() << " triangles");
    check_channel(m, 2, 6, disks);
    CHECK(rep.dropped == 0);
    CHECK(rep.unsplittable == 0);
    CHECK(rep.small_angle_skips == 0);
    const auto [lo, hi] = size_band(m, graded_size(disks, h_body, 10 * h_body));
    INFO("edge / h in [" << lo << ", " << hi << "]");
    CHECK(lo >= 0.4);
    CHECK(hi <= 1.2);
    for (const Circle& d : disks) {
      const auto nodes = m.boundary_nodes(d.tag);
      CHECK(nodes.size() >= 8);
      for (Index v : nodes) CHECK(on_circle(m.node(v), d));
    }
    for (int t : {tags::bottom, tags::right, tags::top, tags::left}) CHECK(m.boundary_nodes(t).size() >= 2);
  }
}

TEST_CASE("annulus: angles, area, tags, nodes on circles, sizes", "[mesh][mesher]") {
  const double r1 = 0.25, r2 = 1.0, h = 0.04;
  MesherReport rep;
  const Mesh<2> m = annulus_unstructured(r1, r2, h, &rep);
  const Circle inner{Vec<2>::Zero(), r1, tags::inner}, outer{Vec<2>::Zero(), r2, tags::outer};
  CHECK(min_angle_deg(m) >= 25.0);
  CHECK(rep.dropped == 0);
  const double area = tagged_polygon_area(m, tags::outer, Vec<2>::Zero()) - tagged_polygon_area(m, tags::inner, Vec<2>::Zero());
  CHECK(m.total_measure() == Approx(area).epsilon(1e-12));
  CHECK(area == Approx(pi * (r2 * r2 - r1 * r1)).epsilon(1e-2));
  for (Index f : m.boundary_facets()) {
    const int tag = m.facet_tag(f);
    REQUIRE((tag == tags::inner || tag == tags::outer));
    const Circle& c = tag == tags::inner ? inner : outer;
    for (Index v : m.facet(f)) CHECK(on_circle(m.node(v), c));
  }
  const auto [lo, hi] = size_band(m, uniform_size(h));
  INFO("edge / h in [" << lo << ", " << hi << "]");
  CHECK(lo >= 0.4);
  CHECK(hi <= 1.2);
}

TEST_CASE("large box with a small disk, graded and uniform", "[mesh][mesher]") {
  const Circle disk{Vec<2>(0.3, -0.2), 0.1, 5};
  Domain2D dom{Polyline{{Vec<2>(-5, -5), Vec<2>(5, -5), Vec<2>(5, 5), Vec<2>(-5, 5)}, 0, {1, 2, 3, 4}}, {disk}};
  // the same scene shifted so that the box is [0, 10]^2, for the coordinate checks
  for (const auto& shift : {Vec<2>(5, 5)}) {
    Domain2D d2 = dom;
    auto& poly = std::get<Polyline>(d2.outer);
    for (auto& p : poly.points) p += shift;
    Circle dk = disk;
    dk.centre += shift;
    d2.holes = {dk};
    for (const SizeFunction& h : {graded_size({dk}, 0.005, 0.5), uniform_size(0.08)}) {
      MesherReport rep;
      const Mesh<2> m = generate_mesh(d2, MesherOptions{h}, &rep);
      INFO(m.n_cells() << " triangles");
      check_channel(m, 10, 10, {dk});
      CHECK(rep.dropped == 0);
      const auto [lo, hi] = size_band(m, h);
      INFO("edge / h in [" << lo << ", " << hi << "]");
      CHECK(lo >= 0.4);
      CHECK(hi <= 1.2);
    }
  }
}

TEST_CASE("polyline holes, circle outer boundary, per-segment tags", "[mesh][mesher]") {
  // circle outer with a triangular and a square hole, clockwise given on purpose
  Domain2D dom;
  dom.outer = Circle{Vec<2>(0, 0), 1.0, 7};
  dom.holes.push_back(Polyline{{Vec<2>(-0.5, -0.2), Vec<2>(-0.5, 0.2), Vec<2>(-0.1, 0.0)}, 8});
  dom.holes.push_back(Polyline{{Vec<2>(0.2, -0.2), Vec<2>(0.6, -0.2), Vec<2>(0.6, 0.2), Vec<2>(0.2, 0.2)}, 0, {11, 12, 13, 14}});
  const auto& tri = std::get<Polyline>(dom.holes[0]).points;
  MesherReport rep;
  const Mesh<2> m = generate_mesh(dom, MesherOptions{uniform_size(0.05)}, &rep);
  CHECK(min_angle_deg(m) >= 25.0);  // the domain's angles at the hole corners are all > 180 degrees
  CHECK(rep.dropped == 0);
  const Circle outer = std::get<Circle>(dom.outer);
  for (Index f : m.boundary_facets()) {
    const auto& fv = m.facet(f);
    const Vec<2>&a = m.node(fv[0]), &b = m.node(fv[1]);
    switch (m.facet_tag(f)) {
      case 7: CHECK((on_circle(a, outer) && on_circle(b, outer))); break;
      case 8: CHECK((near_polyline(a, tri) && near_polyline(b, tri))); break;
      case 11: CHECK((a[1] == -0.2 && b[1] == -0.2)); break;
      case 12: CHECK((a[0] == 0.6 && b[0] == 0.6)); break;
      case 13: CHECK((a[1] == 0.2 && b[1] == 0.2)); break;
      case 14: CHECK((a[0] == 0.2 && b[0] == 0.2)); break;
      default: FAIL("untagged or wrongly tagged boundary facet " << f << " tag " << m.facet_tag(f));
    }
  }
  // area: outer inscribed polygon minus the two holes (exact polygons)
  const double area = tagged_polygon_area(m, 7, Vec<2>::Zero()) - 0.5 * 0.4 * 0.4 - 0.4 * 0.4;
  CHECK(m.total_measure() == Approx(area).epsilon(1e-12));
}

TEST_CASE("small input angles: termination, guarantee away from the corner", "[mesh][mesher]") {
  // Wedges of unit side. Triangles spanning the wedge between equidistant boundary nodes
  // (or with the corner as a vertex) are exempt; for 1 and 2 degrees that is everything
  // (the wedge is narrower than h), so only validity is checked there.
  for (double deg : {1.0, 2.0, 10.0, 20.0, 45.0}) {
    const double a = deg * pi / 180;
    Domain2D dom{Polyline{{Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(std::cos(a), std::sin(a))}, 1}, {}};
    MesherReport rep;
    const Mesh<2> m = generate_mesh(dom, MesherOptions{uniform_size(0.05)}, &rep);
    INFO(deg << " degrees: " << m.n_cells() << " triangles, " << rep.small_angle_skips << " skips");
    CHECK(rep.dropped == 0);
    CHECK(rep.unsplittable == 0);
    for (Index c = 0; c < m.n_cells(); ++c) {
      bool near_corner = false;
      for (Index v : m.cell(c)) near_corner = near_corner || m.node(v).norm() < 0.3;
      if (!near_corner && deg >= 10) CHECK(cell_min_angle(m, c) >= 25.0);
    }
    CHECK(m.total_measure() == Approx(0.5 * std::sin(a)).epsilon(1e-12));
  }
}

TEST_CASE("small features: disk close to a wall and to another disk", "[mesh][mesher]") {
  const std::vector<Circle> disks{{Vec<2>(0.13, 1), 0.125, 5}, {Vec<2>(0.385, 1), 0.125, 6}};  // gaps 0.005
  MesherReport rep;
  const Mesh<2> m = channel_with_disks(2, 6, disks, 0.02, 0.2, &rep);
  check_channel(m, 2, 6, disks);
  CHECK(rep.dropped == 0);
}

TEST_CASE("mesher is deterministic", "[mesh][mesher]") {
  const std::vector<Circle> disks{{Vec<2>(1, 4), 0.125, 5}, {Vec<2>(0.9, 4.6), 0.125, 6}};
  const Mesh<2> a = channel_with_disks(2, 6, disks, 0.01, 0.1);
  const Mesh<2> b = channel_with_disks(2, 6, disks, 0.01, 0.1);
  REQUIRE(a.n_nodes() == b.n_nodes());
  REQUIRE(a.n_cells() == b.n_cells());
  CHECK(a.coordinates() == b.coordinates());
  CHECK(a.cells() == b.cells());
  CHECK(a.boundary_facets() == b.boundary_facets());
}

TEST_CASE("curved_edge_midpoints puts boundary midpoints on the circles", "[mesh][mesher]") {
  const Domain2D dom{Circle{Vec<2>(0.5, 0.25), 1.0, 2}, {Circle{Vec<2>(0.4, 0.3), 0.3, 1}}};
  const Mesh<2> m = generate_mesh(dom, MesherOptions{uniform_size(0.1)});
  const auto mid = curved_edge_midpoints(m, dom);
  REQUIRE(mid.size() == std::size_t(m.n_edges()));
  const Circle c2 = std::get<Circle>(dom.outer), c1 = std::get<Circle>(dom.holes[0]);
  std::vector<char> curved(mid.size(), 0);
  for (int tag : {1, 2})
    for (Index e : m.boundary_edges(tag)) {
      curved[e] = 1;
      const Circle& c = tag == 1 ? c1 : c2;
      CHECK(on_circle(mid[e], c, 1e-14));
      const double da = (mid[e] - m.node(m.edge(e)[0])).norm(), db = (mid[e] - m.node(m.edge(e)[1])).norm();
      CHECK(da == Approx(db).epsilon(1e-10));
      CHECK(da < m.edge_length(e));
    }
  for (Index e = 0; e < m.n_edges(); ++e)
    if (!curved[e]) CHECK((mid[e] - 0.5 * (m.node(m.edge(e)[0]) + m.node(m.edge(e)[1]))).norm() == 0);
}

TEST_CASE("elliptic holes: nodes on the ellipses, angles, area, curved midpoints", "[mesh][mesher]") {
  // two tilted ellipses (aspect 2 and 4) in a box
  const Polyline box{{Vec<2>(-2, -2), Vec<2>(2, -2), Vec<2>(2, 2), Vec<2>(-2, 2)}, 9};
  const Ellipse e1{Vec<2>(-0.8, 0.1), 0.6, 0.3, 0.4, 1}, e2{Vec<2>(0.9, -0.2), 0.8, 0.2, -1.1, 2};
  const Domain2D dom{box, {e1, e2}};
  MesherReport rep;
  const Mesh<2> m = generate_mesh(dom, MesherOptions{uniform_size(0.04)}, &rep);
  CHECK(min_angle_deg(m) >= 25.0);
  CHECK(rep.dropped == 0);
  for (Index f : m.boundary_facets()) {
    const int tag = m.facet_tag(f);
    if (tag == 9) continue;
    REQUIRE((tag == 1 || tag == 2));
    const Ellipse& e = tag == 1 ? e1 : e2;
    for (Index v : m.facet(f)) CHECK(std::abs(e.level(m.node(v)) - 1) < 1e-14);
  }
  // the mesh's measure: the box minus the polygons through the ellipses' nodes
  const double holes = tagged_polygon_area(m, 1, e1.centre) + tagged_polygon_area(m, 2, e2.centre);
  CHECK(m.total_measure() == Approx(16 - holes).epsilon(1e-12));
  // curved midpoints at the parameter midpoint: the ellipse is the affine image (det a b) of
  // the unit circle, so the parabolic segment over an edge spanning dt of parameter has the
  // area of the unit circle's, a b 4/3 sin(dt/2) (1 - cos(dt/2)) (Archimedes: 4/3 of the
  // triangle), and the elliptic segment a b (dt - sin dt) / 2
  const auto mid = curved_edge_midpoints(m, dom);
  double polygon_defect = 0, quadratic_defect = 0;
  for (int tag : {1, 2})
    for (Index e : m.boundary_edges(tag)) {
      const Ellipse& el = tag == 1 ? e1 : e2;
      const Vec<2> A = m.node(m.edge(e)[0]), B = m.node(m.edge(e)[1]);
      CHECK(std::abs(el.level(mid[e]) - 1) < 1e-14);
      double dt = std::abs(el.parameter(B) - el.parameter(A));
      if (dt > pi) dt = 2 * pi - dt;
      const Vec<2> a = A - mid[e], b = B - mid[e];
      const double bulge = 4.0 / 3.0 * 0.5 * std::abs(a[0] * b[1] - a[1] * b[0]);
      const double ab = el.a * el.b;
      CHECK(bulge == Approx(ab * 4.0 / 3.0 * std::sin(dt / 2) * (1 - std::cos(dt / 2))).epsilon(1e-9));
      polygon_defect += ab * (dt - std::sin(dt)) / 2;
      quadratic_defect += ab * (dt - std::sin(dt)) / 2 - bulge;
    }
  // the polygons miss exactly the elliptic segments
  CHECK(holes + polygon_defect == Approx(pi * (e1.a * e1.b + e2.a * e2.b)).epsilon(1e-12));
  INFO("area missed: polygons " << polygon_defect << ", quadratic boundary " << quadratic_defect);
  CHECK(std::abs(quadratic_defect) < 1e-3 * polygon_defect);  // O(dt^5) against O(dt^3) per edge
  // an ellipse is a hole only; overlapping ellipses are refused by name
  auto mesh = [](const Domain2D& d) { return [=] { (void)generate_mesh(d, MesherOptions{uniform_size(0.2)}); }; };
  CHECK(invalid_parameter(mesh({Ellipse{Vec<2>::Zero(), 2, 1, 0, 1}, {}})) == "outer");
  CHECK(invalid_parameter(mesh({box, {Ellipse{Vec<2>::Zero(), 0.5, 0, 0, 1}}})) == "holes[0].b");
  CHECK(invalid_parameter(mesh({box, {e1, Ellipse{Vec<2>(-0.3, 0.1), 0.3, 0.1, 0, 3}}})) == "holes[1]");
  CHECK(invalid_parameter(mesh({box, {Ellipse{Vec<2>(1.5, 0), 0.6, 0.1, 0, 3}}})) == "holes[0]");  // crosses the wall
}

TEST_CASE("mesher rejects bad input naming the parameter", "[mesh][mesher]") {
  const Polyline box{{Vec<2>(0, 0), Vec<2>(2, 0), Vec<2>(2, 2), Vec<2>(0, 2)}, 1};
  const MesherOptions ok{uniform_size(0.2)};
  auto mesh = [](const Domain2D& d, const MesherOptions& o) { return [=] { (void)generate_mesh(d, o); }; };
  // size
  CHECK(invalid_parameter([] { (void)uniform_size(0); }) == "h");
  CHECK(invalid_parameter(mesh({box, {}}, MesherOptions{})) == "size");
  CHECK(invalid_parameter(mesh({box, {}}, MesherOptions{[](const Vec<2>&) { return -1.0; }})) == "size");
  CHECK(invalid_parameter(mesh({box, {}}, MesherOptions{[](const Vec<2>& x) { return x[0] > 1.5 ? 0.0 : 0.1; }})) == "size");
  CHECK(invalid_parameter([] { (void)graded_size({}, 0, 1); }) == "h_body");
  CHECK(invalid_parameter([] { (void)graded_size({}, 0.1, 0.05); }) == "h_far");
  CHECK(invalid_parameter([] { (void)graded_size({}, 0.1, 1, -1); }) == "grading");
  CHECK(invalid_parameter(mesh({box, {}}, MesherOptions{uniform_size(0.2), 40})) == "min_angle_deg");
  CHECK(invalid_parameter(mesh({box, {}}, MesherOptions{uniform_size(0.01), 25, 1000})) == "max_points");
  // polylines
  CHECK(invalid_parameter(mesh({Polyline{{Vec<2>(0, 0), Vec<2>(1, 0)}, 1}, {}}, ok)) == "outer.points");
  CHECK(invalid_parameter(mesh({Polyline{{Vec<2>(0, 0), Vec<2>(1, 1), Vec<2>(1, 0), Vec<2>(0, 1)}, 1}, {}}, ok)) ==
        "outer.points");  // bow tie
  CHECK(invalid_parameter(mesh({Polyline{{Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(2, 0)}, 1}, {}}, ok)) == "outer.points");
  CHECK(invalid_parameter(mesh({Polyline{box.points, 1, {1, 2}}, {}}, ok)) == "outer.segment_tags");
  CHECK(invalid_parameter(mesh({box, {Polyline{{Vec<2>(0.5, 0.5), Vec<2>(1, 0.5)}, 2}}}, ok)) == "holes[0].points");
  // circles
  CHECK(invalid_parameter(mesh({Circle{Vec<2>(0, 0), 0.0, 1}, {}}, ok)) == "outer.radius");
  CHECK(invalid_parameter(mesh({box, {Circle{Vec<2>(1, 1), -0.1, 2}}}, ok)) == "holes[0].radius");
  // holes outside the outer boundary / overlapping
  CHECK(invalid_parameter(mesh({box, {Circle{Vec<2>(3, 1), 0.2, 2}}}, ok)) == "holes[0]");
  CHECK(invalid_parameter(mesh({box, {Circle{Vec<2>(1.9, 1), 0.2, 2}}}, ok)) == "holes[0]");
  CHECK(invalid_parameter(mesh({box, {Circle{Vec<2>(0.5, 1), 0.2, 2}, Circle{Vec<2>(0.8, 1), 0.2, 3}}}, ok)) == "holes[1]");
  CHECK(invalid_parameter(mesh({box, {Circle{Vec<2>(0.5, 1), 0.2, 2}, Circle{Vec<2>(0.9, 1), 0.2, 3}}}, ok)) ==
        "holes[1]");  // touching
  CHECK(invalid_parameter(mesh({Circle{Vec<2>(0, 0), 1, 1}, {Polyline{{Vec<2>(0, 0), Vec<2>(1.2, 0), Vec<2>(0, 0.5)}, 2}}},
                               ok)) == "holes[0]");
  CHECK(invalid_parameter(mesh({box, {Polyline{{Vec<2>(0.5, 0.5), Vec<2>(1.5, 0.5), Vec<2>(1, 1.5)}, 2},
                                      Circle{Vec<2>(1, 0.8), 0.1, 3}}},
                               ok)) == "holes[1]");  // disk inside the triangle hole
  // scenes
  CHECK(invalid_parameter([] { (void)channel_with_disks(0, 6, {}, 0.1, 0.2); }) == "width");
  CHECK(invalid_parameter([] { (void)annulus_unstructured(1, 0.5, 0.1); }) == "r2");
  CHECK(invalid_parameter([] { (void)annulus_unstructured(0.5, 1, 0); }) == "h");
}

TEST_CASE("hole closer to an outer circle than the sagitta of its chords", "[mesh][mesher]") {
  // h = 0.2 gives chords of sagitta 0.005 on the unit circle; the hole is 0.002 away
  const Circle outer{Vec<2>::Zero(), 1.0, 2}, hole{Vec<2>(0.948, 0), 0.05, 1};
  MesherReport rep;
  const Mesh<2> m = generate_mesh(Domain2D{outer, {hole}}, MesherOptions{uniform_size(0.2)}, &rep);
  CHECK(min_angle_deg(m) >= 25.0);
  CHECK(rep.dropped == 0);
  for (Index v : m.boundary_nodes(2)) CHECK(on_circle(m.node(v), outer));
  for (Index v : m.boundary_nodes(1)) CHECK(on_circle(m.node(v), hole));
  const double area = tagged_polygon_area(m, 2, outer.centre) - tagged_polygon_area(m, 1, hole.centre);
  CHECK(m.total_measure() == Approx(area).epsilon(1e-12));
}
