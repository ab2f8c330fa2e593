#pragma once
/// \file core/types.hpp
/// Scalar and index types and small fixed-size vectors used throughout alefsi.
///
/// `Real` is the floating-point type of every field and coordinate; `Index` is the
/// integer type of mesh entities, DOFs and sparse-matrix indices (32 bit: meshes up to
/// 2^31 entities, which is what Eigen's default sparse storage index supports too).
#include <cstdint>

#include "alefsi/core/eigen.hpp"

namespace alefsi {

using Real = double;
using Index = std::int32_t;

/// A point or vector in R^D (column vector).
template <int D>
using Vec = Eigen::Matrix<Real, D, 1>;

/// A D x E matrix, e.g. the Jacobian of the reference-to-physical map.
template <int D, int E = D>
using Mat = Eigen::Matrix<Real, D, E>;

/// Dynamic vectors and matrices (solution vectors, element matrices of run-time size).
using VecX = Eigen::Matrix<Real, Eigen::Dynamic, 1>;
using MatX = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;

/// Number of vertices, edges and facets of the D-simplex.
template <int D>
inline constexpr int simplex_vertices = D + 1;
template <int D>
inline constexpr int simplex_edges = (D + 1) * D / 2;
template <int D>
inline constexpr int simplex_facets = D + 1;

/// Measure of the reference simplex {x_i >= 0, sum x_i <= 1}: 1/D!.
template <int D>
inline constexpr Real reference_measure = D == 1 ? 1.0 : (D == 2 ? 0.5 : 1.0 / 6.0);

}  // namespace alefsi
