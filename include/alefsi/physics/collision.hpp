#pragma once
/// \file physics/collision.hpp
/// Short-range collision forces between rigid bodies, and between a body and a wall, in 2D and
/// 3D: the paper's eq. (24) with the sign made repulsive (DESIGN.md: as printed, the force on K
/// points towards J).
///
/// For bodies K and J whose surfaces are a distance d apart, d <= delta:
///     F_K = mu (4 Rbar / d)^{3/2} |V^J - V^K| n_JK,     F_J = -F_K        (2D, per unit length)
///     F_K = mu Rbar (4 Rbar / d)^{3/2} |V^J - V^K| n_JK                    (3D),
/// with n_JK = (X_g^K - X_g^J) / |X_g^K - X_g^J| the unit vector from J's centre to K's,
/// Rbar = min(Rbar^K, Rbar^J), Rbar^K the smallest distance from X_g^K to K's surface and
/// delta = `range` * Rbar (the paper's delta = Rbar / 10). The paper derives eq. (24) from the
/// lubrication of two planar faces in 2D, where mu |V| is a force per unit length; in 3D a force
/// needs one more length, and Rbar is the model's only one (without it the force would change
/// with the unit system: x100 from cm to m). At d = delta it is then 253 mu Rbar |V|, against
/// 188 mu R |V| from the sphere-plane lubrication law 6 pi mu R^2 |V| / d (Brenner 1961).
/// A wall is a body J with V^J = 0 and Rbar = Rbar^K; n points from the wall point nearest to
/// the body towards X_g^K. Between disks/spheres, and a disk/sphere and a wall, the force acts
/// at the centre of mass (its line passes through it). For other shapes (facet surfaces) the
/// model is generalised to the contact point: n is the unit vector from J's nearest surface
/// point to K's (the centres' direction if they coincide), and the force acts at their
/// midpoint, so it carries a torque (`arm_k`, `arm_j`: from each centre to that point). The gap
/// entering the magnitude is floored at `min_gap` * delta, so an overlap (d <= 0, which the
/// force is there to prevent) gives a large but finite force instead of a NaN.
///
/// `law`: the magnitude reads |V^J - V^K| (`CollisionLaw::paper`, the default) or the signed
/// normal part (V^J - V^K) . n_JK (`CollisionLaw::lubrication`: resists separation as it resists
/// approach, and never adds energy).
///
/// Optional safeguard (off by default): the repulsive spring of Glowinski et al. (1999,
/// J. Comput. Phys. 169) used in most DKT studies, F_K += F_0 (1 - d / rho)^2 n_JK for
/// d < rho (`spring_range` = rho, `spring_force` = F_0, the force at contact). Eq. (24)
/// vanishes when the bodies stop approaching and is weak until d << delta (mu (4 Rbar /
/// d)^{3/2} |V|); with positions advanced explicitly by the schemes, a body can then cross
/// the last mesh layer in one step. The spring keeps a gap of the order of rho, so the cells
/// in the gap survive; take rho about the mesh size at the bodies.
///
/// Geometry (`ContactGeometry<D>`): a surface is a set of facets (2D: segments, 3D:
/// triangles; the walls' and the bodies' boundary facets, moved with the bodies). A disk or
/// sphere (radius > 0) is exact: d = |X^K - X^J| - r^K - r^J between two of them, the distance
/// from its centre to the nearest facet minus r against facets. Otherwise d is the smallest
/// facet-to-facet distance (exact, 0 for facets that cross), with facet pairs culled by their
/// bounding balls. A body with a convex shape (`CollisionBody::convex`: an ellipse, a capsule,
/// a polygon ...) is measured on that shape by GJK against another shape, a disk/sphere or a
/// wall facet, so its distances and nearest points are those of the exact curve, not of the
/// mesh's facets; n is then the normal at the nearest points (from J's towards K's).
///
/// Search: only pairs whose bounding balls (centre, farthest surface point + reach) overlap
/// are examined, found through a uniform grid of cell size = the largest bounding diameter:
/// O(N) for N bodies of comparable size, not O(N^2). Wall facets are bucketed once into a
/// grid, rebuilt when the mesh topology changes (`set_walls`).
///
///     CollisionModel<3> model({.range = 0.1});
///     model.set_walls(wall_triangles);
///     auto contacts = model.contacts(bodies, mu);   // then force / dforce_dvk per contact
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <utility>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/grid.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/physics/convex.hpp"

namespace alefsi {

/// How eq. (24)'s magnitude reads the relative velocity w = V^J - V^K of a contact.
enum class CollisionLaw {
  /// |w|: the paper's eq. (24), its sign made repulsive. It pushes the bodies apart also while
  /// they separate, so a contact can give back more energy than it took (a sphere landing on a
  /// spring rebounds faster).
  paper,
  /// w . n, signed: it resists approach (repulsive) and separation (attractive) alike, as a
  /// lubrication film does, and never adds energy (F_K . (V^K - V^J) <= 0); sliding (w normal
  /// to n) gives none.
  lubrication
};

struct CollisionOptions {
  Real range = 0.1;     ///< delta = range * Rbar (paper: 1/10); > 0
  bool walls = true;    ///< also between bodies and walls
  Real min_gap = 1e-3;  ///< the gap in the magnitude is floored at min_gap * delta; in (0, 1]
  Real spring_range = 0;  ///< rho of the safeguard spring (length); 0: no spring
  Real spring_force = 0;  ///< F_0: the spring's force at contact (d = 0)
  CollisionLaw law = CollisionLaw::paper;  ///< how eq. (24) reads the relative velocity

  void validate() const {
    ALEFSI_CHECK_ARG(spring_range >= 0 && std::isfinite(spring_range), "collision.spring_range",
                     "must be >= 0 and finite, got ", spring_range);
    ALEFSI_CHECK_ARG(spring_force >= 0 && std::isfinite(spring_force), "collision.spring_force",
                     "must be >= 0 and finite, got ", spring_force);
    ALEFSI_CHECK_ARG(range > 0 && std::isfinite(range), "collision.range", "must be positive and finite, got ", range);
    ALEFSI_CHECK_ARG(min_gap > 0 && min_gap <= 1, "collision.min_gap", "must be in (0, 1], got ", min_gap);
  }
};

/// A boundary facet in world coordinates: a segment in 2D, a triangle in 3D.
template <int D>
using Facet = std::array<Vec<D>, D>;
using Segment2D = Facet<2>;

/// A body as the collision model sees it, at the time level of the force.
template <int D>
struct CollisionBody {
  Vec<D> centre = Vec<D>::Zero();
  Vec<D> velocity = Vec<D>::Zero();  ///< translational velocity V
  Real radius = 0;                   ///< > 0: a disk / sphere of this radius (exact distances)
  Real r_in = 0;                     ///< Rbar: smallest distance from the centre to the surface
  Real r_out = 0;                    ///< largest distance from the centre to the surface
  std::vector<Facet<D>> surface;     ///< used when radius == 0 and there is no `convex` shape
  /// The exact convex shape in world coordinates (physics/convex.hpp), if known: distances to
  /// other shapes, disks/spheres and wall facets by GJK, nearest points exact.
  alefsi::convex::Support<D> convex;
};
using CollisionBody2D = CollisionBody<2>;

/// Body k near body j (j = -1: a wall): the gap between their surfaces, the contact normal
/// and where the force acts.
template <int D>
struct Proximity {
  int k = -1, j = -1;
  Real gap = 0;                    ///< d (<= 0 for an overlap)
  Real rbar = 0;                   ///< min(Rbar^K, Rbar^J) (a wall: Rbar^K)
  Vec<D> normal = Vec<D>::Zero();  ///< unit, towards K (file comment)
  Vec<D> arm_k = Vec<D>::Zero();   ///< from X_g^K to the point of action (0: through the centre)
  Vec<D> arm_j = Vec<D>::Zero();   ///< from X_g^J to it (0 for a wall)
};

/// One active contact: body k against body j (j = -1: a wall).
template <int D>
struct Contact {
  int k = -1, j = -1;
  Real gap = 0;                    ///< d (may be <= 0 for an overlap)
  Real coefficient = 0;            ///< mu (4 Rbar / max(d, min_gap delta))^{3/2} (x Rbar in 3D), 0 when d > delta
  Real spring = 0;                 ///< F_0 (1 - d / rho)^2 (d floored at 0), 0 when d >= rho
  Vec<D> normal = Vec<D>::Zero();  ///< unit, towards K (file comment)
  Vec<D> arm_k = Vec<D>::Zero();   ///< from X_g^K to the point of action (0: through the centre)
  Vec<D> arm_j = Vec<D>::Zero();   ///< from X_g^J to it (0 for a wall)
  CollisionLaw law = CollisionLaw::paper;
};
using Contact2D = Contact<2>;

namespace detail {

/// The point of segment [a, b] closest to p.
template <int D>
Vec<D> closest_on_segment(const Vec<D>& p, const Vec<D>& a, const Vec<D>& b) {
  const Vec<D> e = b - a;
  const Real l2 = e.squaredNorm();
  const Real t = l2 > 0 ? std::clamp((p - a).dot(e) / l2, Real(0), Real(1)) : Real(0);
  return a + t * e;
}

/// The point of a facet (2D: segment, 3D: triangle) closest to p.
inline Vec<2> closest_on_facet(const Vec<2>& p, const Facet<2>& s) { return closest_on_segment<2>(p, s[0], s[1]); }
inline Vec<3> closest_on_facet(const Vec<3>& p, const Facet<3>& t) {
  // Ericson, Real-Time Collision Detection, 5.1.5: Voronoi regions of the triangle
  const Vec<3> &a = t[0], &b = t[1], &c = t[2];
  const Vec<3> ab = b - a, ac = c - a, ap = p - a;
  const Real d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec<3> bp = p - b;
  const Real d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Vec<3> cp = p - c;
  const Real d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const Real den = 1 / (va + vb + vc);
  return a + ab * (vb * den) + ac * (vc * den);
}

/// Closest points (on [p0, p1], on [q0, q1]) of two segments in any dimension (Ericson 5.1.9):
/// the closest points of the lines, clamped to the segments; exact also for segments that cross
/// (distance 0 up to round-off) and for parallel or degenerate ones.
template <int D>
std::pair<Vec<D>, Vec<D>> closest_segments(const Vec<D>& p0, const Vec<D>& p1, const Vec<D>& q0, const Vec<D>& q1) {
  const Vec<D> d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const Real a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  Real s = 0, t = 0;
  if (a <= 0 && e <= 0) {
  } else if (a <= 0) {
    t = std::clamp(f / e, Real(0), Real(1));
  } else {
    const Real c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, Real(0), Real(1));
    } else {
      const Real b = d1.dot(d2), den = a * e - b * b;
      s = den > 0 ? std::clamp((b * f - c * e) / den, Real(0), Real(1)) : Real(0);
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0, s = std::clamp(-c / a, Real(0), Real(1));
      } else if (t > 1) {
        t = 1, s = std::clamp((b - c) / a, Real(0), Real(1));
      }
    }
  }
  return {Vec<D>(p0 + s * d1), Vec<D>(q0 + t * d2)};
}

/// Where segment [p, q] crosses triangle t, if it does (the crossing of a closed surface by
/// another, which no vertex or edge distance sees).
inline bool segment_crosses_triangle(const Vec<3>& p, const Vec<3>& q, const Facet<3>& t, Vec<3>& x) {
  const Vec<3> n = (t[1] - t[0]).cross(t[2] - t[0]);
  const Real sp = n.dot(p - t[0]), sq = n.dot(q - t[0]);
  if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0) || sp == sq) return false;
  x = p + sp / (sp - sq) * (q - p);
  for (int i = 0; i < 3; ++i)
    if ((t[(i + 1) % 3] - t[i]).cross(x - t[i]).dot(n) < 0) return false;
  return true;
}

/// Closest points (on a, on b) of two facets: segments in 2D, triangles in 3D (the nearest of
/// the 9 edge pairs and the 6 vertex-to-triangle distances, or a crossing point).
inline std::pair<Vec<2>, Vec<2>> closest_facets(const Facet<2>& a, const Facet<2>& b) {
  return closest_segments<2>(a[0], a[1], b[0], b[1]);
}
inline std::pair<Vec<3>, Vec<3>> closest_facets(const Facet<3>& a, const Facet<3>& b) {
  std::pair<Vec<3>, Vec<3>> best;
  Real bd = std::numeric_limits<Real>::infinity();
  auto consider = [&](const Vec<3>& pa, const Vec<3>& pb) {
    const Real d = (pa - pb).squaredNorm();
    if (d < bd) bd = d, best = {pa, pb};
  };
  Vec<3> x;
  for (int i = 0; i < 3; ++i) {
    if (segment_crosses_triangle(a[i], a[(i + 1) % 3], b, x)) return {x, x};
    if (segment_crosses_triangle(b[i], b[(i + 1) % 3], a, x)) return {x, x};
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const auto [pa, pb] = closest_segments<3>(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]);
      consider(pa, pb);
    }
  for (const Vec<3>& v : a) consider(v, closest_on_facet(v, b));
  for (const Vec<3>& v : b) consider(closest_on_facet(v, a), v);
  return best;
}

/// A ball around a facet: its centroid and the largest distance from it to a vertex.
template <int D>
std::pair<Vec<D>, Real> facet_ball(const Facet<D>& f) {
  Vec<D> c = Vec<D>::Zero();
  for (const auto& v : f) c += v;
  c /= Real(D);
  Real r = 0;
  for (const auto& v : f) r = std::max(r, (v - c).norm());
  return {c, r};
}

/// The nearest points of two surfaces: distance, and the points on each.
template <int D>
struct Nearest {
  Real distance = std::numeric_limits<Real>::infinity();
  Vec<D> a = Vec<D>::Zero(), b = Vec<D>::Zero();
  void take(const Vec<D>& pa, const Vec<D>& pb) {
    const Real d = (pa - pb).norm();
    if (d < distance) distance = d, a = pa, b = pb;
  }
};

/// The nearest points of two facet sets. Pairs whose bounding balls are farther apart than the
/// best distance so far are skipped; the pair of nearest balls is measured first.
template <int D>
Nearest<D> nearest_facets(const std::vector<Facet<D>>& A, const std::vector<Facet<D>>& B) {
  Nearest<D> out;
  if (A.empty() || B.empty()) return out;
  std::vector<std::pair<Vec<D>, Real>> ba(A.size()), bb(B.size());
  for (std::size_t i = 0; i < A.size(); ++i) ba[i] = facet_ball<D>(A[i]);
  for (std::size_t j = 0; j < B.size(); ++j) bb[j] = facet_ball<D>(B[j]);
  auto bound = [&](std::size_t i, std::size_t j) { return (ba[i].first - bb[j].first).norm() - ba[i].second - bb[j].second; };
  std::size_t si = 0, sj = 0;
  Real sb = std::numeric_limits<Real>::infinity();
  for (std::size_t i = 0; i < A.size(); ++i)
    for (std::size_t j = 0; j < B.size(); ++j)
      if (const Real b = bound(i, j); b < sb) sb = b, si = i, sj = j;
  const auto [pa, pb] = closest_facets(A[si], B[sj]);
  out.take(pa, pb);
  for (std::size_t i = 0; i < A.size(); ++i)
    for (std::size_t j = 0; j < B.size(); ++j)
      if (bound(i, j) < out.distance) {
        const auto [qa, qb] = closest_facets(A[i], B[j]);
        out.take(qa, qb);
      }
  return out;
}

/// The nearest points of a disk/sphere (centre c, radius r) and a facet set: the distance is
/// the centre's minus r (negative for an overlap); a is on the sphere, b on the facets.
template <int D>
Nearest<D> nearest_ball_facets(const Vec<D>& c, Real r, const std::vector<Facet<D>>& B) {
  Nearest<D> out;
  for (const auto& f : B) {
    const Vec<D> p = closest_on_facet(c, f);
    const Real d = (p - c).norm() - r;
    if (d < out.distance) {
      out.distance = d, out.b = p;
      out.a = (p - c).norm() > 0 ? Vec<D>(c + r * (p - c).normalized()) : c;
    }
  }
  return out;
}

/// A wall facet as a GJK shape (the hull of its D vertices).
template <int D>
struct FacetShape {
  const Facet<D>* facet;
  Vec<D> support(const Vec<D>& d) const {
    int best = 0;
    for (int i = 1; i < D; ++i)
      if ((*facet)[i].dot(d) > (*facet)[best].dot(d)) best = i;
    return (*facet)[best];
  }
  Real margin() const { return 0; }
};

template <int D>
using CellKey = std::array<std::int64_t, D>;
template <int D>
struct CellKeyHash {
  std::size_t operator()(const CellKey<D>& c) const {
    static constexpr std::int64_t prime[3] = {73856093LL, 19349663LL, 83492791LL};
    std::int64_t h = 0;
    for (int d = 0; d < D; ++d) h ^= c[d] * prime[d];
    return std::hash<std::int64_t>()(h);
  }
};
template <int D>
CellKey<D> key_of(const Vec<D>& x, Real cell) {
  CellKey<D> k;
  for (int d = 0; d < D; ++d) k[d] = std::int64_t(std::floor(x[d] / cell));
  return k;
}

}  // namespace detail

/// The distances of a contact model: fixed walls bucketed in a grid, and the nearest points of
/// bodies and walls.
template <int D>
class ContactGeometry {
 public:
  /// Wall facets (fixed in time); bucketed into a grid of cell size `cell` (default: the mean
  /// facet diameter times 4).
  void set_walls(std::vector<Facet<D>> walls, Real cell = 0) {
    walls_ = std::move(walls);
    grid_.clear();
    if (walls_.empty()) return;
    if (cell <= 0) {
      Real s = 0;
      for (const auto& w : walls_) s += 2 * detail::facet_ball<D>(w).second;
      cell = 4 * s / Real(walls_.size());
    }
    wall_cell_ = cell > 0 ? cell : 1;
    lo_ = hi_ = walls_[0][0];
    for (const auto& w : walls_)
      for (const auto& x : w) lo_ = lo_.cwiseMin(x), hi_ = hi_.cwiseMax(x);
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      Vec<D> lo = walls_[w][0], hi = walls_[w][0];
      for (const auto& x : walls_[w]) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
      for_each_in_box(detail::key_of<D>(lo, wall_cell_), detail::key_of<D>(hi, wall_cell_),
                           [&](const detail::CellKey<D>& key) { grid_[key].push_back(Index(w)); });
    }
  }
  const std::vector<Facet<D>>& walls() const { return walls_; }

  /// Every pair of bodies, and (with `walls`) every body and its nearest wall point, whose gap
  /// is at most the reach max(range * Rbar, extra) (range may be infinite: every pair, and
  /// the nearest wall of every body).
  std::vector<Proximity<D>> near(const std::vector<CollisionBody<D>>& bodies, Real range, Real extra, bool walls) const {
    std::vector<Proximity<D>> out;
    if (bodies.empty()) return out;
    auto reach = [&](Real rbar) { return std::max(range * rbar, extra); };
    Real outer = 0;
    for (const auto& b : bodies) outer = std::max(outer, b.r_out + reach(b.r_in));
    if (!std::isfinite(outer)) {
      for (std::size_t k = 0; k < bodies.size(); ++k)
        for (std::size_t j = k + 1; j < bodies.size(); ++j) pair(bodies, int(k), int(j), reach, out);
    } else {
      // each body in the cell of its centre; neighbours in the 3^D block around it
      const Real cell = std::max(2 * outer, std::numeric_limits<Real>::min());
      std::unordered_map<detail::CellKey<D>, std::vector<int>, detail::CellKeyHash<D>> cells;
      for (std::size_t k = 0; k < bodies.size(); ++k) cells[detail::key_of<D>(bodies[k].centre, cell)].push_back(int(k));
      for (std::size_t k = 0; k < bodies.size(); ++k) {
        detail::CellKey<D> a = detail::key_of<D>(bodies[k].centre, cell), b = a;
        for (int d = 0; d < D; ++d) --a[d], ++b[d];
        for_each_in_box(a, b, [&](const detail::CellKey<D>& key) {
          const auto it = cells.find(key);
          if (it == cells.end()) return;
          for (int j : it->second)
            if (j > int(k)) pair(bodies, int(k), j, reach, out);
        });
      }
    }
    if (walls && !walls_.empty())
      for (std::size_t k = 0; k < bodies.size(); ++k) wall(bodies[k], int(k), reach(bodies[k].r_in), out);
    return out;
  }

  /// Per body, the smallest time to contact, gap / closing speed, over the bodies and every
  /// wall facet it approaches (infinity if none). Against a wall facet, a body without radius
  /// counts from its outer radius.
  std::vector<Real> times_to_contact(const std::vector<CollisionBody<D>>& bodies) const {
    std::vector<Real> t(bodies.size(), std::numeric_limits<Real>::infinity());
    auto take = [&](std::size_t k, Real gap, Real closing) {
      if (closing > 0) t[k] = std::min(t[k], std::max(gap, Real(0)) / closing);
    };
    // bodies: the normal points from j to k, the gap closes at -(V_k - V_j) . n
    for (const auto& c : near(bodies, std::numeric_limits<Real>::infinity(), 0, false)) {
      const std::size_t k = std::size_t(c.k), j = std::size_t(c.j);
      take(k, c.gap, -(bodies[k].velocity - bodies[j].velocity).dot(c.normal));
      t[j] = std::min(t[j], t[k]);
    }
    // every wall facet, not only the nearest (a body sliding along a side wall still falls
    // toward the floor)
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      const Real r = bodies[k].radius > 0 ? bodies[k].radius : bodies[k].r_out;
      for (const auto& w : walls_) {
        const Vec<D> d = bodies[k].centre - detail::closest_on_facet(bodies[k].centre, w);
        const Real dist = d.norm();
        if (dist > 0) take(k, dist - r, -bodies[k].velocity.dot(d / dist));
      }
    }
    return t;
  }

 private:
  template <class Reach>
  void pair(const std::vector<CollisionBody<D>>& bodies, int k, int j, const Reach& reach,
            std::vector<Proximity<D>>& out) const {
    const auto &A = bodies[k], &B = bodies[j];
    const Real rbar = std::min(A.r_in, B.r_in);
    const Real delta = reach(rbar);
    const Vec<D> dc = A.centre - B.centre;
    const Real dist = dc.norm();
    if (dist - A.r_out - B.r_out > delta || dist == 0) return;
    if (A.radius > 0 && B.radius > 0) {
      const Real gap = dist - A.radius - B.radius;
      if (gap <= delta) out.push_back({k, j, gap, rbar, dc / dist});
      return;
    }
    if ((A.convex || A.radius > 0) && (B.convex || B.radius > 0)) {
      const auto g = convex::distance<D>(shape(A), shape(B));
      if (g.distance > delta) return;
      const Vec<D> x = (g.a + g.b) / 2;
      out.push_back({k, j, g.distance, rbar, direction(g.normal, dc / dist, 1), x - A.centre, x - B.centre});
      return;
    }
    if (A.convex || B.convex) {  // a shape against a body known by its facets
      const bool k_shaped = bool(A.convex);
      const CollisionBody<D>& S = k_shaped ? A : B;
      std::vector<const Facet<D>*> facets;
      for (const auto& f : (k_shaped ? B : A).surface) facets.push_back(&f);
      const auto g = nearest_to_facets(S, facets);
      if (g.distance > delta) return;
      const Vec<D> x = (g.a + g.b) / 2;
      const Vec<D> normal = k_shaped ? g.normal : Vec<D>(-g.normal);  // from J towards K
      out.push_back({k, j, g.distance, rbar, direction(normal, dc / dist, 1), x - A.centre, x - B.centre});
      return;
    }
    detail::Nearest<D> n;  // a on K, b on J
    if (A.radius > 0) {
      n = detail::nearest_ball_facets<D>(A.centre, A.radius, B.surface);
    } else if (B.radius > 0) {
      n = detail::nearest_ball_facets<D>(B.centre, B.radius, A.surface);
      std::swap(n.a, n.b);
    } else {
      n = detail::nearest_facets<D>(A.surface, B.surface);
    }
    if (n.distance > delta) return;
    const Vec<D> x = (n.a + n.b) / 2;
    out.push_back({k, j, n.distance, rbar, direction(n.a - n.b, dc / dist, rbar), x - A.centre, x - B.centre});
  }

  /// The unit vector along v, or `fallback` if v is shorter than 1e-12 `scale` (nearest points
  /// that coincide or nearly: the direction would be round-off).
  static Vec<D> direction(const Vec<D>& v, const Vec<D>& fallback, Real scale) {
    const Real n = v.norm();
    return n > 1e-12 * scale ? Vec<D>(v / n) : fallback;
  }

  /// A disk/sphere or a convex shape as a GJK shape.
  static convex::Support<D> shape(const CollisionBody<D>& b) {
    if (b.convex) return b.convex;
    return {[c = b.centre](const Vec<D>&) { return c; }, b.radius};
  }

  void wall(const CollisionBody<D>& b, int k, Real delta, std::vector<Proximity<D>>& out) const {
    // the wall facets within reach: from the grid, or all of them for an infinite reach
    std::vector<Index> cand;
    if (!std::isfinite(delta)) {
      cand.resize(walls_.size());
      std::iota(cand.begin(), cand.end(), Index(0));
    } else {
      const Vec<D> r = Vec<D>::Constant(b.r_out + delta);
      const Vec<D> qlo = (b.centre - r).cwiseMax(lo_), qhi = (b.centre + r).cwiseMin(hi_);  // only cells that hold walls
      if ((qlo.array() > qhi.array()).any()) return;
      for_each_in_box(detail::key_of<D>(qlo, wall_cell_), detail::key_of<D>(qhi, wall_cell_),
                           [&](const detail::CellKey<D>& key) {
                             const auto it = grid_.find(key);
                             if (it != grid_.end()) cand.insert(cand.end(), it->second.begin(), it->second.end());
                           });
      std::sort(cand.begin(), cand.end());
      cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
    }
    Real best = std::numeric_limits<Real>::infinity();
    Vec<D> best_point = b.centre, body_point = b.centre;
    if (b.convex) {
      std::vector<const Facet<D>*> facets;
      for (Index w : cand) facets.push_back(&walls_[w]);
      const auto g = nearest_to_facets(b, facets);
      if (g.distance > delta) return;
      const Vec<D> c = b.centre - g.b;
      const Vec<D> x = (g.a + g.b) / 2;
      out.push_back({k, -1, g.distance, b.r_in, direction(g.normal, c.norm() > 0 ? Vec<D>(c.normalized()) : g.normal, 1),
                     x - b.centre});
      return;
    }
    if (b.radius > 0) {
      for (Index w : cand) {
        const Vec<D> p = detail::closest_on_facet(b.centre, walls_[w]);
        const Real gap = (b.centre - p).norm() - b.radius;
        if (gap < best) best = gap, best_point = p;
      }
    } else {
      // the facets in order of a lower bound on their distance (centre's minus r_out)
      std::vector<std::pair<Real, Index>> order;
      order.reserve(cand.size());
      for (Index w : cand) order.push_back({(b.centre - detail::closest_on_facet(b.centre, walls_[w])).norm() - b.r_out, w});
      std::sort(order.begin(), order.end());
      for (const auto& [bound, w] : order) {
        if (bound >= best) break;
        const auto n = detail::nearest_facets<D>(b.surface, {walls_[w]});
        if (n.distance < best) best = n.distance, best_point = n.b, body_point = n.a;
      }
    }
    if (best > delta) return;
    const Vec<D> n = b.centre - best_point;
    const Real nn = n.norm();
    if (nn == 0) return;
    if (b.radius > 0) {
      out.push_back({k, -1, best, b.r_in, n / nn});
    } else {
      const Vec<D> x = (body_point + best_point) / 2;
      out.push_back({k, -1, best, b.r_in, direction(body_point - best_point, n / nn, b.r_in), x - b.centre});
    }
  }

  /// The nearest of `facets` to body b's convex shape (GJK; a on the shape, b on the facet,
  /// the normal from the facet towards the shape), the facets taken in order of a lower bound on
  /// their distance until it exceeds the best found. The bound: with p the facet's point nearest
  /// b's centre c and u = (p - c) / |p - c|, the facet lies in u.(y - c) >= |p - c| and the shape
  /// in u.(x - c) <= h(u), its support value, so their distance is at least |p - c| - h(u).
  static convex::Distance<D> nearest_to_facets(const CollisionBody<D>& b, const std::vector<const Facet<D>*>& facets) {
    const convex::Support<D> s = shape(b);
    std::vector<std::pair<Real, const Facet<D>*>> order;
    order.reserve(facets.size());
    for (const Facet<D>* f : facets) {
      const Vec<D> pc = detail::closest_on_facet(b.centre, *f) - b.centre;
      const Real r = pc.norm();
      const Real bound = r > 0 ? r - (pc / r).dot(s.support(Vec<D>(pc / r)) - b.centre) - s.margin()
                               : -std::numeric_limits<Real>::infinity();
      order.push_back({bound, f});
    }
    std::sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    convex::Distance<D> best;
    for (const auto& [bound, f] : order) {
      if (bound >= best.distance) break;
      const auto g = convex::distance<D>(s, detail::FacetShape<D>{f});
      if (g.distance < best.distance) best = g;
    }
    return best;
  }

  std::vector<Facet<D>> walls_;
  Real wall_cell_ = 1;
  Vec<D> lo_ = Vec<D>::Zero(), hi_ = Vec<D>::Zero();  // bounding box of the walls
  std::unordered_map<detail::CellKey<D>, std::vector<Index>, detail::CellKeyHash<D>> grid_;
};

/// The collision model: the geometry's contacts within reach, and eq. (24) + spring on them.
template <int D>
class CollisionModel {
 public:
  explicit CollisionModel(CollisionOptions opt = {}) : opt_(opt) { opt_.validate(); }

  const CollisionOptions& options() const { return opt_; }
  void set_walls(std::vector<Facet<D>> walls, Real cell = 0) { geometry_.set_walls(std::move(walls), cell); }
  const std::vector<Facet<D>>& walls() const { return geometry_.walls(); }
  const ContactGeometry<D>& geometry() const { return geometry_; }

  /// Active contacts (gap <= max(delta, rho)) among `bodies` and against the walls, with
  /// viscosity mu.
  std::vector<Contact<D>> contacts(const std::vector<CollisionBody<D>>& bodies, Real mu) const {
    std::vector<Contact<D>> out;
    for (const auto& p : geometry_.near(bodies, opt_.range, opt_.spring_range, opt_.walls)) out.push_back(make(p, mu));
    return out;
  }

  /// The force on body k of contact c (on body j it is the opposite).
  static Vec<D> force(const Contact<D>& c, const std::vector<CollisionBody<D>>& bodies) {
    const Vec<D> w = relative_velocity(c, bodies);
    const Real speed = c.law == CollisionLaw::paper ? w.norm() : w.dot(c.normal);
    return (c.coefficient * speed + c.spring) * c.normal;
  }
  /// d F_k / d V^k (D x D); d F_k / d V^j = -(d F_k / d V^k); at |V^J - V^K| = 0 the
  /// derivative of the norm is taken as 0.
  static Mat<D> dforce_dvk(const Contact<D>& c, const std::vector<CollisionBody<D>>& bodies) {
    if (c.law == CollisionLaw::lubrication) return -c.coefficient * c.normal * c.normal.transpose();
    const Vec<D> w = relative_velocity(c, bodies);
    const Real n = w.norm();
    if (n == 0) return Mat<D>::Zero();
    return -c.coefficient * c.normal * (w / n).transpose();
  }

 private:
  static Vec<D> relative_velocity(const Contact<D>& c, const std::vector<CollisionBody<D>>& bodies) {
    const Vec<D> vj = c.j >= 0 ? bodies[c.j].velocity : Vec<D>(Vec<D>::Zero());
    return vj - bodies[c.k].velocity;
  }

  Contact<D> make(const Proximity<D>& p, Real mu) const {
    const Real delta = opt_.range * p.rbar;
    const Real d = std::max(p.gap, opt_.min_gap * delta);
    // 2D: a force per unit length, mu |V| times a number; 3D: times the length Rbar
    const Real scale = D == 3 ? mu * p.rbar : mu;
    Contact<D> c{p.k,    p.j, p.gap, p.gap <= delta ? scale * std::pow(4 * p.rbar / d, 1.5) : 0.0, 0.0, p.normal,
                 p.arm_k, p.arm_j, opt_.law};
    if (p.gap < opt_.spring_range) {
      const Real s = 1 - std::max(p.gap, Real(0)) / opt_.spring_range;
      c.spring = opt_.spring_force * s * s;
    }
    return c;
  }

  CollisionOptions opt_;
  ContactGeometry<D> geometry_;
};
using CollisionModel2D = CollisionModel<2>;

}  // namespace alefsi
