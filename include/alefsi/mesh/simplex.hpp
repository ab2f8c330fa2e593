#pragma once
/// \file mesh/simplex.hpp
/// Reference-simplex conventions shared by meshes and finite elements.
///
/// Local vertex i of a cell is the reference vertex 0 (origin) for i = 0 and e_i otherwise.
/// Local edges follow the VTK quadratic-cell order, so a P2 cell's mid-edge nodes can be
/// written to VTU without permutation:
///   triangle:    (0,1) (1,2) (2,0)
///   tetrahedron: (0,1) (1,2) (2,0) (0,3) (1,3) (2,3)
/// Local facet i is the one opposite vertex i; its vertices are listed in increasing local order.
#include <array>

#include "alefsi/core/types.hpp"

namespace alefsi {

template <int D>
struct SimplexTopology;

template <>
struct SimplexTopology<2> {
  static constexpr std::array<std::array<int, 2>, 3> edges{{{0, 1}, {1, 2}, {2, 0}}};
  static constexpr std::array<std::array<int, 2>, 3> facets{{{1, 2}, {0, 2}, {0, 1}}};
};

template <>
struct SimplexTopology<3> {
  static constexpr std::array<std::array<int, 2>, 6> edges{
      {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}};
  static constexpr std::array<std::array<int, 3>, 4> facets{
      {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}}};
};

/// Coordinates of reference vertex i.
template <int D>
Vec<D> reference_vertex(int i) {
  Vec<D> x = Vec<D>::Zero();
  if (i > 0) x[i - 1] = 1.0;
  return x;
}

}  // namespace alefsi
