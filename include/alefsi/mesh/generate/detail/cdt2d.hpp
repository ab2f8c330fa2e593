#pragma once
/// \file mesh/generate/detail/cdt2d.hpp
/// Constrained Delaunay triangulation and Ruppert/Chew refinement in the plane: the engine
/// behind `generate_mesh` (mesher2d.hpp). Not a public interface.
///
/// Data structure: triangles with three vertices (counterclockwise), three neighbours and
/// three segment ids (neighbour / segment across the edge opposite vertex i; -1 if none).
/// Dead triangle slots go to a free list and are reused (LIFO, deterministic).
///
/// Operations:
///  - Bowyer-Watson insertion: the cavity (triangles whose circumcircle strictly contains
///    the new point, grown through unconstrained edges) is computed read-only, checked
///    (every new triangle strictly positively oriented, optionally: no boundary segment of
///    the cavity encroached by the point) and only then committed. A rejected insertion
///    changes nothing, so the triangulation is valid after every step.
///  - Segment recovery by edge flips (Sloan), then Lawson flips to the CDT.
///  - Exterior removal by a parity flood fill across constrained edges.
///  - Refinement: encroached segments (an apex inside the diametral circle) are split first
///    (straight: midpoint, or a power-of-two distance from a small-angle corner; arcs of a
///    circle or an ellipse: the parameter midpoint, so the node lies on the curve); then bad
///    triangles (radius-edge ratio above 1 / (2 sin theta_min), or circumradius above
///    h / sqrt(3)) get their circumcentre, located by a straight walk; a circumcentre behind
///    a segment or encroaching one is rejected in favour of splitting that segment.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/detail/predicates.hpp"

namespace alefsi::detail {

/// A boundary loop: a conic (a circle or an ellipse, with parameters t on its segments:
/// x(t) = centre + R (ra cos t, rb sin t), R the rotation by the angle with cosine cs and sine
/// sn) or a polyline.
struct CdtLoop {
  bool circle = false;  ///< a conic: the segments carry parameters
  XY centre{0, 0};
  double ra = 0, rb = 0;  ///< semi-axes (equal on a circle)
  double cs = 1, sn = 0;
  /// The point at parameter t (on a circle: centre + r (cos t, sin t), to the last bit).
  XY at(double t) const {
    const double u = ra * std::cos(t), v = rb * std::sin(t);
    return {centre.x + (cs * u - sn * v), centre.y + (sn * u + cs * v)};
  }
};

/// A boundary segment (subsegment of an input boundary).
struct CdtSeg {
  Index a = -1, b = -1;
  int loop = -1;
  int tag = 0;
  double ta = 0, tb = 0;  ///< parameters of a and b on a conic loop (|tb - ta| < pi)
  int input_edge = -1;    ///< input polyline edge (-1 on conics)
};

/// An input polyline vertex with its domain-side angle and incident input edges.
struct CdtCorner {
  double angle = 0;  ///< radians, domain side
  int e0 = -1, e1 = -1;
  bool small = false;  ///< angle < 60 degrees: exempt from the angle guarantee
};

struct CdtTri {
  std::array<Index, 3> v{-1, -1, -1};  ///< vertices, counterclockwise; v[0] = -1: dead slot
  std::array<Index, 3> n{-1, -1, -1};  ///< neighbour across the edge opposite v[i]
  std::array<Index, 3> s{-1, -1, -1};  ///< segment on the edge opposite v[i]
};

/// Counters reported by the mesher.
struct CdtStats {
  std::size_t steiner_points = 0;       ///< circumcentres inserted
  std::size_t segment_splits = 0;       ///< boundary segments split
  std::size_t small_angle_skips = 0;    ///< bad triangles left alone next to small input angles
  std::size_t dropped = 0;              ///< bad triangles given up (should stay 0)
  std::size_t unsplittable = 0;         ///< segments too short to split (should stay 0)
};

class Cdt2D {
 public:
  // ---- input, filled by the front end ----------------------------------------------
  std::vector<XY> pts;         ///< vertices; 0, 1, 2 are the super-triangle
  std::vector<int> v_edge;     ///< input polyline edge a vertex lies in the interior of (-1)
  std::vector<int> v_corner;   ///< input corner at the vertex (-1)
  std::vector<CdtLoop> loops;
  std::vector<CdtSeg> segs;
  std::vector<CdtCorner> corners;
  std::vector<std::array<int, 2>> edge_corners;  ///< corners at both ends of an input edge
  std::function<double(const XY&)> size;
  double min_angle_deg = 25;
  std::size_t max_points = 50'000'000;
  CdtStats stats;

  // ---- output ----------------------------------------------------------------------
  std::vector<CdtTri> tris;

  Cdt2D() {
    for (int i = 0; i < 3; ++i) add_vertex({0, 0}, -1, -1);
  }

  Index add_vertex(const XY& p, int edge, int corner) {
    if (corner >= 0) {
      if (corner_vertex_.size() <= static_cast<std::size_t>(corner)) corner_vertex_.resize(static_cast<std::size_t>(corner) + 1, -1);
      corner_vertex_[static_cast<std::size_t>(corner)] = static_cast<Index>(pts.size());
    }
    pts.push_back(p);
    v_edge.push_back(edge);
    v_corner.push_back(corner);
    vtri_.push_back(-1);
    vmark_.push_back(0);
    vnew_.push_back(-1);
    return static_cast<Index>(pts.size() - 1);
  }

  bool alive(Index t) const { return tris[t].v[0] >= 0; }

  /// Delaunay triangulation of all vertices, segment recovery, exterior removal.
  void triangulate() {
    make_super_triangle();
    Index last = 0;
    for (Index p = 3; p < static_cast<Index>(pts.size()); ++p) {
      const Index t = locate(pts[p], last);
      if (insert(p, t, -1, false) != Ins::ok)
        throw InvalidArgument("domain", concat("boundary point (", pts[p].x, ", ", pts[p].y,
                                               ") coincides with another boundary point"));
      last = newtris_.front();
    }
    nosplit_.assign(segs.size(), 0);
    for (Index s = 0; s < static_cast<Index>(segs.size()); ++s) recover_segment(s);
    remove_exterior();
  }

  /// Ruppert refinement to the angle and size bounds.
  void refine() {
    const double sn = std::sin(min_angle_deg * std::numbers::pi / 180.0);
    ratio2_ = 4.0 * sn * sn;
    for (Index t = 0; t < static_cast<Index>(tris.size()); ++t)
      if (alive(t) && is_bad(t)) badq_.emplace_back(t, tstamp_[t]);
    for (Index s = 0; s < static_cast<Index>(segs.size()); ++s)
      if (encroached(s)) segq_.emplace_back(s, false);
    for (;;) {
      if (!segq_.empty()) {
        const auto [s, force] = segq_.front();
        segq_.pop_front();
        if (!nosplit_[s] && (force || encroached(s))) split_segment(s);
        continue;
      }
      if (badq_.empty()) break;
      const auto [t, st] = badq_.front();
      badq_.pop_front();
      if (!alive(t) || tstamp_[t] != st) continue;
      refine_triangle(t);
    }
  }

 private:
  enum class Ins { ok, encroaches, failed };
  struct BEdge {
    Index a, b, out, seg;
    int out_k;
  };

  static std::size_t nx(int k) { return static_cast<std::size_t>((k + 1) % 3); }
  static std::size_t pv(int k) { return static_cast<std::size_t>((k + 2) % 3); }
  static int vindex(const CdtTri& T, Index v) { return T.v[0] == v ? 0 : (T.v[1] == v ? 1 : 2); }
  int nindex(Index u, Index t) const {
    const CdtTri& U = tris[u];
    return U.n[0] == t ? 0 : (U.n[1] == t ? 1 : 2);
  }

  double orient(Index a, Index b, Index c) const { return orient2d(pts[a], pts[b], pts[c]); }
  double in_circle(Index t, const XY& p) const {
    const CdtTri& T = tris[t];
    return incircle(pts[T.v[0]], pts[T.v[1]], pts[T.v[2]], p);
  }
  /// p inside the diametral circle of segment ab.
  static bool encroaches(const XY& p, const XY& a, const XY& b) {
    return (a.x - p.x) * (b.x - p.x) + (a.y - p.y) * (b.y - p.y) < 0;
  }

  Index alloc_tri() {
    Index t;
    if (!free_.empty()) {
      t = free_.back();
      free_.pop_back();
    } else {
      t = static_cast<Index>(tris.size());
      tris.emplace_back();
      tstamp_.push_back(0);
      cmark_.push_back(0);
      rmark_.push_back(0);
    }
    ++tstamp_[t];
    return t;
  }
  void kill_tri(Index t) {
    tris[t].v[0] = -1;
    free_.push_back(t);
  }

  void make_super_triangle() {
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (std::size_t i = 3; i < pts.size(); ++i) {
      x0 = std::min(x0, pts[i].x), x1 = std::max(x1, pts[i].x);
      y0 = std::min(y0, pts[i].y), y1 = std::max(y1, pts[i].y);
    }
    const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1), d = std::max(x1 - x0, y1 - y0);
    pts[0] = {cx - 40 * d, cy - 30 * d};
    pts[1] = {cx + 40 * d, cy - 30 * d};
    pts[2] = {cx, cy + 40 * d};
    tiny2_ = 1e-24 * d * d;
    const Index t = alloc_tri();
    tris[t].v = {0, 1, 2};
    for (Index v = 0; v < 3; ++v) vtri_[v] = t;
  }

  /// Visibility walk (terminates on Delaunay triangulations); brute force as a fallback.
  Index locate(const XY& p, Index t) const {
    int entry = -1;
    for (std::size_t steps = 0; steps <= tris.size(); ++steps) {
      const CdtTri& T = tris[t];
      int k = 0;
      for (; k < 3; ++k) {
        if (k == entry) continue;
        if (orient2d(pts[T.v[nx(k)]], pts[T.v[pv(k)]], p) < 0) break;
      }
      if (k == 3) return t;
      const Index u = T.n[k];
      entry = nindex(u, t);
      t = u;
    }
    for (Index u = 0; u < static_cast<Index>(tris.size()); ++u) {
      if (!alive(u)) continue;
      const CdtTri& T = tris[u];
      if (orient2d(pts[T.v[1]], pts[T.v[2]], p) >= 0 &&
          orient2d(pts[T.v[2]], pts[T.v[0]], p) >= 0 && orient2d(pts[T.v[0]], pts[T.v[1]], p) >= 0)
        return u;
    }
    throw Error("mesher: point location failed");
  }

  /// Bowyer-Watson insertion of vertex p. t0 contains p; or, with split_k >= 0, edge split_k
  /// of t0 is the boundary segment split by p into pieces[0] (at the edge's first vertex) and
  /// pieces[1]. Nothing changes unless the result is `ok`; the new triangles are in newtris_.
  Ins insert(Index p, Index t0, int split_k, bool reject_encroach, std::array<Index, 2> pieces = {-1, -1}) {
    ++stamp_;
    cav_.clear();
    bnd_.clear();
    encroached_.clear();
    newtris_.clear();
    const XY P = pts[p];
    bool cap_only = false;
    if (in_circle(t0, P) > 0) {
      cmark_[t0] = stamp_;
      cav_.push_back(t0);
    } else if (split_k >= 0) {
      cap_only = true;
    } else {
      return Ins::failed;
    }
    for (std::size_t i = 0; i < cav_.size(); ++i) {
      const CdtTri& T = tris[cav_[i]];
      for (int k = 0; k < 3; ++k) {
        const Index u = T.n[k];
        if (u < 0 || T.s[k] >= 0 || cmark_[u] == stamp_ || rmark_[u] == stamp_) continue;
        if (in_circle(u, P) > 0) {
          cmark_[u] = stamp_;
          cav_.push_back(u);
        } else {
          rmark_[u] = stamp_;
        }
      }
    }
    for (const Index t : cav_) {
      const CdtTri& T = tris[t];
      for (int k = 0; k < 3; ++k) {
        if (t == t0 && k == split_k) continue;
        const Index u = T.n[k];
        if (u >= 0 && cmark_[u] == stamp_) {
          if (T.s[k] >= 0) return Ins::failed;
          continue;
        }
        bnd_.push_back({T.v[nx(k)], T.v[pv(k)], u, T.s[k], u >= 0 ? nindex(u, t) : -1});
      }
    }
    if (reject_encroach) {
      for (const BEdge& e : bnd_)
        if (e.seg >= 0 && encroaches(P, pts[e.a], pts[e.b])) encroached_.push_back(e.seg);
      if (!encroached_.empty()) return Ins::encroaches;
    }
    for (const BEdge& e : bnd_) {
      if (!(orient2d(pts[e.a], pts[e.b], P) > 0)) return Ins::failed;
      if (vmark_[e.a] == stamp_) return Ins::failed;  // cavity not a disk
      vmark_[e.a] = stamp_;
    }
    Index sa = -1, sb = -1;
    if (split_k >= 0) {
      sa = tris[t0].v[nx(split_k)];
      sb = tris[t0].v[pv(split_k)];
    }
    if (cap_only) {
      if (!(orient(sb, sa, p) > 0)) return Ins::failed;
      const Index nt = alloc_tri();
      tris[nt].v = {p, sb, sa};
      tris[nt].n = {t0, -1, -1};
      tris[nt].s = {-1, pieces[0], pieces[1]};
      tris[t0].n[static_cast<std::size_t>(split_k)] = nt;
      tris[t0].s[static_cast<std::size_t>(split_k)] = -1;
      newtris_.push_back(nt);
      for (Index v : tris[nt].v) vtri_[v] = nt;
      return Ins::ok;
    }
    // commit
    for (const Index t : cav_) kill_tri(t);
    for (const BEdge& e : bnd_) {
      const Index nt = alloc_tri();
      CdtTri& N = tris[nt];
      N.v = {p, e.a, e.b};
      N.n = {e.out, -1, -1};
      N.s = {e.seg, -1, -1};
      if (e.out >= 0) tris[e.out].n[static_cast<std::size_t>(e.out_k)] = nt;
      vnew_[e.a] = nt;
      newtris_.push_back(nt);
    }
    for (const Index nt : newtris_) {
      CdtTri& N = tris[nt];
      const Index b = N.v[2];
      if (vmark_[b] == stamp_) {
        const Index m = vnew_[b];
        N.n[1] = m;
        tris[m].n[2] = nt;
      } else {
        ALEFSI_ASSERT(b == sa);
        N.s[1] = pieces[0];
      }
      if (N.v[1] == sb) N.s[2] = pieces[1];
      for (Index v : N.v) vtri_[v] = nt;
    }
    return Ins::ok;
  }

  // ---- edges and flips ---------------------------------------------------------------
  bool find_edge(Index a, Index b, Index& t_out, int& k_out) const {
    auto check = [&](Index t) {
      const CdtTri& T = tris[t];
      const int i = vindex(T, a);
      if (T.v[nx(i)] == b) return t_out = t, k_out = (i + 2) % 3, true;
      if (T.v[pv(i)] == b) return t_out = t, k_out = (i + 1) % 3, true;
      return false;
    };
    const Index t0 = vtri_[a];
    if (t0 < 0) return false;
    Index t = t0;
    do {  // counterclockwise around a
      if (check(t)) return true;
      t = tris[t].n[nx(vindex(tris[t], a))];
    } while (t >= 0 && t != t0);
    if (t == t0) return false;
    t = t0;
    for (;;) {  // clockwise around a (a on the boundary)
      t = tris[t].n[pv(vindex(tris[t], a))];
      if (t < 0) return false;
      if (check(t)) return true;
    }
  }

  void replace_neighbour(Index w, Index from, Index to) {
    CdtTri& W = tris[w];
    for (auto& n : W.n)
      if (n == from) {
        n = to;
        return;
      }
  }

  /// Flips edge i of t: t = (x, u, v), neighbour (y, v, u) -> (x, u, y), (y, v, x).
  void flip(Index t, int i) {
    const Index s = tris[t].n[static_cast<std::size_t>(i)];
    const int j = nindex(s, t);
    CdtTri& T = tris[t];
    CdtTri& S = tris[s];
    const std::size_t ui = static_cast<std::size_t>(i);
    const std::size_t uj = static_cast<std::size_t>(j);
    const Index x = T.v[ui], u = T.v[nx(i)], v = T.v[pv(i)], y = S.v[uj];
    const Index nt_vx = T.n[nx(i)], st_vx = T.s[nx(i)];
    const Index nt_xu = T.n[pv(i)], st_xu = T.s[pv(i)];
    const Index ns_uy = S.n[nx(j)], ss_uy = S.s[nx(j)];
    const Index ns_yv = S.n[pv(j)], ss_yv = S.s[pv(j)];
    T.v = {x, u, y};
    T.n = {ns_uy, s, nt_xu};
    T.s = {ss_uy, -1, st_xu};
    S.v = {y, v, x};
    S.n = {nt_vx, t, ns_yv};
    S.s = {st_vx, -1, ss_yv};
    if (ns_uy >= 0) replace_neighbour(ns_uy, s, t);
    if (nt_vx >= 0) replace_neighbour(nt_vx, t, s);
    vtri_[x] = t, vtri_[u] = t, vtri_[y] = t, vtri_[v] = s;
  }

  static int sgn(double x) { return (x > 0) - (x < 0); }

  /// Does segment xy cross segment ab in their interiors?
  bool crosses(Index a, Index b, Index x, Index y) const {
    if (x == a || x == b || y == a || y == b) return false;
    return sgn(orient(a, b, x)) * sgn(orient(a, b, y)) < 0 && sgn(orient(x, y, a)) * sgn(orient(x, y, b)) < 0;
  }

  [[noreturn]] void vertex_on_segment(Index s, Index w) const {
    throw InvalidArgument("domain", concat("boundary point (", pts[w].x, ", ", pts[w].y,
                                           ") lies on the boundary segment from (", pts[segs[s].a].x, ", ",
                                           pts[segs[s].a].y, ") to (", pts[segs[s].b].x, ", ",
                                           pts[segs[s].b].y, ")"));
  }

  void mark_segment(Index s, Index t, int k) {
    tris[t].s[static_cast<std::size_t>(k)] = s;
    const Index u = tris[t].n[static_cast<std::size_t>(k)];
    if (u >= 0) tris[u].s[static_cast<std::size_t>(nindex(u, t))] = s;
  }

  /// Sloan's flip-based segment recovery, then Lawson flips (constrained edges fixed).
  void recover_segment(Index s) {
    const Index a = segs[s].a, b = segs[s].b;
    Index t;
    int k;
    if (find_edge(a, b, t, k)) return mark_segment(s, t, k);
    // the triangle at a whose angle contains the direction to b
    Index p = -1, q = -1;
    {
      const Index t0 = vtri_[a];
      t = t0;
      std::size_t guard = 0;
      for (;;) {
        const CdtTri& T = tris[t];
        const int i = vindex(T, a);
        const Index pp = T.v[nx(i)], qq = T.v[pv(i)];
        const double op = orient(a, pp, b), oq = orient(a, qq, b);
        auto ahead = [&](Index w) {
          return (pts[w].x - pts[a].x) * (pts[b].x - pts[a].x) + (pts[w].y - pts[a].y) * (pts[b].y - pts[a].y) > 0;
        };
        if (op == 0 && ahead(pp)) vertex_on_segment(s, pp);
        if (oq == 0 && ahead(qq)) vertex_on_segment(s, qq);
        if (op > 0 && oq < 0) {
          p = pp, q = qq;
          break;
        }
        t = T.n[static_cast<std::size_t>((i + 1) % 3)];
        if (t < 0 || ++guard > tris.size()) throw Error("mesher: segment recovery lost its way");
      }
    }
    std::deque<std::array<Index, 2>> crossing;
    crossing.push_back({p, q});
    for (std::size_t guard = 0;; ++guard) {
      if (guard > tris.size()) throw Error("mesher: segment recovery lost its way");
      const CdtTri& T = tris[t];
      const int ki = 3 - vindex(T, p) - vindex(T, q);  // edge (p, q)
      const Index u = T.n[static_cast<std::size_t>(ki)];
      const CdtTri& U = tris[u];
      const Index w = U.v[static_cast<std::size_t>(3 - vindex(U, p) - vindex(U, q))];
      if (w == b) break;
      const double o = orient(a, b, w);
      if (o == 0) vertex_on_segment(s, w);
      if (o > 0) q = w;
      else p = w;
      crossing.push_back({p, q});
      t = u;
    }
    std::vector<std::array<Index, 2>> fresh;
    const std::size_t limit = 64 * (crossing.size() + 4) * (crossing.size() + 4);
    for (std::size_t guard = 0; !crossing.empty(); ++guard) {
      if (guard > limit) throw Error("mesher: segment recovery does not terminate");
      const auto [u, v] = crossing.front();
      crossing.pop_front();
      int i;
      if (!find_edge(u, v, t, i)) throw Error("mesher: segment recovery lost an edge");
      const CdtTri& T = tris[t];
      const Index x = T.v[static_cast<std::size_t>(i)], uu = T.v[nx(i)], vv = T.v[pv(i)];
      const Index sn = T.n[static_cast<std::size_t>(i)];
      const Index y = tris[sn].v[static_cast<std::size_t>(nindex(sn, t))];
      if (orient(x, y, uu) < 0 && orient(x, y, vv) > 0) {
        flip(t, i);
        if (crosses(a, b, x, y)) crossing.push_back({x, y});
        else fresh.push_back({x, y});
      } else {
        crossing.push_back({u, v});
      }
    }
    if (!find_edge(a, b, t, k)) throw Error("mesher: segment recovery failed");
    mark_segment(s, t, k);
    // Lawson flips back to the constrained Delaunay triangulation
    while (!fresh.empty()) {
      const auto [u, v] = fresh.back();
      fresh.pop_back();
      int i;
      if (!find_edge(u, v, t, i)) continue;
      const CdtTri& T = tris[t];
      const Index sn = T.n[static_cast<std::size_t>(i)];
      if (T.s[static_cast<std::size_t>(i)] >= 0 || sn < 0) continue;
      const Index y = tris[sn].v[static_cast<std::size_t>(nindex(sn, t))];
      if (in_circle(t, pts[y]) > 0) {
        const Index x = T.v[static_cast<std::size_t>(i)], uu = T.v[nx(i)], vv = T.v[pv(i)];
        flip(t, i);
        fresh.push_back({x, uu}), fresh.push_back({uu, y}), fresh.push_back({y, vv}), fresh.push_back({vv, x});
      }
    }
  }

  /// Removes the triangles outside the domain: parity of constrained edges crossed from the
  /// super-triangle.
  void remove_exterior() {
    std::vector<signed char> side(tris.size(), -1);
    std::vector<Index> stack{vtri_[0]};
    side[static_cast<std::size_t>(vtri_[0])] = 0;
    while (!stack.empty()) {
      const Index t = stack.back();
      stack.pop_back();
      const CdtTri& T = tris[t];
      for (std::size_t k = 0; k < 3; ++k) {
        const Index u = T.n[k];
        if (u < 0) continue;
        const signed char su = static_cast<signed char>(side[static_cast<std::size_t>(t)] ^ (T.s[k] >= 0 ? 1 : 0));
        if (side[static_cast<std::size_t>(u)] < 0) {
          side[static_cast<std::size_t>(u)] = su;
          stack.push_back(u);
        } else if (side[static_cast<std::size_t>(u)] != su) {
          throw Error("mesher: boundary loops are not consistent (crossing boundaries?)");
        }
      }
    }
    for (Index t = 0; t < static_cast<Index>(tris.size()); ++t)
      if (alive(t) && side[static_cast<std::size_t>(t)] == 0) kill_tri(t);
    std::fill(vtri_.begin(), vtri_.end(), -1);
    for (Index t = 0; t < static_cast<Index>(tris.size()); ++t) {
      if (!alive(t)) continue;
      CdtTri& T = tris[t];
      for (std::size_t k = 0; k < 3; ++k) {
        if (T.n[k] >= 0 && !alive(T.n[k])) {
          if (T.s[k] < 0) throw Error("mesher: interior edge on the domain boundary");
          T.n[k] = -1;
        }
        vtri_[T.v[k]] = t;
      }
    }
    if (vtri_[0] >= 0 || vtri_[1] >= 0 || vtri_[2] >= 0) throw Error("mesher: super-triangle inside the domain");
  }

  // ---- refinement --------------------------------------------------------------------
  bool on_input_edge(Index v, int e) const {
    if (v_edge[v] == e) return true;
    const int c = v_corner[v];
    return c >= 0 && (corners[c].e0 == e || corners[c].e1 == e);
  }

  /// Bad triangles next to small input angles that refinement cannot (and must not try
  /// to) improve.
  bool small_angle_exempt(const CdtTri& T, int shortest) const {
    if (!has_small_corners_) return false;
    for (std::size_t i = 0; i < 3; ++i) {
      const int c = v_corner[T.v[i]];
      if (c < 0 || !corners[c].small) continue;
      const Index p = T.v[(i + 1) % 3], q = T.v[(i + 2) % 3];
      const int e0 = corners[c].e0, e1 = corners[c].e1;
      if ((on_input_edge(p, e0) && on_input_edge(q, e1)) || (on_input_edge(p, e1) && on_input_edge(q, e0))) return true;
    }
    // the shortest edge joins two vertices on different input edges meeting at a small
    // corner, at the same distance from it (the same concentric shell)
    const Index p = T.v[nx(shortest)], q = T.v[pv(shortest)];
    const int ep = v_edge[p], eq = v_edge[q];
    if (ep < 0 || eq < 0 || ep == eq) return false;
    for (int c : edge_corners[ep]) {
      if (c < 0 || !corners[c].small || (edge_corners[eq][0] != c && edge_corners[eq][1] != c)) continue;
      const XY& z = pts[corner_vertex_[c]];
      const double dp = std::hypot(pts[p].x - z.x, pts[p].y - z.y), dq = std::hypot(pts[q].x - z.x, pts[q].y - z.y);
      if (std::abs(dp - dq) <= 1e-6 * (dp + dq)) return true;
    }
    return false;
  }

  bool is_bad(Index t) {
    const CdtTri& T = tris[t];
    const XY &A = pts[T.v[0]], &B = pts[T.v[1]], &C = pts[T.v[2]];
    const double l0 = (B.x - C.x) * (B.x - C.x) + (B.y - C.y) * (B.y - C.y);
    const double l1 = (C.x - A.x) * (C.x - A.x) + (C.y - A.y) * (C.y - A.y);
    const double l2 = (A.x - B.x) * (A.x - B.x) + (A.y - B.y) * (A.y - B.y);
    const double a2 = (B.x - A.x) * (C.y - A.y) - (B.y - A.y) * (C.x - A.x);  // twice the area
    const double r2 = l0 * l1 * l2 / (4.0 * a2 * a2);                          // circumradius^2
    const int shortest = l0 <= l1 ? (l0 <= l2 ? 0 : 2) : (l1 <= l2 ? 1 : 2);
    const double lmin = std::min({l0, l1, l2});
    if (lmin < ratio2_ * r2) {
      if (small_angle_exempt(T, shortest)) {
        ++stats.small_angle_skips;
        return false;
      }
      return true;
    }
    const XY g{(A.x + B.x + C.x) / 3.0, (A.y + B.y + C.y) / 3.0};
    const double h = size(g);
    if (!(h > 0) || !std::isfinite(h))
      throw InvalidArgument("size", concat("must be positive and finite, got ", h, " at (", g.x, ", ", g.y, ")"));
    return 3.0 * r2 > h * h;
  }

  bool encroached(Index s) const {
    Index t;
    int k;
    if (!find_edge(segs[s].a, segs[s].b, t, k)) return false;
    return encroaches(pts[tris[t].v[static_cast<std::size_t>(k)]], pts[segs[s].a], pts[segs[s].b]);
  }

  XY circumcentre(Index t) const {
    const CdtTri& T = tris[t];
    const XY &A = pts[T.v[0]], &B = pts[T.v[1]], &C = pts[T.v[2]];
    const double bx = B.x - A.x, by = B.y - A.y, cx = C.x - A.x, cy = C.y - A.y;
    const double d = 2.0 * (bx * cy - by * cx);
    const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    return {A.x + (cy * b2 - by * c2) / d, A.y + (bx * c2 - cx * b2) / d};
  }

  /// Straight walk from the centroid of t towards c. Returns the triangle containing c
  /// and -1, or the triangle and edge where a segment blocks the way; {-1, -1} on failure.
  std::pair<Index, int> walk(Index t, const XY& c) const {
    const CdtTri& T0 = tris[t];
    const XY &A = pts[T0.v[0]], &B = pts[T0.v[1]], &C = pts[T0.v[2]];
    if (orient2d(B, C, c) >= 0 && orient2d(C, A, c) >= 0 && orient2d(A, B, c) >= 0) return {t, -1};
    const XY g{(A.x + B.x + C.x) / 3.0, (A.y + B.y + C.y) / 3.0};
    if (!(orient2d(B, C, g) > 0 && orient2d(C, A, g) > 0 && orient2d(A, B, g) > 0)) return {-1, -1};
    int entry = -1;
    for (std::size_t steps = 0; steps <= tris.size(); ++steps) {
      const CdtTri& T = tris[t];
      int exit = -1;
      for (int k = 0; k < 3; ++k) {
        if (k == entry) continue;
        if (orient2d(g, c, pts[T.v[nx(k)]]) <= 0 && orient2d(g, c, pts[T.v[pv(k)]]) > 0) {
          exit = k;
          break;
        }
      }
      if (exit < 0) return {-1, -1};
      const std::size_t ue = static_cast<std::size_t>(exit);
      if (orient2d(pts[T.v[nx(exit)]], pts[T.v[pv(exit)]], c) >= 0) return {t, -1};
      if (T.s[ue] >= 0 || T.n[ue] < 0) return {t, exit};
      const Index u = T.n[ue];
      entry = nindex(u, t);
      t = u;
    }
    return {-1, -1};
  }

  Index new_point(const XY& p, int edge) {
    if (pts.size() - 3 >= max_points)
      throw InvalidArgument("max_points", concat("refinement needs more than ", max_points,
                                                 " points (is the size function too small?)"));
    return add_vertex(p, edge, -1);
  }
  void drop_last_point() {
    pts.pop_back(), v_edge.pop_back(), v_corner.pop_back(), vtri_.pop_back(), vmark_.pop_back(), vnew_.pop_back();
  }

  void after_insert() {
    for (const Index nt : newtris_) {
      if (is_bad(nt)) badq_.emplace_back(nt, tstamp_[nt]);
      const CdtTri& N = tris[nt];
      for (std::size_t k = 0; k < 3; ++k)
        if (N.s[k] >= 0 && encroaches(pts[N.v[k]], pts[N.v[(k + 1) % 3]], pts[N.v[(k + 2) % 3]]))
          segq_.emplace_back(N.s[k], false);
    }
  }

  void refine_triangle(Index t) {
    const XY c = circumcentre(t);
    const auto [tc, kb] = walk(t, c);
    if (tc < 0) {
      ++stats.dropped;
      return;
    }
    if (kb >= 0) {  // a segment lies between t and its circumcentre: it is encroached
      const Index s = tris[tc].s[static_cast<std::size_t>(kb)];
      if (s >= 0 && !nosplit_[s]) {
        segq_.emplace_back(s, true);
        badq_.emplace_back(t, tstamp_[t]);
      } else {
        ++stats.dropped;
      }
      return;
    }
    const Index p = new_point(c, -1);
    const Ins r = insert(p, tc, -1, true);
    if (r == Ins::ok) {
      ++stats.steiner_points;
      after_insert();
      return;
    }
    drop_last_point();
    bool queued = false;
    if (r == Ins::encroaches)
      for (const Index s : encroached_)
        if (!nosplit_[s]) segq_.emplace_back(s, true), queued = true;
    if (queued) badq_.emplace_back(t, tstamp_[t]);
    else ++stats.dropped;
  }

  void split_segment(Index s) {
    const CdtSeg sg = segs[s];
    Index t;
    int k;
    if (!find_edge(sg.a, sg.b, t, k)) return;
    const XY &A = pts[sg.a], &B = pts[sg.b];
    const double len2 = (B.x - A.x) * (B.x - A.x) + (B.y - A.y) * (B.y - A.y);
    XY m;
    double tm = 0;
    if (loops[sg.loop].circle) {
      tm = 0.5 * (sg.ta + sg.tb);
      m = loops[sg.loop].at(tm);
    } else {
      const int ca = v_corner[sg.a], cb = v_corner[sg.b];
      const bool sa = ca >= 0 && corners[ca].small, sb = cb >= 0 && corners[cb].small;
      double f = 0.5;  // fraction from a to b
      if (sa != sb) {  // concentric shells around a small-angle corner
        const double len = std::sqrt(len2);
        const double d = std::exp2(std::round(std::log2(0.5 * len)));
        f = sa ? d / len : 1.0 - d / len;
      }
      m = {A.x + f * (B.x - A.x), A.y + f * (B.y - A.y)};
      if (f == 0.5) m = {0.5 * (A.x + B.x), 0.5 * (A.y + B.y)};
    }
    auto same = [](const XY& u, const XY& v) { return u.x == v.x && u.y == v.y; };
    if (len2 <= tiny2_ || same(m, A) || same(m, B)) {
      nosplit_[s] = 1;
      ++stats.unsplittable;
      return;
    }
    const Index p = new_point(m, sg.input_edge);
    const Index ns = static_cast<Index>(segs.size());
    const bool a_first = tris[t].v[nx(k)] == sg.a;
    const std::array<Index, 2> pieces = a_first ? std::array<Index, 2>{s, ns} : std::array<Index, 2>{ns, s};
    if (insert(p, t, k, false, pieces) != Ins::ok) {
      drop_last_point();
      nosplit_[s] = 1;
      ++stats.unsplittable;
      return;
    }
    segs[s].b = p;
    segs[s].tb = tm;
    CdtSeg second = sg;
    second.a = p;
    second.ta = tm;
    segs.push_back(second);
    nosplit_.push_back(0);
    ++stats.segment_splits;
    after_insert();
  }

 public:
  bool has_small_corners_ = false;  ///< set by the front end

 private:
  std::vector<Index> free_, vtri_, vnew_, cav_, newtris_, encroached_, corner_vertex_;
  std::vector<std::uint32_t> tstamp_, cmark_, rmark_, vmark_;
  std::uint32_t stamp_ = 0;
  std::vector<BEdge> bnd_;
  std::vector<char> nosplit_;
  std::deque<std::pair<Index, std::uint32_t>> badq_;
  std::deque<std::pair<Index, bool>> segq_;  ///< segment, split even if no vertex encroaches it
  double ratio2_ = 0, tiny2_ = 0;
};

}  // namespace alefsi::detail
