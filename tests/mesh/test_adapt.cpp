// Tests of 2D mesh adaptation and field transfer (mesh/adapt.hpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/mesh/adapt.hpp"
#include "alefsi/mesh/generate/structured.hpp"

using namespace alefsi;

namespace {

constexpr double pi = std::numbers::pi;

double worst_quality(const Mesh<2>& m) {
  double q = 1;
  for (Index c = 0; c < m.n_cells(); ++c) q = std::min(q, m.quality(c));
  return q;
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

/// Area of the polygon through the boundary nodes with the given tag, ordered by angle
/// around `centre` (for a circle: the inscribed polygon the mesh actually uses).
double tagged_polygon_area(const Mesh<2>& m, int tag, const Vec<2>& centre) {
  std::vector<Vec<2>> p;
  for (Index v : m.boundary_nodes(tag)) p.push_back(m.node(v) - centre);
  std::sort(p.begin(), p.end(), [](const Vec<2>& a, const Vec<2>& b) { return std::atan2(a[1], a[0]) < std::atan2(b[1], b[0]); });
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) a += p[i][0] * p[(i + 1) % p.size()][1] - p[(i + 1) % p.size()][0] * p[i][1];
  return 0.5 * a;
}

double max_circle_error(const Mesh<2>& m, int tag, const Circle& c) {
  double e = 0;
  for (Index v : m.boundary_nodes(tag)) e = std::max(e, std::abs((m.node(v) - c.centre).norm() - c.radius));
  return e;
}

/// Every boundary facet carries one of the expected tags; every boundary node is on 2 facets.
void check_boundary_tags(const Mesh<2>& m, const std::vector<int>& expected) {
  std::vector<int> count(static_cast<std::size_t>(m.n_nodes()), 0);
  for (Index f : m.boundary_facets()) {
    CHECK(std::find(expected.begin(), expected.end(), m.facet_tag(f)) != expected.end());
    for (Index v : m.facet(f)) ++count[v];
  }
  for (int c : count) CHECK((c == 0 || c == 2));
}

Polyline channel_walls(double W, double H) {
  return Polyline{{Vec<2>(0, 0), Vec<2>(W, 0), Vec<2>(W, H), Vec<2>(0, H)}, 0, {tags::bottom, tags::right, tags::top, tags::left}};
}

/// Values of f at the P1 (degree 1) or P2 (degree 2) DOF points of a mesh (DofMap numbering).
template <int D>
std::vector<double> interpolate(const Mesh<D>& m, int degree, const std::function<double(const Vec<D>&)>& f) {
  std::vector<double> v;
  for (Index i = 0; i < m.n_nodes(); ++i) v.push_back(f(m.node(i)));
  if (degree == 2)
    for (Index e = 0; e < m.n_edges(); ++e) v.push_back(f(0.5 * (m.node(m.edge(e)[0]) + m.node(m.edge(e)[1]))));
  return v;
}
std::vector<double> interpolate(const Mesh<2>& m, int degree, const std::function<double(const Vec<2>&)>& f) {
  return interpolate<2>(m, degree, f);
}
std::vector<double> interpolate(const Mesh<3>& m, int degree, const std::function<double(const Vec<3>&)>& f) {
  return interpolate<3>(m, degree, f);
}

/// P1 transfer of an affine field (gradient norm `grad`) to a mesh with nodes outside `from`:
/// extrapolated, exact for the space; clamped, no overshoot and an error within grad times the
/// distance to the old mesh. Returns that largest distance.
template <int D>
double check_outside_points(const Mesh<D>& from, const Mesh<D>& to, const std::function<double(const Vec<D>&)>& lin,
                            double grad) {
  const FieldTransfer<D> clamp(from, to, 1), extra(from, to, 1, {}, OutsidePolicy::extrapolate);
  std::printf("%dD outside points: %d of %d, max distance %.2e\n", D, clamp.n_outside(), to.n_nodes(),
              clamp.max_outside_distance());
  CHECK(clamp.n_outside() > 0);
  CHECK(clamp.n_outside() == extra.n_outside());
  const auto src = interpolate<D>(from, 1, lin);
  const double lo = *std::min_element(src.begin(), src.end()), hi = *std::max_element(src.begin(), src.end());
  const auto vc = clamp.apply(src), ve = extra.apply(src);
  double err_c = 0;
  for (Index i = 0; i < to.n_nodes(); ++i) {
    const double exact = lin(to.node(i));
    err_c = std::max(err_c, std::abs(vc[i] - exact));
    CHECK(std::abs(ve[i] - exact) <= 1e-12);              // extrapolation: exact for the space
    CHECK((vc[i] >= lo - 1e-12 && vc[i] <= hi + 1e-12));  // clamping: no overshoot
  }
  CHECK(err_c > 1e-8);  // the clamped value is the one at the nearest point of the old mesh
  CHECK(err_c <= grad * clamp.max_outside_distance() + 1e-12);
  return clamp.max_outside_distance();
}

/// Max and rms error of the P`degree` transfer of f from `from` to `to`, at the DOF points of `to`.
template <int D>
std::pair<double, double> transfer_error(const Mesh<D>& from, const Mesh<D>& to, int degree,
                                         const std::function<double(const Vec<D>&)>& f) {
  const auto v = FieldTransfer<D>(from, to, degree).apply(interpolate<D>(from, degree, f));
  const auto e = interpolate<D>(to, degree, f);
  double mx = 0, s2 = 0;
  for (std::size_t i = 0; i < v.size(); ++i) mx = std::max(mx, std::abs(v[i] - e[i])), s2 += (v[i] - e[i]) * (v[i] - e[i]);
  return {mx, std::sqrt(s2 / double(v.size()))};
}

/// box_mesh of the unit cube moved by a smooth map onto itself (boundary fixed).
Mesh<3> perturbed_cube(int n) {
  Mesh<3> m = box_mesh(n, n, n);
  std::vector<Vec<3>> x = m.coordinates();
  for (auto& p : x) p += 0.05 * std::sin(pi * p[0]) * std::sin(pi * p[1]) * std::sin(pi * p[2]) * Vec<3>(1.0, -0.7, 0.4);
  m.set_coordinates(x);
  return m;
}

Mesh<2> square_mesh(double h) {
  Domain2D dom{Polyline{{Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(1, 1), Vec<2>(0, 1)}, 1}};
  return generate_mesh(dom, MesherOptions{uniform_size(h)});
}

/// rectangle_mesh moved by a smooth map of the unit square onto itself (boundary fixed).
Mesh<2> perturbed_square(int n) {
  Mesh<2> m = rectangle_mesh(n, n);
  std::vector<Vec<2>> x = m.coordinates();
  for (auto& p : x) p += 0.06 * std::sin(pi * p[0]) * std::sin(pi * p[1]) * Vec<2>(1.0, -0.7);
  m.set_coordinates(x);
  return m;
}

}  // namespace

TEST_CASE("adapt: annulus with the inner disk rotated by 2 pi, adapted every step", "[mesh][adapt]") {
  const double r1 = 0.25, r2 = 1.0, h = 0.05;
  const int steps = 80;
  Mesh<2> m = annulus_unstructured(r1, r2, h);
  const Circle inner{Vec<2>::Zero(), r1, tags::inner}, outer{Vec<2>::Zero(), r2, tags::outer};
  const std::vector<BoundaryCurve> curves{outer, inner};
  AdaptOptions opt;
  opt.size = uniform_size(h);
  const double dtheta = 2 * pi / steps;
  auto affine = [](const Vec<2>& x) { return 1.0 + 2.0 * x[0] - 3.0 * x[1]; };
  double worst_angle = 180, worst_q = 1, band_lo = 1e9, band_hi = 0;
  int ops = 0;
  std::printf("annulus rotation: %d cells at start\n", m.n_cells());
  for (int s = 0; s < steps; ++s) {
    // smooth ALE motion: rotation by dtheta * w(r), w = 1 on the disk, 0 on the outer wall
    std::vector<Vec<2>> x = m.coordinates();
    for (auto& p : x) {
      const double u = std::clamp((p.norm() - r1) / (r2 - r1), 0.0, 1.0);
      const double a = dtheta * 0.5 * (1 + std::cos(pi * u));
      p = Vec<2>(std::cos(a) * p[0] - std::sin(a) * p[1], std::sin(a) * p[0] + std::cos(a) * p[1]);
    }
    Mesh<2> moved = m;
    moved.set_coordinates(x);  // throws if the motion inverted a cell
    AdaptReport rep;
    m = adapt(moved, curves, opt, &rep);  // the Mesh constructor throws on an inverted cell
    const auto [lo, hi] = size_band(m, opt.size);
    std::printf("  step %2d: moved min angle %5.2f q %.3f -> adapted %5d cells, min angle %5.2f, worst q %.3f, "
                "L/h in [%.2f, %.2f] (split %d collapse %d flip %d smooth %d refused %d)\n",
                s, min_angle_deg(moved), worst_quality(moved), m.n_cells(), rep.min_angle_deg, rep.worst_quality, lo, hi,
                rep.splits, rep.collapses, rep.flips, rep.smoothed, rep.refused);
    worst_angle = std::min(worst_angle, rep.min_angle_deg);
    worst_q = std::min(worst_q, rep.worst_quality);
    band_lo = std::min(band_lo, lo), band_hi = std::max(band_hi, hi);
    ops += rep.splits + rep.collapses + rep.flips;
    REQUIRE(rep.worst_quality == Approx(worst_quality(m)));
    // boundary: nodes on their circles, tags carried, area = polygon area (no overlap, no gap)
    CHECK(max_circle_error(m, tags::inner, inner) <= 1e-14);
    CHECK(max_circle_error(m, tags::outer, outer) <= 1e-14);
    check_boundary_tags(m, {tags::inner, tags::outer});
    const double poly = tagged_polygon_area(m, tags::outer, Vec<2>::Zero()) - tagged_polygon_area(m, tags::inner, Vec<2>::Zero());
    CHECK(m.total_measure() == Approx(poly).epsilon(1e-12));
    CHECK(m.total_measure() == Approx(pi * (r2 * r2 - r1 * r1)).epsilon(h * h));
    // transfer from the moved to the adapted mesh: exact for an affine field (points on
    // the arcs lie outside the old polygon: extrapolation keeps it exact)
    const auto v = transfer<1>(moved, interpolate(moved, 1, affine), 1, m, {}, OutsidePolicy::extrapolate);
    double err = 0;
    for (Index i = 0; i < m.n_nodes(); ++i) err = std::max(err, std::abs(v[i] - affine(m.node(i))));
    CHECK(err <= 1e-12);
  }
  std::printf("annulus rotation: worst min angle %.2f deg, worst quality %.3f, L/h in [%.2f, %.2f], %d cells at the end\n",
              worst_angle, worst_q, band_lo, band_hi, m.n_cells());
  // floors chosen from the measurement (see the report) with a margin
  CHECK(worst_angle >= 20.0);
  CHECK(worst_q >= 0.55);
  CHECK(band_lo >= 0.25);
  CHECK(band_hi <= 1.0 + opt.tolerance);
  CHECK(ops > 1000);  // the mesh was really reconnected
}

TEST_CASE("adapt: an ellipse turned in a box, adapted every step: nodes stay on the ellipse", "[mesh][adapt]") {
  // an ellipse (aspect 3) turned by pi / 2 in 20 steps with a smooth ALE rotation field; each
  // adaptation is given the ellipse at its new angle, and new or sliding nodes land on it
  const Polyline box{{Vec<2>(-1.5, -1.5), Vec<2>(1.5, -1.5), Vec<2>(1.5, 1.5), Vec<2>(-1.5, 1.5)}, 9};
  Ellipse body{Vec<2>::Zero(), 0.6, 0.2, 0.0, 1};
  const double h = 0.06;
  Mesh<2> m = generate_mesh(Domain2D{box, {body}}, MesherOptions{uniform_size(h)});
  AdaptOptions opt;
  opt.size = uniform_size(h);
  const int steps = 20;
  const double dtheta = 0.5 * pi / steps;
  double worst_q = 1, worst_level = 0;
  int ops = 0;
  for (int s = 0; s < steps; ++s) {
    std::vector<Vec<2>> x = m.coordinates();
    for (auto& p : x) {  // w = 1 inside r = 0.6, 0 beyond r = 1.4
      const double u = std::clamp((p.norm() - 0.6) / 0.8, 0.0, 1.0), a = dtheta * 0.5 * (1 + std::cos(pi * u));
      p = Vec<2>(std::cos(a) * p[0] - std::sin(a) * p[1], std::sin(a) * p[0] + std::cos(a) * p[1]);
    }
    Mesh<2> moved = m;
    moved.set_coordinates(x);
    body.angle += dtheta;
    AdaptReport rep;
    m = adapt(moved, {box, body}, opt, &rep);
    worst_q = std::min(worst_q, rep.worst_quality);
    ops += rep.splits + rep.collapses + rep.flips;
    for (Index v : m.boundary_nodes(1)) worst_level = std::max(worst_level, std::abs(body.level(m.node(v)) - 1));
    check_boundary_tags(m, {1, 9});
  }
  std::printf("ellipse turned by pi/2: worst quality %.3f, worst |level - 1| on the ellipse %.2e, %d operations\n",
              worst_q, worst_level, ops);
  CHECK(worst_level < 1e-12);  // rotated nodes carry round-off of the rotation; new ones are exact
  CHECK(worst_q >= 0.55);      // the annulus test's floor
  CHECK(ops > 100);
  // the mesh's measure: the box minus the polygon through the ellipse's nodes
  CHECK(m.total_measure() == Approx(9 - tagged_polygon_area(m, 1, Vec<2>::Zero())).epsilon(1e-12));
}

TEST_CASE("adapt: disk translated across a channel, adapted every step", "[mesh][adapt]") {
  const double W = 6, H = 2, r = 0.125, hb = 0.02, travel = 1.5;  // 6 diameters
  const int steps = 60;
  Vec<2> c(1, 1);
  Mesh<2> m = channel_with_disks(W, H, {Circle{c, r, 5}}, hb, 10 * hb);
  const Polyline walls = channel_walls(W, H);
  double worst_angle = 180, worst_q = 1, band_lo = 1e9, band_hi = 0;
  int splits = 0, collapses = 0, refused = 0;
  std::printf("channel with a moving disk: %d cells at start\n", m.n_cells());
  for (int s = 0; s < steps; ++s) {
    // smooth bump displacement: rigid on and near the disk, zero beyond 0.5 from it
    const double dx = travel / steps;
    std::vector<Vec<2>> x = m.coordinates();
    for (auto& p : x) {
      const double u = std::clamp(((p - c).norm() - (r + 0.05)) / 0.45, 0.0, 1.0);
      p[0] += dx * 0.5 * (1 + std::cos(pi * u));
    }
    c[0] += dx;
    Mesh<2> moved = m;
    moved.set_coordinates(x);
    const Circle disk{c, r, 5};
    AdaptOptions opt;
    opt.size = graded_size({disk}, hb, 10 * hb);
    AdaptReport rep;
    m = adapt(moved, {walls, disk}, opt, &rep);
    const auto [lo, hi] = size_band(m, opt.size);
    std::printf("  step %2d: moved min angle %5.2f q %.3f -> adapted %5d cells, min angle %5.2f, worst q %.3f, "
                "L/h in [%.2f, %.2f] (split %d collapse %d flip %d smooth %d refused %d)\n",
                s, min_angle_deg(moved), worst_quality(moved), m.n_cells(), rep.min_angle_deg, rep.worst_quality, lo, hi,
                rep.splits, rep.collapses, rep.flips, rep.smoothed, rep.refused);
    worst_angle = std::min(worst_angle, rep.min_angle_deg);
    worst_q = std::min(worst_q, rep.worst_quality);
    band_lo = std::min(band_lo, lo), band_hi = std::max(band_hi, hi);
    splits += rep.splits, collapses += rep.collapses, refused += rep.refused;
    // walls stay straight, corners stay, disk nodes on the moved circle
    for (Index v : m.boundary_nodes(tags::bottom)) CHECK(m.node(v)[1] == 0.0);
    for (Index v : m.boundary_nodes(tags::top)) CHECK(m.node(v)[1] == H);
    for (Index v : m.boundary_nodes(tags::left)) CHECK(m.node(v)[0] == 0.0);
    for (Index v : m.boundary_nodes(tags::right)) CHECK(m.node(v)[0] == W);
    int corners = 0;
    for (Index v = 0; v < m.n_nodes(); ++v)
      for (const auto& p : walls.points) corners += m.node(v) == p;
    CHECK(corners == 4);
    CHECK(max_circle_error(m, 5, disk) <= 1e-14);
    check_boundary_tags(m, {tags::bottom, tags::right, tags::top, tags::left, 5});
    // straight walls: the area is W * H minus the disk's polygon, to round-off
    CHECK(m.total_measure() == Approx(W * H - tagged_polygon_area(m, 5, c)).epsilon(1e-13));
  }
  std::printf("channel: worst min angle %.2f deg, worst quality %.3f, L/h in [%.2f, %.2f], %d splits, %d collapses\n",
              worst_angle, worst_q, band_lo, band_hi, splits, collapses);
  CHECK(worst_angle >= 20.0);
  CHECK(worst_q >= 0.55);
  CHECK(band_lo >= 0.2);  // collapses refused for quality leave a few edges below 0.3 h
  CHECK(band_hi <= 1.7);
  CHECK(splits > 0);
  CHECK(collapses > 0);
  CHECK(refused > 0);  // some operations were refused, and every mesh was still valid
}

TEST_CASE("adapt: paper mode (no size function) restores sizes of a compressed mesh", "[mesh][adapt]") {
  // a smooth monotone map x -> x^2.5: edges near x = 0 shrink, near x = 1 grow
  Mesh<2> moved = rectangle_mesh(16, 16);
  std::vector<Vec<2>> x = moved.coordinates();
  for (auto& p : x) p[0] = std::pow(p[0], 2.5);
  moved.set_coordinates(x);
  const std::vector<BoundaryCurve> curves{channel_walls(1, 1)};
  AdaptOptions opt;  // no size: E from the *input* mesh's node sizes
  AdaptReport rep;
  const Mesh<2> out = adapt(moved, curves, opt, &rep);
  std::printf("paper mode: %d -> %d cells, %d splits, %d collapses, min angle %.2f -> %.2f\n", moved.n_cells(),
              out.n_cells(), rep.splits, rep.collapses, min_angle_deg(moved), rep.min_angle_deg);
  CHECK(out.total_measure() == Approx(1.0).epsilon(1e-13));
  CHECK(rep.changed);
  CHECK(rep.flips + rep.smoothed > 0);
  CHECK(rep.min_angle_deg > min_angle_deg(moved));
  // with a size function the compressed strip is coarsened and the stretched part refined
  opt.size = uniform_size(1.0 / 16);
  const Mesh<2> out2 = adapt(moved, curves, opt, &rep);
  CHECK(rep.splits > 0);
  CHECK(rep.collapses > 0);
  const auto [lo, hi] = size_band(out2, opt.size);
  std::printf("uniform target: %d cells, L/h in [%.2f, %.2f], min angle %.2f\n", out2.n_cells(), lo, hi, rep.min_angle_deg);
  CHECK(hi <= 1.7);
  CHECK(rep.min_angle_deg >= 20.0);
  CHECK(out2.total_measure() == Approx(1.0).epsilon(1e-13));
  CHECK(out2.boundary_nodes(tags::bottom).size() >= 2);
}

TEST_CASE("adapt: deterministic, and an unchanged good mesh stays valid", "[mesh][adapt]") {
  Mesh<2> m = annulus_unstructured(0.25, 1.0, 0.1);
  const std::vector<BoundaryCurve> curves{Circle{Vec<2>::Zero(), 1.0, tags::outer}, Circle{Vec<2>::Zero(), 0.25, tags::inner}};
  std::vector<Vec<2>> x = m.coordinates();
  for (auto& p : x) p *= 1.0 + 0.3 * (1 - p.norm()) * (p.norm() - 0.25);  // boundary nodes stay
  m.set_coordinates(x);
  AdaptOptions opt;
  opt.size = uniform_size(0.08);
  const Mesh<2> a = adapt(m, curves, opt), b = adapt(m, curves, opt);
  REQUIRE(a.n_nodes() == b.n_nodes());
  REQUIRE(a.cells() == b.cells());
  CHECK(a.coordinates() == b.coordinates());
  CHECK(a.cell_tags() == b.cell_tags());
}

TEST_CASE("adapt: unknown boundary tags are kept fixed, region tags preserved", "[mesh][adapt]") {
  Mesh<2> m = rectangle_mesh(12, 12);
  std::vector<int> ctags(static_cast<std::size_t>(m.n_cells()));
  for (Index c = 0; c < m.n_cells(); ++c) ctags[c] = m.centroid(c)[0] < 0.5 ? 1 : 2;
  std::vector<Mesh<2>::Facet> f;
  std::vector<int> t;
  for (Index b : m.boundary_facets()) f.push_back(m.facet(b)), t.push_back(m.facet_tag(b));
  Mesh<2> tagged(m.coordinates(), m.cells(), f, t, ctags);
  std::vector<Vec<2>> x = tagged.coordinates();
  for (auto& p : x) p[1] = p[1] * p[1];  // compress near y = 0
  tagged.set_coordinates(x);
  AdaptOptions opt;
  opt.size = uniform_size(1.0 / 12);
  AdaptReport rep;
  const Mesh<2> out = adapt(tagged, {}, opt, &rep);  // no curves: every boundary node fixed
  CHECK(out.total_measure() == Approx(1.0).epsilon(1e-13));
  // boundary nodes: no boundary node removed, the only new ones are chord midpoints
  for (int tag : {1, 2, 3, 4}) CHECK(out.boundary_nodes(tag).size() >= tagged.boundary_nodes(tag).size());
  // region interface x = 0.5 intact: cells of tag 1 left of it, of tag 2 right of it
  double area1 = 0;
  for (Index c = 0; c < out.n_cells(); ++c) {
    if (out.cell_tag(c) == 1) {
      area1 += out.measure(c);
      CHECK(out.centroid(c)[0] < 0.5);
    } else {
      CHECK(out.centroid(c)[0] > 0.5);
    }
  }
  CHECK(area1 == Approx(0.5).epsilon(1e-13));
}

TEST_CASE("locate: bucket grid, walk with hint, nearest cell outside", "[mesh][adapt]") {
  const Mesh<2> m = annulus_unstructured(0.25, 1.0, 0.1);
  const PointLocator2D loc(m);
  for (int k = 0; k < 200; ++k) {
    const double r = 0.26 + 0.73 * (k % 17) / 16.0, a = 0.37 * k;
    const Vec<2> x(r * std::cos(a), r * std::sin(a));
    Vec<3> l;
    const Index c = loc.locate(x, &l);
    REQUIRE(c >= 0);
    const auto& v = m.cell(c);
    CHECK((l[0] * m.node(v[0]) + l[1] * m.node(v[1]) + l[2] * m.node(v[2]) - x).norm() <= 1e-13);
    CHECK(l.minCoeff() >= 0.0);
    Vec<3> l2;
    const Index c2 = loc.locate(x, &l2, (7 * k) % m.n_cells());  // walk from an arbitrary cell
    const auto& v2 = m.cell(c2);
    CHECK((l2[0] * m.node(v2[0]) + l2[1] * m.node(v2[1]) + l2[2] * m.node(v2[2]) - x).norm() <= 1e-13);
  }
  // outside: in the hole and beyond the outer circle: nearest cell, clamped coordinates
  for (const Vec<2>& x : {Vec<2>(0.0, 0.0), Vec<2>(0.1, 0.05), Vec<2>(1.3, -0.2), Vec<2>(-5.0, 4.0)}) {
    const Location L = loc.find(x);
    REQUIRE(L.cell >= 0);
    CHECK(L.distance > 0);
    CHECK(L.lambda.minCoeff() >= 0.0);
    CHECK(L.lambda.sum() == Approx(1.0));
    const auto& v = m.cell(L.cell);
    const Vec<2> p = L.lambda[0] * m.node(v[0]) + L.lambda[1] * m.node(v[1]) + L.lambda[2] * m.node(v[2]);
    CHECK((p - x).norm() == Approx(L.distance));
    // brute force: no cell is closer
    double best = 1e300;
    for (Index c = 0; c < m.n_cells(); ++c) {
      const auto& w = m.cell(c);
      const Vec<3> q = detail::closest_barycentric(m.node(w[0]), m.node(w[1]), m.node(w[2]), x);
      best = std::min(best, (q[0] * m.node(w[0]) + q[1] * m.node(w[1]) + q[2] * m.node(w[2]) - x).norm());
    }
    CHECK(L.distance == Approx(best).epsilon(1e-12));
  }
}

TEST_CASE("transfer: exact for affine (P1) and quadratic (P2) fields", "[mesh][adapt]") {
  const Mesh<2> from = perturbed_square(9);
  const Mesh<2> to = square_mesh(0.07);
  auto lin = [](const Vec<2>& x) { return 0.5 - 1.5 * x[0] + 2.5 * x[1]; };
  auto quad = [](const Vec<2>& x) { return 1 + x[0] - 2 * x[1] + 3 * x[0] * x[0] - x[0] * x[1] + 2 * x[1] * x[1]; };
  const FieldTransfer2D T1(from, to, 1);
  CHECK(T1.n_outside() == 0);
  const auto v1 = T1.apply(interpolate(from, 1, lin));
  const auto e1 = interpolate(to, 1, lin);
  for (std::size_t i = 0; i < v1.size(); ++i) CHECK(std::abs(v1[i] - e1[i]) <= 1e-12);
  const FieldTransfer2D T2(from, to, 2);
  const auto v2 = T2.apply(interpolate(from, 2, quad));
  const auto e2 = interpolate(to, 2, quad);
  REQUIRE(v2.size() == std::size_t(to.n_nodes() + to.n_edges()));
  for (std::size_t i = 0; i < v2.size(); ++i) CHECK(std::abs(v2[i] - e2[i]) <= 1e-12);

  // several components, several history levels, matrix form: all the same numbers
  const std::vector<double> s0 = interpolate(from, 2, quad), s1 = interpolate(from, 2, lin);
  std::vector<double> inter(2 * s0.size());
  MatX mat(static_cast<Index>(s0.size()), 2);
  for (std::size_t i = 0; i < s0.size(); ++i) {
    inter[2 * i] = s0[i], inter[2 * i + 1] = s1[i];
    mat(Index(i), 0) = s0[i], mat(Index(i), 1) = s1[i];
  }
  const auto levels = T2.apply(std::vector<std::vector<double>>{s0, s1});
  const auto both = T2.apply(inter, 2);
  const MatX mout = T2.apply(mat);
  const auto e2l = interpolate(to, 2, lin);
  for (std::size_t i = 0; i < e2.size(); ++i) {
    CHECK(both[2 * i] == levels[0][i]);
    CHECK(both[2 * i + 1] == levels[1][i]);
    CHECK(mout(Index(i), 0) == Approx(levels[0][i]).margin(1e-14));
    CHECK(std::abs(levels[1][i] - e2l[i]) <= 1e-12);
  }
}

TEST_CASE("transfer: outside points (curved boundary) clamped or extrapolated", "[mesh][adapt]") {
  // the finer annulus has boundary nodes on the arcs between the coarse one's nodes:
  // outside the coarse inscribed polygons, at distance <= h^2 / (8 r) + ...
  const Mesh<2> from = annulus_unstructured(0.25, 1.0, 0.12);
  const Mesh<2> to = annulus_unstructured(0.25, 1.0, 0.05);
  auto lin = [](const Vec<2>& x) { return 2.0 + 3.0 * x[0] - 1.0 * x[1]; };
  const double outside = check_outside_points<2>(from, to, lin, std::sqrt(10.0));
  CHECK(outside <= 0.12 * 0.12 / (8 * 0.25) * 1.5);

  // P2 with the edge DOFs of the boundary edges on the arcs: quadratic field reproduced
  // by extrapolation; clamped: error O(h^2) at those points only
  auto quad = [](const Vec<2>& x) { return 1 + x[0] * x[0] - 2 * x[0] * x[1] + 0.5 * x[1]; };
  const Domain2D dom{Circle{Vec<2>::Zero(), 1.0, tags::outer}, {Circle{Vec<2>::Zero(), 0.25, tags::inner}}};
  const std::vector<Vec<2>> arcs = curved_edge_midpoints(to, dom);
  const auto src2 = interpolate(from, 2, quad);
  const auto v2 = FieldTransfer2D(from, to, 2, arcs, OutsidePolicy::extrapolate).apply(src2);
  const auto c2 = FieldTransfer2D(from, to, 2, arcs).apply(src2);
  double err2 = 0;
  for (Index i = 0; i < to.n_nodes() + to.n_edges(); ++i) {
    const Vec<2> p = i < to.n_nodes() ? to.node(i) : arcs[i - to.n_nodes()];
    CHECK(std::abs(v2[i] - quad(p)) <= 1e-12);
    err2 = std::max(err2, std::abs(c2[i] - quad(p)));
  }
  CHECK(err2 <= 4 * outside);
}

namespace {
// The field f as the isoparametric P`degree` space on `m` with edge points `ep` holds it: its
// values at the nodes, then (P2) at the edge points.
std::vector<double> interpolate_at(const Mesh<2>& m, int degree, const std::vector<Vec<2>>& ep,
                                   const std::function<double(const Vec<2>&)>& f) {
  std::vector<double> v;
  for (Index i = 0; i < m.n_nodes(); ++i) v.push_back(f(m.node(i)));
  if (degree == 2)
    for (const auto& p : ep) v.push_back(f(p));
  return v;
}
}  // namespace

TEST_CASE("transfer: from curved cells (isoparametric P2), exact for the space and O(h^3)", "[mesh][adapt]") {
  // A source annulus whose boundary edges have their points on the arcs (curved_edge_midpoints):
  // its cells are the P2 maps' images and its fields polynomials of the reference coordinates.
  // Mapping the target points back through the straight cells instead is an O(h^2) error in the
  // reference point beside the arcs, which the affine field shows at once.
  const Domain2D dom{Circle{Vec<2>::Zero(), 1.0, tags::outer}, {Circle{Vec<2>::Zero(), 0.25, tags::inner}}};
  const Mesh<2> to = annulus_unstructured(0.25, 1.0, 0.03);
  const std::vector<Vec<2>> to_arcs = curved_edge_midpoints(to, dom);
  auto lin = [](const Vec<2>& x) { return 2.0 + 3.0 * x[0] - 1.0 * x[1]; };
  {
    const Mesh<2> from = annulus_unstructured(0.25, 1.0, 0.12);
    const std::vector<Vec<2>> arcs = curved_edge_midpoints(from, dom);
    // isoparametric P2 holds the affine fields (P1 on curved cells does not: it is linear in
    // the reference coordinates, which are not affine in x there)
    const auto src = interpolate_at(from, 2, arcs, lin);
    const FieldTransfer2D curved(from, to, 2, to_arcs, OutsidePolicy::extrapolate, arcs);
    const FieldTransfer2D straight(from, to, 2, to_arcs, OutsidePolicy::extrapolate);
    const auto vc = curved.apply(src), vs = straight.apply(src);
    const auto exact = interpolate_at(to, 2, to_arcs, lin);
    double ec = 0, es = 0;
    for (std::size_t i = 0; i < exact.size(); ++i)
      ec = std::max(ec, std::abs(vc[i] - exact[i])), es = std::max(es, std::abs(vs[i] - exact[i]));
    std::printf("P2 transfer from curved cells, affine field: max error %.2e (straight location %.2e); %d points "
                "outside, at most %.1e\n",
                ec, es, curved.n_outside(), curved.max_outside_distance());
    CHECK(ec <= 1e-12);
    CHECK(es > 1e-4);  // the straight cells' coordinates: O(h^2) beside the arcs
    // The target's arc points lie outside the source's boundary, the parabola through each
    // boundary edge's ends and its arc's midpoint: in the chord coordinate s the arc is
    // -s^2 / (2 r) - s^4 / (8 r^3) + ..., whose s^4 term the parabola misses by at most
    // h^4 / (512 r^3) (at s^2 = h^2 / 8), h the chord: 2.6e-5 for h = 0.12, r = 0.25.
    CHECK(curved.n_outside() > 0);
    CHECK(curved.max_outside_distance() <= std::pow(0.12, 4) / (512 * std::pow(0.25, 3)));
  }
  // a smooth field, the interpolant of the isoparametric P2 space: O(h^3) with the curved
  // location, O(h^2) with the straight one (the error is at the points beside the arcs)
  auto f = [](const Vec<2>& x) { return std::sin(3 * x[0] + 1) * std::cos(2 * x[1]); };
  const auto exact = interpolate_at(to, 2, to_arcs, f);
  std::vector<double> ec, es;
  for (double h : {0.16, 0.08, 0.04}) {
    const Mesh<2> from = annulus_unstructured(0.25, 1.0, h);
    const std::vector<Vec<2>> arcs = curved_edge_midpoints(from, dom);
    const auto src = interpolate_at(from, 2, arcs, f);
    const auto vc = FieldTransfer2D(from, to, 2, to_arcs, OutsidePolicy::clamp, arcs).apply(src);
    const auto vs = FieldTransfer2D(from, to, 2, to_arcs).apply(src);
    double mc = 0, ms = 0;
    for (std::size_t i = 0; i < exact.size(); ++i)
      mc = std::max(mc, std::abs(vc[i] - exact[i])), ms = std::max(ms, std::abs(vs[i] - exact[i]));
    ec.push_back(mc), es.push_back(ms);
  }
  for (std::size_t k = 1; k < ec.size(); ++k)
    std::printf("P2 transfer from the annulus at h = %.3g: curved %.3e (rate %.2f), straight location %.3e (rate %.2f)\n",
                0.16 / double(1 << k), ec[k], std::log2(ec[k - 1] / ec[k]), es[k], std::log2(es[k - 1] / es[k]));
  // the mesher's meshes are not nested, so the max norm's rate varies from one halving to the
  // next (2.6 then 3.6 here): the rate over both halvings
  const double rc = std::log2(ec[0] / ec[2]) / 2, rs = std::log2(es[0] / es[2]) / 2;
  CHECK(rc >= 3 - 0.3);
  CHECK(rs <= 2 + 0.3);
}

TEST_CASE("transfer: convergence at the interpolation order for a smooth field", "[mesh][adapt]") {
  auto f = [](const Vec<2>& x) { return std::sin(3 * x[0] + 1) * std::cos(2 * x[1]); };
  const Mesh<2> to = square_mesh(0.02);
  for (int degree : {1, 2}) {
    std::vector<double> emax, erms;
    for (int n : {8, 16, 32, 64}) {
      const auto [mx, rms] = transfer_error<2>(perturbed_square(n), to, degree, f);
      emax.push_back(mx), erms.push_back(rms);
    }
    for (std::size_t k = 1; k < emax.size(); ++k) {
      const double rmax = std::log2(emax[k - 1] / emax[k]), rrms = std::log2(erms[k - 1] / erms[k]);
      std::printf("P%d transfer, h = 1/%d: max error %.3e (rate %.2f), rms %.3e (rate %.2f)\n", degree, 8 << k, emax[k],
                  rmax, erms[k], rrms);
      CHECK(rmax >= degree + 1 - 0.25);
      CHECK(rrms >= degree + 1 - 0.2);
    }
  }
}

// ---- 3D: tetrahedra ----------------------------------------------------------------------

TEST_CASE("locate in 3D: bucket grid, walk with hint, nearest cell outside", "[mesh][adapt]") {
  const Mesh<3> m = spherical_shell_mesh(0.5, 1.0, 2);  // a hole and a curved outside
  const PointLocator<3> loc(m);
  auto point = [&](Index c, const Vec<4>& l) {
    Vec<3> p = Vec<3>::Zero();
    for (int k = 0; k < 4; ++k) p += l[k] * m.node(m.cell(c)[k]);
    return p;
  };
  for (int k = 0; k < 300; ++k) {  // points well inside the polyhedral shell
    const double r = 0.56 + 0.38 * (k % 13) / 12.0, th = 0.1 + 2.9 * (k % 7) / 6.0, ph = 0.41 * k;
    const Vec<3> x(r * std::sin(th) * std::cos(ph), r * std::sin(th) * std::sin(ph), r * std::cos(th));
    Vec<4> l;
    const Index c = loc.locate(x, &l);
    REQUIRE(c >= 0);
    CHECK((point(c, l) - x).norm() <= 1e-13);
    CHECK(l.minCoeff() >= 0.0);
    Vec<4> l2;
    const Index c2 = loc.locate(x, &l2, (11 * k) % m.n_cells());  // walk from an arbitrary cell
    CHECK((point(c2, l2) - x).norm() <= 1e-13);
  }
  // outside: the hole, beyond the outer sphere, far away; nearest cell against brute force
  for (const Vec<3>& x : {Vec<3>(0, 0, 0), Vec<3>(0.1, 0.2, -0.1), Vec<3>(0.3, -0.9, 0.6), Vec<3>(-4, 3, 7)}) {
    const PointLocation<3> L = loc.find(x);
    REQUIRE(L.cell >= 0);
    CHECK(L.distance > 0);
    CHECK(L.lambda.minCoeff() >= 0.0);
    CHECK(L.lambda.sum() == Approx(1.0));
    CHECK((point(L.cell, L.lambda) - x).norm() == Approx(L.distance));
    CHECK((point(L.cell, L.raw) - x).norm() <= 1e-12);  // the unclamped coordinates reproduce x
    double best = 1e300;
    for (Index c = 0; c < m.n_cells(); ++c) best = std::min(best, (point(c, detail::cell_closest_barycentric(m, c, x)) - x).norm());
    CHECK(L.distance == Approx(best).epsilon(1e-12));
  }
  // the closest point of a tetrahedron: on a face, an edge, a vertex (unit corner tetrahedron)
  const Vec<3> o(0, 0, 0), ex(1, 0, 0), ey(0, 1, 0), ez(0, 0, 1);
  CHECK(detail::closest_barycentric(o, ex, ey, ez, Vec<3>(0.2, 0.3, -1)).isApprox(Vec<4>(0.5, 0.2, 0.3, 0)));
  CHECK(detail::closest_barycentric(o, ex, ey, ez, Vec<3>(0.5, -1, -1)).isApprox(Vec<4>(0.5, 0.5, 0, 0)));
  CHECK(detail::closest_barycentric(o, ex, ey, ez, Vec<3>(2, 2, 2)).isApprox(Vec<4>(0, 1, 1, 1) / 3));
  CHECK(detail::closest_barycentric(o, ex, ey, ez, Vec<3>(-1, -2, -3)).isApprox(Vec<4>(1, 0, 0, 0)));
}

TEST_CASE("transfer in 3D: exact for affine (P1) and quadratic (P2) fields", "[mesh][adapt]") {
  const Mesh<3> from = perturbed_cube(5);
  const Mesh<3> to = box_mesh(7, 6, 4);
  auto lin = [](const Vec<3>& x) { return 0.5 - 1.5 * x[0] + 2.5 * x[1] - 0.75 * x[2]; };
  auto quad = [](const Vec<3>& x) {
    return 1 + x[0] - 2 * x[1] + x[2] + 3 * x[0] * x[0] - x[0] * x[1] + 2 * x[1] * x[1] - x[2] * x[2] + 1.5 * x[1] * x[2] -
           0.5 * x[0] * x[2];
  };
  const FieldTransfer<3> T1(from, to, 1);
  CHECK(T1.n_outside() == 0);
  const auto v1 = T1.apply(interpolate(from, 1, lin));
  const auto e1 = interpolate(to, 1, lin);
  for (std::size_t i = 0; i < v1.size(); ++i) CHECK(std::abs(v1[i] - e1[i]) <= 1e-12);
  const FieldTransfer<3> T2(from, to, 2);
  const auto v2 = T2.apply(interpolate(from, 2, quad));
  const auto e2 = interpolate(to, 2, quad);
  REQUIRE(v2.size() == std::size_t(to.n_nodes() + to.n_edges()));
  double worst = 0;
  for (std::size_t i = 0; i < v2.size(); ++i) worst = std::max(worst, std::abs(v2[i] - e2[i]));
  CHECK(worst <= 1e-12);
  // three interleaved components (a velocity): each the same as alone
  const auto sq = interpolate(from, 2, quad), sl = interpolate(from, 2, lin);
  std::vector<double> inter(3 * sq.size());
  for (std::size_t i = 0; i < sq.size(); ++i) inter[3 * i] = sq[i], inter[3 * i + 1] = sl[i], inter[3 * i + 2] = -sq[i];
  const auto both = T2.apply(inter, 3);
  const auto e2l = interpolate(to, 2, lin);
  for (std::size_t i = 0; i < e2.size(); ++i) {
    CHECK(both[3 * i] == v2[i]);
    CHECK(std::abs(both[3 * i + 1] - e2l[i]) <= 1e-12);
    CHECK(both[3 * i + 2] == -v2[i]);
  }
}

TEST_CASE("transfer in 3D: a spherical shell's new boundary points, clamped or extrapolated", "[mesh][adapt]") {
  // the finer shell's boundary nodes lie on the spheres, outside the coarse one's polyhedra
  const Mesh<3> from = spherical_shell_mesh(0.5, 1.0, 1), to = spherical_shell_mesh(0.5, 1.0, 2);
  auto lin = [](const Vec<3>& x) { return 2.0 + 3.0 * x[0] - 1.0 * x[1] + 0.5 * x[2]; };
  check_outside_points<3>(from, to, lin, std::sqrt(9.0 + 1.0 + 0.25));
}

TEST_CASE("transfer in 3D: convergence at the interpolation order for a smooth field", "[mesh][adapt]") {
  auto f = [](const Vec<3>& x) { return std::sin(3 * x[0] + 1) * std::cos(2 * x[1]) * std::exp(x[2]); };
  const Mesh<3> to = box_mesh(13, 11, 12);
  for (int degree : {1, 2}) {
    std::vector<double> emax, erms;
    for (int n : {4, 8, 16}) {
      const auto [mx, rms] = transfer_error<3>(perturbed_cube(n), to, degree, f);
      emax.push_back(mx), erms.push_back(rms);
    }
    for (std::size_t k = 1; k < emax.size(); ++k) {
      const double rmax = std::log2(emax[k - 1] / emax[k]), rrms = std::log2(erms[k - 1] / erms[k]);
      std::printf("3D P%d transfer, h = 1/%d: max error %.3e (rate %.2f), rms %.3e (rate %.2f)\n", degree, 4 << k, emax[k],
                  rmax, erms[k], rrms);
      if (k + 1 == emax.size()) {  // the finest pair: the interpolation orders 2 and 3
        CHECK(rmax >= degree + 1 - 0.25);
        CHECK(rrms >= degree + 1 - 0.2);
      }
    }
  }
}

TEST_CASE("adapt and transfer: bad input names the parameter", "[mesh][adapt]") {
  const Mesh<2> m = rectangle_mesh(4, 4);
  auto param_of = [](auto&& fn) {
    try {
      fn();
    } catch (const InvalidArgument& e) {
      return e.parameter();
    }
    return std::string("<no throw>");
  };
  AdaptOptions opt;
  opt.tolerance = 0;
  CHECK(param_of([&] { adapt(m, {}, opt); }) == "tolerance");
  opt = {}, opt.tolerance = std::nan("");
  CHECK(param_of([&] { adapt(m, {}, opt); }) == "tolerance");
  opt = {}, opt.min_quality = 1.0;
  CHECK(param_of([&] { adapt(m, {}, opt); }) == "min_quality");
  opt = {}, opt.smoothing_sweeps = -1;
  CHECK(param_of([&] { adapt(m, {}, opt); }) == "smoothing_sweeps");
  opt = {}, opt.max_passes = 0;
  CHECK(param_of([&] { adapt(m, {}, opt); }) == "max_passes");
  opt = {}, opt.size = [](const Vec<2>&) { return 0.0; };
  CHECK(param_of([&] { adapt(m, {}, opt); }) == "size");
  opt = {};
  CHECK(param_of([&] { adapt(m, {Circle{Vec<2>::Zero(), -1.0, 1}}, opt); }) == "curves[0].radius");
  CHECK(param_of([&] { adapt(m, {Polyline{{Vec<2>(0, 0), Vec<2>(1, 0)}, 1}}, opt); }) == "curves[0].points");
  {  // a tagged interior edge (an embedded sensor line) would be lost: refused, not dropped
    const Mesh<2> square({Vec<2>(0, 0), Vec<2>(1, 0), Vec<2>(1, 1), Vec<2>(0, 1)}, {{0, 1, 2}, {0, 2, 3}}, {{0, 2}},
                         {7});
    REQUIRE(square.tagged_interior_facets().size() == 1);
    CHECK(param_of([&] { adapt(square, {}, opt); }) == "moved");
  }

  CHECK(param_of([&] { FieldTransfer2D(m, m, 3); }) == "degree");
  CHECK(param_of([&] { FieldTransfer2D(m, m, 1, std::vector<Vec<2>>(3)); }) == "to_edge_points");
  CHECK(param_of([&] { FieldTransfer2D(m, m, 2, std::vector<Vec<2>>(3)); }) == "to_edge_points");
  const FieldTransfer2D T(m, m, 1);
  CHECK(param_of([&] { T.apply(std::vector<double>(5)); }) == "values");
  CHECK(param_of([&] { T.apply(std::vector<double>(25), 0); }) == "components");
  CHECK(param_of([&] { T.apply(MatX(3, 1)); }) == "values");
  CHECK(param_of([&] { PointLocator2D(m, -1); }) == "max_walk");
  const PointLocator2D loc(m);
  CHECK(param_of([&] { loc.locate(Vec<2>(std::nan(""), 0.0)); }) == "x");
  CHECK(param_of([&] { loc.locate(Vec<2>(0.5, 0.5), nullptr, m.n_cells()); }) == "hint");
  const Mesh<3> cube = box_mesh(2, 2, 2);
  CHECK(param_of([&] { FieldTransfer<3>(cube, cube, 2, std::vector<Vec<3>>(3)); }) == "to_edge_points");
  CHECK(param_of([&] { PointLocator<3>(cube).locate(Vec<3>(0.5, std::nan(""), 0.5)); }) == "x");
}
