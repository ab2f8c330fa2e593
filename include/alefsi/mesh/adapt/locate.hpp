#pragma once
/// \file mesh/adapt/locate.hpp
/// Point location in a triangle (2D) or tetrahedron (3D) mesh: which cell contains x, and x's
/// barycentric coordinates in it.
///
/// Algorithm: a uniform bucket grid over the bounding box (about one bucket per cell;
/// each cell is filed in every bucket its bounding box overlaps), plus an optional
/// visibility walk from a hint cell (cross the facet opposite the most negative
/// barycentric coordinate). A query first walks from the hint (at most `max_walk`
/// steps; the walk stops at the boundary, e.g. next to a hole), then scans the bucket of x
/// and keeps the cell whose smallest barycentric coordinate is largest (deterministic:
/// ties go to the lower cell index). A point in no cell (outside the mesh, e.g. on a
/// circle arc just outside the inscribed polygon) gets the *nearest* cell, searched
/// ring by ring around x in the grid, and the barycentric coordinates of the point of
/// that cell closest to x (so they are >= 0 and sum to 1: "clamped"); `Location::distance`
/// is then > 0 and `Location::raw` holds the unclamped (extrapolating) coordinates.
///
/// In 3D the grid, the walk and the search outside are the same; the closest point of a
/// tetrahedron is found on its faces (triangle, then edge, then vertex).
///
/// Cost: construction O(n_cells) time and memory. A query costs O(cells per bucket),
/// O(1) for quasi-uniform meshes; graded meshes put more cells in the buckets of their
/// fine regions, which a hint avoids: queries made in the order of a nearby mesh's nodes
/// with the previous answer as hint cost O(1) each (O(n) for a whole transfer). Points
/// outside the mesh cost O(cells within the distance to the mesh).
///
/// Barycentric coordinate i belongs to local vertex i of the cell (`mesh.cell(c)[i]`).
///
///     alefsi::PointLocator2D loc(mesh);                  // PointLocator<3> for tetrahedra
///     Vec<3> lambda;
///     Index c = loc.locate(Vec<2>(0.3, 0.4), &lambda);   // cell, barycentrics
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/grid.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

/// Result of a point location (barycentric coordinates: D + 1 of them).
template <int D>
struct PointLocation {
  Index cell = -1;          ///< containing (or nearest) cell
  Vec<D + 1> lambda;        ///< barycentric coordinates in `cell`, clamped to the cell
  Vec<D + 1> raw;           ///< unclamped barycentric coordinates (== lambda inside)
  Real distance = 0;        ///< 0 inside the mesh, else distance from x to `cell`
};
using Location = PointLocation<2>;

namespace detail {

/// Barycentric coordinates of x in triangle (a, b, c) (any orientation, non-degenerate).
inline Vec<3> barycentric(const Vec<2>& a, const Vec<2>& b, const Vec<2>& c, const Vec<2>& x) {
  const Real det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  const Real l1 = ((x[0] - a[0]) * (c[1] - a[1]) - (x[1] - a[1]) * (c[0] - a[0])) / det;
  const Real l2 = ((b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0])) / det;
  return Vec<3>(1 - l1 - l2, l1, l2);
}

/// Barycentric coordinates of x in tetrahedron (a, b, c, d) (any orientation, non-degenerate):
/// ratios of signed volumes.
inline Vec<4> barycentric(const Vec<3>& a, const Vec<3>& b, const Vec<3>& c, const Vec<3>& d, const Vec<3>& x) {
  const Vec<3> ab = b - a, ac = c - a, ad = d - a, ax = x - a;
  const Real det = ab.dot(ac.cross(ad));
  const Real l1 = ax.dot(ac.cross(ad)) / det, l2 = ab.dot(ax.cross(ad)) / det, l3 = ab.dot(ac.cross(ax)) / det;
  return Vec<4>(1 - l1 - l2 - l3, l1, l2, l3);
}

/// Barycentric coordinates (in a, b, c) of the point of triangle (a, b, c)'s edges closest to x
/// (2D or 3D): the best of the three clamped projections.
template <int D>
Vec<3> closest_on_edges(const Vec<D>& a, const Vec<D>& b, const Vec<D>& c, const Vec<D>& x) {
  const std::array<const Vec<D>*, 3> p{&a, &b, &c};
  Real best = std::numeric_limits<Real>::infinity();
  Vec<3> out = Vec<3>::Zero();
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const Vec<D> d = *p[j] - *p[i];
    const Real t = std::clamp((x - *p[i]).dot(d) / d.squaredNorm(), Real(0), Real(1));
    const Real dist = (*p[i] + t * d - x).squaredNorm();
    if (dist < best) {
      best = dist;
      out.setZero();
      out[i] = 1 - t;
      out[j] = t;
    }
  }
  return out;
}

/// Barycentric coordinates of the point of triangle (a, b, c) closest to x.
inline Vec<3> closest_barycentric(const Vec<2>& a, const Vec<2>& b, const Vec<2>& c, const Vec<2>& x) {
  const Vec<3> l = barycentric(a, b, c, x);
  if (l.minCoeff() >= 0) return l;
  return closest_on_edges<2>(a, b, c, x);  // the closest point lies on an edge
}

/// Barycentric coordinates (in a, b, c) of the point of the 3D triangle (a, b, c) closest to x:
/// the projection onto its plane if that is inside, else the best of its three edges.
inline Vec<3> closest_barycentric(const Vec<3>& a, const Vec<3>& b, const Vec<3>& c, const Vec<3>& x) {
  const Vec<3> e1 = b - a, e2 = c - a, r = x - a;
  const Real g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2), r1 = r.dot(e1), r2 = r.dot(e2);
  const Real det = g11 * g22 - g12 * g12;
  const Real s = (g22 * r1 - g12 * r2) / det, t = (g11 * r2 - g12 * r1) / det;
  if (s >= 0 && t >= 0 && s + t <= 1) return Vec<3>(1 - s - t, s, t);
  return closest_on_edges<3>(a, b, c, x);
}

/// Barycentric coordinates of the point of tetrahedron (a, b, c, d) closest to x: x's own if
/// it is inside, else the best over the faces opposite the negative coordinates (only those
/// faces can hold the closest point).
inline Vec<4> closest_barycentric(const Vec<3>& a, const Vec<3>& b, const Vec<3>& c, const Vec<3>& d, const Vec<3>& x) {
  const Vec<4> l = barycentric(a, b, c, d, x);
  if (l.minCoeff() >= 0) return l;
  const std::array<const Vec<3>*, 4> p{&a, &b, &c, &d};
  Real best = std::numeric_limits<Real>::infinity();
  Vec<4> out = Vec<4>::Zero();
  for (int k = 0; k < 4; ++k) {
    if (l[k] >= 0) continue;
    const auto& f = SimplexTopology<3>::facets[k];  // the face opposite vertex k
    const Vec<3> q = closest_barycentric(*p[f[0]], *p[f[1]], *p[f[2]], x);
    const Real dist = (q[0] * *p[f[0]] + q[1] * *p[f[1]] + q[2] * *p[f[2]] - x).squaredNorm();
    if (dist < best) {
      best = dist;
      out.setZero();
      for (int i = 0; i < 3; ++i) out[f[i]] = q[i];
    }
  }
  return out;
}

/// Barycentric coordinates of x in cell c of a mesh, and of the cell's point closest to x.
template <int D>
Vec<D + 1> cell_barycentric(const Mesh<D>& m, Index c, const Vec<D>& x) {
  const auto& v = m.cell(c);
  if constexpr (D == 2)
    return barycentric(m.node(v[0]), m.node(v[1]), m.node(v[2]), x);
  else
    return barycentric(m.node(v[0]), m.node(v[1]), m.node(v[2]), m.node(v[3]), x);
}
template <int D>
Vec<D + 1> cell_closest_barycentric(const Mesh<D>& m, Index c, const Vec<D>& x) {
  const auto& v = m.cell(c);
  if constexpr (D == 2)
    return closest_barycentric(m.node(v[0]), m.node(v[1]), m.node(v[2]), x);
  else
    return closest_barycentric(m.node(v[0]), m.node(v[1]), m.node(v[2]), m.node(v[3]), x);
}

}  // namespace detail

template <int D>
class PointLocator {
  static_assert(D == 2 || D == 3, "PointLocator: triangles or tetrahedra");
  using Bary = Vec<D + 1>;
  using Cell = std::array<int, D>;  // a bucket's grid coordinates

 public:
  /// Builds the bucket grid (O(n_cells)). The mesh must outlive the locator.
  explicit PointLocator(const Mesh<D>& mesh, int max_walk = 64) : mesh_(&mesh), max_walk_(max_walk) {
    ALEFSI_CHECK_ARG(max_walk >= 0, "max_walk", "must be >= 0, got ", max_walk);
    lo_ = hi_ = mesh.node(0);
    for (const auto& x : mesh.coordinates()) lo_ = lo_.cwiseMin(x), hi_ = hi_.cwiseMax(x);
    const Vec<D> ext = (hi_ - lo_).cwiseMax(1e-300);
    // about one bucket per cell, cube-ish buckets
    const Real n = std::max<Real>(1, mesh.n_cells());
    const Real side = std::pow(ext.prod() / n, Real(1) / D);
    for (int d = 0; d < D; ++d) {
      n_[d] = std::clamp(static_cast<int>(std::ceil(ext[d] / std::max(side, 1e-300))), 1, D == 2 ? 1 << 14 : 1 << 10);
      inv_[d] = n_[d] / ext[d];
    }
    std::size_t nb = 1;
    for (int d = 0; d < D; ++d) nb *= static_cast<std::size_t>(n_[d]);
    start_.assign(nb + 1, 0);
    auto range = [&](Index c, Cell& i0, Cell& i1) {
      Vec<D> a = mesh.node(mesh.cell(c)[0]), b = a;
      for (Index v : mesh.cell(c)) a = a.cwiseMin(mesh.node(v)), b = b.cwiseMax(mesh.node(v));
      for (int d = 0; d < D; ++d) i0[d] = coord(a[d], d), i1[d] = coord(b[d], d);
    };
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      Cell i0, i1;
      range(c, i0, i1);
      for_each_in_box(i0, i1, [&](const Cell& i) { ++start_[bucket(i) + 1]; });
    }
    for (std::size_t b = 0; b < nb; ++b) start_[b + 1] += start_[b];
    items_.resize(start_[nb]);
    std::vector<Index> fill(start_.begin(), start_.end() - 1);
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      Cell i0, i1;
      range(c, i0, i1);
      for_each_in_box(i0, i1, [&](const Cell& i) { items_[fill[bucket(i)]++] = c; });
    }
  }

  /// Cell containing x (or the nearest cell, see the file comment); the clamped
  /// barycentric coordinates go to *lambda if given. `hint`: a cell near x (or -1).
  Index locate(const Vec<D>& x, Bary* lambda = nullptr, Index hint = -1) const {
    const PointLocation<D> l = find(x, hint);
    if (lambda) *lambda = l.lambda;
    return l.cell;
  }

  /// Full answer: cell, clamped and raw barycentrics, distance to the mesh.
  PointLocation<D> find(const Vec<D>& x, Index hint = -1) const {
    ALEFSI_CHECK_ARG(x.allFinite(), "x", "must be finite");
    ALEFSI_CHECK_ARG(hint < mesh_->n_cells(), "hint", "cell ", hint, " out of range");
    constexpr Real tol = -1e-12;
    if (hint >= 0) {
      Index c = hint;
      for (int step = 0; step <= max_walk_; ++step) {
        const Bary l = detail::cell_barycentric(*mesh_, c, x);
        Index k;
        if (l.minCoeff(&k) >= tol) return inside(c, l);
        const auto& fc = mesh_->facet_cells(mesh_->cell_facets(c)[k]);  // facet opposite vertex k
        const Index next = fc[0] == c ? fc[1] : fc[0];
        if (next < 0) break;
        c = next;
      }
    }
    // bucket scan: the cell whose smallest barycentric coordinate is largest
    if ((x.array() >= lo_.array()).all() && (x.array() <= hi_.array()).all()) {
      Cell i;
      for (int d = 0; d < D; ++d) i[d] = coord(x[d], d);
      const std::size_t b = bucket(i);
      Real best = -std::numeric_limits<Real>::infinity();
      Index bc = -1;
      Bary bl;
      for (Index p = start_[b]; p < start_[b + 1]; ++p) {
        const Index c = items_[p];
        const Bary l = detail::cell_barycentric(*mesh_, c, x);
        if (l.minCoeff() > best) best = l.minCoeff(), bc = c, bl = l;
      }
      if (bc >= 0 && best >= tol) return inside(bc, bl);
    }
    return nearest(x);
  }

  const Mesh<D>& mesh() const { return *mesh_; }

 private:
  int coord(Real x, int d) const { return std::clamp(static_cast<int>((x - lo_[d]) * inv_[d]), 0, n_[d] - 1); }
  std::size_t bucket(const Cell& i) const {
    std::size_t b = 0;
    for (int d = D - 1; d >= 0; --d) b = b * static_cast<std::size_t>(n_[d]) + static_cast<std::size_t>(i[d]);
    return b;
  }
  static PointLocation<D> inside(Index c, const Bary& l) {
    PointLocation<D> out;
    out.cell = c;
    out.raw = l;
    // tiny negative round-off: clamp and renormalise (changes values by ~1e-12 relative)
    out.lambda = l.cwiseMax(0.0);
    out.lambda /= out.lambda.sum();
    out.distance = 0;
    return out;
  }

  /// Nearest cell by shells of buckets around x (Chebyshev rings); stops once the ring is
  /// farther than the best distance found.
  PointLocation<D> nearest(const Vec<D>& x) const {
    Real step = std::numeric_limits<Real>::infinity();
    Cell ci;
    int max_ring = 0, far = 0;
    for (int d = 0; d < D; ++d) {
      step = std::min(step, (hi_[d] - lo_[d]) / n_[d]);
      ci[d] = static_cast<int>(std::floor((x[d] - lo_[d]) * inv_[d]));
      max_ring = std::max(max_ring, n_[d]);
      far = std::max({far, std::abs(ci[d]), std::abs(ci[d] - n_[d])});
    }
    max_ring += far;
    Real best = std::numeric_limits<Real>::infinity();
    PointLocation<D> out;
    auto visit = [&](const Cell& i) {
      const std::size_t b = bucket(i);
      for (Index p = start_[b]; p < start_[b + 1]; ++p) {
        const Index c = items_[p];
        const Bary l = detail::cell_closest_barycentric(*mesh_, c, x);
        const auto& v = mesh_->cell(c);
        Vec<D> q = Vec<D>::Zero();
        for (int k = 0; k <= D; ++k) q += l[k] * mesh_->node(v[k]);
        const Real dist = (q - x).norm();
        if (dist < best || (dist == best && c < out.cell)) {
          best = dist;
          out.cell = c;
          out.lambda = l;
          out.raw = detail::cell_barycentric(*mesh_, c, x);
          out.distance = dist;
        }
      }
    };
    for (int r = 0; r <= max_ring; ++r) {
      // every point in ring r is at least (r - 1) * step away from x
      if (out.cell >= 0 && (r - 1) * step > best) break;
      Cell i0, i1, j0, j1;  // the ring's box, and that box clipped to the grid
      bool empty = false;
      for (int d = 0; d < D; ++d) {
        i0[d] = ci[d] - r, i1[d] = ci[d] + r;
        j0[d] = std::max(i0[d], 0), j1[d] = std::min(i1[d], n_[d] - 1);
        empty = empty || j0[d] > j1[d];
      }
      if (empty) continue;
      // the shell of the box: the cells with at least one coordinate on its faces
      for_each_in_box(j0, j1, [&](const Cell& i) {
        for (int d = 0; d < D; ++d)
          if (i[d] == i0[d] || i[d] == i1[d]) return visit(i);
      });
    }
    return out;
  }

  const Mesh<D>* mesh_;
  int max_walk_;
  Vec<D> lo_, hi_, inv_;
  Cell n_;
  std::vector<Index> start_, items_;
};

using PointLocator2D = PointLocator<2>;

}  // namespace alefsi
