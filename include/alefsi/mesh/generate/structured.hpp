#pragma once
/// \file mesh/generate/structured.hpp
/// Structured simplex meshes for tests and simple scenes: rectangle, box and annulus.
///
/// Boundary tags (constants in `alefsi::tags`):
///   rectangle: bottom = 1 (y = y0), right = 2 (x = x1), top = 3 (y = y1), left = 4 (x = x0)
///   box:       xmin = 1, xmax = 2, ymin = 3, ymax = 4, zmin = 5, zmax = 6
///   annulus, spherical shell:   inner = 1, outer = 2
///
///     auto sq = alefsi::rectangle_mesh(16, 16);                   // [0,1]^2, 512 triangles
///     auto cube = alefsi::box_mesh(4, 4, 4);                      // [0,1]^3, 384 tetrahedra
///     auto ring = alefsi::annulus_mesh(0.25, 1.0, 8, 64);         // radii 0.25 and 1
///     auto shell = alefsi::spherical_shell_mesh(0.5, 1.0, 2);     // 2 layers, 2,688 tetrahedra
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

namespace tags {
inline constexpr int bottom = 1, right = 2, top = 3, left = 4;
inline constexpr int xmin = 1, xmax = 2, ymin = 3, ymax = 4, zmin = 5, zmax = 6;
inline constexpr int inner = 1, outer = 2;
}  // namespace tags

/// [x0,x1] x [y0,y1] cut into nx * ny rectangles, each split into two triangles along the
/// diagonal from its lower-left to its upper-right corner.
inline Mesh<2> rectangle_mesh(int nx, int ny, Real x0 = 0, Real x1 = 1, Real y0 = 0, Real y1 = 1) {
  ALEFSI_CHECK_ARG(nx >= 1, "nx", "must be >= 1, got ", nx);
  ALEFSI_CHECK_ARG(ny >= 1, "ny", "must be >= 1, got ", ny);
  ALEFSI_CHECK_ARG(x1 > x0, "x1", "must exceed x0");
  ALEFSI_CHECK_ARG(y1 > y0, "y1", "must exceed y0");
  std::vector<Vec<2>> x;
  x.reserve(std::size_t(nx + 1) * (ny + 1));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) x.emplace_back(x0 + (x1 - x0) * i / nx, y0 + (y1 - y0) * j / ny);
  auto id = [&](int i, int j) { return Index(j * (nx + 1) + i); };
  std::vector<Mesh<2>::Cell> cells;
  cells.reserve(std::size_t(2) * nx * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      cells.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      cells.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  std::vector<Mesh<2>::Facet> bf;
  std::vector<int> bt;
  for (int i = 0; i < nx; ++i) {
    bf.push_back({id(i, 0), id(i + 1, 0)}), bt.push_back(tags::bottom);
    bf.push_back({id(i, ny), id(i + 1, ny)}), bt.push_back(tags::top);
  }
  for (int j = 0; j < ny; ++j) {
    bf.push_back({id(0, j), id(0, j + 1)}), bt.push_back(tags::left);
    bf.push_back({id(nx, j), id(nx, j + 1)}), bt.push_back(tags::right);
  }
  return Mesh<2>(std::move(x), std::move(cells), bf, bt);
}

/// [x0,x1] x [y0,y1] x [z0,z1] cut into nx * ny * nz boxes, each split into six tetrahedra
/// around its main diagonal (Kuhn triangulation; conforming across boxes).
inline Mesh<3> box_mesh(int nx, int ny, int nz, const Vec<3>& lo = Vec<3>::Zero(),
                        const Vec<3>& hi = Vec<3>::Ones()) {
  ALEFSI_CHECK_ARG(nx >= 1 && ny >= 1 && nz >= 1, "nx, ny, nz", "must be >= 1");
  ALEFSI_CHECK_ARG((hi - lo).minCoeff() > 0, "hi", "must exceed lo in every coordinate");
  const std::array<int, 3> n{nx, ny, nz};
  std::vector<Vec<3>> x;
  x.reserve(std::size_t(nx + 1) * (ny + 1) * (nz + 1));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        x.emplace_back(lo[0] + (hi[0] - lo[0]) * i / nx, lo[1] + (hi[1] - lo[1]) * j / ny,
                       lo[2] + (hi[2] - lo[2]) * k / nz);
  auto id = [&](std::array<int, 3> p) { return Index((p[2] * (ny + 1) + p[1]) * (nx + 1) + p[0]); };
  static constexpr std::array<std::array<int, 3>, 6> perms{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  static constexpr std::array<bool, 6> odd{false, true, true, false, false, true};
  std::vector<Mesh<3>::Cell> cells;
  cells.reserve(std::size_t(6) * nx * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (int p = 0; p < 6; ++p) {
          std::array<int, 3> q{i, j, k};
          Mesh<3>::Cell c;
          c[0] = id(q);
          for (int s = 0; s < 3; ++s) {
            ++q[perms[p][s]];
            c[s + 1] = id(q);
          }
          if (odd[p]) std::swap(c[1], c[2]);
          cells.push_back(c);
        }
  // boundary: each box face split into two triangles consistently with the Kuhn split
  std::vector<Mesh<3>::Facet> bf;
  std::vector<int> bt;
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side)
      for (int u = 0; u < n[a]; ++u)
        for (int v = 0; v < n[b]; ++v) {
          std::array<int, 3> p0{}, p1{}, p2{}, p3{};
          p0[axis] = p1[axis] = p2[axis] = p3[axis] = side * n[axis];
          p0[a] = u, p0[b] = v;
          p1 = p0, ++p1[a];
          p2 = p0, ++p2[b];
          p3 = p1, ++p3[b];
          bf.push_back({id(p0), id(p1), id(p3)}), bt.push_back(2 * axis + 1 + side);
          bf.push_back({id(p0), id(p2), id(p3)}), bt.push_back(2 * axis + 1 + side);
        }
  }
  return Mesh<3>(std::move(x), std::move(cells), bf, bt);
}

/// The annulus r1 < |x - centre| < r2 with nr layers of cells across the gap and nt
/// sectors around; nodes on both circles lie exactly on the circles.
inline Mesh<2> annulus_mesh(Real r1, Real r2, int nr, int nt, const Vec<2>& centre = Vec<2>::Zero()) {
  ALEFSI_CHECK_ARG(r1 > 0, "r1", "must be positive, got ", r1);
  ALEFSI_CHECK_ARG(r2 > r1, "r2", "must exceed r1");
  ALEFSI_CHECK_ARG(nr >= 1, "nr", "must be >= 1, got ", nr);
  ALEFSI_CHECK_ARG(nt >= 3, "nt", "must be >= 3, got ", nt);
  std::vector<Vec<2>> x;
  for (int j = 0; j <= nr; ++j) {
    const Real r = r1 + (r2 - r1) * j / nr;
    for (int i = 0; i < nt; ++i) {
      const Real t = 2 * std::numbers::pi * i / nt;
      x.push_back(centre + r * Vec<2>(std::cos(t), std::sin(t)));
    }
  }
  auto id = [&](int i, int j) { return Index(j * nt + (i % nt)); };
  // (angle, radius) -> (x, y) reverses orientation, hence the vertex order below
  std::vector<Mesh<2>::Cell> cells;
  for (int j = 0; j < nr; ++j)
    for (int i = 0; i < nt; ++i) {
      if ((i + j) % 2 == 0) {
        cells.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
        cells.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      } else {
        cells.push_back({id(i, j), id(i, j + 1), id(i + 1, j)});
        cells.push_back({id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)});
      }
    }
  std::vector<Mesh<2>::Facet> bf;
  std::vector<int> bt;
  for (int i = 0; i < nt; ++i) {
    bf.push_back({id(i, 0), id(i + 1, 0)}), bt.push_back(tags::inner);
    bf.push_back({id(i, nr), id(i + 1, nr)}), bt.push_back(tags::outer);
  }
  return Mesh<2>(std::move(x), std::move(cells), bf, bt);
}

/// The spherical shell r1 < |x - centre| < r2 with n layers of cells across the gap: the cube
/// [-1, 1]^3 cut into (4n)^3 boxes, the central (2n)^3 (the cube [-1/2, 1/2]^3) removed, the
/// rest split into six tetrahedra around a diagonal (336 n^3 tetrahedra), then mapped onto the
/// shell by the equiangular cubed-sphere map: on the face |p_k| = s = |p|_inf of a cube shell
/// the other two coordinates go to s tan(pi/4 p_j / s) (equal angles along the face), and the
/// point to radius r1 + (r2 - r1) (2 s - 1) along that direction. The split is box_mesh's
/// mirrored into each octant (every box's diagonal points at the centre, conforming across the
/// mirror planes), so that no tetrahedron has its four vertices on one sphere (the corner and
/// edge boxes of a cube shell would otherwise give flat slivers on the sphere). Nodes on both
/// spheres lie exactly on them; sizes vary by about 1.4 between face centres and corners.
inline Mesh<3> spherical_shell_mesh(Real r1, Real r2, int n, const Vec<3>& centre = Vec<3>::Zero()) {
  ALEFSI_CHECK_ARG(r1 > 0 && std::isfinite(r1), "r1", "must be positive and finite, got ", r1);
  ALEFSI_CHECK_ARG(r2 > r1 && std::isfinite(r2), "r2", "must be finite and exceed r1, got ", r2);
  ALEFSI_CHECK_ARG(n >= 1, "n", "must be >= 1, got ", n);
  const int m = 4 * n;
  auto grid = [&](const std::array<int, 3>& q) { return std::size_t((q[2] * (m + 1) + q[1]) * (m + 1) + q[0]); };
  auto removed = [&](int i, int j, int k) {  // box (i, j, k) inside the inner cube
    return i >= n && i < 3 * n && j >= n && j < 3 * n && k >= n && k < 3 * n;
  };
  // nodes: every grid point not strictly inside the inner cube, mapped onto the shell
  std::vector<Index> id(std::size_t(m + 1) * (m + 1) * (m + 1), -1);
  std::vector<Vec<3>> x;
  std::vector<char> on_sphere;  // 1 inner, 2 outer, 0 neither
  for (int k = 0; k <= m; ++k)
    for (int j = 0; j <= m; ++j)
      for (int i = 0; i <= m; ++i) {
        if (i > n && i < 3 * n && j > n && j < 3 * n && k > n && k < 3 * n) continue;
        Vec<3> p(Real(2 * i - m) / m, Real(2 * j - m) / m, Real(2 * k - m) / m);
        const Real s = p.cwiseAbs().maxCoeff();
        for (int d = 0; d < 3; ++d)
          if (std::abs(p[d]) < s) p[d] = s * std::tan(std::numbers::pi / 4 * p[d] / s);
        id[grid({i, j, k})] = Index(x.size());
        x.push_back(centre + (r1 + (r2 - r1) * (2 * s - 1)) * p.normalized());
        const int is = std::max({std::abs(2 * i - m), std::abs(2 * j - m), std::abs(2 * k - m)});
        on_sphere.push_back(is == m ? 2 : is == m / 2 ? 1 : 0);
      }
  // cells: six tetrahedra per box along monotone paths from the box's outer corner to its inner one
  static constexpr std::array<std::array<int, 3>, 6> perms{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  std::vector<Mesh<3>::Cell> cells;
  cells.reserve(std::size_t(336) * n * n * n);
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        if (removed(i, j, k)) continue;
        const std::array<int, 3> box{i, j, k};
        std::array<int, 3> start{}, step{};
        for (int d = 0; d < 3; ++d) {
          const bool upper = 2 * box[d] >= m;  // the diagonal runs towards the centre
          start[d] = upper ? box[d] + 1 : box[d];
          step[d] = upper ? -1 : 1;
        }
        for (const auto& perm : perms) {
          std::array<int, 3> q = start;
          Mesh<3>::Cell c;
          c[0] = id[grid(q)];
          for (int t = 0; t < 3; ++t) {
            q[perm[t]] += step[perm[t]];
            c[t + 1] = id[grid(q)];
          }
          const Mat<3> J = (Mat<3>() << x[std::size_t(c[1])] - x[std::size_t(c[0])],
                            x[std::size_t(c[2])] - x[std::size_t(c[0])], x[std::size_t(c[3])] - x[std::size_t(c[0])])
                               .finished();
          if (J.determinant() < 0) std::swap(c[1], c[2]);
          cells.push_back(c);
        }
      }
  // boundary: the facets of one cell only; on the inner or the outer sphere
  std::map<std::array<Index, 3>, int> count;
  for (const auto& c : cells)
    for (const auto& lf : SimplexTopology<3>::facets) {
      std::array<Index, 3> f{c[lf[0]], c[lf[1]], c[lf[2]]};
      std::sort(f.begin(), f.end());
      ++count[f];
    }
  std::vector<Mesh<3>::Facet> bf;
  std::vector<int> bt;
  for (const auto& [f, k] : count) {
    if (k != 1) continue;
    bf.push_back({f[0], f[1], f[2]});
    bt.push_back(on_sphere[std::size_t(f[0])] == 1 ? tags::inner : tags::outer);
  }
  return Mesh<3>(std::move(x), std::move(cells), bf, bt);
}

}  // namespace alefsi
