// The contact geometry and eq. (24) in 2D and 3D (physics/collision.hpp): exact distances
// between segments, triangles, disks/spheres and facet surfaces, the grid search against brute
// force, and the force of eq. (24) + spring on spheres against its formula.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>
#include <set>

#include "alefsi/physics/collision.hpp"

using namespace alefsi;

namespace {
template <int D>
CollisionBody<D> ball(const Vec<D>& c, Real r, const Vec<D>& v = Vec<D>::Zero()) {
  CollisionBody<D> b;
  b.centre = c, b.radius = b.r_in = b.r_out = r, b.velocity = v;
  return b;
}

/// The 12 triangles of the surface of the cube [c - a, c + a]^3.
std::vector<Facet<3>> cube_surface(const Vec<3>& c, Real a) {
  std::vector<Facet<3>> out;
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      auto corner = [&](int su, int sv) {
        Vec<3> x = c;
        x[axis] += side * a, x[u] += su * a, x[v] += sv * a;
        return x;
      };
      out.push_back({corner(-1, -1), corner(1, -1), corner(1, 1)});
      out.push_back({corner(-1, -1), corner(1, 1), corner(-1, 1)});
    }
  return out;
}
CollisionBody<3> cube(const Vec<3>& c, Real a) {
  CollisionBody<3> b;
  b.centre = c, b.r_in = a, b.r_out = std::sqrt(3.0) * a, b.surface = cube_surface(c, a);
  return b;
}
/// The walls of the box [0, L]^3, two triangles per side.
std::vector<Facet<3>> box_walls(Real L) { return cube_surface(Vec<3>::Constant(L / 2), L / 2); }
}  // namespace

TEST_CASE("segment and triangle distances: exact for skew, crossing, parallel and coplanar facets",
          "[collision][quick]") {
  // 2D: crossing segments are at distance 0 (an X whose end points are all far from the other)
  auto [a, b] = detail::closest_segments<2>(Vec<2>(-1, -1), Vec<2>(1, 1), Vec<2>(-1, 1), Vec<2>(1, -1));
  CHECK((a - b).norm() < 1e-15);
  CHECK(a.norm() < 1e-15);
  // 3D skew segments: x-axis at z = 0 and y-axis at z = h, crossing over the origin
  const Real h = 0.37;
  auto [p, q] = detail::closest_segments<3>(Vec<3>(-1, 0, 0), Vec<3>(2, 0, 0), Vec<3>(0, -3, h), Vec<3>(0, 1, h));
  CHECK((p - q).norm() == Approx(h).epsilon(1e-14));
  CHECK(p.norm() < 1e-15);
  // parallel, overlapping in x: the distance between the lines
  std::tie(p, q) = detail::closest_segments<3>(Vec<3>(0, 0, 0), Vec<3>(1, 0, 0), Vec<3>(0.5, 0.3, 0.4), Vec<3>(3, 0.3, 0.4));
  CHECK((p - q).norm() == Approx(0.5).epsilon(1e-14));
  // triangles: a face above a face (vertex-to-face), an edge over an edge, one piercing another
  const Facet<3> floor = {Vec<3>(0, 0, 0), Vec<3>(1, 0, 0), Vec<3>(0, 1, 0)};
  const Facet<3> above = {Vec<3>(0.2, 0.2, h), Vec<3>(0.3, 0.2, h + 1), Vec<3>(0.2, 0.3, h + 1)};
  std::tie(p, q) = detail::closest_facets(above, floor);
  CHECK((p - q).norm() == Approx(h).epsilon(1e-14));
  CHECK(q.isApprox(Vec<3>(0.2, 0.2, 0)));
  const Facet<3> edge_over = {Vec<3>(1, 1, h), Vec<3>(0, 0, h + 10), Vec<3>(2, 2, h + 10)};  // vertex over the hypotenuse
  std::tie(p, q) = detail::closest_facets(edge_over, floor);
  CHECK((p - q).norm() == Approx(std::sqrt(0.5 + h * h)).epsilon(1e-13));  // to the hypotenuse's midpoint
  const Facet<3> pierce = {Vec<3>(0.2, 0.2, -1), Vec<3>(0.25, 0.2, 1), Vec<3>(0.2, 0.25, 1)};
  std::tie(p, q) = detail::closest_facets(pierce, floor);
  CHECK((p - q).norm() == 0.0);
  CHECK(std::abs(p[2]) < 1e-15);
  const Facet<3> coplanar = {Vec<3>(0.1, 0.1, 0), Vec<3>(2, 0.1, 0), Vec<3>(0.1, 2, 0)};  // overlapping in the plane
  std::tie(p, q) = detail::closest_facets(coplanar, floor);
  CHECK((p - q).norm() < 1e-15);
}

TEST_CASE("gaps of 3D bodies: spheres exact, a sphere and a cube, two cubes, a cube and the box walls",
          "[collision][quick]") {
  ContactGeometry<3> g;
  g.set_walls(box_walls(4));
  const Real inf = std::numeric_limits<Real>::infinity();
  // two spheres, and each to its nearest wall
  std::vector<CollisionBody<3>> b = {ball<3>(Vec<3>(1, 2, 0.7), 0.5), ball<3>(Vec<3>(2.2, 2.6, 1.3), 0.3)};
  auto near = g.near(b, inf, 0, true);
  REQUIRE(near.size() == 3);
  CHECK(near[0].gap == Approx(std::sqrt(1.44 + 0.36 + 0.36) - 0.8).epsilon(1e-14));
  CHECK(near[0].normal.isApprox((b[0].centre - b[1].centre).normalized()));
  CHECK(near[1].j == -1);
  CHECK(near[1].gap == Approx(0.2).epsilon(1e-13));  // sphere 0 to the floor
  CHECK(near[1].normal.isApprox(Vec<3>(0, 0, 1)));
  CHECK(near[2].gap == Approx(1.0).epsilon(1e-13));  // sphere 1 to the floor
  // a sphere above a cube's face, and beside its edge
  b = {ball<3>(Vec<3>(2, 2, 3.1), 0.25), cube(Vec<3>(2, 2, 2), 0.5)};
  near = g.near(b, inf, 0, false);
  REQUIRE(near.size() == 1);
  CHECK(near[0].gap == Approx(3.1 - 2.5 - 0.25).epsilon(1e-13));
  b[0].centre = Vec<3>(2.9, 2.9, 2.2);  // nearest: the vertical edge x = y = 2.5
  CHECK(g.near(b, inf, 0, false)[0].gap == Approx(std::sqrt(0.32) - 0.25).epsilon(1e-13));
  b[1] = cube(Vec<3>(2, 2, 2), 0.5);
  // two cubes: face to face, then edge to edge, then overlapping
  b[0] = cube(Vec<3>(2, 2, 3.3), 0.5);
  CHECK(g.near(b, inf, 0, false)[0].gap == Approx(0.3).epsilon(1e-13));
  b[0] = cube(Vec<3>(3.2, 3.2, 2.3), 0.5);  // the vertical edges at (2.5, 2.5) and (2.7, 2.7), overlapping in z
  CHECK(g.near(b, inf, 0, false)[0].gap == Approx(std::sqrt(0.08)).epsilon(1e-13));
  b[0] = cube(Vec<3>(2.3, 2.1, 2.9), 0.5);
  const auto o = g.near(b, 0, 0, false);  // what overlaps() asks: gap <= 0
  REQUIRE(o.size() == 1);
  CHECK(o[0].gap == 0.0);
  // a cube and the walls: the nearest wall point is on the floor
  near = g.near({cube(Vec<3>(1, 3, 0.8), 0.5)}, inf, 0, true);
  REQUIRE(near.size() == 1);
  CHECK(near[0].gap == Approx(0.3).epsilon(1e-13));
  CHECK(near[0].normal[2] > 0);
  // finite reach: only what is within it
  CHECK(g.near({cube(Vec<3>(1, 3, 0.8), 0.5)}, 0.5, 0.2, true).empty());  // reach max(0.25, 0.2) < 0.3
  CHECK(g.near({cube(Vec<3>(1, 3, 0.8), 0.5)}, 0.7, 0, true).size() == 1);
}

TEST_CASE("3D eq. (24) + spring on spheres: magnitude, direction, action = reaction, Jacobian",
          "[collision][quick]") {
  const Real R = 0.5, mu = 0.2, d = 0.02;
  CollisionModel<3> model({.range = 0.1, .spring_range = 0.04, .spring_force = 3});
  model.set_walls(box_walls(4));
  const Vec<3> n = Vec<3>(1, -2, 2).normalized();
  std::vector<CollisionBody<3>> b = {ball<3>(Vec<3>(2, 2, 2), R, Vec<3>(0.3, 0.1, -0.2)),
                                     ball<3>(Vec<3>(2, 2, 2) + (2 * R + d) * n, R, Vec<3>(-0.1, 0.4, 0.5))};
  const auto c = model.contacts(b, mu);
  REQUIRE(c.size() == 1);
  CHECK(c[0].gap == Approx(d).epsilon(1e-12));
  const Vec<3> F = CollisionModel<3>::force(c[0], b);
  const Real s = 1 - d / 0.04;
  const Real expected = mu * R * std::pow(4 * R / d, 1.5) * (b[1].velocity - b[0].velocity).norm() + 3 * s * s;
  CHECK(F.norm() == Approx(expected).epsilon(1e-12));
  CHECK(F.dot(b[c[0].k].centre - b[c[0].j].centre) > 0);  // repulsive
  CHECK((F.normalized() - c[0].normal).norm() < 1e-14);
  const Mat<3> J = CollisionModel<3>::dforce_dvk(c[0], b);
  const Real h = 1e-7;
  for (int j = 0; j < 3; ++j) {
    auto bp = b, bm = b;
    bp[c[0].k].velocity[j] += h, bm[c[0].k].velocity[j] -= h;
    const Vec<3> fd = (CollisionModel<3>::force(c[0], bp) - CollisionModel<3>::force(c[0], bm)) / (2 * h);
    for (int i = 0; i < 3; ++i) CHECK(J(i, j) == Approx(fd[i]).epsilon(1e-6).margin(1e-9));
  }
  // a sphere resting near a side wall: the wall's normal and eq. (24) with V^J = 0
  b = {ball<3>(Vec<3>(4 - R - 0.01, 1, 2), R, Vec<3>(0.5, 0, 0))};
  const auto w = model.contacts(b, mu);
  REQUIRE(w.size() == 1);
  CHECK(w[0].j == -1);
  CHECK(w[0].normal.isApprox(Vec<3>(-1, 0, 0)));
  const Real sw = 1 - 0.01 / 0.04;
  CHECK(CollisionModel<3>::force(w[0], b)[0] == Approx(-(mu * R * std::pow(4 * R / 0.01, 1.5) * 0.5 + 3 * sw * sw)).epsilon(1e-12));
}

TEST_CASE("eq. (24) is a force in both unit systems: the same contact in SI and in cgs, 2D and 3D",
          "[collision][quick]") {
  // ten Cate's E4 sphere (R = 7.5 mm, mu = 0.058 Pa s) 0.5 mm above the floor, falling at
  // 0.09 m/s. In cgs: R = 0.75 cm, mu = 0.58 g / (cm s), V = 9 cm/s, and 1 N = 1e5 dyn (3D);
  // a force per unit length in 2D, 1 N/m = 1e3 dyn/cm
  auto floor_force = [](auto dim, Real L, Real mu, Real R, Real gap, Real v) {
    constexpr int D = decltype(dim)::value;
    CollisionModel<D> model({.range = 0.1});
    Vec<D> c = Vec<D>::Constant(L / 2), vel = Vec<D>::Zero();
    c[D - 1] = R + gap, vel[D - 1] = -v;
    if constexpr (D == 3) model.set_walls(box_walls(L));
    else model.set_walls({{Vec<2>(0, 0), Vec<2>(L, 0)}});
    const std::vector<CollisionBody<D>> b = {ball<D>(c, R, vel)};
    const auto contact = model.contacts(b, mu);
    REQUIRE(contact.size() == 1);
    return CollisionModel<D>::force(contact[0], b)[D - 1];
  };
  const Real si3 = floor_force(std::integral_constant<int, 3>{}, 0.1, 0.058, 7.5e-3, 5e-4, 0.09);
  const Real cgs3 = floor_force(std::integral_constant<int, 3>{}, 10, 0.58, 0.75, 0.05, 9);
  CHECK(si3 > 0);
  CHECK(cgs3 == Approx(1e5 * si3).epsilon(1e-12));
  const Real si2 = floor_force(std::integral_constant<int, 2>{}, 0.1, 0.058, 7.5e-3, 5e-4, 0.09);
  const Real cgs2 = floor_force(std::integral_constant<int, 2>{}, 10, 0.58, 0.75, 0.05, 9);
  CHECK(cgs2 == Approx(1e3 * si2).epsilon(1e-12));
  // and at d = delta the 3D force is within a factor 1.35 of the sphere-plane lubrication force
  // 6 pi mu R^2 V / d (Brenner 1961): 40^{3/2} = 253 against 60 pi = 188
  const Real at_delta = floor_force(std::integral_constant<int, 3>{}, 0.1, 0.058, 7.5e-3, 7.5e-4 * (1 - 1e-12), 0.09);
  const Real lubrication = 6 * std::numbers::pi * 0.058 * 7.5e-3 * 7.5e-3 * 0.09 / 7.5e-4;
  CHECK(at_delta / lubrication == Approx(std::pow(40, 1.5) / (60 * std::numbers::pi)).epsilon(1e-9));
}

TEST_CASE("CollisionLaw::lubrication: the signed normal velocity; it resists separation, never adds energy, "
          "and ignores sliding",
          "[collision][quick]") {
  const Real R = 0.5, mu = 0.2, d = 0.02;
  CollisionModel<3> model({.range = 0.1, .law = CollisionLaw::lubrication});
  const Vec<3> n = Vec<3>(1, -2, 2).normalized();
  std::vector<CollisionBody<3>> b = {ball<3>(Vec<3>(2, 2, 2), R), ball<3>(Vec<3>(2, 2, 2) + (2 * R + d) * n, R)};
  const Real c = mu * R * std::pow(4 * R / d, 1.5);
  std::mt19937 rng(3);
  std::uniform_real_distribution<Real> U(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    b[0].velocity = Vec<3>(U(rng), U(rng), U(rng)), b[1].velocity = Vec<3>(U(rng), U(rng), U(rng));
    const auto contact = model.contacts(b, mu);
    REQUIRE(contact.size() == 1);
    const Contact<3>& k = contact[0];
    const Vec<3> F = CollisionModel<3>::force(k, b);
    const Vec<3> w = b[k.j].velocity - b[k.k].velocity;
    CHECK((F - c * w.dot(k.normal) * k.normal).norm() < 1e-12 * c);
    CHECK(F.dot(-w) <= 1e-14 * c);  // the power on the pair, F_K . (V^K - V^J), is never positive
    const Mat<3> J = CollisionModel<3>::dforce_dvk(k, b);
    for (int j = 0; j < 3; ++j) {
      auto bp = b, bm = b;
      bp[k.k].velocity[j] += 1e-7, bm[k.k].velocity[j] -= 1e-7;
      const Vec<3> fd = (CollisionModel<3>::force(k, bp) - CollisionModel<3>::force(k, bm)) / 2e-7;
      for (int i = 0; i < 3; ++i) CHECK(J(i, j) == Approx(fd[i]).epsilon(1e-6).margin(1e-9 * c));
    }
  }
  // separating along n: attractive (towards J), where the paper's law pushes them apart
  const auto contact = model.contacts(b, mu);
  const int k = contact[0].k, j = contact[0].j;
  b[k].velocity = 0.1 * contact[0].normal, b[j].velocity.setZero();
  CHECK(CollisionModel<3>::force(contact[0], b).dot(contact[0].normal) == Approx(-0.1 * c).epsilon(1e-12));
  Contact<3> paper = contact[0];
  paper.law = CollisionLaw::paper;
  CHECK(CollisionModel<3>::force(paper, b).dot(contact[0].normal) == Approx(0.1 * c).epsilon(1e-12));
  // sliding past each other: no force
  b[k].velocity = n.cross(Vec<3>(0, 0, 1)).normalized();
  CHECK(CollisionModel<3>::force(contact[0], b).norm() < 1e-12 * c);
}

TEST_CASE("3D search: the grid finds exactly the sphere pairs a brute-force loop finds", "[collision][quick]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<Real> U(0, 6), Rr(0.05, 0.2);
  std::vector<CollisionBody<3>> b;
  while (b.size() < 500) {
    const auto cand = ball<3>(Vec<3>(U(rng), U(rng), U(rng)), Rr(rng));
    bool ok = true;
    for (const auto& o : b) ok &= (o.centre - cand.centre).norm() > o.radius + cand.radius + 1e-6;
    if (ok) b.push_back(cand);
  }
  CollisionModel<3> model({.range = 0.5, .walls = false});
  std::set<std::pair<int, int>> got, want;
  for (const auto& c : model.contacts(b, 1.0)) got.insert({std::min(c.k, c.j), std::max(c.k, c.j)});
  for (int k = 0; k < int(b.size()); ++k)
    for (int j = k + 1; j < int(b.size()); ++j)
      if ((b[k].centre - b[j].centre).norm() - b[k].radius - b[j].radius <= 0.5 * std::min(b[k].radius, b[j].radius))
        want.insert({k, j});
  CHECK(want.size() > 10);
  CHECK(got == want);
}

TEST_CASE("2D: a disk and a polygon body, and crossing polygons", "[collision][quick]") {
  // a square body [1, 2]^2 as segments, a disk to its right; before, a disk against a body
  // without radius found no surface and no gap
  CollisionBody<2> square;
  square.centre = Vec<2>(1.5, 1.5), square.r_in = 0.5, square.r_out = std::sqrt(0.5);
  const Vec<2> v[4] = {Vec<2>(1, 1), Vec<2>(2, 1), Vec<2>(2, 2), Vec<2>(1, 2)};
  for (int i = 0; i < 4; ++i) square.surface.push_back({v[i], v[(i + 1) % 4]});
  ContactGeometry<2> g;
  const Real inf = std::numeric_limits<Real>::infinity();
  auto near = g.near({square, ball<2>(Vec<2>(2.4, 1.2), 0.3)}, inf, 0, false);
  REQUIRE(near.size() == 1);
  CHECK(near[0].gap == Approx(0.1).epsilon(1e-13));
  // the square turned by 45 degrees about (2.4, 1.5): its corner enters the first square's
  // right side, no vertex of either square within 0.1 of the other's edges
  CollisionBody<2> diamond = square;
  diamond.centre = Vec<2>(2.4, 1.5), diamond.surface.clear();
  const Real a = std::sqrt(0.5);
  const Vec<2> w[4] = {Vec<2>(2.4 - a, 1.5), Vec<2>(2.4, 1.5 - a), Vec<2>(2.4 + a, 1.5), Vec<2>(2.4, 1.5 + a)};
  for (int i = 0; i < 4; ++i) diamond.surface.push_back({w[i], w[(i + 1) % 4]});
  near = g.near({square, diamond}, 0, 0, false);
  REQUIRE(near.size() == 1);
  CHECK(std::abs(near[0].gap) < 1e-14);
}

TEST_CASE("facet bodies: the contact acts at the nearest points (a moment), and agrees with the disk model "
          "where the shapes coincide",
          "[collision][quick]") {
  const Real inf = std::numeric_limits<Real>::infinity();
  SECTION("2D: a 512-gon against an exact disk and a wall, as the disk it approximates") {
    const Real R = 0.3;
    const int n = 512;
    CollisionBody<2> gon;
    gon.centre = Vec<2>(1, 0.5), gon.r_out = R, gon.r_in = R * std::cos(std::numbers::pi / n);
    for (int i = 0; i < n; ++i) {
      auto at = [&](int j) {
        const Real a = 2 * std::numbers::pi * j / n + 0.1;  // no vertex on the line of centres
        return Vec<2>(gon.centre + R * Vec<2>(std::cos(a), std::sin(a)));
      };
      gon.surface.push_back({at(i), at(i + 1)});
    }
    ContactGeometry<2> g;
    g.set_walls({{Vec<2>(-5, 0), Vec<2>(5, 0)}});
    const Vec<2> dir = Vec<2>(3, 1).normalized();
    const auto other = ball<2>(gon.centre + (2 * R + 0.01) * dir, R);
    const auto near = g.near({gon, other}, inf, 0, true);
    REQUIRE(near.size() == 3);  // the pair, and each body's nearest wall
    const Real sag = R - gon.r_in;  // the polygon lies between its inner and outer circles
    CHECK(near[0].gap >= 0.01 - 1e-15);
    CHECK(near[0].gap <= 0.01 + sag);
    CHECK((near[0].normal + dir).norm() < 2 * std::numbers::pi / n);  // towards the polygon
    // the point of action is on the line of centres to within the polygon's edge: a moment arm
    // of at most R pi / n
    CHECK(std::abs(near[0].arm_k[0] * near[0].normal[1] - near[0].arm_k[1] * near[0].normal[0]) < R * std::numbers::pi / n);
    CHECK(near[1].gap >= 0.2 - 1e-15);  // the wall y = 0, 0.5 - R below
    CHECK(near[1].gap <= 0.2 + sag);
    CHECK((near[1].normal - Vec<2>(0, 1)).norm() < 1e-12);
  }
  SECTION("3D: a tilted cube whose corner is nearest the floor") {
    // the cube [-a, a]^3 turned so that the corner (-a, -a, -a) points straight down: that corner
    // is sqrt(3) a below the centre
    const Real a = 0.5, h = 0.02;
    const Eigen::Quaternion<Real> q = Eigen::Quaternion<Real>::FromTwoVectors(Vec<3>(-1, -1, -1).normalized(), Vec<3>(0, 0, -1));
    CollisionBody<3> body = cube(Vec<3>::Zero(), a);
    const Vec<3> c(2, 2, std::sqrt(3.0) * a + h);
    for (auto& f : body.surface)
      for (auto& v : f) v = c + q * v;
    body.centre = c;
    ContactGeometry<3> g;
    g.set_walls(box_walls(4));
    const auto near = g.near({body}, inf, 0, true);
    REQUIRE(near.size() == 1);
    CHECK(near[0].gap == Approx(h).epsilon(1e-12));
    CHECK((near[0].normal - Vec<3>(0, 0, 1)).norm() < 1e-12);
    // the point of action: midway between the corner and the floor, straight below the centre
    CHECK((near[0].arm_k - Vec<3>(0, 0, -std::sqrt(3.0) * a - h / 2)).norm() < 1e-12);
    // shifted sideways against a side wall instead: the nearest points are off the centre's line
    body.centre = Vec<3>(3, 2, 2);  // its farthest vertex in x is at most 0.82 from the centre
    for (auto& f : body.surface)
      for (auto& v : f) v += body.centre - c;
    const auto side = g.near({body}, inf, 0, true);
    REQUIRE(side.size() == 1);
    CHECK((side[0].normal - Vec<3>(-1, 0, 0)).norm() < 1e-12);
    CHECK(side[0].arm_k.cross(side[0].normal).norm() > 0.1);  // a moment about the centre
  }
}
