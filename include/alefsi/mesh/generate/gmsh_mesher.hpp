#pragma once
/// \file mesh/generate/gmsh_mesher.hpp
/// Tetrahedral meshes of a box with spherical holes (mesh/generate/spheres_in_box.hpp,
/// `gmsh_box_mesh`) and of a ball with an ellipsoidal hole (`gmsh_ellipsoid_in_sphere_mesh`),
/// made by gmsh's C++ API: the solid minus the holes by OpenCASCADE, surface meshes by
/// Frontal-Delaunay, the volume by Delaunay with gmsh's optimiser, the size given by a
/// SizeFunction3D (gmsh asks it at every point it inserts). Needs gmsh (GPL; Debian: libgmsh-dev): link alefsi::gmsh,
/// which CMake defines when it finds it (ALEFSI_WITH_GMSH); a program linking it is bound by
/// gmsh's licence.
///
/// What comes out: a valid Mesh<3> (cells positively oriented, numbered as gmsh numbered its
/// nodes, unused nodes dropped), the box's faces tagged BoxDomain::tags, each sphere's facets
/// its tag, and every node of a sphere's surface exactly on it (projected: |x - c| = r to
/// round-off), so that a body's surface is its sphere wherever its nodes are placed from its
/// rigid motion. The same input gives the same mesh (one thread): a run that remeshes restarts
/// bit for bit from a checkpoint. A cell with two faces on a body (a cap, in a fold of the
/// surface triangulation: gmsh makes one in about a fifth of the meshes of a sphere in a box)
/// is removed (`GmshMeshOptions::remove_caps`): it is a sliver, the worst cell of its mesh, and
/// no curved cell could be made of it.
///
/// gmsh keeps global state: the mesher initialises it for the call and finalises it after (a
/// program must not hold its own gmsh session across the call). Failures (a gmsh error, a
/// result below the quality floor) throw MeshError naming the cause; nothing else is changed.
///
///     alefsi::GmshMeshReport rep;
///     auto mesh = alefsi::gmsh_box_mesh(box, spheres, alefsi::graded_size(spheres, 0.05, 0.5), {}, &rep);
#ifndef ALEFSI_HAVE_GMSH
#error "alefsi/mesh/generate/gmsh_mesher.hpp needs gmsh's library: link alefsi::gmsh (apt install libgmsh-dev)"
#endif
#include <gmsh.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <string>
#include <unordered_map>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/geometry.hpp"
#include "alefsi/mesh/generate/spheres_in_box.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/mesh/quality.hpp"

namespace alefsi {

struct GmshMeshOptions {
  Real quality_floor = 0.02;  ///< a mesh whose worst Mesh::quality is below is refused (MeshError)
  bool netgen = false;        ///< also run gmsh's Netgen optimiser (better worst cells, slower)
  bool remove_caps = true;    ///< remove the bodies' caps (GmshMeshReport::caps_removed); false: gmsh's mesh as it is
  int verbosity = 0;          ///< gmsh's General.Verbosity (0: silent, 5: everything)

  void validate() const {
    ALEFSI_CHECK_ARG(quality_floor >= 0 && quality_floor < 1, "quality_floor", "must be in [0, 1), got ",
                     quality_floor);
  }
};

/// What one call made, and what it cost.
struct GmshMeshReport {
  Real seconds = 0;  ///< wall time of the call (geometry, meshing, conversion)
  Index cells = 0, nodes = 0;
  QualityStats quality;  ///< of the result
  /// Cells removed as caps of a body: a tetrahedron with two faces on one body's surface lies
  /// between them and the surface's other diagonal, inside the body (which is convex there), and
  /// would be turned inside out when the faces are curved onto the surface (`remove_caps`).
  Index caps_removed = 0;
};

namespace detail {

// gmsh for the length of a call: initialised without reading the user's configuration files,
// silent, one thread, finalised on every way out.
class GmshSession {
 public:
  explicit GmshSession(int verbosity) {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", verbosity > 0 ? 1 : 0);
    gmsh::option::setNumber("General.Verbosity", verbosity);
    gmsh::option::setNumber("General.NumThreads", 1);
    gmsh::model::add("alefsi");
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

// Which face of the box (0..5: xmin, xmax, ..., zmax) or which sphere (6 + k) an OpenCASCADE
// surface is, from its centre of mass (a face's is on its plane, a whole sphere's is its
// centre); -1 if none.
inline int classify_surface(const BoxDomain& box, const std::vector<Sphere>& spheres, const Vec<3>& centre) {
  const Real tol = 1e-9 * (box.hi - box.lo).maxCoeff();
  for (std::size_t k = 0; k < spheres.size(); ++k)
    if ((centre - spheres[k].centre).norm() < 1e-6 * spheres[k].radius) return 6 + static_cast<int>(k);
  for (int c = 0; c < 3; ++c) {
    if (std::abs(centre[c] - box.lo[c]) < tol) return 2 * c;
    if (std::abs(centre[c] - box.hi[c]) < tol) return 2 * c + 1;
  }
  return -1;
}

// How a gmsh surface's triangles come out of `gmsh_generate`.
struct GmshSurface {
  int tag = 0;                                // the facets' tag
  std::function<Vec<3>(const Vec<3>&)> onto;  // onto the exact surface (null: left as gmsh put it)
  bool body = false;                          // a body's surface (convex: its caps are removed)
};

// Removes the caps of the body surfaces whose tags are `body_tags`: a cell with two or more
// faces tagged with one body's tag has all its vertices on that surface, so it lies inside the
// body's convex hull, in a fold of the triangulated surface (two facets meeting in a valley
// where the other diagonal of their quadrilateral would make a ridge). Its other faces take its
// place on the surface, which then has the ridge. Repeated until no cap is left; returns the
// number removed.
inline Index remove_caps(std::vector<Mesh<3>::Cell>& cells, std::vector<Mesh<3>::Facet>& facets,
                         std::vector<int>& facet_tags, const std::vector<int>& body_tags) {
  auto key = [](std::array<Index, 3> f) {
    std::sort(f.begin(), f.end());
    return f;
  };
  std::map<std::array<Index, 3>, int> tagged;  // body facets, sorted vertices -> tag
  for (std::size_t i = 0; i < facets.size(); ++i)
    if (std::find(body_tags.begin(), body_tags.end(), facet_tags[i]) != body_tags.end())
      tagged[key(facets[i])] = facet_tags[i];
  if (tagged.empty()) return 0;
  Index removed = 0;
  std::vector<char> gone(cells.size(), 0);
  for (bool again = true; again;) {
    again = false;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (gone[c]) continue;
      std::array<std::array<Index, 3>, 4> face;
      std::array<int, 4> tag{0, 0, 0, 0};
      for (int j = 0; j < 4; ++j) {
        face[std::size_t(j)] = key({cells[c][(j + 1) % 4], cells[c][(j + 2) % 4], cells[c][(j + 3) % 4]});
        const auto it = tagged.find(face[std::size_t(j)]);
        if (it != tagged.end()) tag[std::size_t(j)] = it->second;
      }
      int on = 0, body = 0;
      for (int t : tag)
        if (t != 0 && (body == 0 || t == body)) body = t, ++on;
      if (on < 2) continue;
      for (std::size_t j = 0; j < 4; ++j) {
        if (tag[j] == body)
          tagged.erase(face[j]);
        else
          tagged[face[j]] = body;
      }
      gone[c] = 1, ++removed, again = true;
    }
  }
  if (removed == 0) return 0;
  std::size_t n = 0;
  for (std::size_t c = 0; c < cells.size(); ++c)
    if (!gone[c]) cells[n++] = cells[c];
  cells.resize(n);
  std::vector<Mesh<3>::Facet> kept;
  std::vector<int> kept_tags;
  for (std::size_t i = 0; i < facets.size(); ++i)  // the other surfaces' facets, in their order
    if (std::find(body_tags.begin(), body_tags.end(), facet_tags[i]) == body_tags.end())
      kept.push_back(facets[i]), kept_tags.push_back(facet_tags[i]);
  for (const auto& [f, t] : tagged) kept.push_back({f[0], f[1], f[2]}), kept_tags.push_back(t);
  facets = std::move(kept), facet_tags = std::move(kept_tags);
  return removed;
}

// Meshes the model's volume with alefsi's settings (Frontal-Delaunay surfaces, Delaunay volume,
// gmsh's optimiser, sizes from `size` only) and converts it: the tetrahedra (positively
// oriented, nodes numbered in gmsh's order, unused ones dropped) and the triangles of each
// surface in `surfaces` (gmsh surface -> alefsi tag, in increasing gmsh order), whose nodes are
// moved by that surface's `onto` (if set) onto the exact surface; the bodies' caps removed
// (`caps`: how many).
inline Mesh<3> gmsh_generate(const std::map<int, GmshSurface>& surfaces, const SizeFunction3D& size,
                             const GmshMeshOptions& opt, Index& caps) {
  gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.Algorithm", 6);    // Frontal-Delaunay surfaces
  gmsh::option::setNumber("Mesh.Algorithm3D", 1);  // Delaunay volume
  gmsh::option::setNumber("Mesh.Optimize", 1);
  gmsh::option::setNumber("Mesh.OptimizeNetgen", opt.netgen ? 1 : 0);
  gmsh::model::mesh::setSizeCallback([&size](int, int, double x, double y, double z) { return size(Vec<3>(x, y, z)); });
  gmsh::model::mesh::generate(3);

  // nodes
  std::vector<std::size_t> node_tags;
  std::vector<double> coords, param;
  gmsh::model::mesh::getNodes(node_tags, coords, param, -1, -1, false, false);
  std::unordered_map<std::size_t, Index> gmsh_node;  // gmsh tag -> position in coords
  for (std::size_t i = 0; i < node_tags.size(); ++i) gmsh_node[node_tags[i]] = static_cast<Index>(i);

  // tetrahedra, numbering the nodes they use in the order gmsh numbered them
  std::vector<std::size_t> tet_tags, tet_nodes;
  gmsh::model::mesh::getElementsByType(4, tet_tags, tet_nodes, -1);
  if (tet_tags.empty()) throw MeshError(MeshError::Entity::mesh, -1, "gmsh made no tetrahedra");
  std::vector<Index> index(node_tags.size(), -1);
  for (std::size_t t : tet_nodes) index[gmsh_node.at(t)] = 0;
  std::vector<Vec<3>> x;
  for (std::size_t i = 0; i < node_tags.size(); ++i)
    if (index[i] == 0) {
      index[i] = static_cast<Index>(x.size());
      x.emplace_back(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);
    }
  auto node = [&](std::size_t gmsh_tag) {
    const Index i = index[gmsh_node.at(gmsh_tag)];
    if (i < 0) throw MeshError(MeshError::Entity::mesh, -1, "gmsh: a surface node is in no tetrahedron");
    return i;
  };

  // boundary triangles, their nodes put on the exact surfaces
  std::vector<Mesh<3>::Facet> facets;
  std::vector<int> facet_tags;
  for (const auto& [s, surface] : surfaces) {
    std::vector<std::size_t> tri_tags, tri_nodes;
    gmsh::model::mesh::getElementsByType(2, tri_tags, tri_nodes, s);
    for (std::size_t e = 0; e < tri_tags.size(); ++e) {
      Mesh<3>::Facet f;
      for (int j = 0; j < 3; ++j) {
        f[j] = node(tri_nodes[3 * e + j]);
        if (surface.onto) x[f[j]] = surface.onto(x[f[j]]);  // idempotent: shared nodes may come twice
      }
      facets.push_back(f);
      facet_tags.push_back(surface.tag);
    }
  }
  std::vector<Mesh<3>::Cell> cells(tet_tags.size());
  for (std::size_t e = 0; e < cells.size(); ++e) {
    for (int j = 0; j < 4; ++j) cells[e][j] = node(tet_nodes[4 * e + j]);
    const Vec<3> a = x[cells[e][0]];
    if ((x[cells[e][1]] - a).dot((x[cells[e][2]] - a).cross(x[cells[e][3]] - a)) < 0) std::swap(cells[e][2], cells[e][3]);
  }
  std::vector<int> body_tags;
  for (const auto& [s, surface] : surfaces)
    if (surface.body) body_tags.push_back(surface.tag);
  caps = opt.remove_caps ? remove_caps(cells, facets, facet_tags, body_tags) : 0;
  return Mesh<3>(std::move(x), std::move(cells), facets, facet_tags);
}

inline Mesh<3> gmsh_box_mesh_impl(const BoxDomain& box, const std::vector<Sphere>& spheres, const SizeFunction3D& size,
                                  const GmshMeshOptions& opt, Index& caps) {
  GmshSession session(opt.verbosity);
  namespace occ = gmsh::model::occ;
  const Vec<3> L = box.hi - box.lo;
  const int solid = occ::addBox(box.lo[0], box.lo[1], box.lo[2], L[0], L[1], L[2]);
  gmsh::vectorpair holes, fluid;
  for (const Sphere& s : spheres) holes.emplace_back(3, occ::addSphere(s.centre[0], s.centre[1], s.centre[2], s.radius));
  if (holes.empty()) {
    fluid = {{3, solid}};
  } else {
    std::vector<gmsh::vectorpair> map;
    occ::cut({{3, solid}}, holes, fluid, map);
  }
  occ::synchronize();
  if (fluid.size() != 1 || fluid[0].first != 3)
    throw MeshError(MeshError::Entity::mesh, -1, "gmsh: the box minus the spheres is not one volume");

  // which tag each surface's triangles get; the spheres' nodes put exactly on their spheres
  gmsh::vectorpair entities;
  gmsh::model::getEntities(entities, 2);
  std::map<int, GmshSurface> surfaces;  // ordered: the facets in the same order every time
  for (const auto& [dim, s] : entities) {
    double x, y, z;
    occ::getCenterOfMass(dim, s, x, y, z);
    const int which = classify_surface(box, spheres, Vec<3>(x, y, z));
    if (which < 0)
      throw MeshError(MeshError::Entity::mesh, -1, "gmsh: surface " + std::to_string(s) +
                                                       " is neither a face of the box nor a sphere");
    if (which < 6) {
      surfaces[s] = {box.tags[which], nullptr};
    } else {
      const Sphere& sp = spheres[std::size_t(which - 6)];
      surfaces[s] = {sp.tag, onto_sphere<3>(sp.centre, sp.radius), true};
    }
  }
  return gmsh_generate(surfaces, size, opt, caps);
}

// An axis-aligned ellipsoid (semi-axes `semi_axes`, centred at the origin) cut out of the ball
// of radius `radius` about the origin.
// `poles_on_longest`: the unit sphere turned before it is stretched so that the poles of its
// parametrisation end on the longest axis (else they stay on z).
inline Mesh<3> gmsh_ellipsoid_in_sphere_impl(Real radius, const Vec<3>& semi_axes, int body_tag, int container_tag,
                                             const SizeFunction3D& size, const GmshMeshOptions& opt,
                                             bool poles_on_longest, Index& caps) {
  GmshSession session(opt.verbosity);
  namespace occ = gmsh::model::occ;
  const int ball = occ::addSphere(0, 0, 0, radius);
  const int body = occ::addSphere(0, 0, 0, 1);
  if (poles_on_longest) {
    Index longest = 0;
    semi_axes.maxCoeff(&longest);
    const Real half_pi = std::numbers::pi / 2;
    if (longest == 0) occ::rotate({{3, body}}, 0, 0, 0, 0, 1, 0, half_pi);   // z -> x
    if (longest == 1) occ::rotate({{3, body}}, 0, 0, 0, 1, 0, 0, -half_pi);  // z -> y
  }
  occ::dilate({{3, body}}, 0, 0, 0, semi_axes[0], semi_axes[1], semi_axes[2]);
  gmsh::vectorpair fluid;
  std::vector<gmsh::vectorpair> map;
  occ::cut({{3, ball}}, {{3, body}}, fluid, map);
  occ::synchronize();
  if (fluid.size() != 1 || fluid[0].first != 3)
    throw MeshError(MeshError::Entity::mesh, -1, "gmsh: the ball minus the ellipsoid is not one volume");
  gmsh::vectorpair entities;
  gmsh::model::getEntities(entities, 2);
  std::map<int, GmshSurface> surfaces;
  for (const auto& [dim, s] : entities) {  // the container reaches `radius`, the body max(semi_axes)
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(dim, s, x0, y0, z0, x1, y1, z1);
    const Real reach = std::max({x1, y1, z1});
    if (std::abs(reach - radius) < 1e-3 * radius)
      surfaces[s] = {container_tag, onto_sphere<3>(Vec<3>::Zero(), radius)};
    else if (std::abs(reach - semi_axes.maxCoeff()) < 1e-3 * semi_axes.maxCoeff())
      surfaces[s] = {body_tag, onto_ellipsoid<3>(Vec<3>::Zero(), semi_axes), true};
    else
      throw MeshError(MeshError::Entity::mesh, -1, "gmsh: surface " + std::to_string(s) +
                                                       " is neither the container nor the ellipsoid");
  }
  return gmsh_generate(surfaces, size, opt, caps);
}

// Runs `make(caps)` (a gmsh call), turning gmsh's errors into MeshError, and refuses a result
// below the quality floor; fills `report`.
template <class Make>
Mesh<3> gmsh_checked(Make&& make, const GmshMeshOptions& opt, GmshMeshReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  Mesh<3> mesh;
  Index caps = 0;
  try {
    mesh = make(caps);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw MeshError(MeshError::Entity::mesh, -1, std::string("gmsh failed: ") + e.what());
  } catch (const std::string& e) {  // gmsh's API throws its last error message
    throw MeshError(MeshError::Entity::mesh, -1, "gmsh failed: " + e);
  } catch (...) {
    throw MeshError(MeshError::Entity::mesh, -1, "gmsh failed");
  }
  const QualityStats q = quality_stats(mesh);
  if (q.worst < opt.quality_floor)
    throw MeshError(MeshError::Entity::mesh, -1,
                    concat("the new mesh's worst quality ", q.worst, " is below the floor ", opt.quality_floor,
                           " (dihedral angles ", q.min_dihedral_deg, " to ", q.max_dihedral_deg, " degrees)"));
  if (report)
    *report = {std::chrono::duration<Real>(std::chrono::steady_clock::now() - t0).count(), mesh.n_cells(),
               mesh.n_nodes(), q, caps};
  return mesh;
}

}  // namespace detail

/// A mesh of `box` minus the `spheres` with edge lengths near `size` (file comment). Throws
/// InvalidArgument naming the body for a scene it cannot mesh (check_spheres_in_box), MeshError
/// when gmsh fails or the worst cell is below `opt.quality_floor`.
inline Mesh<3> gmsh_box_mesh(const BoxDomain& box, const std::vector<Sphere>& spheres, const SizeFunction3D& size,
                             const GmshMeshOptions& opt = {}, GmshMeshReport* report = nullptr) {
  check_spheres_in_box(box, spheres);
  opt.validate();
  ALEFSI_CHECK_ARG(static_cast<bool>(size), "size", "a size function is needed");
  return detail::gmsh_checked([&](Index& caps) { return detail::gmsh_box_mesh_impl(box, spheres, size, opt, caps); },
                              opt, report);
}

/// A mesh of the ball |x| < `radius` minus the ellipsoid sum (x_i / semi_axes_i)^2 < 1 (both
/// about the origin, the ellipsoid's axes along the coordinate axes), with edge lengths near
/// `size`: the ellipsoid's facets tagged `body_tag`, the sphere's `container_tag`, every node of
/// the sphere on it and every node of the ellipsoid on it (the nearest point, `onto_ellipsoid`).
/// A body turned in a flow is the flow turned about the body (scenes/jeffery3d.hpp). The
/// ellipsoid is OpenCASCADE's unit sphere stretched, whose parametrisation has its poles on z;
/// when gmsh's surface mesher fails on it (a slender spheroid along x: b / a = 0.33 and below
/// at h = 0.08, the poles squeezed into slits), the mesh is made again with the poles turned
/// onto the longest axis, at the tips. Throws InvalidArgument naming the parameter, MeshError
/// as gmsh_box_mesh.
inline Mesh<3> gmsh_ellipsoid_in_sphere_mesh(Real radius, const Vec<3>& semi_axes, const SizeFunction3D& size,
                                             const GmshMeshOptions& opt = {}, GmshMeshReport* report = nullptr,
                                             int body_tag = 1, int container_tag = 2) {
  ALEFSI_CHECK_ARG(semi_axes.minCoeff() > 0 && semi_axes.allFinite(), "semi_axes", "must be positive and finite, got ",
                   semi_axes.transpose());
  ALEFSI_CHECK_ARG(std::isfinite(radius) && radius > 1.5 * semi_axes.maxCoeff(), "radius",
                   "the container must reach past 1.5 times the largest semi-axis, got ", radius);
  ALEFSI_CHECK_ARG(body_tag != container_tag, "body_tag", "must differ from container_tag (", container_tag, ")");
  opt.validate();
  ALEFSI_CHECK_ARG(static_cast<bool>(size), "size", "a size function is needed");
  return detail::gmsh_checked(
      [&](Index& caps) {
        try {
          return detail::gmsh_ellipsoid_in_sphere_impl(radius, semi_axes, body_tag, container_tag, size, opt, false,
                                                       caps);
        } catch (const Error&) {
          throw;
        } catch (...) {  // gmsh could not mesh the squeezed parametrisation: the poles to the tips
          return detail::gmsh_ellipsoid_in_sphere_impl(radius, semi_axes, body_tag, container_tag, size, opt, true,
                                                       caps);
        }
      },
      opt, report);
}

}  // namespace alefsi
