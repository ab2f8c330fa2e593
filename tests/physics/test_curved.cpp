// Isoparametric P2 geometry (fem/geometry.hpp): the quadratic map, its area / volume order, edge
// points that follow moving nodes, the curved Stokes and ALE Navier–Stokes kernels against the
// affine ones, and Taylor–Hood's rates on curved domains restored (Couette flow in an annulus
// and in a spherical shell: L2 3, H1 2 instead of 2, 1.5).
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>
#include <string>

#include "alefsi/fem/geometry.hpp"
#include "alefsi/fem/norms.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/mesh/io/gmsh.hpp"
#include "alefsi/physics/navier_stokes.hpp"
#include "alefsi/physics/stokes.hpp"
#include "alefsi/scenes/jeffery.hpp"
#include "alefsi/sim/ale_flow.hpp"
#include "alefsi/sim/driver.hpp"
#include "alefsi/sim/remesher2d.hpp"

using namespace alefsi;
using std::numbers::pi;

namespace {

Mesh<3> shell_mesh(const std::string& h) {
  return read_gmsh<3>(std::string(ALEFSI_TEST_DATA_DIR) + "/gmsh/shell3d_h" + h + ".msh").mesh;
}

// The measure of the domain through the geometry's map (degree-4 rule: exact for straight
// cells, far below the geometric error on curved ones).
template <int D>
Real measure(const QuadraticGeometry<D>& g) {
  using G = QuadraticGeometry<D>;
  const auto& rule = simplex_quadrature<D>(4);
  Real m = 0;
  for (Index c = 0; c < g.mesh().n_cells(); ++c) {
    const auto X = g.cell_nodes(c);
    for (int q = 0; q < rule.size(); ++q)
      m += rule.weights[q] * G::jacobian(X, G::Shape::gradients(rule.points[q])).determinant();
  }
  return m;
}

// Circular Couette flow between r = a (turning at omega) and r = b (fixed), Stokes:
// 2D u_theta = A r + B / r; 3D u = (A + B / r^3) (omega_hat x x), pressure constant.
constexpr Real a = 0.5, b = 1.0, omega = 1.0, mu = 1.0;

template <int D>
struct Couette;
template <>
struct Couette<2> {
  static constexpr Real A = omega * a * a / (a * a - b * b), B = omega * a * a * b * b / (b * b - a * a);
  static Vec<2> u(const Vec<2>& x) {
    const Real f = A + B / x.squaredNorm();
    return {-f * x[1], f * x[0]};
  }
  static Mat<2> grad(const Vec<2>& x) {  // of (-f y, f x), f = A + B / r^2
    const Real r2 = x.squaredNorm(), f = A + B / r2, df = -2 * B / (r2 * r2);
    Mat<2> g;
    g << -df * x[0] * x[1], -f - df * x[1] * x[1], f + df * x[0] * x[0], df * x[0] * x[1];
    return g;
  }
  static Vec<2> wall(const Vec<2>& x) { return {-omega * x[1], omega * x[0]}; }
};
template <>
struct Couette<3> {  // rotation about z
  static constexpr Real B = omega / (1 / (a * a * a) - 1 / (b * b * b)), A = -B / (b * b * b);
  static Vec<3> u(const Vec<3>& x) {
    const Real f = A + B / std::pow(x.norm(), 3);
    return {-f * x[1], f * x[0], 0};
  }
  static Mat<3> grad(const Vec<3>& x) {  // of f (-y, x, 0), f = A + B r^-3, grad f = -3 B r^-5 x
    const Real r = x.norm(), f = A + B / (r * r * r);
    const Vec<3> df = -3 * B / std::pow(r, 5) * x;
    Mat<3> g = Mat<3>::Zero();
    g.row(0) = -x[1] * df.transpose();
    g.row(1) = x[0] * df.transpose();
    g(0, 1) -= f;
    g(1, 0) += f;
    return g;
  }
  static Vec<3> wall(const Vec<3>& x) { return {-omega * x[1], omega * x[0], 0}; }
};

// Solves the Couette problem on `mesh` (inner tag 1, outer tag 2), with the boundary edges on
// the circles / spheres when `curved`; returns the velocity errors and the DOF count.
template <int D>
std::pair<FlowErrors, Real> couette(const Mesh<D>& mesh, bool curved) {
  QuadraticGeometry<D> g(mesh);
  Stokes<D, TaylorHood> stokes(mesh, mu);
  if (curved) {
    project_boundary_edges(g, 1, onto_sphere<D>(Vec<D>::Zero(), a));
    project_boundary_edges(g, 2, onto_sphere<D>(Vec<D>::Zero(), b));
    stokes.set_geometry(g);
  }
  stokes.set_velocity(1, Couette<D>::wall);
  stokes.set_velocity(2, [](const Vec<D>&) { return Vec<D>::Zero().eval(); });
  const VecX field = stokes.solve();
  const auto e = flow_errors<D, TaylorHood>(
      stokes.space(), field, Couette<D>::u, Couette<D>::grad, [](const Vec<D>&) { return 0.0; },
      curved ? &g : nullptr);
  return {e, Real(field.size())};
}

// The errors of the interpolant of the Couette flow (at the DOF points of the geometry).
template <int D>
FlowErrors couette_interpolant(const Mesh<D>& mesh, bool curved) {
  QuadraticGeometry<D> g(mesh);
  if (curved) {
    project_boundary_edges(g, 1, onto_sphere<D>(Vec<D>::Zero(), a));
    project_boundary_edges(g, 2, onto_sphere<D>(Vec<D>::Zero(), b));
  }
  MixedSpace<D, TaylorHood> space(mesh);
  VecX field = VecX::Zero(space.n_field());
  for (Index i = 0; i < space.velocity().n_dofs(); ++i) {
    const Vec<D> u = Couette<D>::u(g.dof_point(i));
    for (int k = 0; k < D; ++k) field[space.velocity_field(i, k)] = u[k];
  }
  return flow_errors<D, TaylorHood>(
      space, field, Couette<D>::u, Couette<D>::grad, [](const Vec<D>&) { return 0.0; }, curved ? &g : nullptr);
}

}  // namespace

TEST_CASE("quadratic geometry: the annulus' area converges at O(h^4) with edge points on the circles, O(h^2) without",
          "[curved][quick]") {
  // Chords cut a segment of area ~ R dtheta^3 / 12 per edge; a parabola through the arc's
  // midpoint leaves O(dtheta^5) per edge (the map interpolates the arc at three points).
  const Real exact = pi * (b * b - a * a);
  Real es[3], ec[3];
  for (int k = 0; k < 3; ++k) {
    const auto mesh = annulus_mesh(a, b, 2 << k, 24 << k);
    QuadraticGeometry<2> g(mesh);
    es[k] = std::abs(measure(g) / exact - 1);
    CHECK(g.n_curved() == 0);
    project_boundary_edges(g, 1, onto_sphere<2>(Vec<2>::Zero(), a));
    project_boundary_edges(g, 2, onto_sphere<2>(Vec<2>::Zero(), b));
    CHECK(g.n_curved() == 2 * (24 << k));  // one cell on each boundary edge (structured mesh)
    ec[k] = std::abs(measure(g) / exact - 1);
  }
  std::cout << "annulus area, relative error straight " << es[0] << " " << es[1] << " " << es[2] << ", curved " << ec[0]
            << " " << ec[1] << " " << ec[2] << "\n";
  for (int k = 1; k < 3; ++k) {
    CHECK(std::log2(es[k - 1] / es[k]) == Approx(2).margin(0.05));
    CHECK(std::log2(ec[k - 1] / ec[k]) == Approx(4).margin(0.1));
  }
}

TEST_CASE("onto_ellipsoid: the nearest point, on the surface, along its normal, no farther than any other point; "
          "turned by its axes",
          "[curved][quick]") {
  // a slender triaxial ellipsoid and an ellipse; points outside, just inside (a chord's midpoint)
  // and on the axis inside a tip's circle of curvature
  auto check = [](const auto& s, const auto& points) {
    constexpr int D = std::decay_t<decltype(s)>::RowsAtCompileTime;
    const Vec<D> c = Vec<D>::Constant(0.3);
    const auto onto = onto_ellipsoid<D>(c, s);
    std::vector<Vec<D>> surface;  // a dense sample of the surface
    const int n = D == 2 ? 20000 : 400;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < (D == 2 ? 1 : 2 * n); ++j) {
        const Real th = pi * (i + 0.5) / n, ph = pi * j / n;
        Vec<D> u;
        if constexpr (D == 2) u = Vec<D>(std::cos(2 * th), std::sin(2 * th));
        else u = Vec<D>(std::cos(th), std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph));
        surface.push_back(c + s.cwiseProduct(u));
      }
    for (const Vec<D>& x : points) {
      const Vec<D> y = onto(Vec<D>(c + x));
      INFO("x - c = " << x.transpose() << ", y - c = " << (y - c).transpose());
      CHECK(std::abs((y - c).cwiseQuotient(s).norm() - 1) < 1e-15);
      const Vec<D> nrm = (y - c).cwiseQuotient(s.cwiseProduct(s)).normalized(), r = c + x - y;
      CHECK((r - r.dot(nrm) * nrm).norm() < 1e-12 * (1 + r.norm()));  // along the normal
      Real nearest = 1e300;
      for (const Vec<D>& z : surface) nearest = std::min(nearest, (c + x - z).norm());
      CHECK(r.norm() <= nearest + 1e-12);
    }
  };
  const Vec<3> s3(1, 0.25, 0.4);
  check(s3, std::vector<Vec<3>>{{1.3, 0.2, -0.1}, {0.2, -0.5, 0.6}, {-0.75, 0.16, 0.2},
                                {0.98, 0.0, 0.0}, {0.5 * (0.95 + 0.9), 0.5 * 0.25 * (0.312 - 0.436), 0.0}});
  const Vec<2> s2(1, 0.2);
  check(s2, std::vector<Vec<2>>{{1.2, 0.1}, {-0.8, 0.1}, {0.0, -0.19}, {0.97, 0.0}, {3, 4}});
  // the midpoint of a chord near a slender ellipse's tip moves along the normal by the sagitta
  // (0.6 % of it along the chord: the curvature changes along it), where the radial projection
  // moves it twice as far, 85 % of that along the chord
  const Vec<2> p(std::cos(0.3), 0.2 * std::sin(0.3)), q(std::cos(0.45), 0.2 * std::sin(0.45)), m = (p + q) / 2;
  const Vec<2> nearest = onto_ellipsoid<2>(Vec<2>::Zero(), s2)(m), radial = m / m.cwiseQuotient(s2).norm();
  CHECK(std::abs((nearest - m).dot(q - p)) < 0.02 * (nearest - m).norm() * (q - p).norm());
  CHECK(std::abs((radial - m).dot((q - p).normalized())) > 0.5 * (radial - m).norm());
  CHECK_THROWS_WITH(onto_ellipsoid<2>(Vec<2>::Zero(), Vec<2>(1, 0)), Catch::Contains("semi_axes"));
  // a turned ellipsoid (axes the columns of a rotation): the axis-aligned one's nearest point,
  // turned: on the turned surface, along its normal
  const Mat<3, 3> A = Eigen::AngleAxis<Real>(0.7, Vec<3>(1, 2, 3).normalized()).toRotationMatrix();
  const Vec<3> c3(0.3, -0.2, 0.5);
  const auto turned = onto_ellipsoid<3>(c3, s3, A);
  const auto aligned = onto_ellipsoid<3>(Vec<3>::Zero(), s3);
  for (const Vec<3>& x : std::vector<Vec<3>>{{1.3, 0.2, -0.1}, {-0.75, 0.16, 0.2}, {0.2, -0.5, 0.6}}) {
    const Vec<3> y = turned(Vec<3>(c3 + A * x));
    CHECK((y - (c3 + A * aligned(x))).norm() < 1e-14);
    CHECK(std::abs((A.transpose() * (y - c3)).cwiseQuotient(s3).norm() - 1) < 1e-15);
  }
  const Mat<2, 2> A2 = Eigen::Rotation2D<Real>(0.6).toRotationMatrix();
  const Vec<2> y2 = onto_ellipsoid<2>(Vec<2>::Zero(), s2, A2)(A2 * m);
  CHECK((y2 - A2 * nearest).norm() < 1e-15);
  CHECK_THROWS_WITH(onto_ellipsoid<2>(Vec<2>::Zero(), s2, Mat<2, 2>(2 * A2)), Catch::Contains("axes"));
}

TEST_CASE("quadratic geometry: the shell's volume error drops from O(h^2) to O(h^3) or better", "[curved][quick]") {
  // A P2 triangle through six points of a sphere leaves an O(h^3) gap, so the volume error is
  // O(h^3) at least (in 2D the arc's interpolation error is odd about the edge's midpoint and
  // cancels to O(h^5) per edge, hence h^4). On the structured shells (1..4 layers, h ~ 1/n)
  // symmetric pairs of faces cancel too and the order is 4; on gmsh's unstructured shells it is
  // 2.86 and 2.90 (h = 0.35, 0.25, 0.18, orders from the cell counts).
  const Real exact = 4 * pi / 3 * (b * b * b - a * a * a);
  Real es[4], ec[4];
  for (int k = 0; k < 4; ++k) {
    const auto mesh = spherical_shell_mesh(a, b, k + 1);
    QuadraticGeometry<3> g(mesh);
    es[k] = std::abs(measure(g) / exact - 1);
    project_boundary_edges(g, 1, onto_sphere<3>(Vec<3>::Zero(), a));
    project_boundary_edges(g, 2, onto_sphere<3>(Vec<3>::Zero(), b));
    ec[k] = std::abs(measure(g) / exact - 1);
  }
  std::cout << "shell volume, relative error straight " << es[0] << " " << es[1] << " " << es[2] << " " << es[3]
            << ", curved " << ec[0] << " " << ec[1] << " " << ec[2] << " " << ec[3] << "\n";
  const Real rs = std::log(es[2] / es[3]) / std::log(4.0 / 3), rc = std::log(ec[2] / ec[3]) / std::log(4.0 / 3);
  std::cout << "  orders (3 -> 4 layers): straight " << rs << ", curved " << rc << "\n";
  CHECK(rs == Approx(2).margin(0.1));
  CHECK(rc > 2.9);  // measured 3.98
  // and on gmsh's unstructured shells (h = 0.35, 0.25, 0.18): the same gap; the orders (from
  // the cell counts) are noisy on such meshes and only printed (measured: straight 2.06, 2.81;
  // curved 2.86, 2.90)
  Real gs[3], gc[3], n[3];
  int k = 0;
  for (const char* name : {"035", "025", "018"}) {
    const auto mesh = shell_mesh(name);
    QuadraticGeometry<3> g(mesh);
    gs[k] = std::abs(measure(g) / exact - 1);
    project_boundary_edges(g, 1, onto_sphere<3>(Vec<3>::Zero(), a));
    project_boundary_edges(g, 2, onto_sphere<3>(Vec<3>::Zero(), b));
    gc[k] = std::abs(measure(g) / exact - 1);
    n[k] = Real(mesh.n_cells());
    CHECK(gc[k] < 0.01 * gs[k]);  // measured 3.5e-3 .. 2.5e-3 of it
    ++k;
  }
  std::cout << "gmsh shells: relative volume error straight " << gs[0] << " " << gs[1] << " " << gs[2] << ", curved "
            << gc[0] << " " << gc[1] << " " << gc[2] << "; orders straight " << observed_rate(n[0], gs[0], n[1], gs[1], 3)
            << " " << observed_rate(n[1], gs[1], n[2], gs[2], 3) << ", curved "
            << observed_rate(n[0], gc[0], n[1], gc[1], 3) << " " << observed_rate(n[1], gc[1], n[2], gc[2], 3) << "\n";
}

TEST_CASE("the flux through curved facets: the divergence theorem on the curved cells, and the flat rule at the "
          "midpoints",
          "[curved][quick]") {
  // a smooth field with no symmetry the meshes could cancel
  auto f2 = [](const Vec<2>& x) { return Vec<2>(std::sin(x[0] + 2 * x[1]), x[0] * x[0] * x[1] + std::exp(x[1])); };
  auto f3 = [](const Vec<3>& x) {
    return Vec<3>(std::sin(x[0] + 2 * x[1]), x[0] * x[2] * x[2] + std::exp(x[1]), std::cos(x[2] - x[0]) * x[1]);
  };
  // the flux out of the domain (curved_surface_flux orients away from the centre: the inner
  // boundary counts negatively) against the integral of div f_h over the cells, f_h the
  // interpolant at the geometry's DOF points; equal to round-off when the facet rule is the
  // cells' divergence theorem
  auto check = [](const auto& mesh, const auto& f, bool curved) {
    constexpr int D = std::decay_t<decltype(mesh)>::dim;
    QuadraticGeometry<D> g(mesh);
    if (curved) {
      project_boundary_edges(g, 1, onto_sphere<D>(Vec<D>::Zero(), a));
      project_boundary_edges(g, 2, onto_sphere<D>(Vec<D>::Zero(), b));
    }
    Real out = 0, flat = 0;
    for (int tag : {1, 2}) {
      std::vector<std::array<Vec<D>, D*(D + 1) / 2>> facets;
      std::vector<std::array<Vec<D>, D>> corners;
      for (Index k : mesh.boundary_facets())
        if (mesh.facet_tag(k) == tag) {
          facets.push_back(g.facet_nodes(k));
          std::array<Vec<D>, D> x;
          for (int i = 0; i < D; ++i) x[std::size_t(i)] = facets.back()[std::size_t(i)];
          corners.push_back(x);
        }
      const Real sign = tag == 1 ? -1 : 1;
      out += sign * curved_surface_flux<D>(facets, f);
      flat += sign * surface_flux<D>(corners, f, 2);
    }
    MixedSpace<D, TaylorHood> space(mesh);
    VecX field = VecX::Zero(space.n_field());
    for (Index i = 0; i < space.velocity().n_dofs(); ++i) {
      const Vec<D> u = f(g.dof_point(i));
      for (int k = 0; k < D; ++k) field[space.velocity_field(i, k)] = u[k];
    }
    const Real div = divergence_integral<D, TaylorHood>(space, field, curved ? &g : nullptr);
    std::cout << D << "D, " << (curved ? "curved" : "straight") << ": flux out " << out << ", integral of div f_h "
              << div << ", difference " << out - div << "\n";
    CHECK(std::abs(out - div) < 1e-12 * std::abs(div));
    if (!curved) CHECK(std::abs(out - flat) < 1e-13 * std::abs(flat));  // the edge points at the midpoints
    else CHECK(std::abs(out - flat) > 1e-6 * std::abs(flat));
    return out;
  };
  const auto annulus = annulus_mesh(a, b, 4, 48);
  const auto shell = shell_mesh("025");
  for (bool curved : {false, true}) {
    check(annulus, f2, curved);
    check(shell, f3, curved);
  }
}

TEST_CASE("edge points follow their nodes: rigidly with a rigid motion, at the frame rule's derivative otherwise",
          "[curved][quick]") {
  auto check = [](auto mesh, const auto& rotation) {
    constexpr int D = std::decay_t<decltype(mesh)>::dim;
    QuadraticGeometry<D> g(mesh);
    project_boundary_edges(g, 1, onto_sphere<D>(Vec<D>::Zero(), a));
    project_boundary_edges(g, 2, onto_sphere<D>(Vec<D>::Zero(), b));
    const std::vector<Vec<D>> X0 = mesh.coordinates(), P0 = g.edge_points();
    // a rigid motion x -> Q x + s of every node: the edge points move with it
    const Mat<D> Q = rotation;
    const Vec<D> shift = Vec<D>::LinSpaced(0.3, -0.2);
    std::vector<Vec<D>> X1(X0.size());
    for (std::size_t i = 0; i < X0.size(); ++i) X1[i] = Q * X0[i] + shift;
    Real rigid = 0;
    for (Index e = 0; e < mesh.n_edges(); ++e)
      rigid = std::max(rigid, (g.edge_point(e, X1) - (Q * P0[std::size_t(e)] + shift)).norm());
    // a rigid velocity field v0 + W x (W skew): the edge points' velocities are its values there
    Mat<D> W = Mat<D>::Zero();
    W(0, 1) = -0.7, W(1, 0) = 0.7;
    if constexpr (D == 3) W(0, 2) = 0.4, W(2, 0) = -0.4, W(1, 2) = -0.25, W(2, 1) = 0.25;
    const Vec<D> v0 = Vec<D>::LinSpaced(-0.5, 0.8);
    std::vector<Vec<D>> V(X0.size());
    for (std::size_t i = 0; i < X0.size(); ++i) V[i] = v0 + W * X0[i];
    const auto We = g.edge_velocities(V);
    Real vel = 0;
    for (Index e = 0; e < mesh.n_edges(); ++e)
      vel = std::max(vel, (We[std::size_t(e)] - (v0 + W * P0[std::size_t(e)])).norm());
    // any other field: the derivative of edge_point(e, X + s V) at s = 0 (central differences)
    for (std::size_t i = 0; i < X0.size(); ++i) V[i] = (X0[i].array() * 3.1).sin().matrix() + Vec<D>::Constant(0.2);
    const auto Wg = g.edge_velocities(V);
    const Real s = 1e-6;
    std::vector<Vec<D>> Xp(X0.size()), Xm(X0.size());
    for (std::size_t i = 0; i < X0.size(); ++i) Xp[i] = X0[i] + s * V[i], Xm[i] = X0[i] - s * V[i];
    Real fd = 0;
    for (Index e = 0; e < mesh.n_edges(); ++e)
      fd = std::max(fd, ((g.edge_point(e, Xp) - g.edge_point(e, Xm)) / (2 * s) - Wg[std::size_t(e)]).norm());
    // a body's surface turning while the nodes around it move otherwise: its edge points turn
    // with it (their frames use the surface's nodes only)
    std::vector<Vec<D>> X2 = X0;
    for (std::size_t i = 0; i < X0.size(); ++i) X2[i] += 0.01 * V[i];
    for (Index i : mesh.boundary_nodes(1)) X2[std::size_t(i)] = Q * X0[std::size_t(i)];
    Real body = 0;
    for (Index e : mesh.boundary_edges(1))
      body = std::max(body, (g.edge_point(e, X2) - Q * P0[std::size_t(e)]).norm());
    CHECK(body < 1e-14);
    // after the mesh moved, the geometry's points are the moved ones (nothing to update)
    mesh.set_coordinates(X1);
    Real upd = 0;
    for (Index e = 0; e < mesh.n_edges(); ++e)
      upd = std::max(upd, (g.edge_point(e) - (Q * P0[std::size_t(e)] + shift)).norm());
    std::cout << D << "D edge points: rigid motion " << rigid << ", rigid velocity " << vel << ", derivative vs FD " << fd
              << ", a turning surface " << body << ", after the mesh moved " << upd << "\n";
    CHECK(rigid < 1e-14);
    CHECK(vel < 1e-14);
    CHECK(fd < 1e-8);
    CHECK(upd < 1e-14);
  };
  const Real t = 0.8;
  check(annulus_mesh(a, b, 3, 24), (Mat<2>() << std::cos(t), -std::sin(t), std::sin(t), std::cos(t)).finished());
  check(spherical_shell_mesh(a, b, 1), Eigen::AngleAxis<Real>(t, Vec<3>(1, 2, 2).normalized()).toRotationMatrix());
}

TEST_CASE("the curved Stokes kernel with edge points at the midpoints equals the affine kernel", "[curved][quick]") {
  auto compare = [](const auto& mesh) {
    constexpr int D = std::decay_t<decltype(mesh)>::dim;
    using Kernel = StokesKernel<D, TaylorHood>;
    MixedSpace<D, TaylorHood> space(mesh);
    auto force = [](const Vec<D>& x) { return Vec<D>(x.array().sin().matrix() + Vec<D>::Ones()); };
    Kernel affine(space, 0.7, force), curved(space, 0.7, force);
    QuadraticGeometry<D> g(mesh);
    for (Index e = 0; e < mesh.n_edges(); ++e) g.set_edge_point(e, g.edge_point(e));  // marks every cell curved
    REQUIRE(g.n_curved() == mesh.n_cells());
    curved.set_geometry(&g);
    typename Kernel::LocalVec u = Kernel::LocalVec::LinSpaced(-1, 2), r0, r1;
    typename Kernel::LocalMat A0, A1;
    Real worst = 0;
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      affine.cell(c, u, A0, r0);
      curved.cell(c, u, A1, r1);
      worst = std::max({worst, (A1 - A0).cwiseAbs().maxCoeff() / A0.cwiseAbs().maxCoeff(),
                        (r1 - r0).cwiseAbs().maxCoeff() / r0.cwiseAbs().maxCoeff()});
    }
    return worst;
  };
  const Real e2 = compare(annulus_mesh(a, b, 2, 12)), e3 = compare(box_mesh(2, 2, 2));
  std::cout << "curved kernel on straight cells against the affine kernel: max relative difference 2D " << e2 << ", 3D "
            << e3 << "\n";
  CHECK(e2 < 1e-13);
  CHECK(e3 < 1e-13);
}

TEST_CASE("the curved ALE Navier-Stokes kernel with edge points at the midpoints equals the affine kernel",
          "[curved][quick]") {
  // every term: mass with a history, theta = 1/2 with u^n, convection with a mesh velocity
  // (edge velocities the midpoint averages, given explicitly and not), Newton and semi-implicit,
  // a body force; and without convection (unsteady Stokes)
  auto compare = []<bool Convection>(const auto& mesh, Linearisation lin, bool edge_velocities) {
    constexpr int D = std::decay_t<decltype(mesh)>::dim;
    using Kernel = AleNavierStokesKernel<D, TaylorHood, Convection>;
    MixedSpace<D, TaylorHood> space(mesh);
    Kernel affine(space, 1.3, 0.7, lin), curved(space, 1.3, 0.7, lin);
    QuadraticGeometry<D> g(mesh);
    for (Index e = 0; e < mesh.n_edges(); ++e) g.set_edge_point(e, g.edge_point(e));
    REQUIRE(g.n_curved() == mesh.n_cells());
    curved.set_geometry(&g);
    const Index n = space.n_field();
    VecX hist(n), prev(n), extra(n);
    for (Index k = 0; k < n; ++k) {
      hist[k] = std::sin(0.3 * Real(k)), prev[k] = std::cos(0.7 * Real(k)), extra[k] = std::sin(1.1 * Real(k) + 0.2);
    }
    std::vector<Vec<D>> mv(std::size_t(mesh.n_nodes())), ev(std::size_t(mesh.n_edges()));
    for (Index v = 0; v < mesh.n_nodes(); ++v) mv[std::size_t(v)] = Vec<D>::Constant(0.4) + 0.5 * mesh.node(v);
    for (Index e = 0; e < mesh.n_edges(); ++e)
      ev[std::size_t(e)] = 0.5 * (mv[std::size_t(mesh.edge(e)[0])] + mv[std::size_t(mesh.edge(e)[1])]);
    StepInputs<D> s{.dt = 0.05, .theta = 0.5, .a0 = 1.5, .history = &hist, .previous = &prev, .extrapolated = &extra,
                    .mesh_velocity = &mv, .edge_velocity = edge_velocities ? &ev : nullptr,
                    .force = [](const Vec<D>& x) { return Vec<D>(x.array().cos().matrix()); }};
    affine.set_step(s);
    curved.set_step(s);
    typename Kernel::LocalVec u = Kernel::LocalVec::LinSpaced(-1, 2), r0, r1;
    typename Kernel::LocalMat A0, A1;
    Real worst = 0;
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      affine.cell(c, u, A0, r0);
      curved.cell(c, u, A1, r1);
      worst = std::max({worst, (A1 - A0).cwiseAbs().maxCoeff() / A0.cwiseAbs().maxCoeff(),
                        (r1 - r0).cwiseAbs().maxCoeff() / r0.cwiseAbs().maxCoeff()});
    }
    return worst;
  };
  for (auto lin : {Linearisation::newton, Linearisation::semi_implicit})
    for (bool ev : {false, true}) {
      const Real e2 = compare.template operator()<true>(annulus_mesh(a, b, 2, 12), lin, ev),
                 e3 = compare.template operator()<true>(box_mesh(2, 2, 2), lin, ev);
      std::cout << "curved NS kernel on straight cells against the affine kernel ("
                << (lin == Linearisation::newton ? "Newton" : "semi-implicit") << (ev ? ", edge velocities" : "")
                << "): max relative difference 2D " << e2 << ", 3D " << e3 << "\n";
      CHECK(e2 < 1e-13);
      CHECK(e3 < 1e-13);
    }
  const Real s2 = compare.template operator()<false>(annulus_mesh(a, b, 2, 12), Linearisation::newton, true),
             s3 = compare.template operator()<false>(box_mesh(2, 2, 2), Linearisation::newton, true);
  std::cout << "... unsteady Stokes: 2D " << s2 << ", 3D " << s3 << "\n";
  CHECK(s2 < 1e-13);
  CHECK(s3 < 1e-13);
}

TEST_CASE("an edge point that folds its cell is rejected, naming the cell", "[curved][quick]") {
  const auto mesh = annulus_mesh(a, b, 2, 12);
  QuadraticGeometry<2> g(mesh);
  const Index e = mesh.boundary_edges(1)[0];
  const Vec<2> m = g.edge_point(e);
  g.set_edge_point(e, 4 * m);  // far outside, past the opposite side of its cell
  Index bad = -1;
  for (Index c = 0; c < mesh.n_cells(); ++c)
    if (g.curved(c)) bad = c;
  REQUIRE(bad >= 0);
  CHECK(g.jacobian_ratio(bad) < 0);
  try {
    g.check_all();
    FAIL("no exception");
  } catch (const MeshError& err) {
    CHECK(err.index() == bad);
    CHECK(std::string(err.what()).find("singular") != std::string::npos);
  }
  CHECK_THROWS_AS(QuadraticGeometry<2>(mesh, std::vector<Vec<2>>(3)), InvalidArgument);
  CHECK_THROWS_AS(project_boundary_edges(g, 99, onto_sphere<2>(Vec<2>::Zero(), 1.0)), InvalidArgument);
}

TEST_CASE("isoparametric Taylor-Hood: Couette annulus at L2 rate 3, H1 rate 2 (straight cells: 2, 1.5)",
          "[curved][quick]") {
  FlowErrors es[3], ec[3];
  Real n[3];
  for (int k = 0; k < 3; ++k) {
    const auto mesh = annulus_mesh(a, b, 4 << k, 24 << k);
    es[k] = couette(mesh, false).first;
    std::tie(ec[k], n[k]) = couette(mesh, true);
  }
  for (int k = 1; k < 3; ++k) {
    const Real sl2 = observed_rate(n[k - 1], es[k - 1].u_l2, n[k], es[k].u_l2, 2);
    const Real sh1 = observed_rate(n[k - 1], es[k - 1].u_h1, n[k], es[k].u_h1, 2);
    const Real cl2 = observed_rate(n[k - 1], ec[k - 1].u_l2, n[k], ec[k].u_l2, 2);
    const Real ch1 = observed_rate(n[k - 1], ec[k - 1].u_h1, n[k], ec[k].u_h1, 2);
    std::cout << "Couette annulus level " << k << ": straight L2 " << es[k].u_l2 << " (rate " << sl2 << "), H1 "
              << es[k].u_h1 << " (" << sh1 << "); curved L2 " << ec[k].u_l2 << " (" << cl2 << "), H1 " << ec[k].u_h1
              << " (" << ch1 << ")\n";
    CHECK(sl2 == Approx(2).margin(0.15));
    CHECK(sh1 == Approx(1.5).margin(0.15));
    CHECK(cl2 == Approx(3).margin(0.15));
    CHECK(ch1 == Approx(2).margin(0.15));
  }
}

TEST_CASE("isoparametric Taylor-Hood: spherical-shell Couette flow, quasi-optimal on curved cells", "[curved][convergence]") {
  // spherical_shell_mesh, 1..3 layers. The flow's 1/r^3 profile keeps these levels
  // pre-asymptotic (the interpolant's own L2 rates: 2.47, 2.70, then 2.80 at 4 layers), so the
  // test compares each solution with the interpolant of the exact flow on its geometry: on
  // curved cells the Stokes error is the interpolation error (Cea's lemma with the geometry
  // exact to O(h^3)); on straight ones the O(h^2) boundary error dominates and grows against it.
  FlowErrors es[3], ec[3], is[3], ic[3];
  Real n[3];
  for (int k = 0; k < 3; ++k) {
    const auto mesh = spherical_shell_mesh(a, b, k + 1);
    es[k] = couette(mesh, false).first;
    std::tie(ec[k], n[k]) = couette(mesh, true);
    is[k] = couette_interpolant(mesh, false);
    ic[k] = couette_interpolant(mesh, true);
  }
  for (int k = 0; k < 3; ++k) {
    std::cout << "Couette shell, " << k + 1 << " layers (" << n[k] << " DOFs): straight L2 " << es[k].u_l2
              << " (interpolant " << is[k].u_l2 << "), H1 " << es[k].u_h1 << " (" << is[k].u_h1 << "); curved L2 "
              << ec[k].u_l2 << " (" << ic[k].u_l2 << "), H1 " << ec[k].u_h1 << " (" << ic[k].u_h1 << ")";
    if (k > 0)
      std::cout << "; rates straight L2 " << observed_rate(n[k - 1], es[k - 1].u_l2, n[k], es[k].u_l2, 3) << ", curved L2 "
                << observed_rate(n[k - 1], ec[k - 1].u_l2, n[k], ec[k].u_l2, 3) << " H1 "
                << observed_rate(n[k - 1], ec[k - 1].u_h1, n[k], ec[k].u_h1, 3);
    std::cout << "\n";
  }
  for (int k = 1; k < 3; ++k) {  // measured: solution / interpolant 1.07, 1.04 (curved); 3.9, 6.1 (straight)
    CHECK(ec[k].u_l2 < 1.1 * ic[k].u_l2);
    CHECK(ec[k].u_h1 < 1.1 * ic[k].u_h1);
    CHECK(es[k].u_l2 > 3 * is[k].u_l2);
  }
  CHECK(es[2].u_l2 / is[2].u_l2 > es[1].u_l2 / is[1].u_l2);  // the straight geometry's error takes over
  // rates from the DOF counts, 2 -> 3 layers: measured L2 2.95, H1 1.84 (straight L2 1.95)
  CHECK(observed_rate(n[1], ec[1].u_l2, n[2], ec[2].u_l2, 3) > 2.8);
  CHECK(observed_rate(n[1], ec[1].u_h1, n[2], ec[2].u_h1, 3) > 1.75);
}

// ---- moving meshes: free bodies with curved surfaces ----------------------------------------

namespace {
// A free inner cylinder / sphere (radius a, external torque T) in a fixed outer one (radius b),
// unsteady Stokes to steady state; `curved`: isoparametric cells on both surfaces. Returns the
// steady spin w (2D: T = 4 pi mu w a^2 b^2 / (b^2 - a^2); 3D: T = 8 pi mu w a^3 b^3 / (b^3 - a^3)).
Real spin_2d(int nr, int nt, bool curved) {
  AleFlow<FlowConfig<2, TaylorHood, BDF2_BDF2E, UnsteadyStokes>> flow(annulus_mesh(a, b, nr, nt), FlowOptions{0.01, mu});
  flow.set_velocity(tags::outer, [](const Vec<2>&, Real) { return Vec<2>(0, 0); });
  RigidBody2D body;
  body.tag = tags::inner;
  body.mass = 1e-3;
  body.inertia = 1e-3;
  body.external_load = Vec<3>(0, 0, 1.0);
  flow.add_body(body);
  if (curved) {
    flow.curve_boundary(tags::inner, onto_sphere<2>(Vec<2>::Zero(), a));
    flow.curve_boundary(tags::outer, onto_sphere<2>(Vec<2>::Zero(), b));
  }
  for (int n = 0; n < 40; ++n) flow.step(0.0025);
  CHECK(flow.body_hydrodynamic_load(0)[2] == Approx(-1.0).epsilon(1e-3));  // the momentum balance closes
  CHECK(flow.body_centre(0).norm() < 1e-12);
  return flow.body_velocity(0)[2];
}
Real spin_3d(const Mesh<3>& mesh, bool curved) {
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, UnsteadyStokes>> flow(mesh, FlowOptions{0.01, mu});
  flow.set_velocity(2, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
  RigidBody3D body;
  body.tag = 1;
  body.mass = 1e-3;
  body.inertia = 1e-3 * Mat<3>::Identity();
  body.external_load[5] = 1.0;
  body.radius = a;
  flow.add_body(body);
  if (curved) {
    flow.curve_boundary(1, onto_sphere<3>(Vec<3>::Zero(), a));
    flow.curve_boundary(2, onto_sphere<3>(Vec<3>::Zero(), b));
  }
  for (int n = 0; n < 6; ++n) flow.step(0.02);
  CHECK(flow.body_hydrodynamic_load(0)[5] == Approx(-1.0).epsilon(1e-3));
  return flow.body_velocity(0)[5];
}
}  // namespace

TEST_CASE("a free cylinder turning in a fixed one on curved cells: the torque law at O(h^4)",
          "[curved][bodies][convergence]") {
  // The steady spin is a functional of the solution: O(h^2k) = O(h^4) with Taylor–Hood once the
  // O(h^2) of the polygons is gone (measured orders straight 1.70, 1.88; curved 3.86, 3.94).
  const Real w_exact = (b * b - a * a) / (4 * pi * mu * a * a * b * b);
  Real es[3], ec[3];
  for (int k = 0; k < 3; ++k) {
    es[k] = std::abs(spin_2d(3 << k, 48 << k, false) / w_exact - 1);
    ec[k] = std::abs(spin_2d(3 << k, 48 << k, true) / w_exact - 1);
  }
  std::cout << "cylinder Couette, relative error in w (48, 96, 192 sides): straight " << es[0] << " " << es[1] << " "
            << es[2] << ", curved " << ec[0] << " " << ec[1] << " " << ec[2] << "; orders straight "
            << std::log2(es[0] / es[1]) << " " << std::log2(es[1] / es[2]) << ", curved " << std::log2(ec[0] / ec[1])
            << " " << std::log2(ec[1] / ec[2]) << "\n";
  CHECK(std::log2(es[1] / es[2]) == Approx(2).margin(0.3));
  CHECK(std::log2(ec[1] / ec[2]) == Approx(4).margin(0.3));
}

TEST_CASE("a free sphere turning in a fixed one on curved cells: the torque law at O(h^3) or better",
          "[curved][bodies3d][convergence]") {
  // Structured shells of 1..3 layers (h ~ 1/n): measured errors straight 17.5 %, 5.6 %, 2.7 %;
  // curved 3.1 %, 0.42 %, 0.106 % (orders 2.87, 3.39, rising towards 4). On gmsh's shells of
  // h = 0.25 / 0.18 (tests/physics/test_bodies3d.cpp): straight 6.6 % / 3.8 %, curved 0.56 % /
  // 0.46 %.
  const Real w_exact = (b * b * b - a * a * a) / (8 * pi * mu * a * a * a * b * b * b);
  Real es[3], ec[3];
  for (int n = 1; n <= 3; ++n) {
    const auto mesh = spherical_shell_mesh(a, b, n);
    es[n - 1] = std::abs(spin_3d(mesh, false) / w_exact - 1);
    ec[n - 1] = std::abs(spin_3d(mesh, true) / w_exact - 1);
  }
  std::cout << "sphere Couette, relative error in w (1, 2, 3 layers): straight " << es[0] << " " << es[1] << " " << es[2]
            << ", curved " << ec[0] << " " << ec[1] << " " << ec[2] << "; orders curved " << std::log2(ec[0] / ec[1])
            << " " << std::log(ec[1] / ec[2]) / std::log(1.5) << "\n";
  CHECK(std::log(ec[1] / ec[2]) / std::log(1.5) > 3);
  CHECK(ec[2] < 0.05 * es[2]);
  for (const char* name : {"025", "018"}) {
    const auto mesh = shell_mesh(name);
    const Real s = std::abs(spin_3d(mesh, false) / w_exact - 1), c = std::abs(spin_3d(mesh, true) / w_exact - 1);
    std::cout << "sphere Couette, gmsh shell h = 0." << name + 1 << ": relative error in w straight " << s << ", curved "
              << c << "\n";
    CHECK(c < 0.15 * s);
  }
}

namespace {
// A sphere (radius a) driven at U = 1 along z at the centre of a fixed sphere (radius b),
// quasi-static Stokes (rho = 1e-18: each step solves the steady problem; the sphere moves 1.2e-4
// a in all). Three steps: the first is the midpoint start-up, whose load is the average over the
// step (half the force, from rest); the BDF2 steps after it report the load at t^{n+1}.
// Returns the hydrodynamic force along z. Exact (Williams 1915; Haberman & Sayre 1958; Happel &
// Brenner 1965, section 4-22): F = -6 pi mu a U K, K = (1 - l^5) / (1 - 9/4 l + 5/2 l^3 - 9/4 l^5
// + l^6), l = a / b (at l = 1/2, K = 124/17: the Stokes solution psi = sin^2(theta) (A/r + B r +
// C r^2 + D r^4) with the four boundary conditions gives it exactly).
Real drag_3d(const Mesh<3>& mesh, bool curved) {
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, UnsteadyStokes>> flow(mesh, FlowOptions{1e-18, mu});
  flow.set_velocity(2, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
  RigidBody3D body;
  body.tag = 1;
  body.mass = 1;
  body.inertia = Mat<3>::Identity();
  body.radius = a;
  body.prescribed = [](Real) { return (Vec<6>() << 0, 0, 1, 0, 0, 0).finished(); };
  flow.add_body(body);
  if (curved) {
    flow.curve_boundary(1, onto_sphere<3>(Vec<3>::Zero(), a));
    flow.curve_boundary(2, onto_sphere<3>(Vec<3>::Zero(), b));
  }
  for (int n = 0; n < 3; ++n) flow.step(2e-5);
  const auto F = flow.body_hydrodynamic_load(0);
  CHECK(F.template head<2>().norm() < 1e-3 * std::abs(F[2]));  // symmetric up to the mesh
  CHECK(F.template tail<3>().norm() < 1e-3 * std::abs(F[2]) * a);
  return F[2];
}
}  // namespace

TEST_CASE("a sphere translating at the centre of a fixed sphere: the drag converges to the exact formula",
          "[curved][bodies3d][convergence]") {
  const Real l = a / b, K = (1 - std::pow(l, 5)) / (1 - 2.25 * l + 2.5 * std::pow(l, 3) - 2.25 * std::pow(l, 5) + std::pow(l, 6));
  const Real F_exact = -6 * pi * mu * a * K;
  CHECK(K == Approx(124.0 / 17).epsilon(1e-14));
  Real es[3], ec[3];
  for (int n = 1; n <= 3; ++n) {
    const auto mesh = spherical_shell_mesh(a, b, n);
    es[n - 1] = std::abs(drag_3d(mesh, false) / F_exact - 1);
    ec[n - 1] = std::abs(drag_3d(mesh, true) / F_exact - 1);
  }
  std::cout << "sphere in a sphere, relative error in the drag (1, 2, 3 layers): straight " << es[0] << " " << es[1]
            << " " << es[2] << ", curved " << ec[0] << " " << ec[1] << " " << ec[2] << "; orders straight "
            << std::log2(es[0] / es[1]) << " " << std::log(es[1] / es[2]) / std::log(1.5) << ", curved "
            << std::log2(ec[0] / ec[1]) << " " << std::log(ec[1] / ec[2]) / std::log(1.5) << "\n";
  // The force is a functional of the solution: O(h^4) with Taylor–Hood once the geometry is
  // exact to O(h^3), O(h^2) on the polyhedra. Measured orders (h ~ 1 / layers): curved 1.91, 3.00,
  // then 3.33 at 4 layers (1.31e-3; 57 s, 2.2 GB, so not run here), rising towards 4 as the
  // torque's do; straight 1.44, 1.59, towards 2. The curved cells remove 86 % of the error at 3
  // layers.
  CHECK(std::log(ec[1] / ec[2]) / std::log(1.5) > 2.8);
  CHECK(ec[2] < 0.25 * es[2]);
  for (const char* name : {"025", "018"}) {
    const auto mesh = shell_mesh(name);
    const Real s = std::abs(drag_3d(mesh, false) / F_exact - 1), c = std::abs(drag_3d(mesh, true) / F_exact - 1);
    std::cout << "sphere in a sphere, gmsh shell h = 0." << name + 1 << ": relative error in the drag straight " << s
              << ", curved " << c << "\n";
    CHECK(c < 0.5 * s);  // measured 0.26 (h = 0.25), 0.43 (h = 0.18)
  }
}

namespace {
// A massless squirmer (slip B1 sin(theta) e_theta about z: squirmer_slip(B1, 0, e_z); radius a)
// at the centre of a fixed sphere (radius b), quasi-static Stokes (rho = 1e-18, three steps of
// 2e-5 as drag_3d). Returns V_z / B1; `net` is the net flux of the computed velocity (the
// integral of div u_h over the cells, through their maps), `removed` the normal speed the flow
// took off the slip to make its discrete flux zero.
Real squirmer_in_sphere(const Mesh<3>& mesh, bool curved, Real& net, Real& removed) {
  constexpr Real B1 = 1;
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, UnsteadyStokes>> flow(mesh, FlowOptions{1e-18, mu});
  flow.set_velocity(2, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
  RigidBody3D body = massless_sphere(1, Vec<3>::Zero(), a);
  body.slip = squirmer_slip(B1, 0, Vec<3>(0, 0, 1));
  flow.add_body(body);
  if (curved) {
    flow.curve_boundary(1, onto_sphere<3>(Vec<3>::Zero(), a));
    flow.curve_boundary(2, onto_sphere<3>(Vec<3>::Zero(), b));
  }
  for (int n = 0; n < 3; ++n) flow.step(2e-5);
  net = divergence_integral<3, TaylorHood>(flow.space(), flow.field(), flow.geometry());
  removed = flow.slip_flux_removed(0);
  const Vec<6> Z = flow.body_velocity(0);
  CHECK(Z.head<2>().norm() < 1e-2 * std::abs(Z[2]));  // symmetric up to the mesh
  CHECK(Z.tail<3>().norm() * a < 1e-2 * std::abs(Z[2]));
  return Z[2] / B1;
}
}  // namespace

TEST_CASE("a squirmer at the centre of a fixed sphere: its slip flux-free through curved facets, its speed "
          "converging to the exact one",
          "[curved][bodies3d][convergence]") {
  // Exact: the Stokes stream function psi = sin^2(theta) (A / r + B r + C r^2 + D r^4) (as for
  // the drag above), with u = U e_z + B1 sin(theta) e_theta on r = a, u = 0 on r = b and no
  // force (B = 0: the Stokeslet's coefficient is the force, F = -8 pi mu B), gives
  // U / B1 = (2/3) (1 + l + l^2 - 3/2 l^3 - 3/2 l^4) / (1 + l + l^2 + l^3 + l^4), l = a / b:
  // Blake's 2/3 unbounded (l -> 0), 47/93 at l = 1/2.
  const Real l = a / b;
  const Real U = 2.0 / 3 * (1 + l + l * l - 1.5 * std::pow(l, 3) - 1.5 * std::pow(l, 4)) /
                 (1 + l + l * l + std::pow(l, 3) + std::pow(l, 4));
  CHECK(U == Approx(47.0 / 93).epsilon(1e-14));
  const Real scale = 4 * pi * a * a;  // the slip's flux scale (B1 = 1)
  Real es[2], ec[2];
  for (int n = 2; n <= 3; ++n) {
    const auto mesh = spherical_shell_mesh(a, b, n);
    Real net, removed;
    es[n - 2] = std::abs(squirmer_in_sphere(mesh, false, net, removed) / U - 1);
    CHECK(std::abs(net) < 1e-12 * scale);
    ec[n - 2] = std::abs(squirmer_in_sphere(mesh, true, net, removed) / U - 1);
    CHECK(std::abs(net) < 1e-12 * scale);
  }
  std::cout << "squirmer in a sphere, relative error in V (2, 3 layers): straight " << es[0] << " " << es[1]
            << ", curved " << ec[0] << " " << ec[1] << "; orders straight " << std::log(es[0] / es[1]) / std::log(1.5)
            << ", curved " << std::log(ec[0] / ec[1]) / std::log(1.5) << "\n";
  // V is a functional of the solution, as the drag: O(h^4) once the geometry is exact to O(h^3),
  // O(h^2) on the polyhedra. Measured (h ~ 1 / layers): straight 2.31e-2, 8.59e-3 (order 2.45,
  // pre-asymptotic as the drag's 1.59), curved 8.40e-3, 2.27e-3 (order 3.23, the drag's 3.00)
  const Real order_s = std::log(es[0] / es[1]) / std::log(1.5), order_c = std::log(ec[0] / ec[1]) / std::log(1.5);
  CHECK(order_c > 2.8);
  CHECK(order_c > order_s);
  for (int k = 0; k < 2; ++k) CHECK(ec[k] < 0.5 * es[k]);
  // on gmsh's unstructured shell the slip's interpolant leaks through the curved facets too
  // (less than through the flat ones): the flow removes it, and the computed velocity's net
  // flux is zero to round-off, so no pressure DOF takes it up (measured: normal speeds removed
  // -7.5e-4 straight, -3.6e-5 curved; errors in V 2.7e-2 and 9.4e-3 on 2-3 cells across the gap)
  const auto mesh = shell_mesh("025");
  Real net_s, removed_s, net_c, removed_c;
  const Real vs = squirmer_in_sphere(mesh, false, net_s, removed_s);
  const Real vc = squirmer_in_sphere(mesh, true, net_c, removed_c);
  std::cout << "squirmer in a sphere, gmsh shell h = 0.25: relative error in V straight " << vs / U - 1 << ", curved "
            << vc / U - 1 << "; normal speed removed straight " << removed_s << ", curved " << removed_c
            << "; net flux " << net_s << ", " << net_c << "\n";
  CHECK(std::abs(net_s) < 1e-12 * scale);
  CHECK(std::abs(net_c) < 1e-12 * scale);
  CHECK(removed_c != 0);
  CHECK(std::abs(removed_c) < std::abs(removed_s));
  CHECK(std::abs(vc / U - 1) < std::abs(vs / U - 1));
}

TEST_CASE("a free ellipse in simple shear turns on Jeffery's orbit (curved cells)", "[curved][bodies][convergence]") {
  // Jeffery (1922), in 2D: w(phi) = -(a^2 sin^2 phi + b^2 cos^2 phi) / (a^2 + b^2), period
  // T = 2 pi (a^2 + b^2) / (a b). In a circular container the form A sin^2 + B cos^2 is exact
  // too (the wall's shear is a rigid rotation at -1/2, which the body follows exactly, plus a
  // strain whose torque turns with the body as cos 2 phi), so w(pi/4) = -1/2 and
  // w(pi/8) = (w(0) + w(pi/2)) / 2 + (w(0) - w(pi/2)) sqrt(2) / 4 hold on every container, and
  // T = 2 pi / sqrt(w(0) w(pi/2)). The container's wall reflects the stresslet: T converges to
  // Jeffery's at O((a / L)^2) (measured factors 4.1, 4.0, 3.8 for L = 8 .. 64), so L = 16 and 32
  // extrapolate to it. Measured at b = 0.5: T / T_J - 1 = 4.02e-3, 1.01e-3, extrapolated 9e-6.
  // (scenes/jeffery.hpp: Stokes, the body massless; h = 0.1 b at the ellipse, 20 cells per b.)
  for (const Real b : {0.5, 0.25}) {
    scenes::Jeffery scene{.b = b, .h_body = 0.1 * b};
    const Real wj0 = scene.jeffery_spin(0), wj90 = scene.jeffery_spin(pi / 2), Tj = scene.jeffery_period();
    Real T[2];
    for (int k = 0; k < 2; ++k) {
      const Real L = 16 << k;
      scene.container = L;
      const Real w0 = scene.spin(0), w90 = scene.spin(pi / 2), w45 = scene.spin(pi / 4), w22 = scene.spin(pi / 8);
      T[k] = 2 * pi / std::sqrt(w0 * w90);
      std::cout << "ellipse b/a = " << b << ", container L = " << L << ": w(0) " << w0 << " (Jeffery " << wj0
                << "), w(pi/2) " << w90 << " (" << wj90 << "), w(pi/4) + 1/2 = " << w45 + 0.5 << ", period "
                << T[k] << " (Jeffery " << Tj << ", " << T[k] / Tj - 1 << ")\n";
      CHECK(std::abs(w45 + 0.5) < 1e-5);
      CHECK(std::abs(w22 - ((w0 + w90) / 2 + (w0 - w90) * std::sqrt(2.0) / 4)) < 1e-5);
    }
    const Real factor = (T[0] / Tj - 1) / (T[1] / Tj - 1), T_ext = (4 * T[1] - T[0]) / 3;
    std::cout << "  container error factor L 16 -> 32: " << factor << "; extrapolated period " << T_ext << ", "
              << T_ext / Tj - 1 << " from Jeffery's\n";
    CHECK(factor == Approx(4).margin(0.3));
    CHECK(std::abs(T_ext / Tj - 1) < 1e-4);
    // straight cells (the ellipse a polygon) against the curved ones on the same meshes, L = 32
    scene.curved = false;
    const Real Ts = 2 * pi / std::sqrt(scene.spin(0) * scene.spin(pi / 2));
    std::cout << "  L = 32: period on straight cells / on curved cells - 1 = " << Ts / T[1] - 1 << "\n";
  }
}

TEST_CASE("a free ellipse followed in time on a moving mesh: its angle converges at order 2 to its orbit",
          "[curved][bodies][convergence]") {
  // scenes::Jeffery::follow_orbit: the ellipse (b/a = 1/2) turns a quarter period, from broadside
  // (phi = pi/2, fastest) to aligned with the shear, in a container L = 8; quasi-static flow,
  // BDF2/BDF2E, the mesh moved by elasticity and the curved edge points with the body. The
  // reference is the orbit of the same discrete problem: in a circular container the spin has
  // the exact form w(0) cos^2 + w(pi/2) sin^2 (the discrete spins, each on its own mesh, to 5e-7:
  // the test above), so two static solves give the orbit in closed form (Jeffery::orbit_angle).
  // What is left is the time error of the scheme and what moving the mesh changes in the spin.
  // Measured: max over the steps of |phi_h - phi| = 8.9e-3, 2.10e-3, 5.09e-4 (dt = 0.2, 0.1,
  // 0.05: orders 2.08, 2.05), worst quality 0.28.
  scenes::Jeffery scene{.b = 0.5, .container = 8, .h_body = 0.1};
  // the closed form: Jeffery's own orbit from phi = 0, and the quarter period from broadside
  CHECK(scenes::Jeffery::orbit_angle(2.7, 0, scene.jeffery_spin(0), scene.jeffery_spin(pi / 2)) ==
        Approx(scene.jeffery_angle(2.7)).margin(1e-14));
  CHECK(scenes::Jeffery::orbit_angle(scene.jeffery_period() / 4, pi / 2, scene.jeffery_spin(0),
                                     scene.jeffery_spin(pi / 2)) == Approx(0).margin(1e-14));
  CHECK(scenes::Jeffery::orbit_angle(2 * pi / std::sqrt(0.07), 1, -0.1, -0.7) == Approx(1 - 2 * pi).margin(1e-13));
  const Real w0 = scene.spin(0), w1 = scene.spin(pi / 2), T4 = scene.jeffery_period() / 4;
  Real err[3];
  for (int k = 0; k < 3; ++k) {
    const Real dt = 0.2 / (1 << k);
    Real e = 0, q = 1, phi_end = 0, t_end = 0;
    scene.follow_orbit(pi / 2, dt, T4, [&](Real t, Real phi, Real quality) {
      e = std::max(e, std::abs(phi - scenes::Jeffery::orbit_angle(t, pi / 2, w0, w1)));
      q = std::min(q, quality);
      phi_end = phi, t_end = t;
    });
    err[k] = e;
    std::cout << "ellipse followed in time, dt = " << dt << ": largest angle error " << e << ", worst quality " << q
              << ", angle at t = " << t_end << ": " << phi_end << " (Jeffery's unbounded orbit: "
              << scenes::Jeffery::orbit_angle(t_end, pi / 2, scene.jeffery_spin(0), scene.jeffery_spin(pi / 2)) << ")\n";
    CHECK(q > 0.2);
  }
  for (int k = 0; k < 2; ++k) {
    INFO("dt " << 0.2 / (1 << k) << " -> " << 0.1 / (1 << k) << ": " << err[k] << " -> " << err[k + 1]);
    CHECK(std::log2(err[k] / err[k + 1]) == Approx(2).margin(0.2));
  }
  CHECK_THROWS_WITH(scene.follow_orbit(0, 0, 1, [](Real, Real, Real) {}), Catch::Contains("dt"));
  CHECK_THROWS_WITH(scenes::Jeffery::orbit_angle(1, 0, 0.2, -0.8), Catch::Contains("w0, w1"));
}

TEST_CASE("a free ellipse followed through a full turn with remeshing on curved cells: order 2 to its orbit",
          "[curved][bodies][remesh][convergence]") {
  // The scene of the test above (b/a = 1/2, L = 8, h_body 0.1) through a whole period, which
  // elasticity alone cannot follow (a half turn brings the cells to quality 0.09): the mesh is
  // adapted whenever its worst cell falls below 0.3. After each remesh the new edges on the
  // ellipse get their points on the ellipse where the body is then (the projection given at
  // phi = pi/2, carried by the body's rigid map) and the container's on its circle, and the
  // state is transferred through the old and new curved cells (the past positions as
  // displacements, so that the container's new nodes stay on it). The orbit error stays the
  // scheme's O(dt^2): measured (dt = T/80, T/160) 6.00e-2, 1.54e-2 (order 1.96) with 13 and 12
  // remeshes, worst quality 0.40; every edge point on its curve to 8e-16. (The centre drifts
  // from the symmetric position by 3.2e-2, 7.9e-3 over the turn: the explicit position update's
  // O(dt^2) as well.)
  scenes::Jeffery scene{.b = 0.5, .container = 8, .h_body = 0.1, .remesh_quality = 0.3};
  const Real w0 = scene.spin(0), w1 = scene.spin(pi / 2), T = 2 * pi / std::sqrt(w0 * w1);
  Real err[2];
  for (int k = 0; k < 2; ++k) {
    const Real dt = T / (80 << k);
    Real e = 0, q = 1, off = 0, phi_end = 0;
    Vec<2> centre = Vec<2>::Zero();
    Index n_checked = 0;
    const Index remeshes =
        scene.follow_orbit(pi / 2, dt, T, [&](Real t, Real phi, Real quality, const scenes::Jeffery::Flow& flow) {
          e = std::max(e, std::abs(phi - scenes::Jeffery::orbit_angle(t, pi / 2, w0, w1)));
          q = std::min(q, quality);
          phi_end = phi;
          // every curved edge point on its curve: the ellipse where the body is now, the circle
          const auto& g = *flow.geometry();
          const Real c = std::cos(phi), s = std::sin(phi);
          centre = flow.body_centre(0);
          for (Index v : flow.mesh().boundary_nodes(2))  // the container's nodes stay on it
            off = std::max(off, std::abs(flow.mesh().node(v).norm() / scene.container - 1));
          for (int tag : {1, 2})
            for (Index edge : flow.mesh().boundary_edges(tag)) {
              const Vec<2> x = tag == 2 ? g.edge_point(edge) : Vec<2>(g.edge_point(edge) - centre);
              const Real r = tag == 2 ? x.norm() / scene.container
                                      : std::hypot((c * x[0] + s * x[1]) / scene.a, (-s * x[0] + c * x[1]) / scene.b);
              off = std::max(off, std::abs(r - 1));
              ++n_checked;
            }
        });
    err[k] = e;
    std::cout << "ellipse through a full turn with remeshing, dt = T/" << (80 << k) << ": largest angle error " << e
              << ", " << remeshes << " remeshes, worst quality " << q << ", edge points off their curves by " << off
              << ", angle after the turn " << phi_end << " (orbit: " << pi / 2 - 2 * pi << "), centre "
              << centre.transpose() << "\n";
    CHECK(remeshes >= 2);
    CHECK(q > 0.2);
    CHECK(off < 1e-12);
    CHECK(n_checked > 0);
  }
  CHECK(std::log2(err[0] / err[1]) == Approx(2).margin(0.3));
}

TEST_CASE("curved cells through remeshes: a checkpoint between two of them restarts bit for bit",
          "[curved][remesh][checkpoint]") {
  // The Jeffery scene (the tests above) stepped past a remesh, checkpointed, stepped past the
  // next one; a flow built on the checkpoint's mesh with the same set-up, loaded and stepped as
  // often, is the same to the last bit: the edge points come from the checkpoint (their frame
  // coefficients), and the next remesh carries the body's projection from its pose as added.
  using Flow = scenes::Jeffery::Flow;
  const scenes::Jeffery scene{.b = 0.5, .container = 8, .h_body = 0.1, .remesh_quality = 0.3};
  const Real phi0 = pi / 2, w0 = -0.8, dt = 0.2;
  const auto file = std::filesystem::temp_directory_path() / "alefsi_curved_restart.bin";
  auto make = [&](Mesh<2> mesh) {
    auto f = std::make_unique<Flow>(std::move(mesh), FlowOptions{1e-18, scene.mu});
    scene.set_up(*f, phi0, w0);
    scene.set_remeshing(*f);
    return f;
  };
  auto a = make(scene.mesh(phi0));
  for (int n = 0; a->stats().remeshes < 1; ++n) {
    REQUIRE(n < 100);
    a->step(dt);
  }
  a->step(dt);
  a->save_checkpoint(file);
  const int saved = a->stats().remeshes;
  int steps = 0;
  for (; a->stats().remeshes < saved + 1; ++steps) {
    REQUIRE(steps < 100);
    a->step(dt);
  }
  for (int i = 0; i < 3; ++i, ++steps) a->step(dt);
  auto b = make(read_checkpoint_mesh<2>(file));
  b->load_checkpoint(file);
  REQUIRE(b->geometry() != nullptr);
  for (int i = 0; i < steps; ++i) b->step(dt);
  std::cout << "curved restart: " << saved << " remesh(es) before the checkpoint, " << a->stats().remeshes - saved
            << " in the " << steps << " steps after it; angle " << a->body_angle(0) << "\n";
  CHECK(b->stats().remeshes == a->stats().remeshes);
  CHECK(b->body_angle(0) == a->body_angle(0));  // bit for bit
  CHECK(b->body_velocity(0) == a->body_velocity(0));
  CHECK(b->mesh().coordinates() == a->mesh().coordinates());
  CHECK(b->geometry()->edge_points() == a->geometry()->edge_points());
  {  // a flow given other curve_boundary calls is refused, and left as it was
    scenes::Jeffery straight = scene;
    straight.curved = false;
    Flow c(read_checkpoint_mesh<2>(file), FlowOptions{1e-18, scene.mu});
    straight.set_up(c, phi0, w0);
    CHECK_THROWS_WITH(c.load_checkpoint(file), Catch::Contains("curved"));
    CHECK(c.time() == 0);
  }
  std::filesystem::remove(file);
  std::filesystem::remove(file.string() + ".prev");
}

namespace {
// Remeshing whose own trigger never fires (Remesher2D's adaptation): every remesh of a flow
// that has it is the curved cells' trigger's.
class CurvedTriggerOnly final : public Remesher<2> {
 public:
  explicit CurvedTriggerOnly(RemeshOptions opt) : inner_(std::move(opt)) {}
  bool enabled() const override { return true; }
  RemeshMemory measure(const Mesh<2>& mesh, const std::vector<RemeshBody<2>>& bodies) const override {
    return inner_.measure(mesh, bodies);
  }
  bool needed(const Mesh<2>&, const std::vector<RemeshBody<2>>&, const RemeshMemory&) const override {
    return false;
  }
  std::optional<Remeshed<2>> adapt(const Mesh<2>& mesh, const std::vector<RemeshBody<2>>& bodies,
                                   int velocity_degree) override {
    return inner_.adapt(mesh, bodies, velocity_degree);
  }

 private:
  Remesher2D inner_;
};
}  // namespace

TEST_CASE("a disk driven onto a floor: a curved cell the motion folds is refused, and the curved cells' trigger "
          "remeshes before it",
          "[curved][remesh][quick]") {
  // A disk (R = 0.4, h = 0.2 at it: edge points a sagitta of about h^2 / (8R) = 0.0125 off
  // their chords) driven at unit speed towards the floor of a 2 x 2 box, elasticity moving the
  // mesh: the cells beneath it flatten, their edge points stay on the circle, and a curved
  // cell's map folds long before a straight cell inverts.
  using Flow = AleFlow<FlowConfig<2, TaylorHood, BDF2_BDF2E>>;
  const Real R = 0.4, dt = 0.01;
  const Circle disk{Vec<2>(1, 1), R, 5};
  auto make = [&] {
    MesherOptions mo;
    mo.size = graded_size({disk}, 0.2, 0.4);
    auto f = std::make_unique<Flow>(generate_mesh(Domain2D{channel_outline(2, 2), {disk}}, mo), FlowOptions{1, 1});
    for (int t : {1, 2, 3, 4}) f->set_velocity(t, [](const Vec<2>&, Real) { return Vec<2>(0, 0); });
    RigidBody2D body = disk_body(disk.tag, disk.centre, R, 1);
    body.prescribed = [](Real) { return Vec<3>(0, -1, 0); };
    f->add_body(body);
    f->curve_boundary(disk.tag, onto_sphere<2>(disk.centre, R));
    return f;
  };
  auto gap = [&](const Flow& f) { return f.body_centre(0)[1] - R; };
  // without remeshing: refused with a MeshError naming the curved cell, the flow left at t^n
  Real gap_fold = 0;
  {
    auto f = make();
    Real t_before = 0;
    try {
      for (int n = 0; n < 60; ++n) {
        t_before = f->time();
        f->step(dt);
      }
      FAIL("no cell folded");
    } catch (const MeshError& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find("curved cell") != std::string::npos);
      CHECK(e.entity() == MeshError::Entity::cell);
    }
    gap_fold = gap(*f);
    std::cout << "disk driven onto a floor: a curved cell folds at gap " << gap_fold << " (straight worst quality "
              << f->worst_quality() << ")\n";
    CHECK(f->time() == t_before);
    CHECK(gap_fold > 0.05);             // long before contact
    CHECK(f->worst_quality() > 0.05);   // and before a straight cell degenerates
  }
  // with remeshing that only the curved cells trigger: through that point, to a tenth of it,
  // where the new meshes are too coarse for the gap and keep some edges straight
  auto f = make();
  f->set_remesher(std::make_unique<CurvedTriggerOnly>(
      RemeshOptions{.walls = {channel_outline(2, 2)},
                    .size = [](const std::vector<Circle>& d) { return graded_size(d, 0.2, 0.4); },
                    .adapt = {}}));
  int steps = 0;
  Real worst = 1;
  while (gap(*f) > gap_fold / 10) {
    REQUIRE(steps < 100);
    if (f->step(dt).remeshed)
      std::cout << "  remesh at gap " << gap(*f) << ": worst det J ratio " << f->geometry()->worst_ratio()
                << ", edges straightened so far " << f->stats().straightened << "\n";
    ++steps;
    worst = std::min(worst, f->geometry()->worst_ratio());
  }
  Real off = 0;  // the edges still set: their points on the circle
  Index set = 0;
  for (Index e : f->mesh().boundary_edges(disk.tag))
    if (f->geometry()->point_set(e)) {
      off = std::max(off, std::abs((f->geometry()->edge_point(e) - f->body_centre(0)).norm() - R));
      ++set;
    }
  std::cout << "  with the curved cells' trigger: " << steps << " steps to gap " << gap(*f) << ", " << f->stats().remeshes
            << " remeshes, worst det J ratio " << worst << ", edges straightened " << f->stats().straightened
            << ", edge points set " << set << " of " << f->mesh().boundary_edges(disk.tag).size()
            << ", off the circle by " << off << "\n";
  CHECK(f->stats().remeshes >= 1);
  CHECK(f->stats().remeshes < steps / 2);  // the hysteresis: not a remesh every step
  CHECK(worst > 0.1);
  CHECK(f->stats().straightened > 0);
  CHECK(set > 0);
  CHECK(off < 1e-12);
}

TEST_CASE("curved boundaries in a flow: what is refused, naming the parameter", "[curved][quick]") {
  using Flow = AleFlow<FlowConfig<2, TaylorHood, BDF2_BDF2E, UnsteadyStokes>>;
  auto scene = [](Flow& flow) {
    flow.set_velocity(tags::outer, [](const Vec<2>&, Real) { return Vec<2>(0, 0); });
    RigidBody2D body;
    body.tag = tags::inner, body.mass = 1, body.inertia = 1;
    flow.add_body(body);
  };
  {
    Flow flow(annulus_mesh(a, b, 2, 24), FlowOptions{1, 1});
    scene(flow);
    CHECK_THROWS_AS(flow.curve_boundary(7, onto_sphere<2>(Vec<2>::Zero(), a)), InvalidArgument);  // no such tag
    flow.curve_boundary(tags::inner, onto_sphere<2>(Vec<2>::Zero(), a));
    CHECK_THROWS_WITH(flow.curve_boundary(tags::inner, onto_sphere<2>(Vec<2>::Zero(), a)),
                      Catch::Contains("tag") && Catch::Contains("curved already"));
    REQUIRE(flow.geometry() != nullptr);
    CHECK(flow.geometry()->n_curved() == 24);
    flow.step(0.01);
    CHECK_THROWS_AS(flow.curve_boundary(tags::outer, onto_sphere<2>(Vec<2>::Zero(), b)), Error);  // after a step
  }
  {  // points that fold a cell: refused when the flow is prepared, naming the cell
    Flow flow(annulus_mesh(a, b, 2, 24), FlowOptions{1, 1});
    scene(flow);
    flow.curve_boundary(tags::inner, onto_sphere<2>(Vec<2>::Zero(), 0.9 * b));  // far beyond the first layer
    CHECK_THROWS_AS(flow.prepare(), MeshError);
  }
  {  // a body's surface is curved in the body's frame: the body must be known first
    Flow flow(annulus_mesh(a, b, 2, 24), FlowOptions{1, 1});
    flow.curve_boundary(tags::inner, onto_sphere<2>(Vec<2>::Zero(), a));
    RigidBody2D body;
    body.tag = tags::inner, body.mass = 1, body.inertia = 1;
    CHECK_THROWS_WITH(flow.add_body(body), Catch::Contains("body.tag") && Catch::Contains("add the body first"));
  }
}
