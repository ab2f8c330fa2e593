#pragma once
/// \file mesh/generate/structured.hpp
/// Structured simplex meshes for tests and simple scenes: rectangle, box and annulus.
///
/// Boundary tags (constants in `alefsi::tags`):
///   rectangle: bottom = 1 (y = y0), right = 2 (x = x1), top = 3 (y = y1), left = 4 (x = x0)
///   box:       xmin = 1, xmax = 2, ymin = 3, ymax = 4, zmin = 5, zmax = 6
///   annulus:   inner = 1, outer = 2
///
///     auto sq = alefsi::rectangle_mesh(16, 16);                   // [0,1]^2, 512 triangles
///     auto cube = alefsi::box_mesh(4, 4, 4);                      // [0,1]^3, 384 tetrahedra
///     auto ring = alefsi::annulus_mesh(0.25, 1.0, 8, 64);         // radii 0.25 and 1
#include <array>
#include <cmath>
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

}  // namespace alefsi
