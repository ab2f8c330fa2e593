#pragma once
/// \file mesh/adapt/adapt2d.hpp
/// Quality-preserving adaptation of a moved (ALE) 2D triangle mesh: the paper's Algorithm 1
/// (split long edges, collapse short ones) followed by Delaunay edge flips and
/// quality-checked smoothing, with boundary nodes kept on their curves.
///
/// Algorithm (`adapt`), repeated until no split or collapse happens (at most `max_passes`):
///  1. Splits. For every edge, L = its length and E = its target: h(edge midpoint) from
///     `AdaptOptions::size`, or, without a size function, the paper's comparative value
///     (mean of the two end points' "node sizes", the mean length of the edges at each node
///     of the input mesh, carried to new nodes by averaging). Edges with (L - E) / E > T
///     are split at their midpoint, longest (relative) first; repeated until none is left.
///     A boundary edge on a curve is split at the projection of its midpoint on the curve
///     (on a circle: the arc midpoint; on an ellipse: along the ray from its centre), and
///     both halves keep the edge's tag.
///  2. Collapses. Edges with (L - E) / E < -T, shortest (relative) first, are collapsed onto
///     one end point (the other one is removed; the paper keeps an end point too). Refused
///     unless: the removed node is free (not a corner, see below), a boundary node is
///     removed only along a boundary edge of its own curve, the link condition holds (the
///     nodes adjacent to both ends are exactly the apexes of the edge's cells: no fold, no
///     pinched boundary), every changed cell keeps a positive orientation, the worst
///     quality of the changed cells is >= min(worst before, min_quality), and no new edge
///     would be split at once ((L - E) / E <= T). Both directions are tried; the better
///     worst quality wins.
///  3. Flips to the (constrained) Delaunay triangulation of the nodes: an interior edge
///     whose opposite angles sum to more than pi is flipped (never a boundary edge nor an
///     edge between cells of different region tags); this maximises the smallest angle
///     for the given nodes.
///  4. Smoothing (`smoothing_sweeps` sweeps): each free node is tried at the mean of its
///     neighbours (Laplacian; a boundary node at the projection on its curve of the mean
///     of its two boundary neighbours), at the mean of the "ideal points" (apex of the
///     equilateral triangle on each opposite edge) and half-way to both; the candidate
///     with the best worst quality of the node's cells is kept only if that strictly
///     improves and no edge of the node leaves the size band (or gets further out of it).
///     Then flips again.
///  5. Repair: each cell of quality below `min_quality`, worst first, gets its shortest
///     edge collapsed, or else its longest edge split, if that strictly improves the worst
///     quality of the cells involved (same validity and size rules as above); then flips
///     and smoothing once more.
///
/// Boundary: `curves` describe the walls and bodies *at their current position* (circles
/// whose centre moved with the body: pass the moved circles). A boundary node is on curve
/// C if the tag of its boundary facets is C's tag (Circle::tag, Polyline::tag or segment
/// tag; several curves with one tag: the nearest). Corners: a boundary node where the tag
/// changes, a node at a polyline vertex, and any node on a boundary tag no curve describes
/// are fixed (never moved nor removed); a node whose cells carry different region tags is
/// fixed too. New boundary facets inherit the tag of the facet they come from.
///
/// Guarantees: the result is a valid Mesh<2> (no inverted or degenerate cell: every
/// operation that would create one is refused); nodes on curves stay on them (input
/// nodes are not projected; new and moved ones are); the region covered changes only by
/// the difference between a curve and its chords (straight walls: area conserved to
/// round-off). Deterministic: no randomness, hashing or threads; the same input gives
/// the same mesh. Surviving nodes keep their relative order, new ones are appended.
///
/// Cost: one pass is O(n log n) (sorting the candidate edges; the operations themselves
/// are O(1) each, node balls being of bounded size); passes stop when a pass neither
/// splits nor collapses (1-3 on the test scenes). Measured (bench/bench_adapt.cpp, one
/// step of the annulus stress test, -O3): about 1.2 microseconds per triangle, linear
/// from 1e3 to 1e5 triangles.
///
/// Quality measured on the stress tests (tests/mesh/test_adapt.cpp, every step): smallest
/// angle >= 22 degrees, worst quality >= 0.60, edge length / h in [0.25, 1.7].
///
///     alefsi::AdaptOptions opt;  opt.size = alefsi::graded_size(disks_now, 0.02, 0.2);
///     alefsi::AdaptReport rep;
///     alefsi::Mesh<2> m2 = alefsi::adapt(moved, {outer_wall, disk_now}, opt, &rep);
#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>
#include <variant>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

/// A tagged boundary curve: a Circle (a body or a circular wall), an Ellipse (a body) or a
/// closed Polyline (walls), the types of mesher2d.hpp. Nodes slide along circles and
/// ellipses by radial projection.
using BoundaryCurve = Boundary2D;

struct AdaptOptions {
  /// Target edge length h(x). Empty: the paper's comparative value (mean length of the
  /// edges at the end points, measured on the input mesh).
  SizeFunction size = {};
  Real tolerance = 0.7;        ///< T: split if (L - E) / E > T, collapse if < -T; in (0, 10]
  Real min_quality = 0.6;      ///< cells below are repaired; collapses keep above it; in [0, 1)
  int smoothing_sweeps = 3;    ///< >= 0
  int max_passes = 6;          ///< split / collapse / flip / smooth rounds, >= 1
};

/// What `adapt` did.
struct AdaptReport {
  int splits = 0, collapses = 0, flips = 0, smoothed = 0;  ///< operations performed
  int refused = 0;            ///< candidate splits / collapses refused (validity, quality, topology)
  int passes = 0;
  Real min_angle_deg = 0;     ///< of the result
  Real worst_quality = 0;     ///< of the result (Mesh::quality)
  bool changed = false;       ///< any node moved, added or removed, or any flip
};

namespace detail {

inline Real tri_quality(const Vec<2>& a, const Vec<2>& b, const Vec<2>& c) {
  const Vec<2> u = b - a, v = c - a, w = c - b;
  const Real area = 0.5 * (u[0] * v[1] - u[1] * v[0]);
  const Real l2 = u.squaredNorm() + v.squaredNorm() + w.squaredNorm();
  return l2 > 0 ? 4.0 * std::sqrt(3.0) * area / l2 : 0.0;
}

/// Cells of quality below this are refused outright (area > 1e-7 h^2, far from the
/// degeneracy test of Mesh).
inline constexpr Real adapt_degenerate_quality = 1e-6;

/// Mutable triangle mesh with node balls and the boundary as doubly linked loops.
class AdaptMesh2D {
 public:
  enum Kind : char { interior = 0, slide = 1, fixed = 2 };

  AdaptMesh2D(const Mesh<2>& m, const std::vector<BoundaryCurve>& curves, const AdaptOptions& opt)
      : curves_(curves), opt_(opt) {
    const Index nn = m.n_nodes();
    X_ = m.coordinates();
    alive_.assign(nn, 1);
    kind_.assign(nn, interior);
    curve_.assign(nn, -1);
    bnext_.assign(nn, -1);
    bprev_.assign(nn, -1);
    btag_.assign(nn, 0);
    T_ = m.cells();
    ttag_ = m.cell_tags();
    talive_.assign(T_.size(), 1);
    ball_.assign(nn, {});
    for (Index t = 0; t < Index(T_.size()); ++t)
      for (Index v : T_[t]) ball_[v].push_back(t);
    // boundary loops: facet opposite local vertex i runs v[i+1] -> v[i+2] with the cell on its left
    for (Index f : m.boundary_facets()) {
      const Index c = m.facet_cells(f)[0];
      int i = 0;
      while (m.cell_facets(c)[i] != f) ++i;
      const Index a = m.cell(c)[(i + 1) % 3], b = m.cell(c)[(i + 2) % 3];
      ALEFSI_CHECK_ARG(bnext_[a] < 0 && bprev_[b] < 0, "moved",
                       "boundary node ", bnext_[a] >= 0 ? a : b, " is on two boundary loops (pinched boundary)");
      bnext_[a] = b, bprev_[b] = a, btag_[a] = m.facet_tag(f);
    }
    // node sizes for the paper's comparative value
    if (!opt_.size) {
      hnode_.assign(nn, 0.0);
      std::vector<int> cnt(nn, 0);
      for (Index e = 0; e < m.n_edges(); ++e) {
        const Real l = m.edge_length(e);
        for (Index v : m.edge(e)) hnode_[v] += l, ++cnt[v];
      }
      for (Index v = 0; v < nn; ++v) hnode_[v] /= cnt[v];
    }
    for (Index v = 0; v < nn; ++v) classify(v);
  }

  // ---- geometry helpers -----------------------------------------------------------------
  Real quality(Index t) const { return tri_quality(X_[T_[t][0]], X_[T_[t][1]], X_[T_[t][2]]); }
  Real target(Index a, Index b) const {
    if (opt_.size) {
      const Vec<2> mid = 0.5 * (X_[a] + X_[b]);
      const Real h = opt_.size(mid);
      if (!(h > 0) || !std::isfinite(h))
        throw InvalidArgument("size", concat("must be positive and finite, got ", h, " at (", mid[0], ", ", mid[1], ")"));
      return h;
    }
    return 0.5 * (hnode_[a] + hnode_[b]);
  }
  Real ratio(Index a, Index b) const { return ((X_[b] - X_[a]).norm() - target(a, b)) / target(a, b); }

  /// Index of the curve carrying `tag` nearest to p, or -1.
  int find_curve(int tag, const Vec<2>& p) const {
    int best = -1;
    Real bd = std::numeric_limits<Real>::infinity();
    for (int i = 0; i < int(curves_.size()); ++i) {
      Real d = std::numeric_limits<Real>::infinity();
      if (const Circle* c = std::get_if<Circle>(&curves_[i])) {
        if (c->tag == tag) d = std::abs((p - c->centre).norm() - c->radius);
      } else if (const Ellipse* e = std::get_if<Ellipse>(&curves_[i])) {
        if (e->tag == tag) d = (e->radial_projection(p) - p).norm();
      } else {
        const Polyline& P = std::get<Polyline>(curves_[i]);
        for (std::size_t s = 0; s < P.points.size(); ++s)
          if (segment_tag(P, s) == tag) d = std::min(d, (project_segment(P, s, p) - p).norm());
      }
      if (d < bd) bd = d, best = i;
    }
    return best;
  }
  Vec<2> project(int curve, int tag, const Vec<2>& p) const {
    if (const Circle* c = std::get_if<Circle>(&curves_[curve])) {
      const Vec<2> d = p - c->centre;
      const Real n = d.norm();
      return n > 0 ? Vec<2>(c->centre + c->radius / n * d) : p;
    }
    if (const Ellipse* e = std::get_if<Ellipse>(&curves_[curve]))
      return p != e->centre ? e->radial_projection(p) : p;
    const Polyline& P = std::get<Polyline>(curves_[curve]);
    Vec<2> best = p;
    Real bd = std::numeric_limits<Real>::infinity();
    for (std::size_t s = 0; s < P.points.size(); ++s) {
      if (segment_tag(P, s) != tag) continue;
      const Vec<2> q = project_segment(P, s, p);
      if ((q - p).norm() < bd) bd = (q - p).norm(), best = q;
    }
    return best;
  }

  // ---- topology helpers -----------------------------------------------------------------
  static bool has(const std::array<Index, 3>& t, Index v) { return t[0] == v || t[1] == v || t[2] == v; }
  bool boundary_edge(Index a, Index b) const { return bnext_[a] == b || bnext_[b] == a; }
  /// Cells containing both a and b (1 or 2 for an edge, 0 if no such edge).
  int shared(Index a, Index b, std::array<Index, 2>& out) const {
    int n = 0;
    for (Index t : ball_[a])
      if (has(T_[t], b) && n < 2) out[n++] = t;
    return n;
  }
  void ball_remove(Index v, Index t) {
    auto& B = ball_[v];
    B.erase(std::find(B.begin(), B.end(), t));
  }
  /// Unique edges (a < b) of the current mesh, in node order.
  std::vector<std::array<Index, 2>> edges() {
    std::vector<std::array<Index, 2>> out;
    stamp_.resize(X_.size(), -1);
    for (Index a = 0; a < Index(X_.size()); ++a) {
      if (!alive_[a]) continue;
      for (Index t : ball_[a])
        for (Index b : T_[t])
          if (b > a && stamp_[b] != a) stamp_[b] = a, out.push_back({a, b});
    }
    std::fill(stamp_.begin(), stamp_.end(), -1);
    return out;
  }

  // ---- operations ------------------------------------------------------------------------
  int split_pass(int& refused) {
    std::vector<std::tuple<Real, Index, Index>> cand;
    for (const auto& [a, b] : edges()) {
      const Real r = ratio(a, b);
      if (r > opt_.tolerance) cand.emplace_back(-r, a, b);
    }
    std::sort(cand.begin(), cand.end());
    int n = 0;
    for (const auto& [r, a, b] : cand) {
      if (split(a, b)) ++n;
      else ++refused;
    }
    return n;
  }

  /// Splits edge {a, b}; refused if a child would be degenerate or (require_q >= 0) of
  /// quality <= require_q.
  bool split(Index a, Index b, Real require_q = -1) {
    std::array<Index, 2> ts;
    const int ns = shared(a, b, ts);
    if (ns == 0) return false;
    Vec<2> m = 0.5 * (X_[a] + X_[b]);
    const bool bnd = boundary_edge(a, b);
    int curve = -1, tag = 0;
    if (bnd) {
      tag = bnext_[a] == b ? btag_[a] : btag_[b];
      curve = kind_[a] == slide ? curve_[a] : kind_[b] == slide ? curve_[b] : find_curve(tag, m);
      if (curve >= 0) m = project(curve, tag, m);
    }
    // children: in cell t, the edge {a, b} is (t[i], t[i+1]); child 1 replaces t[i+1] by m,
    // child 2 replaces t[i] by m (orientation kept)
    std::array<std::array<Index, 3>, 4> kids;
    const Index mi = Index(X_.size());
    for (int k = 0; k < ns; ++k) {
      const auto& t = T_[ts[k]];
      int i = 0;
      while (!((t[i] == a && t[(i + 1) % 3] == b) || (t[i] == b && t[(i + 1) % 3] == a))) ++i;
      kids[2 * k] = t, kids[2 * k][(i + 1) % 3] = mi;
      kids[2 * k + 1] = t, kids[2 * k + 1][i] = mi;
      for (int j = 0; j < 2; ++j) {
        const auto& c = kids[2 * k + j];
        auto P = [&](Index v) -> const Vec<2>& { return v == mi ? m : X_[v]; };
        const Real q = tri_quality(P(c[0]), P(c[1]), P(c[2]));
        if (!(q > adapt_degenerate_quality) || (require_q >= 0 && !(q > require_q))) return false;
      }
    }
    // commit
    X_.push_back(m);
    alive_.push_back(1);
    kind_.push_back(interior);
    curve_.push_back(-1);
    bnext_.push_back(-1), bprev_.push_back(-1), btag_.push_back(0);
    ball_.emplace_back();
    if (!hnode_.empty()) hnode_.push_back(0.5 * (hnode_[a] + hnode_[b]));
    for (int k = 0; k < ns; ++k) {
      const Index t = ts[k];
      const Index t2 = Index(T_.size());
      T_[t] = kids[2 * k];
      T_.push_back(kids[2 * k + 1]);
      ttag_.push_back(ttag_[t]);
      talive_.push_back(1);
      // the vertex of t not in child 1 is b or a: it leaves t, enters t2
      const Index gone = has(T_[t], a) ? b : a;
      ball_remove(gone, t);
      for (Index v : T_[t2])  // `gone` and the apex
        if (v != mi) ball_[v].push_back(t2);
      ball_[mi].push_back(t), ball_[mi].push_back(t2);
    }
    if (bnd) {
      const Index from = bnext_[a] == b ? a : b, to = from == a ? b : a;
      bnext_[from] = mi, bprev_[mi] = from, bnext_[mi] = to, bprev_[to] = mi, btag_[mi] = btag_[from];
      if (curve >= 0) kind_[mi] = slide, curve_[mi] = curve;
      else kind_[mi] = fixed;
    } else if (ns == 2 && ttag_[ts[0]] != ttag_[ts[1]]) {
      kind_[mi] = fixed;
    }
    return true;
  }

  int collapse_pass(int& refused) {
    std::vector<std::tuple<Real, Index, Index>> cand;
    for (const auto& [a, b] : edges()) {
      const Real r = ratio(a, b);
      if (r < -opt_.tolerance) cand.emplace_back(r, a, b);
    }
    std::sort(cand.begin(), cand.end());
    int n = 0;
    for (const auto& [r, a, b] : cand) {
      if (!alive_[a] || !alive_[b]) continue;
      std::array<Index, 2> ts;
      if (shared(a, b, ts) == 0) continue;
      const Real qa = collapse_quality(b, a), qb = collapse_quality(a, b);
      if (qa < 0 && qb < 0) {
        ++refused;
        continue;
      }
      if (qa >= qb) collapse(b, a);
      else collapse(a, b);
      ++n;
    }
    return n;
  }

  /// Worst quality after removing `rm` onto `keep`, or -1 if the collapse is not allowed.
  /// `strict`: the worst quality must improve (repair), not only stay above min_quality.
  Real collapse_quality(Index rm, Index keep, bool strict = false) {
    if (kind_[rm] == fixed) return -1;
    if (kind_[rm] == slide && !boundary_edge(rm, keep)) return -1;
    std::array<Index, 2> ts;
    const int ns = shared(rm, keep, ts);
    // link condition
    stamp_.resize(X_.size(), -1);
    for (Index t : ball_[keep])
      for (Index v : T_[t]) stamp_[v] = keep;
    int common = 0;
    for (Index t : ball_[rm])
      for (Index v : T_[t])
        if (v != rm && v != keep && stamp_[v] == keep) stamp_[v] = -2, ++common;
    for (Index t : ball_[keep])
      for (Index v : T_[t]) stamp_[v] = -1;
    for (Index t : ball_[rm])
      for (Index v : T_[t]) stamp_[v] = -1;
    if (common != ns) return -1;
    // geometry and quality of the cells that change
    Real old_q = std::numeric_limits<Real>::infinity(), new_q = std::numeric_limits<Real>::infinity();
    for (Index t : ball_[rm]) {
      old_q = std::min(old_q, quality(t));
      if (has(T_[t], keep)) continue;
      std::array<Index, 3> c = T_[t];
      for (Index& v : c)
        if (v == rm) v = keep;
      const Real q = tri_quality(X_[c[0]], X_[c[1]], X_[c[2]]);
      if (!(q > adapt_degenerate_quality)) return -1;
      new_q = std::min(new_q, q);
      for (Index v : c)
        if (v != keep && ratio(keep, v) > opt_.tolerance) return -1;
    }
    if (strict ? !(new_q > old_q + 1e-9) : new_q < std::min(old_q, opt_.min_quality)) return -1;
    return new_q == std::numeric_limits<Real>::infinity() ? 1.0 : new_q;
  }

  void collapse(Index rm, Index keep) {
    const std::vector<Index> B = ball_[rm];
    for (Index t : B) {
      if (has(T_[t], keep)) {
        talive_[t] = 0;
        for (Index v : T_[t])
          if (v != rm) ball_remove(v, t);
      } else {
        for (Index& v : T_[t])
          if (v == rm) v = keep;
        ball_[keep].push_back(t);
      }
    }
    ball_[rm].clear();
    alive_[rm] = 0;
    if (bnext_[rm] == keep) {
      bnext_[bprev_[rm]] = keep, bprev_[keep] = bprev_[rm];
    } else if (bprev_[rm] == keep) {
      bnext_[keep] = bnext_[rm], bprev_[bnext_[rm]] = keep;
    }
    bnext_[rm] = bprev_[rm] = -1;
  }

  /// Quality repair: each cell of quality below min_quality (worst first) gets its
  /// shortest edge collapsed, or else its longest edge split, if that strictly improves
  /// the worst quality of the cells involved and respects the size band. Returns the
  /// number of operations (collapses added to `collapses`, splits to `splits`).
  void repair_pass(int& splits, int& collapses) {
    std::vector<std::pair<Real, Index>> bad;
    for (Index t = 0; t < Index(T_.size()); ++t)
      if (talive_[t] && quality(t) < opt_.min_quality) bad.emplace_back(quality(t), t);
    std::sort(bad.begin(), bad.end());
    for (const auto& [q0, t] : bad) {
      if (!talive_[t]) continue;
      const Real q = quality(t);
      if (q >= opt_.min_quality) continue;
      std::array<std::pair<Real, int>, 3> len;
      for (int i = 0; i < 3; ++i) len[i] = {(X_[T_[t][(i + 1) % 3]] - X_[T_[t][i]]).squaredNorm(), i};
      std::sort(len.begin(), len.end());
      {
        const Index a = T_[t][len[0].second], b = T_[t][(len[0].second + 1) % 3];
        const Real qa = collapse_quality(b, a, true), qb = collapse_quality(a, b, true);
        if (qa >= 0 || qb >= 0) {
          if (qa >= qb) collapse(b, a);
          else collapse(a, b);
          ++collapses;
          continue;
        }
      }
      const Index a = T_[t][len[2].second], b = T_[t][(len[2].second + 1) % 3];
      if (0.5 * std::sqrt(len[2].first) < (1 - opt_.tolerance) * target(a, b)) continue;
      std::array<Index, 2> ts;
      const int ns = shared(a, b, ts);
      Real worst = q;
      for (int k = 0; k < ns; ++k) worst = std::min(worst, quality(ts[k]));
      if (split(a, b, worst + 1e-9)) ++splits;
    }
  }

  /// Delaunay flips until none applies; returns the number of flips.
  int flip_all() {
    std::deque<std::array<Index, 2>> queue;
    for (const auto& e : edges()) queue.push_back(e);
    const long cap = 8 * long(queue.size()) + 100;
    int n = 0;
    while (!queue.empty() && n < cap) {
      const auto [a, b] = queue.front();
      queue.pop_front();
      if (!alive_[a] || !alive_[b] || boundary_edge(a, b)) continue;
      std::array<Index, 2> ts;
      if (shared(a, b, ts) != 2 || ttag_[ts[0]] != ttag_[ts[1]]) continue;
      // t1 = (a, b, c) counter-clockwise, t2 = (b, a, d)
      Index t1 = ts[0], t2 = ts[1];
      auto next_of = [&](Index t, Index v) {
        for (int i = 0; i < 3; ++i)
          if (T_[t][i] == v) return T_[t][(i + 1) % 3];
        return Index(-1);
      };
      if (next_of(t1, a) != b) std::swap(t1, t2);
      const Index c = next_of(t1, b), d = next_of(t2, a);
      if (c == d) continue;
      auto angle = [&](Index p, Index q, Index r) {  // angle at p
        const Vec<2> u = X_[q] - X_[p], v = X_[r] - X_[p];
        return std::atan2(std::abs(u[0] * v[1] - u[1] * v[0]), u.dot(v));
      };
      if (!(angle(c, a, b) + angle(d, a, b) > std::numbers::pi * (1 + 1e-12))) continue;
      const std::array<Index, 3> n1{a, d, c}, n2{d, b, c};
      const Real q1 = tri_quality(X_[a], X_[d], X_[c]), q2 = tri_quality(X_[d], X_[b], X_[c]);
      if (!(q1 > adapt_degenerate_quality && q2 > adapt_degenerate_quality)) continue;
      // c and d must not already be joined (would duplicate an edge)
      std::array<Index, 2> tmp;
      if (shared(c, d, tmp) > 0) continue;
      T_[t1] = n1, T_[t2] = n2;
      ball_remove(a, t2), ball_remove(b, t1);
      ball_[c].push_back(t2), ball_[d].push_back(t1);
      ++n;
      queue.push_back({std::min(a, c), std::max(a, c)});
      queue.push_back({std::min(c, b), std::max(c, b)});
      queue.push_back({std::min(b, d), std::max(b, d)});
      queue.push_back({std::min(d, a), std::max(d, a)});
    }
    return n;
  }

  /// One smoothing sweep; returns the number of nodes moved.
  int smooth_sweep() {
    int n = 0;
    std::vector<Index> link;
    for (Index v = 0; v < Index(X_.size()); ++v) {
      if (!alive_[v] || kind_[v] == fixed || ball_[v].empty()) continue;
      // candidates: the Laplacian point (a boundary node: the projection of the mean of its
      // two boundary neighbours) and, for an interior node, the mean of the ideal points
      // (apex of the equilateral triangle on each opposite edge); then half-way moves
      std::array<Vec<2>, 4> cand;
      int nc = 0;
      const Vec<2> old = X_[v];
      if (kind_[v] == slide) {
        cand[nc++] = project(curve_[v], btag_[v], 0.5 * (X_[bprev_[v]] + X_[bnext_[v]]));
      } else {
        Vec<2> lap = Vec<2>::Zero(), ideal = Vec<2>::Zero();
        for (Index t : ball_[v]) {
          int i = 0;
          while (T_[t][i] != v) ++i;
          const Vec<2>&p = X_[T_[t][(i + 1) % 3]], &q = X_[T_[t][(i + 2) % 3]];
          lap += p + q;
          const Vec<2> d = q - p;
          ideal += 0.5 * (p + q) + (std::sqrt(3.0) / 2) * Vec<2>(-d[1], d[0]);  // left of p -> q
        }
        cand[nc++] = lap / Real(2 * ball_[v].size());
        cand[nc++] = ideal / Real(ball_[v].size());
      }
      for (int k = 0, m = nc; k < m; ++k) {
        cand[nc] = 0.5 * (old + cand[k]);
        if (kind_[v] == slide) cand[nc] = project(curve_[v], btag_[v], cand[nc]);
        ++nc;
      }
      // current state of the ball: worst quality, and edge ratios (not to be spoiled)
      link.clear();
      for (Index t : ball_[v])
        for (Index w : T_[t])
          if (w != v && std::find(link.begin(), link.end(), w) == link.end()) link.push_back(w);
      Real old_q = std::numeric_limits<Real>::infinity(), rmin = 0, rmax = 0;
      for (Index t : ball_[v]) old_q = std::min(old_q, quality(t));
      for (Index w : link) rmin = std::min(rmin, ratio(v, w)), rmax = std::max(rmax, ratio(v, w));
      Real best_q = old_q + 1e-9;
      int best = -1;
      for (int k = 0; k < nc; ++k) {
        X_[v] = cand[k];
        Real q = std::numeric_limits<Real>::infinity();
        for (Index t : ball_[v]) q = std::min(q, quality(t));
        if (q > best_q && q > adapt_degenerate_quality) {
          bool sizes_ok = true;
          for (Index w : link) {
            const Real r = ratio(v, w);
            sizes_ok = sizes_ok && r <= std::max(rmax, opt_.tolerance) && r >= std::min(rmin, -opt_.tolerance);
          }
          if (sizes_ok) best_q = q, best = k;
        }
      }
      X_[v] = best >= 0 ? cand[best] : old;
      n += best >= 0;
    }
    return n;
  }

  /// The compacted Mesh<2> (alive nodes in their order; tags carried).
  Mesh<2> build() const {
    std::vector<Index> map(X_.size(), -1);
    std::vector<Vec<2>> nodes;
    for (Index v = 0; v < Index(X_.size()); ++v)
      if (alive_[v]) map[v] = Index(nodes.size()), nodes.push_back(X_[v]);
    std::vector<Mesh<2>::Cell> cells;
    std::vector<int> tags;
    for (Index t = 0; t < Index(T_.size()); ++t)
      if (talive_[t]) {
        cells.push_back({map[T_[t][0]], map[T_[t][1]], map[T_[t][2]]});
        tags.push_back(ttag_[t]);
      }
    std::vector<Mesh<2>::Facet> facets;
    std::vector<int> ftags;
    for (Index v = 0; v < Index(X_.size()); ++v)
      if (alive_[v] && bnext_[v] >= 0) facets.push_back({map[v], map[bnext_[v]]}), ftags.push_back(btag_[v]);
    return Mesh<2>(std::move(nodes), std::move(cells), facets, ftags, std::move(tags));
  }

 private:
  static int segment_tag(const Polyline& P, std::size_t s) { return P.segment_tags.empty() ? P.tag : P.segment_tags[s]; }
  static Vec<2> project_segment(const Polyline& P, std::size_t s, const Vec<2>& p) {
    const Vec<2>&a = P.points[s], &b = P.points[(s + 1) % P.points.size()];
    const Vec<2> d = b - a;
    const Real t = std::clamp((p - a).dot(d) / d.squaredNorm(), Real(0), Real(1));
    return a + t * d;
  }

  void classify(Index v) {
    if (bnext_[v] >= 0) {
      if (btag_[v] != btag_[bprev_[v]]) return void(kind_[v] = fixed);
      const int c = find_curve(btag_[v], X_[v]);
      if (c < 0) return void(kind_[v] = fixed);
      if (const Polyline* P = std::get_if<Polyline>(&curves_[c])) {
        Real scale = 0;
        for (const auto& p : P->points) scale = std::max(scale, p.norm());
        for (const auto& p : P->points)
          if ((p - X_[v]).norm() <= 1e-9 * (1 + scale)) return void(kind_[v] = fixed);
      }
      kind_[v] = slide, curve_[v] = c;
      return;
    }
    for (Index t : ball_[v])
      if (ttag_[t] != ttag_[ball_[v][0]]) return void(kind_[v] = fixed);
    kind_[v] = interior;
  }

  const std::vector<BoundaryCurve>& curves_;
  const AdaptOptions& opt_;
  std::vector<Vec<2>> X_;
  std::vector<char> alive_;
  std::vector<char> kind_;
  std::vector<int> curve_;
  std::vector<Index> bnext_, bprev_;
  std::vector<int> btag_;
  std::vector<Real> hnode_;
  std::vector<std::array<Index, 3>> T_;
  std::vector<int> ttag_;
  std::vector<char> talive_;
  std::vector<std::vector<Index>> ball_;
  std::vector<Index> stamp_;
};

inline void validate_adapt(const Mesh<2>& moved, const std::vector<BoundaryCurve>& curves, const AdaptOptions& opt) {
  ALEFSI_CHECK_ARG(moved.n_cells() > 0, "moved", "empty mesh");
  // the operators know boundary curves only: an embedded (tagged interior) edge would be lost
  if (const auto embedded = moved.tagged_interior_facets(); !embedded.empty())
    ALEFSI_CHECK_ARG(false, "moved", "has ", embedded.size(), " tagged interior edges (the first: facet ",
                     embedded.front(), ", tag ", moved.facet_tag(embedded.front()),
                     "); adaptation keeps boundary tags only and would drop them");
  ALEFSI_CHECK_ARG(opt.tolerance > 0 && opt.tolerance <= 10, "tolerance", "must be in (0, 10], got ", opt.tolerance);
  ALEFSI_CHECK_ARG(opt.min_quality >= 0 && opt.min_quality < 1, "min_quality", "must be in [0, 1), got ", opt.min_quality);
  ALEFSI_CHECK_ARG(opt.smoothing_sweeps >= 0, "smoothing_sweeps", "must be >= 0, got ", opt.smoothing_sweeps);
  ALEFSI_CHECK_ARG(opt.max_passes >= 1, "max_passes", "must be >= 1, got ", opt.max_passes);
  for (std::size_t i = 0; i < curves.size(); ++i) validate_boundary(curves[i], "curves[" + std::to_string(i) + "]");
}

}  // namespace detail

/// Adapts the moved mesh (see the file comment). Throws InvalidArgument naming the
/// parameter for bad options or curves, and for a size function returning a non-positive
/// or non-finite value.
inline Mesh<2> adapt(const Mesh<2>& moved, const std::vector<BoundaryCurve>& curves, const AdaptOptions& options,
                     AdaptReport* report = nullptr) {
  detail::validate_adapt(moved, curves, options);
  detail::AdaptMesh2D M(moved, curves, options);
  AdaptReport rep;
  for (int pass = 0; pass < options.max_passes; ++pass) {
    ++rep.passes;
    int s = 0;
    for (int round = 0; round < 16; ++round) {
      const int k = M.split_pass(rep.refused);
      s += k;
      if (k == 0) break;
    }
    const int c = M.collapse_pass(rep.refused);
    auto flip_smooth_flip = [&] {
      rep.flips += M.flip_all();
      for (int sweep = 0; sweep < options.smoothing_sweeps; ++sweep) {
        const int k = M.smooth_sweep();
        rep.smoothed += k;
        if (k == 0) break;
      }
      rep.flips += M.flip_all();
    };
    flip_smooth_flip();
    int rs = 0, rc = 0;
    M.repair_pass(rs, rc);
    if (rs + rc > 0) flip_smooth_flip();
    rep.splits += s + rs, rep.collapses += c + rc;
    if (s + c == 0) break;
  }
  Mesh<2> out = M.build();
  rep.changed = rep.splits + rep.collapses + rep.flips + rep.smoothed > 0;
  rep.min_angle_deg = min_angle_deg(out);
  rep.worst_quality = 1;
  for (Index t = 0; t < out.n_cells(); ++t) rep.worst_quality = std::min(rep.worst_quality, out.quality(t));
  if (report) *report = rep;
  return out;
}

}  // namespace alefsi
