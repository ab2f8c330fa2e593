// Convex shapes by support functions and their distance by GJK (physics/convex.hpp), and the
// collision model on them: exact gaps and nearest points against closed forms and against the
// facet model where the two describe the same shape.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>

#include "alefsi/core/error.hpp"
#include "alefsi/physics/collision.hpp"
#include "alefsi/physics/convex.hpp"

using namespace alefsi;

namespace {

Mat<2> rot2(Real a) { return Eigen::Rotation2D<Real>(a).toRotationMatrix(); }
Mat<3> rot3(const Vec<3>& axis, Real a) { return Eigen::AngleAxis<Real>(a, axis.normalized()).toRotationMatrix(); }

// the boundary of a convex polygon as segments
std::vector<Facet<2>> polygon_facets(const std::vector<Vec<2>>& p) {
  std::vector<Facet<2>> f;
  for (std::size_t i = 0; i < p.size(); ++i) f.push_back({p[i], p[(i + 1) % p.size()]});
  return f;
}

// a box's 12 boundary triangles
std::vector<Facet<3>> box_facets(const std::vector<Vec<3>>& v) {  // v: the 8 corners, index bits (x, y, z)
  const int q[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  std::vector<Facet<3>> f;
  for (const auto& r : q) f.push_back({v[r[0]], v[r[1]], v[r[2]]}), f.push_back({v[r[0]], v[r[2]], v[r[3]]});
  return f;
}

}  // namespace

TEST_CASE("GJK: balls and capsules against their closed forms", "[convex][quick]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  SECTION("balls, 2D and 3D: |c_a - c_b| - r_a - r_b, the points on the line of centres") {
    for (int trial = 0; trial < 20; ++trial) {
      const Vec<3> ca(u(rng), u(rng), u(rng)), cb(3 + u(rng), u(rng), u(rng));
      const Real ra = 0.5 + 0.3 * u(rng), rb = 0.7 + 0.3 * u(rng);
      const auto A = convex::placed<3>(convex::Ball<3>{ra}, ca, Mat<3>::Identity());
      const auto B = convex::placed<3>(convex::Ball<3>{rb}, cb, Mat<3>::Identity());
      const auto d = convex::distance<3>(A, B);
      CHECK(d.distance == Approx((ca - cb).norm() - ra - rb).epsilon(1e-14));
      CHECK((d.a - (ca + ra * (cb - ca).normalized())).norm() < 1e-14);
      CHECK((d.normal - (ca - cb).normalized()).norm() < 1e-14);
      const Vec<2> pa = ca.head<2>(), pb = cb.head<2>();
      const auto d2 = convex::distance<2>(convex::placed<2>(convex::Ball<2>{ra}, pa, Mat<2>::Identity()),
                                          convex::placed<2>(convex::Ball<2>{rb}, pb, Mat<2>::Identity()));
      CHECK(d2.distance == Approx((pa - pb).norm() - ra - rb).epsilon(1e-14));
    }
  }
  SECTION("capsules in 3D: the segments' distance minus the radii, also when the margins overlap") {
    for (int trial = 0; trial < 40; ++trial) {
      const convex::Capsule<3> ca{0.5 + 0.4 * u(rng), 0.1}, cb{0.8 + 0.4 * u(rng), 0.15};
      const Vec<3> xa(u(rng), u(rng), u(rng)), xb(0.4 * u(rng), 0.4 * u(rng), 0.4 + 0.4 * u(rng));
      const Mat<3> Qa = rot3(Vec<3>(u(rng), u(rng), u(rng)), 3 * u(rng)), Qb = rot3(Vec<3>(u(rng), u(rng), u(rng)), 3 * u(rng));
      const auto [p, q] = alefsi::detail::closest_segments<3>(xa - ca.half_length * Qa.col(0), xa + ca.half_length * Qa.col(0),
                                                              xb - cb.half_length * Qb.col(0), xb + cb.half_length * Qb.col(0));
      const Real exact = (p - q).norm();
      const auto d = convex::distance<3>(convex::placed<3>(ca, xa, Qa), convex::placed<3>(cb, xb, Qb));
      if (exact < 1e-9) {  // the axes cross: the cores intersect
        CHECK(d.intersecting);
        continue;
      }
      REQUIRE_FALSE(d.intersecting);
      CHECK(d.distance == Approx(exact - 0.25).margin(1e-13));
      CHECK((d.a - d.b).norm() == Approx(std::abs(exact - 0.25)).margin(1e-13));
    }
  }
}

TEST_CASE("GJK: polytopes agree with the facet model's exact distances", "[convex][quick]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<Real> u(-1, 1);
  SECTION("convex polygons (regular, rotated, 3 to 9 sides)") {
    for (int trial = 0; trial < 40; ++trial) {
      auto polygon = [&](int n, Real r, const Vec<2>& c, Real a) {
        std::vector<Vec<2>> p;
        for (int i = 0; i < n; ++i) {
          const Real t = a + 2 * std::numbers::pi * i / n;
          p.push_back(c + r * Vec<2>(std::cos(t), std::sin(t)));
        }
        return p;
      };
      const auto pa = polygon(3 + trial % 7, 0.5, Vec<2>(u(rng), u(rng)), u(rng));
      const auto pb = polygon(3 + (trial / 7) % 7, 0.4, Vec<2>(1.3 + u(rng), u(rng)), u(rng));
      const auto n = alefsi::detail::nearest_facets<2>(polygon_facets(pa), polygon_facets(pb));
      const auto d = convex::distance<2>(convex::Polytope<2>{pa}, convex::Polytope<2>{pb});
      if (n.distance < 1e-12) {
        CHECK(d.intersecting);
        continue;
      }
      CHECK(d.distance == Approx(n.distance).margin(1e-13));
      CHECK((d.a - d.b).norm() == Approx(n.distance).margin(1e-13));
      CHECK(d.iterations <= 12);  // exact termination on polytopes
    }
  }
  SECTION("boxes in 3D (rotated), also rounded: the distance less the rounding") {
    for (int trial = 0; trial < 30; ++trial) {
      auto box = [&](const Vec<3>& c, const Vec<3>& h, const Mat<3>& Q) {
        std::vector<Vec<3>> v;
        for (int i = 0; i < 8; ++i) v.push_back(c + Q * Vec<3>(i & 1 ? h[0] : -h[0], i & 2 ? h[1] : -h[1], i & 4 ? h[2] : -h[2]));
        return v;
      };
      const auto va = box(Vec<3>(u(rng), u(rng), u(rng)), Vec<3>(0.3, 0.2, 0.4), rot3(Vec<3>(u(rng), u(rng), u(rng)), 3 * u(rng)));
      const auto vb = box(Vec<3>(1.8 + u(rng), u(rng), u(rng)), Vec<3>(0.5, 0.1, 0.2), rot3(Vec<3>(u(rng), u(rng), u(rng)), 3 * u(rng)));
      const auto n = alefsi::detail::nearest_facets<3>(box_facets(va), box_facets(vb));
      const auto d = convex::distance<3>(convex::Polytope<3>{va}, convex::Polytope<3>{vb, 0.05});
      if (n.distance < 1e-9) {
        CHECK(d.intersecting);
        continue;
      }
      CHECK(d.distance == Approx(n.distance - 0.05).margin(1e-13));
    }
  }
}

TEST_CASE("GJK: ellipses and ellipsoids, smooth cores", "[convex][quick]") {
  SECTION("against a plane (a long segment / large triangle): h - |A Q^T n|, touching at s(-n)") {
    for (int trial = 0; trial < 12; ++trial) {
      const Real angle = 0.27 * trial, h = 0.35;
      const convex::Ellipsoid<2> e{{0.3, 0.1}};
      const Mat<2> Q = rot2(angle);
      const auto A = convex::placed<2>(e, Vec<2>(0.1, 0.5), Q);
      const convex::Polytope<2> floor{{Vec<2>(-5, 0.5 - h), Vec<2>(5, 0.5 - h), Vec<2>(0, 0.5 - h - 1)}};
      const auto d = convex::distance<2>(A, floor, 1e-14);
      const Vec<2> n(0, 1);
      const Real exact = h - e.semi_axes.cwiseProduct(Q.transpose() * n).norm();
      CHECK(d.converged);
      CHECK(d.distance == Approx(exact).epsilon(1e-10));
      CHECK((d.a - A.support(Vec<2>(-n))).norm() < 1e-5 * e.semi_axes.maxCoeff());  // the flat direction is ill-conditioned
      CHECK((d.normal - n).norm() < 1e-6);
    }
    const convex::Ellipsoid<3> e{{0.3, 0.1, 0.2}};
    const Mat<3> Q = rot3(Vec<3>(1, 2, 3), 0.7);
    const auto A = convex::placed<3>(e, Vec<3>(0, 0, 1), Q);
    const convex::Polytope<3> plane{{Vec<3>(-9, -9, 0), Vec<3>(9, -9, 0), Vec<3>(0, 9, 0), Vec<3>(0, 0, -1)}};
    const auto d = convex::distance<3>(A, plane, 1e-14);
    CHECK(d.distance == Approx(1 - e.semi_axes.cwiseProduct(Q.transpose() * Vec<3>::UnitZ()).norm()).epsilon(1e-10));
  }
  SECTION("two ellipses: on both curves, the segment between them normal to both, below every sampled pair") {
    const convex::Ellipsoid<2> ea{{0.4, 0.1}}, eb{{0.25, 0.15}};
    for (int trial = 0; trial < 10; ++trial) {
      const Mat<2> Qa = rot2(0.3 * trial), Qb = rot2(-0.5 * trial + 0.2);
      const Vec<2> ca(0, 0), cb(0.7, 0.15 + 0.02 * trial);
      const auto d = convex::distance<2>(convex::placed<2>(ea, ca, Qa), convex::placed<2>(eb, cb, Qb), 1e-14);
      REQUIRE(d.converged);
      REQUIRE_FALSE(d.intersecting);
      CHECK(d.iterations <= 24);  // linear convergence on smooth cores: 19-24 on these pairs
      auto level = [](const convex::Ellipsoid<2>& e, const Mat<2>& Q, const Vec<2>& c, const Vec<2>& x) {
        return Vec<2>(Q.transpose() * (x - c)).cwiseQuotient(e.semi_axes).norm();
      };
      auto outward = [](const convex::Ellipsoid<2>& e, const Mat<2>& Q, const Vec<2>& c, const Vec<2>& x) {
        const Vec<2> y = Q.transpose() * (x - c);
        return Vec<2>(Q * y.cwiseQuotient(e.semi_axes.cwiseProduct(e.semi_axes))).normalized();
      };
      CHECK(level(ea, Qa, ca, d.a) == Approx(1).epsilon(1e-9));
      CHECK(level(eb, Qb, cb, d.b) == Approx(1).epsilon(1e-9));
      const Vec<2> ab = (d.b - d.a).normalized();
      CHECK((outward(ea, Qa, ca, d.a) - ab).norm() < 1e-5);
      CHECK((outward(eb, Qb, cb, d.b) + ab).norm() < 1e-5);
      // sampled: 2000 points per curve; the sampled minimum is above the exact one, by at most
      // the sampling's chord error (h^2 / 8 kappa-weighted, < 1e-5 here)
      Real sampled = std::numeric_limits<Real>::infinity();
      const int n = 2000;
      std::vector<Vec<2>> pb(n);
      for (int j = 0; j < n; ++j) {
        const Real t = 2 * std::numbers::pi * j / n;
        pb[j] = cb + Qb * Vec<2>(eb.semi_axes[0] * std::cos(t), eb.semi_axes[1] * std::sin(t));
      }
      for (int i = 0; i < n; ++i) {
        const Real t = 2 * std::numbers::pi * i / n;
        const Vec<2> pa = ca + Qa * Vec<2>(ea.semi_axes[0] * std::cos(t), ea.semi_axes[1] * std::sin(t));
        for (const auto& q : pb) sampled = std::min(sampled, (pa - q).norm());
      }
      CHECK(d.distance <= sampled + 1e-12);
      CHECK(d.distance >= sampled - 1e-5);
    }
  }
  SECTION("overlapping ellipses are reported as intersecting, with a distance <= 0") {
    const convex::Ellipsoid<2> e{{0.4, 0.1}};
    const auto d = convex::distance<2>(convex::placed<2>(e, Vec<2>(0, 0), rot2(0)), convex::placed<2>(e, Vec<2>(0.3, 0.1), rot2(1.2)));
    CHECK(d.intersecting);
    CHECK(d.distance <= 0);
  }
}

TEST_CASE("Convex shapes refuse bad input by name", "[convex][quick]") {
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  CHECK_THAT(message([] { convex::support_of<2>(convex::Ellipsoid<2>{{0.2, -1}}); }), Catch::Contains("semi_axes[1]"));
  CHECK_THAT(message([] { convex::support_of<3>(convex::Capsule<3>{1, 0}); }), Catch::Contains("capsule.radius"));
  CHECK_THAT(message([] { convex::support_of<2>(convex::Polytope<2>{{Vec<2>(0, 0), Vec<2>(1, 1), Vec<2>(2, 2)}}); }),
             Catch::Contains("span no area"));
  CHECK_THAT(message([] { convex::support_of<3>(convex::Polytope<3>{{Vec<3>(0, 0, 0), Vec<3>(1, 0, 0), Vec<3>(0, 1, 0)}}); }),
             Catch::Contains("at least 4 vertices"));
}

TEST_CASE("Collision model on convex shapes: exact gaps, normals and contact points", "[convex][collision][quick]") {
  const std::vector<Facet<2>> floor = {{Vec<2>(-2, 0), Vec<2>(-0.5, 0)}, {Vec<2>(-0.5, 0), Vec<2>(0.5, 0)},
                                       {Vec<2>(0.5, 0), Vec<2>(2, 0)}};
  CollisionModel<2> model({.range = 0.5, .law = CollisionLaw::lubrication});
  model.set_walls(floor);
  const Real a = 0.3, b = 0.1;
  auto ellipse_body = [&](const Vec<2>& c, Real angle, const Vec<2>& v) {
    CollisionBody<2> body;
    body.centre = c, body.velocity = v, body.r_in = b, body.r_out = a;
    body.convex = convex::placed<2>(convex::Ellipsoid<2>{{a, b}}, c, rot2(angle));
    return body;
  };
  SECTION("a tilted ellipse above the floor: gap h - |A Q^T n|, force up, at the lowest point, with its torque") {
    const Real angle = 0.6;
    const Vec<2> c(0.1, 0);
    const Real low = Vec<2>(a * std::sin(angle), b * std::cos(angle)).norm();  // |A Q^T e_y|
    const Real gap = 0.02;
    const auto body = ellipse_body(Vec<2>(c[0], low + gap), angle, Vec<2>(0, -1));
    const auto contacts = model.contacts({body}, 1.0);
    REQUIRE(contacts.size() == 1);
    const auto& k = contacts[0];
    CHECK(k.j == -1);
    CHECK(k.gap == Approx(gap).epsilon(1e-9));
    CHECK((k.normal - Vec<2>(0, 1)).norm() < 1e-7);
    const Vec<2> lowest = body.convex.support(Vec<2>(0, -1));  // the touching point
    CHECK((k.arm_k - (lowest - Vec<2>(0, gap / 2) - body.centre)).norm() < 1e-6);
    const Vec<2> F = CollisionModel<2>::force(k, {body});
    CHECK(F[1] == Approx(std::pow(4 * b / gap, 1.5)));  // mu (4 Rbar / d)^{3/2} (V^J - V^K).n, V^K = -e_y
    // the lowest point of an ellipse turned by +0.6 lies left of its centre: an upward force
    // there turns it clockwise (negative torque), towards lying flat
    CHECK(k.arm_k[0] < 0);
    CHECK(k.arm_k[0] * F[1] - k.arm_k[1] * F[0] < 0);
  }
  SECTION("a disk given as a shape equals the disk model: the same gap, normal and force, no torque") {
    const Real r = 0.2;
    CollisionBody<2> disk;
    disk.centre = Vec<2>(0.05, 0.28), disk.velocity = Vec<2>(0.3, -1), disk.radius = disk.r_in = disk.r_out = r;
    CollisionBody<2> other = ellipse_body(Vec<2>(0.05 + 0.42, 0.40), 0.3, Vec<2>(-0.2, 0.1));
    other.convex = convex::placed<2>(convex::Ball<2>{0.2}, other.centre, Mat<2>::Identity());
    other.r_in = other.r_out = 0.2;
    CollisionBody<2> as_shape = disk;
    as_shape.radius = 0;
    as_shape.convex = convex::placed<2>(convex::Ball<2>{r}, disk.centre, Mat<2>::Identity());
    CollisionBody<2> other_disk = other;
    other_disk.radius = 0.2, other_disk.convex = {};
    const auto exact = model.contacts({disk, other_disk}, 1.0);
    const auto shaped = model.contacts({as_shape, other}, 1.0);
    REQUIRE(exact.size() == shaped.size());
    REQUIRE(exact.size() == 2);  // the pair (gap 0.037) and the disk on the floor (gap 0.08)
    for (std::size_t i = 0; i < exact.size(); ++i) {
      CHECK(shaped[i].gap == Approx(exact[i].gap).epsilon(1e-12));
      CHECK((shaped[i].normal - exact[i].normal).norm() < 1e-12);
      const Vec<2> Fe = CollisionModel<2>::force(exact[i], {disk, other_disk});
      const Vec<2> Fs = CollisionModel<2>::force(shaped[i], {as_shape, other});
      CHECK((Fs - Fe).norm() <= 1e-10 * Fe.norm());
      CHECK(std::abs(shaped[i].arm_k[0] * Fs[1] - shaped[i].arm_k[1] * Fs[0]) <= 1e-12 * Fs.norm());  // through the centre
    }
  }
  SECTION("a shape against a body known only by its facets (a square): the polygon's GJK distance") {
    const std::vector<Vec<2>> sq = {Vec<2>(0.5, 0.3), Vec<2>(0.8, 0.3), Vec<2>(0.8, 0.6), Vec<2>(0.5, 0.6)};
    CollisionBody<2> square;
    square.centre = Vec<2>(0.65, 0.45), square.r_in = 0.15, square.r_out = 0.15 * std::sqrt(2.0);
    square.surface = polygon_facets(sq);
    const auto ell = ellipse_body(Vec<2>(0.2, 0.5), 0.2, Vec<2>(1, 0));
    const auto g = convex::distance<2>(ell.convex, convex::Polytope<2>{sq});
    REQUIRE(g.distance > 0);
    REQUIRE(g.distance < 0.05);
    for (const bool shape_first : {true, false}) {
      const std::vector<CollisionBody<2>> bodies = shape_first ? std::vector{ell, square} : std::vector{square, ell};
      const auto contacts = model.contacts(bodies, 1.0);
      const auto it = std::find_if(contacts.begin(), contacts.end(), [](const auto& c) { return c.j >= 0; });
      REQUIRE(it != contacts.end());
      CHECK(it->gap == Approx(g.distance).epsilon(1e-12));
      const Vec<2> towards_k = shape_first ? g.normal : Vec<2>(-g.normal);  // g.normal: from the square to the ellipse
      CHECK((it->normal - towards_k).norm() < 1e-12);
      // the point along a flat edge is fixed only to the square root of the distance's accuracy
      CHECK((bodies[0].centre + it->arm_k - (g.a + g.b) / 2).norm() < 1e-6);
      CHECK(CollisionModel<2>::force(*it, bodies).dot(towards_k) > 0);  // the ellipse moves towards the square
    }
  }
  SECTION("two ellipses: the normal is the curves' common normal, forces opposite, torques about each centre") {
    const auto A = ellipse_body(Vec<2>(0, 0.6), 0.4, Vec<2>(0.5, 0));
    const auto B = ellipse_body(Vec<2>(0.6, 0.68), -0.3, Vec<2>(-0.5, 0));
    const auto contacts = model.contacts({A, B}, 1.0);
    const auto it = std::find_if(contacts.begin(), contacts.end(), [](const auto& c) { return c.j >= 0; });
    REQUIRE(it != contacts.end());
    REQUIRE((it->k == 0 && it->j == 1));  // pairs are listed with k < j
    const auto g = convex::distance<2>(A.convex, B.convex);  // a on K = A
    const Vec<2> pk = A.centre + it->arm_k, pj = B.centre + it->arm_j;
    CHECK((pk - pj).norm() < 1e-12);  // one point of action
    CHECK((pk - (g.a + g.b) / 2).norm() < 1e-12);
    CHECK(std::abs(it->gap - g.distance) < 1e-12);
    CHECK(it->gap > 0);
    // towards K: from B's nearest point to A's, against A's outward normal there
    const Vec<2> y = rot2(0.4).transpose() * (g.a - A.centre);
    const Vec<2> nA = (rot2(0.4) * Vec<2>(y[0] / (a * a), y[1] / (b * b))).normalized();
    CHECK((it->normal + nA).norm() < 1e-6);
    const Vec<2> F = CollisionModel<2>::force(*it, {A, B});
    CHECK(F.dot(it->normal) > 0);  // approaching: repulsive on K
  }
}
