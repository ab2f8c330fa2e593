#pragma once
/// \file physics/collision.hpp
/// Short-range collision forces between 2D rigid bodies, and between a body and a wall:
/// the paper's eq. (24) with the sign made repulsive (DESIGN.md: as printed, the force on K
/// points towards J).
///
/// For bodies K and J whose surfaces are a distance d apart, d <= delta:
///     F_K = mu (4 Rbar / d)^{3/2} |V^J - V^K| n_JK,     F_J = -F_K,
/// with n_JK = (X_g^K - X_g^J) / |X_g^K - X_g^J| the unit vector from J's centre to K's,
/// Rbar = min(Rbar^K, Rbar^J), Rbar^K the smallest distance from X_g^K to K's surface and
/// delta = `range` * Rbar (the paper's delta = Rbar / 10). A wall is a body J with V^J = 0 and
/// Rbar = Rbar^K; n points from the wall point nearest to the body towards X_g^K. The force
/// acts at the centre of mass (no torque). The gap entering the magnitude is floored at
/// `min_gap` * delta, so an overlap (d <= 0, which the force is there to prevent) gives a
/// large but finite force instead of a NaN.
///
/// Optional safeguard (off by default): the repulsive spring of Glowinski et al. (1999,
/// J. Comput. Phys. 169) used in most DKT studies, F_K += F_0 (1 - d / rho)^2 n_JK for
/// d < rho (`spring_range` = rho, `spring_force` = F_0, the force at contact). Eq. (24)
/// vanishes when the bodies stop approaching and is weak until d << delta (mu (4 Rbar /
/// d)^{3/2} |V|); with positions advanced explicitly by the schemes, a body can then cross
/// the last mesh layer in one step. The spring keeps a gap of the order of rho, so the cells
/// in the gap survive; take rho about the mesh size at the bodies.
///
/// Geometry: a body's surface is a set of segments (its boundary facets, moved with the
/// body); a disk (radius > 0) is treated exactly: d = |X^K - X^J| - r^K - r^J, and against a
/// wall, d = dist(X^K, wall) - r^K. Otherwise d is the smallest segment-to-segment distance.
///
/// Search: only pairs whose bounding circles (centre, farthest surface point + delta) overlap
/// are examined, found through a uniform grid of cell size = the largest bounding diameter:
/// O(N) for N bodies of comparable size, not O(N^2). Wall segments are bucketed once into a
/// grid (`WallGrid`), rebuilt when the mesh topology changes.
///
///     CollisionModel2D model({.range = 0.1});
///     model.set_walls(wall_segments);
///     auto contacts = model.contacts(bodies, mu);   // then force / jacobian per contact
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <unordered_map>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

struct CollisionOptions {
  Real range = 0.1;     ///< delta = range * Rbar (paper: 1/10); > 0
  bool walls = true;    ///< also between bodies and walls
  Real min_gap = 1e-3;  ///< the gap in the magnitude is floored at min_gap * delta; in (0, 1]
  Real spring_range = 0;  ///< rho of the safeguard spring (length); 0: no spring
  Real spring_force = 0;  ///< F_0: the spring's force at contact (d = 0)

  void validate() const {
    ALEFSI_CHECK_ARG(spring_range >= 0 && std::isfinite(spring_range), "collision.spring_range",
                     "must be >= 0 and finite, got ", spring_range);
    ALEFSI_CHECK_ARG(spring_force >= 0 && std::isfinite(spring_force), "collision.spring_force",
                     "must be >= 0 and finite, got ", spring_force);
    ALEFSI_CHECK_ARG(range > 0 && std::isfinite(range), "collision.range", "must be positive and finite, got ", range);
    ALEFSI_CHECK_ARG(min_gap > 0 && min_gap <= 1, "collision.min_gap", "must be in (0, 1], got ", min_gap);
  }
};

using Segment2D = std::array<Vec<2>, 2>;

/// A body as the collision model sees it, at the time level of the force.
struct CollisionBody2D {
  Vec<2> centre = Vec<2>::Zero();
  Vec<2> velocity = Vec<2>::Zero();  ///< translational velocity V
  Real radius = 0;                   ///< > 0: a disk of this radius (exact distances)
  Real r_in = 0;                     ///< Rbar: smallest distance from the centre to the surface
  Real r_out = 0;                    ///< largest distance from the centre to the surface
  std::vector<Segment2D> surface;    ///< used when radius == 0
};

/// One active contact: body k against body j (j = -1: a wall).
struct Contact2D {
  int k = -1, j = -1;
  Real gap = 0;                      ///< d (may be <= 0 for an overlap)
  Real coefficient = 0;              ///< mu (4 Rbar / max(d, min_gap delta))^{3/2}, 0 when d > delta
  Real spring = 0;                   ///< F_0 (1 - d / rho)^2 (d floored at 0), 0 when d >= rho
  Vec<2> normal = Vec<2>::Zero();    ///< unit, from J (or the wall point) towards X_g^K
};

namespace detail {

inline Vec<2> closest_on_segment(const Vec<2>& p, const Segment2D& s) {
  const Vec<2> e = s[1] - s[0];
  const Real l2 = e.squaredNorm();
  const Real t = l2 > 0 ? std::clamp((p - s[0]).dot(e) / l2, Real(0), Real(1)) : Real(0);
  return s[0] + t * e;
}

/// Closest points (on a, on b) of two segments; exact for non-crossing segments, and a
/// crossing pair (distance 0) is reported through the end-point tests as a tiny distance,
/// which is all the force needs (it is floored anyway).
inline std::pair<Vec<2>, Vec<2>> closest_segments(const Segment2D& a, const Segment2D& b) {
  std::pair<Vec<2>, Vec<2>> best;
  Real bd = std::numeric_limits<Real>::infinity();
  auto consider = [&](const Vec<2>& pa, const Vec<2>& pb) {
    const Real d = (pa - pb).squaredNorm();
    if (d < bd) bd = d, best = {pa, pb};
  };
  for (const Vec<2>& p : a) consider(p, closest_on_segment(p, b));
  for (const Vec<2>& p : b) consider(closest_on_segment(p, a), p);
  return best;
}

struct CellKey {
  std::int64_t i, j;
  bool operator==(const CellKey&) const = default;
};
struct CellKeyHash {
  std::size_t operator()(const CellKey& c) const {
    return std::hash<std::int64_t>()(c.i * 73856093LL ^ c.j * 19349663LL);
  }
};

}  // namespace detail

/// The collision model: search and eq. (24).
class CollisionModel2D {
 public:
  explicit CollisionModel2D(CollisionOptions opt = {}) : opt_(opt) { opt_.validate(); }

  const CollisionOptions& options() const { return opt_; }

  /// Wall segments (fixed in time); bucketed into a grid of cell size `cell` (default: the
  /// mean segment length times 4).
  void set_walls(std::vector<Segment2D> walls, Real cell = 0) {
    walls_ = std::move(walls);
    grid_.clear();
    if (walls_.empty()) return;
    if (cell <= 0) {
      Real s = 0;
      for (const auto& w : walls_) s += (w[1] - w[0]).norm();
      cell = 4 * s / Real(walls_.size());
    }
    wall_cell_ = cell > 0 ? cell : 1;
    lo_ = hi_ = walls_[0][0];
    for (const auto& w : walls_)
      for (const auto& x : w) lo_ = lo_.cwiseMin(x), hi_ = hi_.cwiseMax(x);
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const Vec<2> lo = walls_[w][0].cwiseMin(walls_[w][1]), hi = walls_[w][0].cwiseMax(walls_[w][1]);
      for_cells(lo, hi, wall_cell_, [&](detail::CellKey key) { grid_[key].push_back(Index(w)); });
    }
  }
  const std::vector<Segment2D>& walls() const { return walls_; }

  /// Active contacts (gap <= delta) among `bodies` and against the walls, with viscosity mu.
  std::vector<Contact2D> contacts(const std::vector<CollisionBody2D>& bodies, Real mu) const {
    std::vector<Contact2D> out;
    if (bodies.empty()) return out;
    Real reach = 0;
    for (const auto& b : bodies) reach = std::max(reach, b.r_out + this->reach(b.r_in));
    const Real cell = std::max(2 * reach, std::numeric_limits<Real>::min());
    // body pairs: each body in the cell of its centre; neighbours in the 3 x 3 block
    std::unordered_map<detail::CellKey, std::vector<int>, detail::CellKeyHash> cells;
    for (std::size_t k = 0; k < bodies.size(); ++k) cells[key_of(bodies[k].centre, cell)].push_back(int(k));
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      const auto c = key_of(bodies[k].centre, cell);
      for (std::int64_t di = -1; di <= 1; ++di)
        for (std::int64_t dj = -1; dj <= 1; ++dj) {
          const auto it = cells.find({c.i + di, c.j + dj});
          if (it == cells.end()) continue;
          for (int j : it->second)
            if (j > int(k)) pair_contact(bodies, int(k), j, mu, out);
        }
    }
    if (opt_.walls && !walls_.empty())
      for (std::size_t k = 0; k < bodies.size(); ++k) wall_contacts(bodies[k], int(k), mu, out);
    return out;
  }

  /// The force on body k of contact c (on body j it is the opposite).
  static Vec<2> force(const Contact2D& c, const std::vector<CollisionBody2D>& bodies) {
    return (c.coefficient * relative_velocity(c, bodies).norm() + c.spring) * c.normal;
  }
  /// d F_k / d V^k (2 x 2); d F_k / d V^j = -(d F_k / d V^k); at |V^J - V^K| = 0 the
  /// derivative of the norm is taken as 0.
  static Eigen::Matrix<Real, 2, 2> dforce_dvk(const Contact2D& c, const std::vector<CollisionBody2D>& bodies) {
    const Vec<2> w = relative_velocity(c, bodies);
    const Real n = w.norm();
    if (n == 0) return Eigen::Matrix<Real, 2, 2>::Zero();
    return -c.coefficient * c.normal * (w / n).transpose();
  }

 private:
  static Vec<2> relative_velocity(const Contact2D& c, const std::vector<CollisionBody2D>& bodies) {
    const Vec<2> vj = c.j >= 0 ? bodies[c.j].velocity : Vec<2>(Vec<2>::Zero());
    return vj - bodies[c.k].velocity;
  }
  static detail::CellKey key_of(const Vec<2>& x, Real cell) {
    return {std::int64_t(std::floor(x[0] / cell)), std::int64_t(std::floor(x[1] / cell))};
  }
  template <class F>
  static void for_cells(const Vec<2>& lo, const Vec<2>& hi, Real cell, F&& f) {
    const auto a = key_of(lo, cell), b = key_of(hi, cell);
    for (std::int64_t i = a.i; i <= b.i; ++i)
      for (std::int64_t j = a.j; j <= b.j; ++j) f(detail::CellKey{i, j});
  }

  Real reach(Real rbar) const { return std::max(opt_.range * rbar, opt_.spring_range); }
  Contact2D make(int k, int j, Real gap, Real rbar, const Vec<2>& normal, Real mu) const {
    const Real delta = opt_.range * rbar;
    const Real d = std::max(gap, opt_.min_gap * delta);
    Contact2D c{k, j, gap, gap <= delta ? mu * std::pow(4 * rbar / d, 1.5) : 0.0, 0.0, normal};
    if (gap < opt_.spring_range) {
      const Real s = 1 - std::max(gap, Real(0)) / opt_.spring_range;
      c.spring = opt_.spring_force * s * s;
    }
    return c;
  }

  void pair_contact(const std::vector<CollisionBody2D>& bodies, int k, int j, Real mu, std::vector<Contact2D>& out) const {
    const auto &A = bodies[k], &B = bodies[j];
    const Real rbar = std::min(A.r_in, B.r_in);
    const Real delta = reach(rbar);
    const Vec<2> dc = A.centre - B.centre;
    const Real dist = dc.norm();
    if (dist - A.r_out - B.r_out > delta) return;
    Real gap;
    if (A.radius > 0 && B.radius > 0) {
      gap = dist - A.radius - B.radius;
    } else {
      gap = std::numeric_limits<Real>::infinity();
      for (const auto& sa : A.surface)
        for (const auto& sb : B.surface) {
          const auto [pa, pb] = detail::closest_segments(sa, sb);
          gap = std::min(gap, (pa - pb).norm());
        }
    }
    if (gap > delta || dist == 0) return;
    out.push_back(make(k, j, gap, rbar, dc / dist, mu));
  }

  void wall_contacts(const CollisionBody2D& b, int k, Real mu, std::vector<Contact2D>& out) const {
    const Real delta = reach(b.r_in);
    const Vec<2> r = Vec<2>::Constant(b.r_out + delta);
    std::vector<char> seen(walls_.size(), 0);
    Real best = std::numeric_limits<Real>::infinity();
    Vec<2> best_point = b.centre;
    const Vec<2> qlo = (b.centre - r).cwiseMax(lo_), qhi = (b.centre + r).cwiseMin(hi_);  // only cells that hold walls
    if ((qlo.array() > qhi.array()).any()) return;
    for_cells(qlo, qhi, wall_cell_, [&](detail::CellKey key) {
      const auto it = grid_.find(key);
      if (it == grid_.end()) return;
      for (Index w : it->second) {
        if (seen[w]) continue;
        seen[w] = 1;
        if (b.radius > 0) {
          const Vec<2> p = detail::closest_on_segment(b.centre, walls_[w]);
          const Real gap = (b.centre - p).norm() - b.radius;
          if (gap < best) best = gap, best_point = p;
        } else {
          for (const auto& s : b.surface) {
            const auto [pb, pw] = detail::closest_segments(s, walls_[w]);
            const Real gap = (pb - pw).norm();
            if (gap < best) best = gap, best_point = pw;
          }
        }
      }
    });
    if (best > delta) return;
    const Vec<2> n = b.centre - best_point;
    const Real nn = n.norm();
    if (nn == 0) return;
    out.push_back(make(k, -1, best, b.r_in, n / nn, mu));
  }

  CollisionOptions opt_;
  std::vector<Segment2D> walls_;
  Real wall_cell_ = 1;
  Vec<2> lo_ = Vec<2>::Zero(), hi_ = Vec<2>::Zero();  // bounding box of the walls
  std::unordered_map<detail::CellKey, std::vector<Index>, detail::CellKeyHash> grid_;
};

}  // namespace alefsi
