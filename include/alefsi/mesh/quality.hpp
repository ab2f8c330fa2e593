#pragma once
/// \file mesh/quality.hpp
/// The quality figures a remesh reports: the worst shape quality (Mesh::quality: 1 for the
/// regular simplex; in 3D the normalised volume-to-edge ratio 12 (3V)^(2/3) / sum l^2) and, in
/// 3D, the smallest and largest dihedral angles (the angle between the two faces at an edge;
/// 70.53 degrees everywhere in the regular tetrahedron). A sliver has a small quality and both
/// extreme angles near 0 and 180 degrees; a needle a small quality with moderate angles.
///
///     auto q = alefsi::quality_stats(mesh);   // q.worst, q.min_dihedral_deg, q.max_dihedral_deg
#include <algorithm>
#include <cmath>
#include <numbers>

#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

struct QualityStats {
  Real worst = 1;                  ///< smallest Mesh::quality
  Real min_dihedral_deg = 180;     ///< 3D only (0 / 180 in 2D: not computed)
  Real max_dihedral_deg = 0;
};

/// The six dihedral angles (radians) of the tetrahedron (a, b, c, d), one per edge.
inline std::array<Real, 6> dihedral_angles(const Vec<3>& a, const Vec<3>& b, const Vec<3>& c, const Vec<3>& d) {
  const std::array<Vec<3>, 4> p{a, b, c, d};
  // n[k]: normal of the face opposite vertex k, pointing away from vertex k
  std::array<Vec<3>, 4> n;
  for (int k = 0; k < 4; ++k) {
    const Vec<3>& u = p[(k + 1) % 4];
    Vec<3> m = (p[(k + 2) % 4] - u).cross(p[(k + 3) % 4] - u);
    if (m.dot(u - p[k]) < 0) m = -m;
    n[k] = m.normalized();
  }
  // the edge (i, j) is shared by the faces opposite the two other vertices k, l
  static constexpr std::array<std::array<int, 2>, 6> opposite{{{2, 3}, {1, 3}, {1, 2}, {0, 3}, {0, 2}, {0, 1}}};
  std::array<Real, 6> angle;
  for (int e = 0; e < 6; ++e) {
    const Real cosine = std::clamp(n[opposite[e][0]].dot(n[opposite[e][1]]), Real(-1), Real(1));
    angle[e] = std::numbers::pi - std::acos(cosine);
  }
  return angle;
}

template <int D>
QualityStats quality_stats(const Mesh<D>& mesh) {
  QualityStats s;
  if constexpr (D == 2) s.min_dihedral_deg = 0, s.max_dihedral_deg = 180;
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    s.worst = std::min(s.worst, mesh.quality(c));
    if constexpr (D == 3) {
      const auto& v = mesh.cell(c);
      for (Real a : dihedral_angles(mesh.node(v[0]), mesh.node(v[1]), mesh.node(v[2]), mesh.node(v[3]))) {
        s.min_dihedral_deg = std::min(s.min_dihedral_deg, a * 180 / std::numbers::pi);
        s.max_dihedral_deg = std::max(s.max_dihedral_deg, a * 180 / std::numbers::pi);
      }
    }
  }
  return s;
}

}  // namespace alefsi
