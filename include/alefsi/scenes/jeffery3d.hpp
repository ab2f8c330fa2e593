#pragma once
/// \file scenes/jeffery3d.hpp
/// A free spheroid in a linear flow (Jeffery 1922), the 3D analogue of scenes/jeffery.hpp: a
/// massless, force- and torque-free spheroid with semi-axis a along its symmetry axis p and b
/// across it, at the centre of a spherical container of radius L (tag 2) whose wall moves with
/// the linear flow u = G x (G traceless); the spheroid's surface is tag 1. In Stokes flow its
/// angular velocity depends on p and G alone, and Jeffery's law for the unbounded flow is
///     w = Omega + lambda p x (E p),   lambda = (r^2 - 1) / (r^2 + 1),  r = a / b,
/// with Omega the axial vector of W = (G - G^T) / 2 (half the vorticity) and E = (G + G^T) / 2.
/// In the simple shear u = (gamma y, 0, 0), with p in the x-y plane at the angle phi from x,
/// the spin is w_z = -gamma (a^2 sin^2 phi + b^2 cos^2 phi) / (a^2 + b^2), the same function of
/// phi as the 2D ellipse's, and the period of the orbit is T = 2 pi (r + 1 / r) / gamma. The
/// container reflects the body's stresslet: an O((a / L)^3) error.
///
/// The mesh has the spheroid's axis along x (gmsh_ellipsoid_in_sphere_mesh: needs alefsi::gmsh);
/// a body at the axis p in the flow G is the flow R^T G R about that mesh, R e_x = p, so one mesh
/// serves every orientation. `angular_velocity(mesh, p, G)` solves the quasi-static mobility
/// problem (Taylor–Hood, curved cells on the spheroid and the container unless `curved` is
/// false, SaddlePointGmres<3>: the closed domain's pressure as its null space) and returns w in
/// the flow's axes; `strain_mobility(mesh)` gives, from five solves, the angular velocity for
/// every orientation and flow (`from_mobility`).
///
///     scenes::Jeffery3D scene{.b = 0.5, .container = 8};
///     const Mesh<3> mesh = scene.mesh();
///     const Vec<3> w = scene.angular_velocity(mesh, Vec<3>(1, 0, 0), scenes::Jeffery3D::simple_shear());
#ifndef ALEFSI_HAVE_GMSH
#error "alefsi/scenes/jeffery3d.hpp needs gmsh's library: link alefsi::gmsh (apt install libgmsh-dev)"
#endif
#include <algorithm>
#include <cmath>
#include <numbers>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/fem/geometry.hpp"
#include "alefsi/la/krylov.hpp"
#include "alefsi/mesh/generate/gmsh_mesher.hpp"
#include "alefsi/sim/ale_flow.hpp"

namespace alefsi::scenes {

struct Jeffery3D {
  Real a = 1, b = 0.5;    ///< semi-axes: a along the symmetry axis, b across it
  Real mu = 1;            ///< viscosity
  Real container = 8;     ///< radius L of the spherical container
  Real h_body = 0.05;     ///< mesh size at the spheroid
  Real h_far = 1;         ///< largest mesh size
  Real grading = 0.3;     ///< growth of the size with the distance from the sphere of radius max(a, b)
  /// Where the spheroid turns sharply (a slender one's tips), the size at its surface is at most
  /// 2 pi rho / cells_per_turn, rho the smaller principal radius of curvature there, growing by
  /// `grading` away from it (`size`): a curved cell has to be small beside the curve it follows.
  /// 0: h_body alone. At 16, b/a = 1/2 is refined at the tips only where h_body > 0.098.
  Real cells_per_turn = 16;
  bool curved = true;     ///< isoparametric P2 cells on the spheroid and the container
  GmshMeshOptions mesher{};  ///< gmsh's options (quality floor, Netgen optimiser)

  using Flow = AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, UnsteadyStokes, SaddlePointGmres<3>>>;

  void validate() const {
    ALEFSI_CHECK_ARG(a > 0 && b > 0 && std::isfinite(a) && std::isfinite(b), "a, b",
                     "semi-axes must be positive and finite, got ", a, ", ", b);
    ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "must be positive and finite, got ", mu);
    ALEFSI_CHECK_ARG(container > 2 * std::max(a, b), "container", "must exceed twice the larger semi-axis, got ",
                     container);
    ALEFSI_CHECK_ARG(h_body > 0 && h_far >= h_body && grading > 0, "h_body, h_far, grading",
                     "need 0 < h_body <= h_far and grading > 0");
    ALEFSI_CHECK_ARG(cells_per_turn >= 0 && std::isfinite(cells_per_turn), "cells_per_turn",
                     "must be >= 0 (0: no refinement by curvature), got ", cells_per_turn);
  }

  /// The semi-axes in the mesh's axes (the symmetry axis along x).
  Vec<3> semi_axes() const { return Vec<3>(a, b, b); }

  /// The container with the spheroid, its axis along x (gmsh; `report`: cells, quality, time).
  Mesh<3> mesh(GmshMeshReport* report = nullptr) const {
    validate();
    return gmsh_ellipsoid_in_sphere_mesh(
        container, semi_axes(), [s = *this](const Vec<3>& x) { return s.size(x); }, mesher, report, 1, 2);
  }

  /// The mesh size at x: h_body growing by `grading` with the distance from the sphere of
  /// radius max(a, b), capped by h_far and by the curvature's size (`cells_per_turn`) at y, the
  /// nearest point of the spheroid, growing by `grading` with |x| - |y| (<= |x - y|: a little
  /// finer than by the distance, and cheaper).
  Real size(const Vec<3>& x) const {
    const Real r = x.norm();
    Real h = std::min(h_far, h_body + grading * std::max(Real(0), r - std::max(a, b)));
    if (cells_per_turn > 0 && r > 0) {
      const Vec<3> y = onto_ellipsoid<3>(Vec<3>::Zero(), semi_axes())(x);
      const Real h_turn = 2 * std::numbers::pi * curvature_radius(y) / cells_per_turn;
      h = std::min(h, h_turn + grading * std::max(Real(0), r - y.norm()));
    }
    return h;
  }

  /// The smaller principal radius of curvature of the spheroid at its surface point y. On the
  /// meridian (a cos t, b sin t): q = (a^2 sin^2 t + b^2 cos^2 t)^{1/2}, the meridian's radius
  /// q^3 / (a b), the parallel's b q / a; both b^2 / a at the tips.
  Real curvature_radius(const Vec<3>& y) const {
    const Real c = std::clamp(y[0] / a, Real(-1), Real(1));
    const Real q = std::sqrt(a * a * (1 - c * c) + b * b * c * c);
    return std::min(q * q * q / (a * b), b * q / a);
  }

  /// The simple shear u = (gamma y, 0, 0) as a velocity gradient.
  static Mat<3> simple_shear(Real gamma = 1) {
    Mat<3> G = Mat<3>::Zero();
    G(0, 1) = gamma;
    return G;
  }

  /// The spheroid's angular velocity (flow axes) with its axis along the unit vector p in the
  /// linear flow u = G x: the quasi-static mobility problem on `mesh` (made by `mesh()`: the
  /// axis along x), solved in the body's axes. `gmres_iterations`: GMRES's count.
  Vec<3> angular_velocity(const Mesh<3>& mesh, const Vec<3>& p, const Mat<3>& G, int* gmres_iterations = nullptr) const {
    validate();
    ALEFSI_CHECK_ARG(std::abs(p.norm() - 1) < 1e-12, "p", "must be a unit vector, got |p| = ", p.norm());
    ALEFSI_CHECK_ARG(G.allFinite() && std::abs(G.trace()) <= 1e-12 * G.norm(), "G",
                     "must be finite and traceless (an incompressible linear flow), trace ", G.trace());
    const Mat<3> R = body_axes(p);
    const Mat<3> Gb = R.transpose() * G * R;  // the flow about the body, in its axes
    // Stokes: rho = 1e-18 and one step of 1e-6 from rest (the mass term, 1e-12, far below the
    // solution's accuracy)
    Flow flow(mesh, FlowOptions{1e-18, mu});
    flow.set_velocity(2, [Gb](const Vec<3>& x, Real) { return Vec<3>(Gb * x); });
    RigidBody3D body;  // massless and free: force- and torque-free
    body.tag = 1;
    flow.add_body(body);
    if (curved) {
      flow.curve_boundary(1, onto_ellipsoid<3>(Vec<3>::Zero(), semi_axes()));
      flow.curve_boundary(2, onto_sphere<3>(Vec<3>::Zero(), container));
    }
    flow.step(1e-6);
    if (gmres_iterations) *gmres_iterations = flow.solver().iterations();
    return R * Vec<3>(flow.body_velocity(0).template tail<3>());
  }

  /// The spheroid's discrete mobility in strains, in its own axes (the symmetry axis along x):
  /// column i is the angular velocity in the pure strain u = E_i x of `strain_basis(i)`. The
  /// rotational part of a flow is followed exactly (a rigid rotation is in the discrete space,
  /// with zero pressure), so by linearity w = Omega + sum_i c_i K_i for any G whose strain is
  /// sum_i c_i E_i (`from_mobility`), to the solver's tolerance. Jeffery: only K(2, 0) = lambda
  /// (the xy strain turns the axis about z) and K(1, 1) = -lambda (xz, about y) are not zero.
  /// Five solves.
  Eigen::Matrix<Real, 3, 5> strain_mobility(const Mesh<3>& mesh) const {
    Eigen::Matrix<Real, 3, 5> K;
    for (int i = 0; i < 5; ++i) K.col(i) = angular_velocity(mesh, Vec<3>::UnitX(), strain_basis(i));
    return K;
  }
  /// A basis of the traceless symmetric tensors: xy, xz, yz (off-diagonal pairs of 1), then
  /// diag(1, -1, 0) and diag(1, 0, -1).
  static Mat<3> strain_basis(int i) {
    ALEFSI_CHECK_ARG(i >= 0 && i < 5, "i", "a strain basis index is 0..4, got ", i);
    Mat<3> E = Mat<3>::Zero();
    if (i < 3) {
      const int r = i < 2 ? 0 : 1, c = i == 0 ? 1 : 2;
      E(r, c) = E(c, r) = 1;
    } else {
      E(0, 0) = 1, E(i - 2, i - 2) = -1;
    }
    return E;
  }
  /// The angular velocity (flow axes) with the axis along p in u = G x, from the mobility K.
  static Vec<3> from_mobility(const Eigen::Matrix<Real, 3, 5>& K, const Vec<3>& p, const Mat<3>& G) {
    const Mat<3> R = body_axes(p);
    const Mat<3> Gb = R.transpose() * G * R, E = (Gb + Gb.transpose()) / 2;
    const Eigen::Matrix<Real, 5, 1> c(E(0, 1), E(0, 2), E(1, 2), -E(1, 1), -E(2, 2));
    return R * (half_vorticity(Gb) + K * c);
  }

  /// Jeffery's angular velocity (unbounded flow) with the axis along the unit vector p in u = G x.
  Vec<3> jeffery_angular_velocity(const Vec<3>& p, const Mat<3>& G) const {
    const Mat<3> E = (G + G.transpose()) / 2;
    return half_vorticity(G) + jeffery_lambda() * p.cross(E * p);
  }
  /// Jeffery's period of the orbit in the simple shear of rate gamma.
  Real jeffery_period(Real gamma = 1) const { return 2 * std::numbers::pi * (a / b + b / a) / gamma; }
  /// Jeffery's shape factor lambda = (r^2 - 1) / (r^2 + 1), r = a / b.
  Real jeffery_lambda() const {
    const Real r2 = (a / b) * (a / b);
    return (r2 - 1) / (r2 + 1);
  }

  /// The rotation R taking the mesh's axes to the body's, R e_x = p.
  static Mat<3> body_axes(const Vec<3>& p) {
    return Eigen::Quaternion<Real>::FromTwoVectors(Vec<3>::UnitX(), p).toRotationMatrix();
  }
  /// Omega, the axial vector of W = (G - G^T) / 2 (W x = Omega x x): half the vorticity of u = G x.
  static Vec<3> half_vorticity(const Mat<3>& G) {
    const Mat<3> W = (G - G.transpose()) / 2;
    return Vec<3>(W(2, 1), W(0, 2), W(1, 0));
  }
};

}  // namespace alefsi::scenes
