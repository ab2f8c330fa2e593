#pragma once
/// \file mesh/adapt/locate.hpp
/// Point location in a 2D triangle mesh: which cell contains x, and x's barycentric
/// coordinates in it.
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
/// Cost: construction O(n_cells) time and memory. A query costs O(cells per bucket),
/// O(1) for quasi-uniform meshes; graded meshes put more cells in the buckets of their
/// fine regions, which a hint avoids: queries made in the order of a nearby mesh's nodes
/// with the previous answer as hint cost O(1) each (O(n) for a whole transfer). Points
/// outside the mesh cost O(cells within the distance to the mesh).
///
/// Barycentric coordinate i belongs to local vertex i of the cell (`mesh.cell(c)[i]`).
///
///     alefsi::PointLocator2D loc(mesh);
///     Vec<3> lambda;
///     Index c = loc.locate(Vec<2>(0.3, 0.4), &lambda);   // cell, barycentrics
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

/// Result of a point location.
struct Location {
  Index cell = -1;          ///< containing (or nearest) cell
  Vec<3> lambda;            ///< barycentric coordinates in `cell`, clamped to the cell
  Vec<3> raw;               ///< unclamped barycentric coordinates (== lambda inside)
  Real distance = 0;        ///< 0 inside the mesh, else distance from x to `cell`
};

namespace detail {

/// Barycentric coordinates of x in triangle (a, b, c) (any orientation, non-degenerate).
inline Vec<3> barycentric(const Vec<2>& a, const Vec<2>& b, const Vec<2>& c, const Vec<2>& x) {
  const Real det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  const Real l1 = ((x[0] - a[0]) * (c[1] - a[1]) - (x[1] - a[1]) * (c[0] - a[0])) / det;
  const Real l2 = ((b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0])) / det;
  return Vec<3>(1 - l1 - l2, l1, l2);
}

/// Barycentric coordinates of the point of triangle (a, b, c) closest to x.
inline Vec<3> closest_barycentric(const Vec<2>& a, const Vec<2>& b, const Vec<2>& c, const Vec<2>& x) {
  Vec<3> l = barycentric(a, b, c, x);
  if (l.minCoeff() >= 0) return l;
  // closest point lies on one of the edges: take the best of the three projections
  const std::array<const Vec<2>*, 3> p{&a, &b, &c};
  Real best = std::numeric_limits<Real>::infinity();
  Vec<3> out = l;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const Vec<2> d = *p[j] - *p[i];
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

}  // namespace detail

class PointLocator2D {
 public:
  /// Builds the bucket grid (O(n_cells)). The mesh must outlive the locator.
  explicit PointLocator2D(const Mesh<2>& mesh, int max_walk = 64) : mesh_(&mesh), max_walk_(max_walk) {
    ALEFSI_CHECK_ARG(max_walk >= 0, "max_walk", "must be >= 0, got ", max_walk);
    lo_ = hi_ = mesh.node(0);
    for (const auto& x : mesh.coordinates()) lo_ = lo_.cwiseMin(x), hi_ = hi_.cwiseMax(x);
    const Vec<2> ext = (hi_ - lo_).cwiseMax(1e-300);
    // about one bucket per cell, square-ish buckets
    const Real n = std::max<Real>(1, mesh.n_cells());
    const Real side = std::sqrt(ext[0] * ext[1] / n);
    nx_ = std::clamp(static_cast<int>(std::ceil(ext[0] / std::max(side, 1e-300))), 1, 1 << 14);
    ny_ = std::clamp(static_cast<int>(std::ceil(ext[1] / std::max(side, 1e-300))), 1, 1 << 14);
    inv_ = Vec<2>(nx_ / ext[0], ny_ / ext[1]);
    const std::size_t nb = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
    start_.assign(nb + 1, 0);
    auto range = [&](Index c, int& i0, int& i1, int& j0, int& j1) {
      Vec<2> a = mesh.node(mesh.cell(c)[0]), b = a;
      for (Index v : mesh.cell(c)) a = a.cwiseMin(mesh.node(v)), b = b.cwiseMax(mesh.node(v));
      i0 = bx(a[0]), i1 = bx(b[0]), j0 = by(a[1]), j1 = by(b[1]);
    };
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      int i0, i1, j0, j1;
      range(c, i0, i1, j0, j1);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) ++start_[bucket(i, j) + 1];
    }
    for (std::size_t b = 0; b < nb; ++b) start_[b + 1] += start_[b];
    items_.resize(start_[nb]);
    std::vector<Index> fill(start_.begin(), start_.end() - 1);
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      int i0, i1, j0, j1;
      range(c, i0, i1, j0, j1);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) items_[fill[bucket(i, j)]++] = c;
    }
  }

  /// Cell containing x (or the nearest cell, see the file comment); the clamped
  /// barycentric coordinates go to *lambda if given. `hint`: a cell near x (or -1).
  Index locate(const Vec<2>& x, Vec<3>* lambda = nullptr, Index hint = -1) const {
    const Location l = find(x, hint);
    if (lambda) *lambda = l.lambda;
    return l.cell;
  }

  /// Full answer: cell, clamped and raw barycentrics, distance to the mesh.
  Location find(const Vec<2>& x, Index hint = -1) const {
    ALEFSI_CHECK_ARG(std::isfinite(x[0]) && std::isfinite(x[1]), "x", "must be finite");
    ALEFSI_CHECK_ARG(hint < mesh_->n_cells(), "hint", "cell ", hint, " out of range");
    constexpr Real tol = -1e-12;
    Location out;
    if (hint >= 0) {
      Index c = hint;
      for (int step = 0; step <= max_walk_; ++step) {
        const Vec<3> l = bary(c, x);
        Index k;
        if (l.minCoeff(&k) >= tol) return inside(c, l);
        const auto& fc = mesh_->facet_cells(mesh_->cell_facets(c)[k]);  // facet opposite vertex k
        const Index next = fc[0] == c ? fc[1] : fc[0];
        if (next < 0) break;
        c = next;
      }
    }
    // bucket scan: the cell whose smallest barycentric coordinate is largest
    if (x[0] >= lo_[0] && x[0] <= hi_[0] && x[1] >= lo_[1] && x[1] <= hi_[1]) {
      const std::size_t b = bucket(bx(x[0]), by(x[1]));
      Real best = -std::numeric_limits<Real>::infinity();
      Index bc = -1;
      Vec<3> bl;
      for (Index p = start_[b]; p < start_[b + 1]; ++p) {
        const Index c = items_[p];
        const Vec<3> l = bary(c, x);
        if (l.minCoeff() > best) best = l.minCoeff(), bc = c, bl = l;
      }
      if (bc >= 0 && best >= tol) return inside(bc, bl);
    }
    return nearest(x);
  }

  const Mesh<2>& mesh() const { return *mesh_; }

 private:
  int bx(Real x) const { return std::clamp(static_cast<int>((x - lo_[0]) * inv_[0]), 0, nx_ - 1); }
  int by(Real y) const { return std::clamp(static_cast<int>((y - lo_[1]) * inv_[1]), 0, ny_ - 1); }
  std::size_t bucket(int i, int j) const { return static_cast<std::size_t>(j) * nx_ + i; }

  Vec<3> bary(Index c, const Vec<2>& x) const {
    const auto& v = mesh_->cell(c);
    return detail::barycentric(mesh_->node(v[0]), mesh_->node(v[1]), mesh_->node(v[2]), x);
  }

  static Location inside(Index c, const Vec<3>& l) {
    Location out;
    out.cell = c;
    out.raw = l;
    // tiny negative round-off: clamp and renormalise (changes values by ~1e-12 relative)
    out.lambda = l.cwiseMax(0.0);
    out.lambda /= out.lambda.sum();
    out.distance = 0;
    return out;
  }

  /// Nearest cell by rings of buckets around x; stops once the ring is farther than the
  /// best distance found.
  Location nearest(const Vec<2>& x) const {
    const Vec<2> cell_size((hi_[0] - lo_[0]) / nx_, (hi_[1] - lo_[1]) / ny_);
    const Real step = std::min(cell_size[0], cell_size[1]);
    // distance from x to the grid box, in rings
    const int ci = static_cast<int>(std::floor((x[0] - lo_[0]) * inv_[0]));
    const int cj = static_cast<int>(std::floor((x[1] - lo_[1]) * inv_[1]));
    Real best = std::numeric_limits<Real>::infinity();
    Location out;
    const int max_ring = std::max(nx_, ny_) + std::max({std::abs(ci), std::abs(cj), std::abs(ci - nx_), std::abs(cj - ny_)});
    for (int r = 0; r <= max_ring; ++r) {
      // every point in ring r is at least (r - 1) * step away from x
      if (out.cell >= 0 && (r - 1) * step > best) break;
      for (int j = cj - r; j <= cj + r; ++j) {
        if (j < 0 || j >= ny_) continue;
        const bool edge_row = j == cj - r || j == cj + r;
        for (int i = ci - r; i <= ci + r; i += (edge_row ? 1 : 2 * r)) {
          if (i >= 0 && i < nx_) {
            const std::size_t b = bucket(i, j);
            for (Index p = start_[b]; p < start_[b + 1]; ++p) {
              const Index c = items_[p];
              const auto& v = mesh_->cell(c);
              const Vec<2>&a = mesh_->node(v[0]), &bb = mesh_->node(v[1]), &cc = mesh_->node(v[2]);
              const Vec<3> l = detail::closest_barycentric(a, bb, cc, x);
              const Real d = (l[0] * a + l[1] * bb + l[2] * cc - x).norm();
              if (d < best || (d == best && c < out.cell)) {
                best = d;
                out.cell = c;
                out.lambda = l;
                out.raw = detail::barycentric(a, bb, cc, x);
                out.distance = d;
              }
            }
          }
          if (r == 0) break;
        }
      }
    }
    return out;
  }

  const Mesh<2>* mesh_;
  int max_walk_;
  Vec<2> lo_, hi_, inv_;
  int nx_ = 1, ny_ = 1;
  std::vector<Index> start_, items_;
};

}  // namespace alefsi
