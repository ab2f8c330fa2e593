#pragma once
/// \file mesh/generate/spheres_in_box.hpp
/// The scene of the 3D particulate flows: spheres in an axis-aligned box (no-slip walls), as
/// the 3D mesher (mesh/generate/gmsh_mesher.hpp) and remesher (sim/remesher3d.hpp) see it, and
/// the size function graded away from the spheres. No dependency beyond Eigen: a scene can be
/// described and checked without gmsh.
///
///     alefsi::BoxDomain box{.lo = Vec<3>(-5, -5, 0), .hi = Vec<3>(5, 5, 16)};  // faces tagged 1..6
///     std::vector<alefsi::Sphere> s = {{.centre = Vec<3>(0, 0, 12.75), .radius = 0.75, .tag = 7}};
///     alefsi::check_spheres_in_box(box, s);    // refuses spheres outside / touching / overlapping
///     auto h = alefsi::graded_size(s, 0.1, 1.0);
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/mesh/generate/structured.hpp"

namespace alefsi {

/// The fluid's box [lo, hi] and the tags of its faces, in the order xmin, xmax, ymin, ymax,
/// zmin, zmax (box_mesh's tags by default).
struct BoxDomain {
  Vec<3> lo = Vec<3>::Zero(), hi = Vec<3>::Ones();
  std::array<int, 6> tags{tags::xmin, tags::xmax, tags::ymin, tags::ymax, tags::zmin, tags::zmax};

  void validate() const {
    ALEFSI_CHECK_ARG(lo.allFinite() && hi.allFinite() && (hi - lo).minCoeff() > 0, "box.hi",
                     "must exceed box.lo in every coordinate");
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < i; ++j)
        ALEFSI_CHECK_ARG(tags[i] != tags[j], "box.tags", "faces ", j, " and ", i, " share the tag ", tags[i]);
  }
};

/// A sphere in the box (a body: its surface facets get `tag`).
struct Sphere {
  Vec<3> centre = Vec<3>::Zero();
  Real radius = 0;
  int tag = 0;
};

using SizeFunction3D = std::function<Real(const Vec<3>&)>;

/// h(x) = min(h_far, h_body + grading * distance(x, nearest sphere surface)); h_body inside.
inline SizeFunction3D graded_size(std::vector<Sphere> spheres, Real h_body, Real h_far, Real grading = 0.2) {
  ALEFSI_CHECK_ARG(h_body > 0 && std::isfinite(h_body), "h_body", "must be positive and finite, got ", h_body);
  ALEFSI_CHECK_ARG(h_far >= h_body && std::isfinite(h_far), "h_far", "must be finite and >= h_body, got ", h_far);
  ALEFSI_CHECK_ARG(grading > 0 && std::isfinite(grading), "grading", "must be positive and finite, got ", grading);
  for (std::size_t i = 0; i < spheres.size(); ++i)
    ALEFSI_CHECK_ARG(spheres[i].radius > 0, "bodies[" + std::to_string(i) + "].radius", "must be positive, got ",
                     spheres[i].radius);
  return [spheres = std::move(spheres), h_body, h_far, grading](const Vec<3>& x) {
    Real d = std::numeric_limits<Real>::infinity();
    for (const Sphere& s : spheres) d = std::min(d, std::max(Real(0), (x - s.centre).norm() - s.radius));
    return std::min(h_far, h_body + grading * d);
  };
}

/// Refuses a scene the mesher cannot mesh, naming the body (its index and tag): a sphere with a
/// non-positive or non-finite radius, a tag that is a wall's or another sphere's, a sphere that
/// does not lie strictly inside the box (gap to a wall <= `min_gap`), two spheres that touch
/// or overlap (gap <= `min_gap`).
inline void check_spheres_in_box(const BoxDomain& box, const std::vector<Sphere>& spheres, Real min_gap = 0) {
  box.validate();
  auto name = [&](std::size_t k) { return "bodies[" + std::to_string(k) + "]"; };
  for (std::size_t k = 0; k < spheres.size(); ++k) {
    const Sphere& s = spheres[k];
    ALEFSI_CHECK_ARG(s.radius > 0 && std::isfinite(s.radius) && s.centre.allFinite(), name(k),
                     "(tag ", s.tag, ") needs a finite centre and a positive radius, got radius ", s.radius);
    for (int t : box.tags)
      ALEFSI_CHECK_ARG(s.tag != t, name(k), "has tag ", s.tag, ", a wall's tag");
    const Real gap = std::min((s.centre - box.lo).minCoeff(), (box.hi - s.centre).minCoeff()) - s.radius;
    ALEFSI_CHECK_ARG(gap > min_gap, name(k), "(tag ", s.tag, ", centre ", s.centre.transpose(), ", radius ", s.radius,
                     ") is not inside the box [", box.lo.transpose(), "] x [", box.hi.transpose(),
                     "]: its gap to the nearest wall is ", gap);
    for (std::size_t j = 0; j < k; ++j) {
      ALEFSI_CHECK_ARG(spheres[j].tag != s.tag, name(k), "has the tag ", s.tag, " of ", name(j));
      const Real g = (s.centre - spheres[j].centre).norm() - s.radius - spheres[j].radius;
      ALEFSI_CHECK_ARG(g > min_gap, name(k), "(tag ", s.tag, ") overlaps or touches ", name(j), " (tag ",
                       spheres[j].tag, "): their gap is ", g);
    }
  }
}

}  // namespace alefsi
