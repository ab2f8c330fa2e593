#pragma once
/// \file mesh/generate/mesher2d.hpp
/// Built-in unstructured triangle mesher for 2D domains with holes (bodies).
///
/// Domain: an outer closed boundary (polyline or circle) and holes (polylines, circles or
/// ellipses), each with a boundary tag (polylines may tag each side separately). Mesh size: a user
/// size function h(x), e.g. `graded_size` (h_body at the bodies, growing linearly with the
/// distance to h_far) or `uniform_size`.
///
/// Algorithm: the boundaries are discretised with a node spacing following h (nodes on a
/// circle are exactly c + r (cos t, sin t), on an ellipse c + R (a cos t, b sin t)); the points are Delaunay-triangulated
/// (Bowyer-Watson, inside a super-triangle); the boundary segments are recovered by flips
/// (Sloan) to a constrained Delaunay triangulation; the exterior and the holes are removed
/// by parity; then Ruppert/Chew refinement: encroached boundary segments are split (at the
/// midpoint; on a circle or an ellipse at the parameter midpoint, so the new node lies on the
/// curve; next to a small input angle at a power-of-two distance from the corner,
/// "concentric shells"), bad triangles (an angle below min_angle_deg, or circumradius above
/// h(centroid) / sqrt(3)) get their circumcentre inserted, unless it lies behind or
/// encroaches a segment, which is then split instead. See detail/cdt2d.hpp.
///
/// Guarantees: every triangle is positively oriented (insertions are checked with exact
/// predicates before they are committed); every angle is >= min_angle_deg (default 25)
/// except in triangles next to input corners of less than 60 degrees, which are left alone
/// (counted in MesherReport::small_angle_skips); boundary facets carry their tags; no
/// dangling nodes. `max_points` bounds the work (InvalidArgument when exceeded).
/// Sizes: h acts as an upper bound; edge length / h(edge midpoint) measured on the test
/// scenes lies in [0.48, 1.16], median 0.75 (the tests assert [0.4, 1.2]).
///
/// Predicates: orient2d and incircle with Shewchuk's static error-bound filter and an
/// exact floating-point-expansion fallback (detail/predicates.hpp): the signs are exact.
///
/// Determinism: no randomness, no pointer hashing, no threads: the same input gives the
/// same mesh, node for node (on the same platform and compiler flags).
///
/// Speed: point location by walks from the triangle being refined, O(1) work per insertion
/// on average; 1.2-1.6 million triangles per second including the Mesh<2> construction
/// (bench/bench_mesher.cpp). Output nodes are numbered along a Hilbert curve and cells
/// sorted by their smallest node, for memory locality downstream.
///
///     alefsi::Domain2D dom{alefsi::Circle{{0, 0}, 1.0, 2}, {alefsi::Circle{{0.3, 0}, 0.2, 1}}};
///     auto mesh = alefsi::generate_mesh(dom, {alefsi::uniform_size(0.05)});
///     auto chan = alefsi::channel_with_disks(2, 6, {{{1, 4}, 0.125, 5}}, 0.01, 0.1);
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/detail/cdt2d.hpp"
#include "alefsi/mesh/generate/detail/predicates.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

/// A circle boundary; as a hole it is a (disk-shaped) body.
struct Circle {
  Vec<2> centre = Vec<2>::Zero();
  Real radius = 1;
  int tag = 0;
};

/// An ellipse boundary, x(t) = centre + R(angle) (a cos t, b sin t): semi-axis `a` along the
/// direction at `angle` (radians from the x axis), `b` across it. A hole only: an elliptic body.
struct Ellipse {
  Vec<2> centre = Vec<2>::Zero();
  Real a = 1, b = 1;
  Real angle = 0;
  int tag = 0;

  /// The point at parameter t.
  Vec<2> at(Real t) const {
    const Real c = std::cos(angle), s = std::sin(angle), u = a * std::cos(t), v = b * std::sin(t);
    return centre + Vec<2>(c * u - s * v, s * u + c * v);
  }
  /// The ellipse's level function: sqrt((y_1 / a)^2 + (y_2 / b)^2) with y = R^T (x - centre);
  /// 1 on the curve, below inside.
  Real level(const Vec<2>& x) const {
    const Real c = std::cos(angle), s = std::sin(angle);
    const Vec<2> d = x - centre;
    return std::hypot((c * d[0] + s * d[1]) / a, (-s * d[0] + c * d[1]) / b);
  }
  /// The parameter t of the curve's point on the ray from the centre through x (x != centre).
  Real parameter(const Vec<2>& x) const {
    const Real c = std::cos(angle), s = std::sin(angle);
    const Vec<2> d = x - centre;
    return std::atan2((-s * d[0] + c * d[1]) / b, (c * d[0] + s * d[1]) / a);
  }
  /// The curve's point on the ray from the centre through x (x != centre): a projection onto
  /// the ellipse that is smooth in x and exact on the curve (not the closest point).
  Vec<2> radial_projection(const Vec<2>& x) const { return centre + (x - centre) / level(x); }
};

/// A closed polyline (the last point connects to the first); segment i runs from
/// points[i] to points[i + 1]. `segment_tags`, if given, tags each segment separately.
struct Polyline {
  std::vector<Vec<2>> points;
  int tag = 0;
  std::vector<int> segment_tags = {};
};

using Boundary2D = std::variant<Polyline, Circle, Ellipse>;

/// The region inside `outer` and outside every hole. Holes must lie strictly inside the
/// outer boundary and must not touch each other; an Ellipse is a hole only.
struct Domain2D {
  Boundary2D outer;
  std::vector<Boundary2D> holes = {};
};

/// Target edge length as a function of position (positive and finite).
using SizeFunction = std::function<Real(const Vec<2>&)>;

struct MesherOptions {
  SizeFunction size;             ///< required
  Real min_angle_deg = 25;       ///< in (0, 33]
  std::size_t max_points = 50'000'000;
};

/// What the mesher did (optional output of generate_mesh).
struct MesherReport {
  std::size_t boundary_points = 0;     ///< after the initial boundary discretisation
  std::size_t steiner_points = 0;      ///< circumcentres inserted
  std::size_t segment_splits = 0;      ///< boundary segments split during refinement
  std::size_t small_angle_skips = 0;   ///< bad-triangle tests waived next to small input angles
  std::size_t dropped = 0;             ///< bad triangles given up (0 in every test)
  std::size_t unsplittable = 0;        ///< segments too short to split (0 in every test)
};

/// Constant size h.
inline SizeFunction uniform_size(Real h) {
  ALEFSI_CHECK_ARG(h > 0 && std::isfinite(h), "h", "must be positive and finite, got ", h);
  return [h](const Vec<2>&) { return h; };
}

/// h(x) = min(h_far, h_body + grading * distance(x, nearest body surface)); h_body inside
/// bodies.
inline SizeFunction graded_size(std::vector<Circle> bodies, Real h_body, Real h_far, Real grading = 0.2) {
  ALEFSI_CHECK_ARG(h_body > 0 && std::isfinite(h_body), "h_body", "must be positive and finite, got ", h_body);
  ALEFSI_CHECK_ARG(h_far >= h_body && std::isfinite(h_far), "h_far", "must be finite and >= h_body, got ", h_far);
  ALEFSI_CHECK_ARG(grading > 0 && std::isfinite(grading), "grading", "must be positive and finite, got ", grading);
  for (std::size_t i = 0; i < bodies.size(); ++i)
    ALEFSI_CHECK_ARG(bodies[i].radius > 0, "bodies", "body ", i, " has non-positive radius");
  return [bodies = std::move(bodies), h_body, h_far, grading](const Vec<2>& x) {
    Real d = std::numeric_limits<Real>::infinity();
    for (const Circle& c : bodies) d = std::min(d, std::max(Real(0), (x - c.centre).norm() - c.radius));
    return std::min(h_far, h_body + grading * d);
  };
}

namespace detail {

inline XY to_xy(const Vec<2>& v) { return {v[0], v[1]}; }

inline bool finite(const Vec<2>& v) { return std::isfinite(v[0]) && std::isfinite(v[1]); }

inline int sign(double x) { return (x > 0) - (x < 0); }

/// Closed segments pq and rs intersect (exact).
inline bool segments_intersect(const XY& p, const XY& q, const XY& r, const XY& s) {
  const int o1 = sign(orient2d(p, q, r)), o2 = sign(orient2d(p, q, s));
  const int o3 = sign(orient2d(r, s, p)), o4 = sign(orient2d(r, s, q));
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  auto on = [](const XY& a, const XY& b, const XY& c) {  // c on segment ab, given collinear
    return std::min(a.x, b.x) <= c.x && c.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= c.y &&
           c.y <= std::max(a.y, b.y);
  };
  return (o1 == 0 && on(p, q, r)) || (o2 == 0 && on(p, q, s)) || (o3 == 0 && on(r, s, p)) || (o4 == 0 && on(r, s, q));
}

/// +1 strictly inside the closed polygon, 0 on its boundary, -1 outside (exact).
inline int point_in_polygon(const XY& p, const std::vector<XY>& poly) {
  int wn = 0;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const XY &a = poly[i], &b = poly[(i + 1) % n];
    const double o = orient2d(a, b, p);
    if (o == 0 && std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
        p.y <= std::max(a.y, b.y))
      return 0;
    if (a.y <= p.y) {
      if (b.y > p.y && o > 0) ++wn;
    } else if (b.y <= p.y && o < 0) {
      --wn;
    }
  }
  return wn != 0 ? 1 : -1;
}

inline double point_segment_distance(const XY& p, const XY& a, const XY& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - a.x - t * dx, p.y - a.y - t * dy);
}

/// Position of the cell (x, y) on the Hilbert curve through the 2^16 x 2^16 grid.
inline std::uint32_t hilbert_index(std::uint32_t x, std::uint32_t y) {
  std::uint32_t d = 0;
  for (std::uint32_t s = 1u << 15; s > 0; s >>= 1) {
    const std::uint32_t rx = (x & s) ? 1 : 0, ry = (y & s) ? 1 : 0;
    d += s * s * ((3 * rx) ^ ry);
    x &= s - 1, y &= s - 1;
    if (ry == 0) {  // rotate the sub-square
      if (rx == 1) x = s - 1 - x, y = s - 1 - y;
      std::swap(x, y);
    }
  }
  return d;
}

inline double polygon_area(const std::vector<XY>& poly) {
  double a = 0;
  for (std::size_t i = 0, n = poly.size(); i < n; ++i)
    a += poly[i].x * poly[(i + 1) % n].y - poly[(i + 1) % n].x * poly[i].y;
  return 0.5 * a;
}

inline std::vector<XY> polyline_xy(const Polyline& p) {
  std::vector<XY> out;
  out.reserve(p.points.size());
  for (const auto& v : p.points) out.push_back(to_xy(v));
  return out;
}

/// A polygon of n points containing the ellipse: the points of the ellipse scaled by
/// 1 / cos(pi / n) about its centre at equal parameter steps (the affine image of a polygon
/// circumscribed about the unit circle).
inline Polyline circumscribed_polygon(const Ellipse& e, int n = 256) {
  Ellipse big = e;
  big.a /= std::cos(std::numbers::pi / n), big.b /= std::cos(std::numbers::pi / n);
  Polyline p;
  p.tag = e.tag;
  for (int i = 0; i < n; ++i) p.points.push_back(big.at(2 * std::numbers::pi * i / n));
  return p;
}

inline void validate_boundary(const Boundary2D& b, const std::string& name) {
  if (const Ellipse* e = std::get_if<Ellipse>(&b)) {
    ALEFSI_CHECK_ARG(finite(e->centre), name + ".centre", "must be finite");
    ALEFSI_CHECK_ARG(e->a > 0 && std::isfinite(e->a), name + ".a", "must be positive and finite, got ", e->a);
    ALEFSI_CHECK_ARG(e->b > 0 && std::isfinite(e->b), name + ".b", "must be positive and finite, got ", e->b);
    ALEFSI_CHECK_ARG(std::isfinite(e->angle), name + ".angle", "must be finite, got ", e->angle);
    return;
  }
  if (const Circle* c = std::get_if<Circle>(&b)) {
    ALEFSI_CHECK_ARG(finite(c->centre), name + ".centre", "must be finite");
    ALEFSI_CHECK_ARG(c->radius > 0 && std::isfinite(c->radius), name + ".radius",
                     "must be positive and finite, got ", c->radius);
    return;
  }
  const Polyline& p = std::get<Polyline>(b);
  const std::size_t n = p.points.size();
  ALEFSI_CHECK_ARG(n >= 3, name + ".points", "a closed polyline needs at least 3 points, got ", n);
  ALEFSI_CHECK_ARG(p.segment_tags.empty() || p.segment_tags.size() == n, name + ".segment_tags",
                   "must be empty or have one tag per segment (", n, "), got ", p.segment_tags.size());
  for (std::size_t i = 0; i < n; ++i) ALEFSI_CHECK_ARG(finite(p.points[i]), name + ".points", "point ", i, " is not finite");
  const std::vector<XY> q = polyline_xy(p);
  for (std::size_t i = 0; i < n; ++i) {
    const XY &a = q[i], &b1 = q[(i + 1) % n], &c = q[(i + 2) % n];
    ALEFSI_CHECK_ARG(!(a.x == b1.x && a.y == b1.y), name + ".points", "points ", i, " and ", (i + 1) % n, " coincide");
    // adjacent segments folding back onto each other
    const bool fold = orient2d(a, b1, c) == 0 && (b1.x - a.x) * (c.x - b1.x) + (b1.y - a.y) * (c.y - b1.y) < 0;
    ALEFSI_CHECK_ARG(!fold, name + ".points", "self-intersecting: segments ", i, " and ", (i + 1) % n, " overlap");
  }
  // non-adjacent segments must not meet (sweep over x-sorted segments)
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  auto xmin = [&](std::size_t i) { return std::min(q[i].x, q[(i + 1) % n].x); };
  auto xmax = [&](std::size_t i) { return std::max(q[i].x, q[(i + 1) % n].x); };
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return xmin(i) < xmin(j) || (xmin(i) == xmin(j) && i < j); });
  for (std::size_t oi = 0; oi < n; ++oi) {
    const std::size_t i = order[oi];
    for (std::size_t oj = oi + 1; oj < n && xmin(order[oj]) <= xmax(i); ++oj) {
      const std::size_t j = order[oj];
      if ((i + 1) % n == j || (j + 1) % n == i) continue;
      ALEFSI_CHECK_ARG(!segments_intersect(q[i], q[(i + 1) % n], q[j], q[(j + 1) % n]), name + ".points",
                       "self-intersecting polyline: segments ", std::min(i, j), " and ", std::max(i, j), " meet");
    }
  }
  ALEFSI_CHECK_ARG(polygon_area(q) != 0, name + ".points", "polyline encloses zero area");
}

/// Do the two (validated) boundaries' closed regions overlap or touch? (Ellipses: their
/// circumscribed 256-gons, a conservative answer.)
inline bool regions_meet(const Boundary2D& A, const Boundary2D& B) {
  if (const Ellipse* e = std::get_if<Ellipse>(&A)) return regions_meet(Boundary2D(circumscribed_polygon(*e)), B);
  if (const Ellipse* e = std::get_if<Ellipse>(&B)) return regions_meet(A, Boundary2D(circumscribed_polygon(*e)));
  const Circle* ca = std::get_if<Circle>(&A);
  const Circle* cb = std::get_if<Circle>(&B);
  if (ca && cb) return (ca->centre - cb->centre).norm() <= ca->radius + cb->radius;
  if (cb && !ca) return regions_meet(B, A);
  const std::vector<XY> pb = polyline_xy(std::get<Polyline>(B));
  if (ca) {
    const XY c = to_xy(ca->centre);
    if (point_in_polygon(c, pb) >= 0) return true;
    for (std::size_t i = 0; i < pb.size(); ++i)
      if (point_segment_distance(c, pb[i], pb[(i + 1) % pb.size()]) <= ca->radius) return true;
    return false;
  }
  const std::vector<XY> pa = polyline_xy(std::get<Polyline>(A));
  for (std::size_t i = 0; i < pa.size(); ++i)
    for (std::size_t j = 0; j < pb.size(); ++j)
      if (segments_intersect(pa[i], pa[(i + 1) % pa.size()], pb[j], pb[(j + 1) % pb.size()])) return true;
  return point_in_polygon(pa[0], pb) >= 0 || point_in_polygon(pb[0], pa) >= 0;
}

/// Is the (validated) hole strictly inside the (non-ellipse) outer boundary? (An elliptic
/// hole: its circumscribed 256-gon, a conservative answer.)
inline bool strictly_inside(const Boundary2D& hole, const Boundary2D& outer) {
  if (const Ellipse* e = std::get_if<Ellipse>(&hole)) return strictly_inside(Boundary2D(circumscribed_polygon(*e)), outer);
  const Circle* ch = std::get_if<Circle>(&hole);
  if (const Circle* co = std::get_if<Circle>(&outer)) {
    if (ch) return (ch->centre - co->centre).norm() + ch->radius < co->radius;
    for (const auto& p : std::get<Polyline>(hole).points)
      if (!((p - co->centre).norm() < co->radius)) return false;
    return true;
  }
  const std::vector<XY> po = polyline_xy(std::get<Polyline>(outer));
  if (ch) {
    const XY c = to_xy(ch->centre);
    if (point_in_polygon(c, po) <= 0) return false;
    for (std::size_t i = 0; i < po.size(); ++i)
      if (point_segment_distance(c, po[i], po[(i + 1) % po.size()]) <= ch->radius) return false;
    return true;
  }
  const std::vector<XY> ph = polyline_xy(std::get<Polyline>(hole));
  for (const XY& p : ph)
    if (point_in_polygon(p, po) <= 0) return false;
  for (std::size_t i = 0; i < ph.size(); ++i)
    for (std::size_t j = 0; j < po.size(); ++j)
      if (segments_intersect(ph[i], ph[(i + 1) % ph.size()], po[j], po[(j + 1) % po.size()])) return false;
  return true;
}

inline std::string boundary_name(int i) { return i < 0 ? std::string("outer") : "holes[" + std::to_string(i) + "]"; }

inline void validate_domain(const Domain2D& dom, const MesherOptions& opt) {
  ALEFSI_CHECK_ARG(static_cast<bool>(opt.size), "size", "no size function given");
  ALEFSI_CHECK_ARG(opt.min_angle_deg > 0 && opt.min_angle_deg <= 33, "min_angle_deg",
                   "must be in (0, 33] (Ruppert refinement need not terminate above), got ", opt.min_angle_deg);
  ALEFSI_CHECK_ARG(opt.max_points >= 3, "max_points", "must be >= 3");
  validate_boundary(dom.outer, "outer");
  ALEFSI_CHECK_ARG(!std::holds_alternative<Ellipse>(dom.outer), "outer",
                   "an ellipse is supported as a hole (a body) only; give the outer boundary as a Polyline or Circle");
  for (std::size_t i = 0; i < dom.holes.size(); ++i) {
    const std::string name = boundary_name(static_cast<int>(i));
    validate_boundary(dom.holes[i], name);
    ALEFSI_CHECK_ARG(strictly_inside(dom.holes[i], dom.outer), name, "is not strictly inside the outer boundary");
    for (std::size_t j = 0; j < i; ++j)
      ALEFSI_CHECK_ARG(!regions_meet(dom.holes[i], dom.holes[j]), name, "overlaps or touches holes[", j, "]");
  }
}

/// Node parameters s in [0, 1) along a curve x(s) with speed |dx/ds| = speed(s) so that the
/// spacing follows h: n = max(min_pieces, ceil(integral of 1/h)) pieces of equal integral of
/// 1/h (arc length).
template <class At, class Speed>
std::vector<double> distribute(const At& at, const Speed& speed, int min_pieces, const SizeFunction& h,
                               const std::string& where) {
  std::vector<double> cum;
  std::size_t K = 64;
  double total = 0;
  for (int pass = 0; pass < 2; ++pass) {
    cum.assign(K + 1, 0.0);
    double w_prev = 0;
    for (std::size_t j = 0; j <= K; ++j) {
      const XY p = at(double(j) / double(K));
      const double hv = h(Vec<2>(p.x, p.y));
      if (!(hv > 0) || !std::isfinite(hv))
        throw InvalidArgument("size", concat("must be positive and finite, got ", hv, " at (", p.x, ", ", p.y,
                                             ") on ", where));
      const double w = speed(double(j) / double(K)) / hv;
      if (j > 0) cum[j] = cum[j - 1] + 0.5 * (w + w_prev) / double(K);
      w_prev = w;
    }
    total = cum[K];
    if (total * 8 <= double(K)) break;
    ALEFSI_CHECK_ARG(total < 1e8, "size", "implies more than 1e8 nodes on ", where);
    K = static_cast<std::size_t>(std::ceil(total * 8));
  }
  const std::size_t n = std::max<std::size_t>(static_cast<std::size_t>(min_pieces),
                                              static_cast<std::size_t>(std::ceil(total - 1e-9)));
  std::vector<double> s{0.0};
  std::size_t j = 0;
  for (std::size_t k = 1; k < n; ++k) {
    const double target = total * double(k) / double(n);
    while (j + 1 < K && cum[j + 1] <= target) ++j;
    const double f = cum[j + 1] > cum[j] ? (target - cum[j]) / (cum[j + 1] - cum[j]) : 0.0;
    s.push_back((double(j) + f) / double(K));
  }
  return s;
}

/// The same along a curve of constant speed (a straight segment, a circle): length = speed.
template <class At>
std::vector<double> distribute(const At& at, double length, int min_pieces, const SizeFunction& h,
                               const std::string& where) {
  return distribute(at, [length](double) { return length; }, min_pieces, h, where);
}

/// The conic of a Circle or Ellipse boundary as the triangulator's loop (not a conic: a
/// polyline loop).
inline CdtLoop conic_loop(const Boundary2D& b) {
  if (const Circle* c = std::get_if<Circle>(&b)) return {true, to_xy(c->centre), c->radius, c->radius, 1, 0};
  if (const Ellipse* e = std::get_if<Ellipse>(&b))
    return {true, to_xy(e->centre), e->a, e->b, std::cos(e->angle), std::sin(e->angle)};
  return {false, {0, 0}, 0, 0, 1, 0};
}

}  // namespace detail

/// Triangulates the domain. Throws InvalidArgument (naming the parameter) for bad input,
/// checked before meshing.
inline Mesh<2> generate_mesh(const Domain2D& domain, const MesherOptions& options, MesherReport* report = nullptr) {
  using detail::XY;
  detail::validate_domain(domain, options);
  const SizeFunction& h = options.size;
  constexpr double two_pi = 2 * std::numbers::pi;

  // ---- boundary discretisation ------------------------------------------------------
  std::vector<const Boundary2D*> loops{&domain.outer};
  for (const auto& b : domain.holes) loops.push_back(&b);
  std::vector<detail::CdtLoop> conic(loops.size());
  std::vector<std::vector<double>> circle_t(loops.size());  // node parameters of conic loops
  for (std::size_t l = 0; l < loops.size(); ++l) {
    conic[l] = detail::conic_loop(*loops[l]);
    const detail::CdtLoop& C = conic[l];
    if (!C.circle) continue;
    auto at = [&](double s) { return C.at(two_pi * s); };
    const std::string where = detail::boundary_name(int(l) - 1);
    std::vector<double> s;
    if (std::holds_alternative<Circle>(*loops[l])) {
      s = detail::distribute(at, two_pi * C.ra, 8, h, where);
    } else {
      auto speed = [&](double u) { return two_pi * std::hypot(C.ra * std::sin(two_pi * u), C.rb * std::cos(two_pi * u)); };
      s = detail::distribute(at, speed, 8, h, where);
    }
    for (double u : s) circle_t[l].push_back(two_pi * u);
  }
  // an outer circle's chords must pass outside every hole: refine the offending arcs
  if (const Circle* co = std::get_if<Circle>(&domain.outer)) {
    std::vector<XY> hole_pts;
    for (std::size_t l = 1; l < loops.size(); ++l) {
      if (conic[l].circle) {
        for (double t : circle_t[l]) hole_pts.push_back(conic[l].at(t));
      } else {
        for (const auto& p : std::get<Polyline>(*loops[l]).points) hole_pts.push_back(detail::to_xy(p));
      }
    }
    std::vector<double>& T = circle_t[0];
    for (int pass = 0;; ++pass) {
      ALEFSI_CHECK_ARG(pass < 64, "holes", "a hole is too close to the outer circle");
      std::vector<char> split(T.size(), 0);
      bool any = false;
      for (const XY& p : hole_pts) {
        double phi = std::atan2(p.y - co->centre[1], p.x - co->centre[0]);
        if (phi < 0) phi += two_pi;
        const std::size_t n = T.size();
        const std::size_t k = static_cast<std::size_t>(std::upper_bound(T.begin(), T.end(), phi) - T.begin()) - 1;
        for (std::size_t d = n - 1; d <= n + 1; ++d) {
          const std::size_t i = (k + d) % n;
          const XY a = conic[0].at(T[i]), b = conic[0].at(T[(i + 1) % n]);
          if (!(detail::orient2d(a, b, p) > 0)) split[i] = 1, any = true;
        }
      }
      if (!any) break;
      std::vector<double> refined;
      for (std::size_t i = 0; i < T.size(); ++i) {
        refined.push_back(T[i]);
        if (split[i]) refined.push_back(0.5 * (T[i] + (i + 1 < T.size() ? T[i + 1] : two_pi)));
      }
      T = std::move(refined);
    }
  }

  // ---- the PSLG ----------------------------------------------------------------------
  detail::Cdt2D cdt;
  cdt.size = [&h](const XY& p) { return h(Vec<2>(p.x, p.y)); };
  cdt.min_angle_deg = options.min_angle_deg;
  cdt.max_points = options.max_points;
  int input_edges = 0;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const int li = static_cast<int>(l);
    if (conic[l].circle) {
      cdt.loops.push_back(conic[l]);
      const int tag = std::holds_alternative<Circle>(*loops[l]) ? std::get<Circle>(*loops[l]).tag
                                                                : std::get<Ellipse>(*loops[l]).tag;
      const std::vector<double>& T = circle_t[l];
      const Index first = static_cast<Index>(cdt.pts.size());
      for (double t : T) cdt.add_vertex(conic[l].at(t), -1, -1);
      const Index n = static_cast<Index>(T.size());
      for (Index i = 0; i < n; ++i) {
        detail::CdtSeg s;
        s.a = first + i, s.b = first + (i + 1) % n, s.loop = li, s.tag = tag;
        s.ta = T[static_cast<std::size_t>(i)];
        s.tb = i + 1 < n ? T[static_cast<std::size_t>(i + 1)] : two_pi;
        cdt.segs.push_back(s);
      }
      continue;
    }
    const Polyline& P = std::get<Polyline>(*loops[l]);
    cdt.loops.push_back(conic[l]);
    const std::vector<XY> q = detail::polyline_xy(P);
    const std::size_t n = q.size();
    const bool ccw = detail::polygon_area(q) > 0;
    const bool domain_left = (l == 0) == ccw;
    const int e0 = input_edges, c0 = static_cast<int>(cdt.corners.size());
    input_edges += static_cast<int>(n);
    std::vector<Index> loop_vertices;
    std::vector<int> loop_tags, loop_edges;  // per segment starting at loop_vertices[i]
    for (std::size_t i = 0; i < n; ++i) {
      // corner at q[i] between input edges i-1 and i
      const XY &v = q[i], &nxt = q[(i + 1) % n], &prv = q[(i + n - 1) % n];
      const double d1x = nxt.x - v.x, d1y = nxt.y - v.y, d2x = prv.x - v.x, d2y = prv.y - v.y;
      double ang = std::atan2(d1x * d2y - d1y * d2x, d1x * d2x + d1y * d2y);
      if (!domain_left) ang = -ang;
      if (ang < 0) ang += two_pi;
      detail::CdtCorner corner;
      corner.angle = ang;
      corner.e0 = e0 + static_cast<int>((i + n - 1) % n);
      corner.e1 = e0 + static_cast<int>(i);
      corner.small = ang < std::numbers::pi / 3;
      cdt.has_small_corners_ = cdt.has_small_corners_ || corner.small;
      cdt.corners.push_back(corner);
      cdt.edge_corners.push_back({c0 + static_cast<int>(i), c0 + static_cast<int>((i + 1) % n)});
      const int tag = P.segment_tags.empty() ? P.tag : P.segment_tags[i];
      const int edge = e0 + static_cast<int>(i);
      loop_vertices.push_back(cdt.add_vertex(v, -1, c0 + static_cast<int>(i)));
      loop_tags.push_back(tag);
      loop_edges.push_back(edge);
      auto at = [&](double s) { return XY{v.x + s * (nxt.x - v.x), v.y + s * (nxt.y - v.y)}; };
      const std::vector<double> s = detail::distribute(at, std::hypot(nxt.x - v.x, nxt.y - v.y), 1, h,
                                                       detail::boundary_name(li - 1) + " segment " + std::to_string(i));
      for (std::size_t k = 1; k < s.size(); ++k) {
        loop_vertices.push_back(cdt.add_vertex(at(s[k]), edge, -1));
        loop_tags.push_back(tag);
        loop_edges.push_back(edge);
      }
    }
    for (std::size_t i = 0; i < loop_vertices.size(); ++i) {
      detail::CdtSeg sg;
      sg.a = loop_vertices[i], sg.b = loop_vertices[(i + 1) % loop_vertices.size()];
      sg.loop = li, sg.tag = loop_tags[i];
      sg.input_edge = loop_edges[i];
      cdt.segs.push_back(sg);
    }
  }
  const std::size_t boundary_points = cdt.pts.size() - 3;

  // ---- triangulate and refine ----------------------------------------------------------
  cdt.triangulate();
  cdt.refine();

  // ---- output: nodes in Hilbert-curve order, cells by their first node (locality) ----
  std::vector<Index> map(cdt.pts.size(), -1);
  for (const auto& T : cdt.tris)
    if (T.v[0] >= 0)
      for (Index v : T.v) map[v] = 0;
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (std::size_t v = 3; v < cdt.pts.size(); ++v) {
    x0 = std::min(x0, cdt.pts[v].x), x1 = std::max(x1, cdt.pts[v].x);
    y0 = std::min(y0, cdt.pts[v].y), y1 = std::max(y1, cdt.pts[v].y);
  }
  const double scale = 65535.0 / std::max(x1 - x0, y1 - y0);
  std::vector<std::pair<std::uint32_t, Index>> order;  // (Hilbert index, vertex): ties by vertex
  for (std::size_t v = 3; v < cdt.pts.size(); ++v)
    if (map[v] == 0)
      order.emplace_back(detail::hilbert_index(static_cast<std::uint32_t>((cdt.pts[v].x - x0) * scale),
                                               static_cast<std::uint32_t>((cdt.pts[v].y - y0) * scale)),
                         static_cast<Index>(v));
  std::sort(order.begin(), order.end());
  std::vector<Vec<2>> nodes;
  nodes.reserve(order.size());
  for (const auto& [key, v] : order) {
    map[v] = static_cast<Index>(nodes.size());
    nodes.emplace_back(cdt.pts[v].x, cdt.pts[v].y);
  }
  std::vector<Mesh<2>::Cell> cells;
  for (const auto& T : cdt.tris)
    if (T.v[0] >= 0) {
      Mesh<2>::Cell c{map[T.v[0]], map[T.v[1]], map[T.v[2]]};
      std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());  // keeps the orientation
      cells.push_back(c);
    }
  std::sort(cells.begin(), cells.end());
  std::vector<Mesh<2>::Facet> facets;
  std::vector<int> tags;
  facets.reserve(cdt.segs.size());
  tags.reserve(cdt.segs.size());
  for (const auto& s : cdt.segs) {
    facets.push_back({map[s.a], map[s.b]});
    tags.push_back(s.tag);
  }
  if (report) {
    report->boundary_points = boundary_points;
    report->steiner_points = cdt.stats.steiner_points;
    report->segment_splits = cdt.stats.segment_splits;
    report->small_angle_skips = cdt.stats.small_angle_skips;
    report->dropped = cdt.stats.dropped;
    report->unsplittable = cdt.stats.unsplittable;
  }
  return Mesh<2>(std::move(nodes), std::move(cells), facets, tags);
}

/// Smallest interior angle of the mesh, in degrees.
inline Real min_angle_deg(const Mesh<2>& mesh) {
  Real best = 180;
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    const auto& cell = mesh.cell(c);
    for (int i = 0; i < 3; ++i) {
      const Vec<2> a = mesh.node(cell[(i + 1) % 3]) - mesh.node(cell[i]);
      const Vec<2> b = mesh.node(cell[(i + 2) % 3]) - mesh.node(cell[i]);
      best = std::min(best, std::atan2(std::abs(a[0] * b[1] - a[1] * b[0]), a.dot(b)) * 180 / std::numbers::pi);
    }
  }
  return best;
}

/// P2 helper: for every mesh edge (indexed as mesh.edges()), its midpoint, or, for a
/// boundary edge on a circle or an ellipse of the domain, the point of the curve at the mid
/// parameter.
inline std::vector<Vec<2>> curved_edge_midpoints(const Mesh<2>& mesh, const Domain2D& domain) {
  std::vector<Vec<2>> mid(static_cast<std::size_t>(mesh.n_edges()));
  for (Index e = 0; e < mesh.n_edges(); ++e) mid[e] = 0.5 * (mesh.node(mesh.edge(e)[0]) + mesh.node(mesh.edge(e)[1]));
  std::vector<const Circle*> circles;
  if (const Circle* c = std::get_if<Circle>(&domain.outer)) circles.push_back(c);
  for (const auto& b : domain.holes)
    if (const Circle* c = std::get_if<Circle>(&b)) circles.push_back(c);
  std::vector<const Ellipse*> ellipses;
  for (const auto& b : domain.holes)
    if (const Ellipse* e = std::get_if<Ellipse>(&b)) ellipses.push_back(e);
  if (circles.empty() && ellipses.empty()) return mid;
  auto on = [](const Circle& c, const Vec<2>& x) {
    return std::abs((x - c.centre).norm() - c.radius) <= 1e-10 * (c.radius + c.centre.norm());
  };
  for (Index f : mesh.boundary_facets()) {
    const auto& fv = mesh.facet(f);
    const Index cell = mesh.facet_cells(f)[0];
    Index edge = -1;
    for (Index e : mesh.cell_edges(cell))
      if (mesh.edge(e) == fv) edge = e;
    if (edge < 0) continue;
    const Vec<2>&a = mesh.node(fv[0]), &b = mesh.node(fv[1]);
    const Ellipse* ell = nullptr;
    for (const Ellipse* e : ellipses)
      if (std::abs(e->level(a) - 1) <= 1e-10 && std::abs(e->level(b) - 1) <= 1e-10 &&
          (!ell || e->tag == mesh.facet_tag(f)))
        ell = e;
    if (ell) {
      const Real ta = ell->parameter(a);
      Real dt = ell->parameter(b) - ta;
      if (dt > std::numbers::pi) dt -= 2 * std::numbers::pi;
      if (dt < -std::numbers::pi) dt += 2 * std::numbers::pi;
      mid[edge] = ell->at(ta + 0.5 * dt);
      continue;
    }
    const Circle* best = nullptr;
    for (const Circle* c : circles)
      if (on(*c, a) && on(*c, b) && (!best || c->tag == mesh.facet_tag(f))) best = c;
    if (!best) continue;
    const Vec<2> da = a - best->centre, db = b - best->centre;
    const Real ta = std::atan2(da[1], da[0]);
    Real dt = std::atan2(db[1], db[0]) - ta;
    if (dt > std::numbers::pi) dt -= 2 * std::numbers::pi;
    if (dt < -std::numbers::pi) dt += 2 * std::numbers::pi;
    const Real t = ta + 0.5 * dt;
    mid[edge] = best->centre + best->radius * Vec<2>(std::cos(t), std::sin(t));
  }
  return mid;
}

// ---- ready-made scenes ---------------------------------------------------------------

/// The outline of the channel [0, width] x [0, height], tagged as `alefsi::tags`: bottom 1,
/// right 2, top 3, left 4 (the walls for `adapt` and `RemeshOptions`).
inline Polyline channel_outline(Real width, Real height) {
  return Polyline{{Vec<2>(0, 0), Vec<2>(width, 0), Vec<2>(width, height), Vec<2>(0, height)},
                  0,
                  {tags::bottom, tags::right, tags::top, tags::left}};
}

/// The channel [0, width] x [0, height] with disk-shaped bodies (tags from Circle::tag),
/// graded from h_body at the disks to h_far (grading 0.2). Outer tags as `alefsi::tags`:
/// bottom 1, right 2, top 3, left 4.
inline Mesh<2> channel_with_disks(Real width, Real height, const std::vector<Circle>& disks, Real h_body, Real h_far,
                                  MesherReport* report = nullptr) {
  ALEFSI_CHECK_ARG(width > 0 && std::isfinite(width), "width", "must be positive and finite, got ", width);
  ALEFSI_CHECK_ARG(height > 0 && std::isfinite(height), "height", "must be positive and finite, got ", height);
  Domain2D dom;
  dom.outer = channel_outline(width, height);
  for (const Circle& d : disks) dom.holes.emplace_back(d);
  MesherOptions opt;
  opt.size = graded_size(disks, h_body, h_far);
  return generate_mesh(dom, opt, report);
}

/// The annulus r1 < |x| < r2 with uniform size h; inner tag 1, outer tag 2 (as annulus_mesh).
inline Mesh<2> annulus_unstructured(Real r1, Real r2, Real h, MesherReport* report = nullptr) {
  ALEFSI_CHECK_ARG(r1 > 0 && std::isfinite(r1), "r1", "must be positive and finite, got ", r1);
  ALEFSI_CHECK_ARG(r2 > r1 && std::isfinite(r2), "r2", "must be finite and exceed r1, got ", r2);
  Domain2D dom{Circle{Vec<2>::Zero(), r2, tags::outer}, {Circle{Vec<2>::Zero(), r1, tags::inner}}};
  return generate_mesh(dom, MesherOptions{uniform_size(h)}, report);
}

}  // namespace alefsi
