// Rigid bodies coupled monolithically (3D, 6 DOF): the Newton-Euler rows and their Jacobian,
// the orientation update, torque on a sphere turning in a fixed sphere, a free sphere in simple
// shear, and a long run that keeps the quaternion unit and the sphere a sphere.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <numbers>
#include <string>

#include "alefsi/mesh/io/gmsh.hpp"
#include "alefsi/scenes/settling_sphere.hpp"
#include "alefsi/scenes/spheres_settling_in_box.hpp"
#include "alefsi/sim/ale_flow.hpp"

using namespace alefsi;
using std::numbers::pi;

namespace {
Mesh<3> gmsh_mesh(const std::string& name) { return read_gmsh<3>(std::string(ALEFSI_TEST_DATA_DIR) + "/gmsh/" + name).mesh; }

// An anisotropic body, rotated: principal moments (1, 2, 3.5), principal axes turned.
RigidBody3D anisotropic_body() {
  RigidBody3D b;
  b.mass = 1.3;
  const Mat<3> Q = Eigen::AngleAxis<Real>(0.7, Vec<3>(1, 2, 3).normalized()).toRotationMatrix();
  b.inertia = Q * Vec<3>(1.0, 2.0, 3.5).asDiagonal() * Q.transpose();
  return b;
}
}  // namespace

TEST_CASE("3D body rows: Newton-Euler residual and its Jacobian (gyroscopic term) match finite differences",
          "[bodies3d][quick]") {
  using Tr = RigidBodyTraits<3>;
  const RigidBody3D b = anisotropic_body();
  const Eigen::Quaternion<Real> q(Eigen::AngleAxis<Real>(1.1, Vec<3>(-1, 0.5, 2).normalized()));
  const Real dt = 0.01, a0 = 1.5;
  Vec<6> hist, Z;
  hist << 0.3, -0.2, 0.1, 0.4, -1.0, 0.6;
  Z << 0.1, 0.2, -0.3, 1.7, -0.4, 2.2;
  auto residual = [&](const Vec<6>& z) { return Tr::inertia(b, q, z, Vec<6>(a0 * z + hist), dt); };
  // the rotation rows are I_w dw / dt + w x (I_w w), I_w = R I R^T
  const Mat<3> R = q.toRotationMatrix(), Iw = R * b.inertia * R.transpose();
  const Vec<3> w = Z.tail<3>();
  const Vec<6> r = residual(Z);
  CHECK((r.head<3>() - b.mass * (a0 * Z.head<3>() + hist.head<3>()) / dt).norm() < 1e-12);
  CHECK((r.tail<3>() - (Iw * (a0 * w + hist.tail<3>()) / dt + w.cross(Iw * w))).norm() < 1e-10);
  CHECK(w.cross(Iw * w).norm() > 1);  // the gyroscopic term is there and not small
  const Mat<6> J = Tr::inertia_jacobian(b, q, Z, a0, dt);
  const Real h = 1e-6;
  for (int j = 0; j < 6; ++j) {
    Vec<6> zp = Z, zm = Z;
    zp[j] += h, zm[j] -= h;
    const Vec<6> fd = (residual(zp) - residual(zm)) / (2 * h);
    for (int i = 0; i < 6; ++i) CHECK(J(i, j) == Approx(fd[i]).epsilon(1e-7).margin(1e-6));
  }
  // the gyroscopic part alone: d/dw (w x I w) = [w]_x I - [I w]_x
  const Mat<3> G = J.bottomRightCorner<3, 3>() - Iw * a0 / dt;
  for (int j = 0; j < 3; ++j) {
    Vec<3> wp = w, wm = w;
    wp[j] += h, wm[j] -= h;
    const Vec<3> fd = (wp.cross(Iw * wp) - wm.cross(Iw * wm)) / (2 * h);
    for (int i = 0; i < 3; ++i) CHECK(G(i, j) == Approx(fd[i]).epsilon(1e-7).margin(1e-7));
  }
}

TEST_CASE("3D rigid map: H = [I | -[r]_x] gives V + w x r; bad bodies are refused naming the parameter",
          "[bodies3d][quick]") {
  Vec<6> Z;
  Z << 0.1, -0.2, 0.3, 1.0, 2.0, -0.5;
  const Vec<3> r(0.3, -0.7, 0.2);
  const auto H = rigid_rows(r);
  const Vec<3> u = rigid_velocity(Z, r);
  for (int c = 0; c < 3; ++c) CHECK(H[c].dot(Z) == Approx(u[c]).epsilon(1e-14));
  CHECK((u - (Z.head<3>() + Z.tail<3>().cross(r))).norm() < 1e-15);
  const RigidBody3D s = sphere_body(7, Vec<3>(1, 2, 3), 0.5, 2.0);
  CHECK(s.mass == Approx(2.0 * 4.0 / 3.0 * pi * 0.125).epsilon(1e-15));
  CHECK((s.inertia - 0.4 * s.mass * 0.25 * Mat<3>::Identity()).norm() < 1e-15);
  RigidBody3D bad = s;
  bad.inertia(0, 1) = 1;  // not symmetric
  CHECK_THROWS_WITH(bad.validate(3), Catch::Contains("bodies[3].inertia"));
  bad = s;
  bad.inertia(2, 2) = -1;  // not positive definite
  CHECK_THROWS_AS(bad.validate(0), InvalidArgument);
  bad = s;
  bad.orientation = Eigen::Quaternion<Real>(1, 1, 0, 0);
  CHECK_THROWS_WITH(bad.validate(0), Catch::Contains("orientation"));
  CHECK_THROWS_WITH(sphere_body(7, Vec<3>::Zero(), 0.5, 0.0), Catch::Contains("density"));
}

namespace {
// The orientation update alone: q' = 1/2 w q (world axes) with w(t) given, advanced by the
// position formula of BDF order l on the rotation vector (RigidBodyTraits<3>::advance),
// against RK4 with a tiny step; the start-up levels are exact.
Vec<3> spin(Real t) { return Vec<3>(std::cos(t), 0.5 * std::sin(2 * t), 1.0 + 0.3 * t); }
Eigen::Quaternion<Real> exact_orientation(Real t) {
  Eigen::Quaternion<Real> q = Eigen::Quaternion<Real>::Identity();
  const int n = 4000;
  const Real h = t / n;
  auto f = [](Real s, const Vec<4>& y) {
    const Eigen::Quaternion<Real> w(0, spin(s)[0], spin(s)[1], spin(s)[2]);
    return Vec<4>(0.5 * (w * Eigen::Quaternion<Real>(y)).coeffs());
  };
  Vec<4> y = q.coeffs();
  for (int i = 0; i < n; ++i) {
    const Real s = i * h;
    const Vec<4> k1 = f(s, y), k2 = f(s + h / 2, y + h / 2 * k1), k3 = f(s + h / 2, y + h / 2 * k2),
                 k4 = f(s + h, y + h * k3);
    y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return Eigen::Quaternion<Real>(y).normalized();
}
Real orientation_error(int l, int steps, Real T) {
  using Tr = RigidBodyTraits<3>;
  const Real dt = T / steps;
  const auto b = bdf_coefficients(l);
  std::array<Eigen::Quaternion<Real>, 3> q;
  for (int k = 0; k < l; ++k) q[k] = exact_orientation((l - 1 - k) * dt);
  for (int n = l - 1; n < steps; ++n) {
    Vec<6> Z = Vec<6>::Zero();
    Z.tail<3>() = spin((n + 1) * dt);
    const auto next = Tr::advance(q, Z, b, l, dt);
    q[2] = q[1], q[1] = q[0], q[0] = next;
  }
  return q[0].angularDistance(exact_orientation(T));
}
}  // namespace

TEST_CASE("3D orientation update: the BDF position formula on the rotation vector keeps its order",
          "[bodies3d][quick]") {
  for (int l = 1; l <= 3; ++l) {
    const Real e1 = orientation_error(l, 20, 1.0), e2 = orientation_error(l, 40, 1.0);
    const Real rate = std::log2(e1 / e2);
    std::cout << "orientation update, BDF" << l << ": errors " << e1 << " " << e2 << ", rate " << rate << "\n";
    CHECK(rate == Approx(l).margin(0.15));
  }
}

namespace {
// Inner sphere (radius a = 0.5, free, external torque T about z) in a fixed outer sphere
// (b = 1), Stokes: at steady state T = 8 pi mu w a^3 b^3 / (b^3 - a^3).
struct SpinResult {
  Vec<6> Z, load;
  Vec<3> centre;
};
SpinResult sphere_couette(const std::string& mesh, Real T, Real mu, int steps, Real dt) {
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, UnsteadyStokes>> flow(gmsh_mesh(mesh), FlowOptions{0.01, mu});
  flow.set_velocity(2, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
  RigidBody3D body;
  body.tag = 1;
  body.mass = 1e-3;
  body.inertia = 1e-3 * Mat<3>::Identity();
  body.external_load[5] = T;
  body.radius = 0.5;
  flow.add_body(body);
  for (int n = 0; n < steps; ++n) flow.step(dt);
  return {flow.body_velocity(0), flow.body_hydrodynamic_load(0), flow.body_centre(0)};
}
}  // namespace

TEST_CASE("torque on a sphere turning inside a fixed sphere: 8 pi mu w a^3 b^3 / (b^3 - a^3)", "[bodies3d][quick]") {
  const Real a = 0.5, b = 1.0, mu = 1.0, T = 1.0;
  const Real w_exact = T * (b * b * b - a * a * a) / (8 * pi * mu * a * a * a * b * b * b);
  Real err[2];
  int m = 0;
  for (const char* mesh : {"shell3d_h025.msh", "shell3d_h018.msh"}) {
    const SpinResult s = sphere_couette(mesh, T, mu, 6, 0.02);
    err[m++] = std::abs(s.Z[5] / w_exact - 1);
    std::cout << "sphere Couette (" << mesh << "): w = " << s.Z.tail<3>().transpose() << " (exact " << w_exact
              << "), relative error " << err[m - 1] << ", hydrodynamic torque " << s.load.tail<3>().transpose()
              << ", V = " << s.Z.head<3>().transpose() << "\n";
    // the momentum balance closes: hydrodynamic torque = -T at steady state
    CHECK(s.load[5] == Approx(-T).epsilon(1e-3));
    // by symmetry no drift and no other rotation; the unstructured mesh is not symmetric
    // (measured |V| <= 7.7e-4 w a, |w1, w2| <= 6e-4 w, centre drift <= 1.1e-5)
    CHECK(s.centre.norm() < 1e-4);
    CHECK(s.Z.head<3>().norm() < 2e-3 * w_exact * a);
    CHECK(s.Z.segment<2>(3).norm() < 2e-3 * w_exact);
  }
  // measured 6.6e-2 and 3.8e-2 (polygonal spheres: the inscribed surface is smaller, so w is
  // too large; error ratio 1.74 for 2.2 times the cells, i.e. about O(h^2)): see docs/results.md
  CHECK(err[0] < 0.075);
  CHECK(err[1] < 0.8 * err[0]);
  CHECK(err[1] < 0.045);
}

TEST_CASE("a free, neutrally buoyant sphere in simple shear turns at (0, 0, -gamma / 2) and does not drift",
          "[bodies3d][quick]") {
  const Real a = 0.2, gamma = 1.0;
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, UnsteadyStokes>> flow(gmsh_mesh("sphere_in_box3d.msh"), FlowOptions{1.0, 1.0});
  flow.set_velocity(1, [&](const Vec<3>& x, Real) { return Vec<3>(gamma * x[1], 0.0, 0.0); });
  flow.add_body(sphere_body(5, Vec<3>::Zero(), a, 1.0));
  flow.set_initial_velocity([&](const Vec<3>& x) { return Vec<3>(gamma * x[1], 0.0, 0.0); });
  for (int n = 0; n < 6; ++n) flow.step(0.05);
  const Vec<6> Z = flow.body_velocity(0);
  std::cout << "sphere in shear: w = " << Z.tail<3>().transpose() << " (unbounded: 0 0 " << -gamma / 2
            << "), V = " << Z.head<3>().transpose() << "\n";
  // walls at 5 radii: confinement and mesh
  CHECK(Z[5] == Approx(-gamma / 2).epsilon(0.02));
  CHECK(Z.segment<2>(3).norm() < 2e-3 * gamma);
  CHECK(Z.head<3>().norm() < 2e-3 * gamma * a);
}

TEST_CASE("3D body: after many steps the quaternion is unit and the surface nodes are on the sphere to round-off",
          "[bodies3d][quick]") {
  // the outer sphere and the mesh turn rigidly at Omega about z; the inner body is free, light
  // and anisotropic, tilted, so its angular velocity is not along a principal axis
  const Real Omega = 2.0;
  // P1/P1-GLS keeps the 100 steps cheap
  AleFlow<FlowConfig<3, P1P1Gls, BDF2_BDF2E, UnsteadyStokes>> flow(gmsh_mesh("shell3d_h025.msh"), FlowOptions{1.0, 1.0});
  auto turn = [=](const Vec<3>& x, Real) { return Vec<3>(Vec<3>(0, 0, Omega).cross(x)); };
  flow.set_velocity(2, turn);
  flow.set_mesh_velocity(2, turn);
  flow.set_initial_velocity([&](const Vec<3>& x) { return turn(x, 0.0); });
  RigidBody3D body = anisotropic_body();
  body.tag = 1;
  body.mass *= 0.01, body.inertia *= 0.01;
  body.orientation = Eigen::Quaternion<Real>(Eigen::AngleAxis<Real>(0.4, Vec<3>(1, 0, 0)));
  body.velocity << 0, 0, 0, 0.5, 0, Omega;
  body.radius = 0.5;
  flow.add_body(body);
  const auto r0 = flow.body_surface(0);
  const int steps = 100;
  for (int n = 0; n < steps; ++n) flow.step(0.02);
  const auto q = flow.body_orientation(0);
  const auto x = flow.body_surface(0);
  Real dev = 0;
  for (std::size_t j = 0; j < x.size(); ++j)
    dev = std::max(dev, std::abs((x[j] - flow.body_centre(0)).norm() - r0[j].norm()));
  const Real turned = (flow.body_orientation(0) * body.orientation.conjugate()).norm() > 0
                          ? Eigen::AngleAxis<Real>(q * body.orientation.conjugate()).angle()
                          : 0.0;
  std::cout << "after " << steps << " steps: |q| - 1 = " << q.norm() - 1 << ", surface radius deviation " << dev
            << ", turned by " << turned << " rad, w = " << flow.body_velocity(0).tail<3>().transpose() << "\n";
  CHECK(std::abs(q.norm() - 1) < 1e-14);
  CHECK(dev < 1e-14);
  CHECK(turned > 2.0);  // Omega t = 4 rad about z: the rotation from the start is 2 pi - 4 = 2.28 rad
  CHECK(flow.body_centre(0).norm() < 2e-3);  // unsymmetric mesh (Taylor-Hood, 100 steps of 0.01: 6.3e-4)
  CHECK(flow.body_velocity(0)[5] == Approx(Omega).epsilon(0.02));  // it follows the fluid
}

TEST_CASE("3D bodies: checkpoint + restart continues bit for bit", "[bodies3d][checkpoint][quick]") {
  using Flow = AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, UnsteadyStokes>>;
  auto configure = [](Flow& f) {
    f.set_velocity(2, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
    RigidBody3D body = anisotropic_body();
    body.tag = 1;
    body.external_load << 0.1, 0, 0.2, 0.3, -0.5, 1.0;
    f.add_body(body);
  };
  const auto dir = std::filesystem::temp_directory_path() / "alefsi_test_checkpoint3d";
  std::filesystem::create_directories(dir);
  const auto file = dir / "state.bin";
  Flow straight(gmsh_mesh("shell3d_h025.msh"), {.rho = 1, .mu = 1});
  configure(straight);
  for (int n = 0; n < 4; ++n) {
    straight.step(0.01);
    if (n == 1) straight.save_checkpoint(file);
  }
  Flow restarted(read_checkpoint_mesh<3>(file), {.rho = 1, .mu = 1});
  configure(restarted);
  restarted.load_checkpoint(file);
  for (int n = 2; n < 4; ++n) restarted.step(0.01);
  CHECK(restarted.field() == straight.field());
  CHECK(restarted.mesh().coordinates() == straight.mesh().coordinates());
  CHECK(restarted.body_velocity(0) == straight.body_velocity(0));
  CHECK(restarted.body_orientation(0).coeffs() == straight.body_orientation(0).coeffs());
  std::filesystem::remove_all(dir);
}

// --- the sphere squirmer of paper 6.1 (examples/sphere_squirmer.cpp) ----------------------------

namespace {
// Surface mean <f> and (1 / 4 pi) int n x f dOmega over the unit sphere of a field f(n) that
// vanishes on the half r.e < 0: Gauss-Legendre in mu = n.e on (0, 1) (5 points) times the
// uniform rule in the azimuth (12 points), exact for the polynomials of degree <= 4 in n
// here, the jump at mu = 0 falling on the rule's edge.
std::pair<Vec<3>, Vec<3>> hemisphere_moments(const std::function<Vec<3>(const Vec<3>&)>& f, const Vec<3>& e) {
  const Vec<3> t1 = e.unitOrthogonal(), t2 = e.cross(t1);
  const Real a = std::sqrt(5 - 2 * std::sqrt(10.0 / 7)) / 3, b = std::sqrt(5 + 2 * std::sqrt(10.0 / 7)) / 3;
  const Real wa = (322 + 13 * std::sqrt(70.0)) / 900, wb = (322 - 13 * std::sqrt(70.0)) / 900;
  const std::array<Real, 5> x{-b, -a, 0.0, a, b}, w{wb, wa, 128.0 / 225, wa, wb};
  Vec<3> mean = Vec<3>::Zero(), moment = Vec<3>::Zero();
  const int m = 12;
  for (int i = 0; i < 5; ++i) {
    const Real mu = 0.5 * (1 + x[i]), s = std::sqrt(1 - mu * mu);
    for (int k = 0; k < m; ++k) {
      const Real phi = 2 * pi * (k + 0.5) / m;
      const Vec<3> n = mu * e + s * (std::cos(phi) * t1 + std::sin(phi) * t2);
      const Real weight = 0.5 * w[i] * (2 * pi / m) / (4 * pi);  // d Omega = d mu d phi, over 4 pi
      mean += weight * f(n);
      moment += weight * n.cross(f(n));
    }
  }
  return {mean, moment};
}
}  // namespace

TEST_CASE("3D tangential_slip: tangential on its half, zero on the other, half on the circle; V = -Q / 3 and "
          "w = -3 / (8 R) e x Q in closed form",
          "[bodies3d][slip][quick]") {
  const Vec<3> Q(-0.3, 1.1, 0.4), e = Vec<3>(1, -2, 0.5).normalized();
  const Real R = 0.7;
  const auto us = tangential_slip(Q, e);
  for (int k = 0; k < 40; ++k) {
    const Vec<3> n = Vec<3>(std::sin(1.3 * k + 0.2), std::cos(0.7 * k), std::sin(2.9 * k + 1)).normalized();
    const Vec<3> r = R * n, u = us(r);
    if (n.dot(e) > 0) {
      CHECK(std::abs(u.dot(n)) < 1e-15);                   // tangential
      CHECK((u - (Q - Q.dot(n) * n)).norm() < 1e-15);      // the projection of Q
    } else {
      CHECK(u.norm() == 0);
    }
  }
  // on the dividing circle: the mean of the two sides
  const Vec<3> c = R * e.unitOrthogonal();
  CHECK((us(c) - 0.5 * (Q - Q.dot(c.normalized()) * c.normalized())).norm() < 1e-15);
  // Fair & Anderson: V = -<u_s>, w = -3 / (8 pi R^3) int n x u_s dS; for the hemisphere slip
  // <u_s> = Q / 3 (int over the half of n n^T dOmega = 2 pi / 3 I) and int n dOmega = pi e
  const auto [mean, moment] = hemisphere_moments([&](const Vec<3>& n) { return us(R * n); }, e);
  CHECK((-mean - (-Q / 3)).norm() < 1e-14);
  const Vec<3> w = -3.0 / (8 * pi * R) * (4 * pi * moment);
  CHECK((w - (-3.0 / (8 * R)) * e.cross(Q)).norm() < 1e-13);
  // the full-surface projection of Q = -B1 e: the squirmer mode B1 sin(theta), <u_s> = 2 Q / 3
  const auto full = tangential_slip(Vec<3>(-0.5, 0, 0));
  const auto [m1, w1] = hemisphere_moments([&](const Vec<3>& n) { return full(R * n); }, Vec<3>(1, 0, 0));
  const auto [m2, w2] = hemisphere_moments([&](const Vec<3>& n) { return full(R * n); }, Vec<3>(-1, 0, 0));
  CHECK((-(m1 + m2) - Vec<3>(2.0 / 3 * 0.5, 0, 0)).norm() < 1e-14);
  CHECK((w1 + w2).norm() < 1e-15);
  CHECK_THROWS_WITH(tangential_slip(Vec<3>(std::nan(""), 0, 0)), Catch::Contains("Q"));
}

TEST_CASE("massless (force-free) bodies: accepted with zero inertia, refused with inertia or negative mass",
          "[bodies3d][quick]") {
  const RigidBody3D s = massless_sphere(5, Vec<3>(1, 2, 3), 0.25);
  CHECK(s.mass == 0);
  CHECK(s.inertia.isZero(0));
  CHECK(s.radius == 0.25);
  CHECK_NOTHROW(s.validate(0));
  RigidBody3D bad = s;
  bad.inertia = Mat<3>::Identity();
  CHECK_THROWS_WITH(bad.validate(2), Catch::Contains("bodies[2].inertia") && Catch::Contains("massless"));
  bad = s;
  bad.mass = -1;
  CHECK_THROWS_WITH(bad.validate(0), Catch::Contains("bodies[0].mass"));
  CHECK_THROWS_WITH(massless_sphere(5, Vec<3>::Zero(), 0.0), Catch::Contains("radius"));
  RigidBody2D d;
  d.tag = 5;
  CHECK_NOTHROW(d.validate(0));  // mass 0, inertia 0
  d.inertia = 1;
  CHECK_THROWS_WITH(d.validate(1), Catch::Contains("bodies[1].inertia") && Catch::Contains("massless"));
  d.mass = -1;
  CHECK_THROWS_WITH(d.validate(1), Catch::Contains("bodies[1].mass"));
}

namespace {
#ifdef ALEFSI_HAVE_SUITESPARSE
using SquirmerSolver = UmfPackLu;
#else
using SquirmerSolver = SparseLu<>;
#endif
using SquirmerFlow = AleFlow<FlowConfig<3, TaylorHood, BSS, UnsteadyStokes, SquirmerSolver>>;

// sigma n integrated over the boundary facets tagged `tag` (n into the fluid: the force of the
// fluid on the solid there) and its moment about the origin:
// sigma is linear in each cell, r x sigma n quadratic on a facet, so the facet's three edge
// midpoints integrate both exactly.
Vec<6> stress_load(const SquirmerFlow& flow, int tag, Real mu) {
  const auto& m = flow.mesh();
  using P2 = Lagrange<3, 2>;
  using P1 = Lagrange<3, 1>;
  Vec<6> load = Vec<6>::Zero();
  for (Index f : m.boundary_facets()) {
    if (m.facet_tag(f) != tag) continue;
    const Index c = m.facet_cells(f)[0];
    const std::array<Vec<3>, 3> x{m.node(m.facet(f)[0]), m.node(m.facet(f)[1]), m.node(m.facet(f)[2])};
    Vec<3> n = (x[1] - x[0]).cross(x[2] - x[0]);
    const Real area = 0.5 * n.norm();
    n.normalize();
    if (n.dot(m.centroid(c) - (x[0] + x[1] + x[2]) / 3) < 0) n = -n;
    const Mat<3> Jinv = m.jacobian(c).inverse();
    for (int i = 0; i < 3; ++i) {
      const Vec<3> y = 0.5 * (x[i] + x[(i + 1) % 3]);
      const Vec<3> xi = Jinv * (y - m.node(m.cell(c)[0]));
      const Eigen::Matrix<Real, P2::n_dofs, 3> G = P2::gradients(xi) * Jinv;
      Mat<3> grad = Mat<3>::Zero();
      for (int a = 0; a < P2::n_dofs; ++a)
        for (int k = 0; k < 3; ++k)
          grad.row(k) += flow.field()[flow.space().velocity_field(flow.space().velocity().cell_dofs(c)[a], k)] * G.row(a);
      Real p = 0;
      const auto psi = P1::values(xi);
      for (int a = 0; a < P1::n_dofs; ++a) p += psi[a] * flow.field()[flow.space().pressure_field(flow.space().pressure().cell_dofs(c)[a])];
      const Vec<3> t = (-p * Mat<3>::Identity() + mu * (grad + grad.transpose())) * n * (area / 3);
      load.head<3>() += t;
      load.tail<3>() += y.cross(t);
    }
  }
  return load;
}
}  // namespace

TEST_CASE("3D squirmer modes: tangential, -B1 e on the equator, surface mean -2 B1 / 3 e (Blake's speed); a "
          "non-unit axis refused",
          "[bodies3d][squirmer][quick]") {
  const Vec<3> e = Vec<3>(1, 2, 2) / 3;
  const Real B1 = 1.5, B2 = -0.7, R = 0.5;
  const auto us = squirmer_slip(B1, B2, e);
  // the six points +-x, +-y, +-z are a spherical 3-design: their average is the surface mean of
  // any polynomial of degree <= 3 in n, as (B1 + B2 (e.n)) ((e.n) n - e) is; the unbounded
  // squirmer swims at V = -<u_s> = 2 B1 / 3 e, B2 adding nothing (Blake 1971)
  Vec<3> mean = Vec<3>::Zero();
  for (int a = 0; a < 3; ++a)
    for (Real side : {-1.0, 1.0}) {
      Vec<3> n = Vec<3>::Zero();
      n[a] = side;
      const Vec<3> u = us(R * n);
      CHECK(std::abs(u.dot(n)) < 1e-15);  // tangential
      mean += u / 6;
    }
  CHECK((mean + 2 * B1 / 3 * e).norm() < 1e-14);
  CHECK((us(R * e.unitOrthogonal()) + B1 * e).norm() < 1e-14);  // the equator: B1 sin(90 deg) e_theta
  CHECK((us(R * e)).norm() < 1e-15);                            // the poles: no slip
  CHECK_THROWS_AS(squirmer_slip(B1, B2, Vec<3>(1, 1, 0)), InvalidArgument);
  CHECK_THROWS_WITH(squirmer_slip(B1, B2, Vec<3>(1, 1, 0)), Catch::Contains("unit vector"));
}

TEST_CASE("massless squirmer sphere (paper 6.1): V = -<u_s> and w = -3 / (8 R) e x Q, force- and torque-free",
          "[bodies3d][squirmer]") {
  // sphere R = 0.25 in the cube [-2.5, 2.5]^3 (10 R to each wall; h = R / 2.5 on the sphere,
  // mesh from examples/sphere_squirmer.geo with octant = 0, g = 0.4, hmax = 1: no symmetry),
  // steady Stokes (rho -> 0, one BSS step from rest: the geometry does not move)
  const Real R = 0.25, mu = 1;
  const Vec<3> e(1, 0, 0);
  const Mesh<3> mesh = gmsh_mesh("squirmer_sphere3d.msh");
  for (const Vec<3>& Q : {Vec<3>(-1, 0, 0), Vec<3>(0, -1, 0)}) {
    SquirmerFlow flow(mesh, {.rho = 1e-12, .mu = mu, .linearisation = Linearisation::semi_implicit});
    flow.set_velocity(1, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
    flow.set_prescribed_mesh_velocity([](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
    RigidBody3D body = massless_sphere(5, Vec<3>::Zero(), R);
    body.slip = tangential_slip(Q, e);
    Real leak = 0;
    body.slip = flux_free_slip(body, mesh, 2, &leak);
    flow.add_body(body);
    flow.step(1.0);
    const Vec<6> Z = flow.body_velocity(0);
    const Vec<3> V_exact = -Q / 3, w_exact = -3.0 / (8 * R) * e.cross(Q);
    std::cout << "squirmer sphere, Q = " << Q.transpose() << ": V = " << Z.head<3>().transpose() << " (exact "
              << V_exact.transpose() << "), w = " << Z.tail<3>().transpose() << " (exact " << w_exact.transpose()
              << "), flux leak removed " << leak << "\n";
    CHECK(std::abs(leak) < 1e-2);  // O(h^2) and small
    // unbounded values: the walls at 10 R change V by O((R / H)^2), the polygonal sphere by
    // O(h^2) (docs/results.md: 0.2 % at h = R / 3 with the walls at 10 R on a symmetric mesh)
    CHECK((Z.head<3>() - V_exact).norm() < 0.03 * V_exact.norm());
    if (w_exact.norm() > 0) CHECK((Z.tail<3>() - w_exact).norm() < 0.05 * w_exact.norm());
    else CHECK(Z.tail<3>().norm() * R < 0.03 * V_exact.norm());  // spurious rotation, same band as V
    // force- and torque-free: the momentum balance of the fluid, int sigma n over all its
    // boundary = 0, puts no net force or torque on the walls either. Checked from the stress
    // on the walls, where the flow is smooth (on the sphere the slip's jump at the equator makes
    // the shear stress singular, and its integral converges slowly), against the drag of a
    // sphere moving at the same speed, 6 pi mu R |V|
    const Vec<6> walls = stress_load(flow, 1, mu);
    std::cout << "    stress integral over the walls: F = " << walls.head<3>().transpose()
              << ", T = " << walls.tail<3>().transpose() << "\n";
    CHECK(walls.head<3>().norm() < 0.02 * 6 * pi * mu * R * V_exact.norm());
    // the moment of the same tolerance in force, applied at the walls (distance >= H = 2.5)
    CHECK(walls.tail<3>().norm() < 0.02 * 6 * pi * mu * R * V_exact.norm() * 2.5);
  }
}

TEST_CASE("3D contact in a flow: a sphere lands on the floor of its box and rests where the spring carries its "
          "buoyant weight",
          "[bodies3d][collision][quick]") {
  // sphere_in_box3d.msh (box [-1, 1]^3, sphere a = 0.2 at the origin) with the sphere moved 0.55
  // down before the run: each node by w(x) s, w = clamp((0.95 - |x|) / 0.75, 0, 1), 1 on the
  // sphere and 0 on the walls; the sphere starts 0.25 above the floor
  Mesh<3> mesh = gmsh_mesh("sphere_in_box3d.msh");
  const Vec<3> shift(0, 0, -0.55);
  std::vector<Vec<3>> x = mesh.coordinates();
  for (Vec<3>& p : x) p += std::clamp((0.95 - p.norm()) / 0.75, 0.0, 1.0) * shift;
  mesh.set_coordinates(std::move(x));
  const Real a = 0.2, rho_s = 1.5, g = 10, range = 0.2;
  const Real volume = 4.0 / 3.0 * pi * a * a * a, W = (rho_s - 1) * volume * g;
  AleFlow<FlowConfig<3, P1P1Gls, BDF2_BDF2E>> flow(mesh, {.rho = 1, .mu = 0.1});
  flow.set_velocity(1, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
  flow.add_body(sphere_body(5, shift, a, rho_s));
  flow.set_gravity(Vec<3>(0, 0, -g));
  flow.set_collisions({.range = 0.1, .spring_range = range, .spring_force = 4 * W});
  CHECK(flow.body_gaps()[0] == Approx(0.25).epsilon(1e-12));
  Real fastest = 0;
  for (int n = 0; n < 200; ++n) {
    flow.step(0.02);
    fastest = std::max(fastest, -flow.body_velocity(0)[2]);
  }
  // at rest the fluid is hydrostatic, whose pressure (linear) the P1 space holds exactly: the
  // fluid carries rho_f g V_h, V_h the volume inside the sphere's triangles, and the spring
  // the rest, F_0 (1 - d / rho)^2 = (m - rho_f V_h) g
  Real vh = 0;  // the tetrahedra from the centre to the body's facets (the polyhedron is star-shaped)
  for (Index f : flow.mesh().boundary_facets()) {
    if (flow.mesh().facet_tag(f) != 5) continue;
    const auto& v = flow.mesh().facet(f);
    const Vec<3> c = flow.body_centre(0);
    vh += std::abs((flow.mesh().node(v[0]) - c).dot((flow.mesh().node(v[1]) - c).cross(flow.mesh().node(v[2]) - c))) / 6;
  }
  CHECK(vh < volume);  // inscribed: 5.5 % less at h = 0.07 on a = 0.2
  CHECK(vh > 0.9 * volume);
  const Real carried = (rho_s * volume - vh) * g;
  const Real rest = range * (1 - std::sqrt(carried / (4 * W)));
  INFO("fastest descent " << fastest << ", velocity at the end " << flow.body_velocity(0).transpose()
                           << ", centre " << flow.body_centre(0).transpose());
  // it fell, and has stopped falling. (It keeps a slow spin, w = (0.0015, -0.0025, 0), and a
  // drift of 4e-5: the centroid of the polyhedral hole is 3.2e-4 from the centre of mass, so
  // buoyancy has a moment, 8 pi mu a^3 (0.0024, -0.0041, 0) in an unbounded fluid, which the
  // viscous moment balances, larger near the floor; without gravity a spin decays.)
  CHECK(fastest > 0.05);
  CHECK(std::abs(flow.body_velocity(0)[2]) < 1e-4 * fastest);
  CHECK(flow.body_gaps()[0] == Approx(rest).epsilon(1e-4));
  CHECK(flow.body_collision_force(0)[2] == Approx(carried).epsilon(1e-4));
  CHECK(flow.body_collision_force(0).head<2>().norm() < 1e-9 * carried);  // the floor pushes straight up
}

TEST_CASE("scenes::SpheresSettlingInBox: bad parameters are refused by name; its contact model",
          "[bodies3d][scenes][quick]") {
  using scenes::SpheresSettlingInBox;
  const SpheresSettlingInBox s{.box = {.lo = Vec<3>(-1, -1, 0), .hi = Vec<3>(1, 1, 3)},
                               .spheres = {{Vec<3>(0, 0, 2), 0.25, 7}, {Vec<3>(0.5, 0, 1), 0.2, 8}},
                               .rho_f = 1,
                               .mu = 0.1,
                               .rho_p = 1.5,
                               .g = 10,
                               .h_body = 0.1,
                               .h_far = 0.5};
  CHECK_NOTHROW(s.validate());
  auto refused = [](const SpheresSettlingInBox& x, const std::string& name) {
    CAPTURE(name);
    CHECK_THROWS_WITH(x.validate(), Catch::Contains(name));
    CHECK_THROWS_AS(x.validate(), InvalidArgument);
  };
  auto t = s;
  t.rho_p = 1, refused(t, "rho_p");  // would not settle
  t = s, t.mu = 0, refused(t, "mu");
  t = s, t.g = -1, refused(t, "'g'");
  t = s, t.h_far = 0.05, refused(t, "h_far");
  t = s, t.spring_weights = 1, refused(t, "spring_weights");
  t = s, t.spheres.clear(), refused(t, "spheres");
  t = s, t.spheres[1].centre = Vec<3>(0, 0, 2.3), refused(t, "bodies[");  // overlapping the first
  t = s, t.spheres[0].centre = Vec<3>(0, 0, 2.9), refused(t, "bodies[0]");  // through the lid
  t = s, t.velocities = {Vec<3>(0, 0, -1)}, refused(t, "velocities");        // one for two spheres
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  t = s, t.velocities = {Vec<3>(0, 0, -1), Vec<3>(0, nan, 0)}, refused(t, "velocities[1]");
  // eq. (24) on the approach speed, the spring of range h_body / 2 carrying 4 buoyant weights of
  // the smaller sphere
  const CollisionOptions c = s.collisions();
  CHECK(c.law == CollisionLaw::lubrication);
  CHECK(c.range == 0.1);
  CHECK(c.spring_range == Approx(0.05).epsilon(1e-15));
  CHECK(c.spring_force == Approx(4 * 0.5 * 4.0 / 3.0 * std::numbers::pi * 0.008 * 10).epsilon(1e-14));
  CHECK(s.size_rule()(s.spheres)(Vec<3>(0, 0, 2.25)) == Approx(0.1).epsilon(1e-15));  // h_body on a sphere
  CHECK(s.size_rule()(s.spheres)(Vec<3>(-1, -1, 0)) == Approx(0.5).epsilon(1e-15));   // h_far far away
}

TEST_CASE("scenes::SettlingSphere: bad parameters are refused by name; the wall factor of concentric spheres",
          "[bodies3d][scenes][quick]") {
  using scenes::SettlingSphere;
  auto refused = [](SettlingSphere s, const char* name) {
    CAPTURE(name);
    CHECK_THROWS_WITH(s.validate(), Catch::Contains(std::string("'") + name + "'"));
    CHECK_THROWS_AS(s.mesh(), InvalidArgument);  // nothing built
  };
  SettlingSphere s;
  s.a = 0, refused(s, "a");
  s = {}, s.b = 0.2, refused(s, "b");
  s = {}, s.rho_s = -1, refused(s, "rho_s");
  s = {}, s.mu = std::nan(""), refused(s, "mu");
  s = {}, s.layers = 0, refused(s, "layers");
  s = {}, s.grading = 0.5, refused(s, "grading");
  s = {}, s.start = Vec<3>(0, 0, -1.76), refused(s, "start");  // b - a = 1.75
  s = {}, s.spring_weights = 1, refused(s, "spring_weights");
  s = {}, s.spring_range = 0, refused(s, "spring_range");
  // K(a / b) -> 1 for a small sphere (Stokes' drag), K(1/8) = 1.382 (Haberman & Sayre 1958)
  s = {}, s.a = 1e-4;
  CHECK(s.wall_factor() == Approx(1.0).margin(1e-3));
  s = {};
  CHECK(s.wall_factor() == Approx(1.382).margin(5e-4));
  const Real stokes = 2.0 / 9.0 * (s.rho_s - s.rho_f) * 980 * s.a * s.a / s.mu;
  CHECK(s.terminal_speed() == Approx(stokes / s.wall_factor()).epsilon(1e-12));
}

TEST_CASE("3D scene refusals name the body: a sphere tag missing from a gmsh file, a sphere whose radius or centre "
          "is not its surface's",
          "[bodies3d][quick]") {
  // sphere_in_box3d.msh: the walls are tag 1, the sphere (a = 0.2 at the origin) tag 5
  using Flow = AleFlow<FlowConfig<3, P1P1Gls, BDF2_BDF2E>>;
  auto refused = [](const RigidBody3D& second, const std::string& parameter, const std::string& what) {
    Flow flow(gmsh_mesh("sphere_in_box3d.msh"), {.rho = 1, .mu = 1});
    flow.add_body(sphere_body(5, Vec<3>::Zero(), 0.2, 1.5));  // the right one
    try {
      flow.add_body(second);
      flow.step(0.01);
      FAIL("accepted: " << what);
    } catch (const InvalidArgument& e) {
      CHECK(e.parameter() == parameter);
      CHECK_THAT(e.what(), Catch::Contains(what));
    }
  };
  refused(sphere_body(6, Vec<3>::Zero(), 0.2, 1.5), "body.tag", "bodies[1]: no boundary facet has its tag 6");
  refused(sphere_body(5, Vec<3>::Zero(), 0.2, 1.5), "body.tag", "bodies[1] has the tag 5 of an earlier body");
  auto wrong = [](const RigidBody3D& body, const std::string& what) {
    Flow flow(gmsh_mesh("sphere_in_box3d.msh"), {.rho = 1, .mu = 1});
    try {
      flow.add_body(body);
      flow.step(0.01);
      FAIL("accepted: " << what);
    } catch (const InvalidArgument& e) {
      CHECK(e.parameter() == "body.radius");
      CHECK_THAT(e.what(), Catch::Contains(what));
    }
  };
  wrong(sphere_body(5, Vec<3>::Zero(), 0.25, 1.5), "bodies[0] (tag 5): surface node");
  wrong(sphere_body(5, Vec<3>(0.01, 0, 0), 0.2, 1.5), "bodies[0] (tag 5): surface node");
}

TEST_CASE("exact buoyancy: a neutrally buoyant sphere in a closed box stays at rest to round-off, where the "
          "pressure's buoyancy on the inscribed polyhedron lets it sink; open boundaries and non-spheres refused",
          "[bodies3d][quick]") {
  // sphere_in_box3d.msh: walls tag 1, a sphere of radius 0.2 at the origin, tag 5, h ~ 0.07 on it
  using Flow = AleFlow<FlowConfig<3, P1P1Gls, BDF2_BDF2E>>;
  auto settle = [](Buoyancy b) {
    Flow flow(gmsh_mesh("sphere_in_box3d.msh"), {.rho = 1, .mu = 0.1});
    flow.set_velocity(1, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
    flow.add_body(sphere_body(5, Vec<3>::Zero(), 0.2, 1.0));  // the fluid's density
    flow.set_gravity(Vec<3>(0, 0, -10), b);
    for (int n = 0; n < 3; ++n) flow.step(0.02);
    return std::pair{flow.body_velocity(0), flow.body_hydrodynamic_load(0)};
  };
  const auto [z_exact, load_exact] = settle(Buoyancy::exact);
  const auto [z_pressure, load_pressure] = settle(Buoyancy::pressure);
  INFO("exact: Z = " << z_exact.transpose() << "; pressure: Z = " << z_pressure.transpose());
  // exact: (m - rho_f V) g = 0 and p - rho_f g.x = 0, u = 0 solve the discrete problem
  CHECK(z_exact.norm() < 1e-12);
  CHECK(load_exact.norm() < 1e-12);
  // pressure: the hole holds V_h = 0.945 V, so a weight 0.055 rho_f V g is not carried
  CHECK(z_pressure[2] < -1e-3);
  CHECK(z_pressure.head<2>().norm() < 0.05 * std::abs(z_pressure[2]));

  Flow open(gmsh_mesh("sphere_in_box3d.msh"), {.rho = 1, .mu = 0.1});  // tag 1 left natural
  open.add_body(sphere_body(5, Vec<3>::Zero(), 0.2, 1.0));
  open.set_gravity(Vec<3>(0, 0, -10), Buoyancy::exact);
  CHECK_THROWS_AS(open.step(0.02), InvalidArgument);
  CHECK_THROWS_WITH(open.step(0.02), Catch::Contains("facets with tag 1 have a natural (traction) condition"));
  Flow cube(gmsh_mesh("sphere_in_box3d.msh"), {.rho = 1, .mu = 0.1});
  cube.set_velocity(1, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
  RigidBody3D shape = anisotropic_body();  // not a sphere (no radius)
  shape.tag = 5;
  cube.add_body(shape);
  cube.set_gravity(Vec<3>(0, 0, -10), Buoyancy::exact);
  CHECK_THROWS_WITH(cube.step(0.02), Catch::Contains("exact buoyancy needs the displaced volume: bodies[0] (tag 5) "
                                                      "is not a sphere and has no volume"));
  // given its volume, the same body (no radius, anisotropic inertia) of the fluid's density is
  // in equilibrium exactly, as the sphere is
  Flow given(gmsh_mesh("sphere_in_box3d.msh"), {.rho = 1, .mu = 0.1});
  given.set_velocity(1, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
  shape.volume = 4.0 / 3.0 * std::numbers::pi * 0.2 * 0.2 * 0.2;
  shape.mass = 1.0 * shape.volume;
  given.add_body(shape);
  given.set_gravity(Vec<3>(0, 0, -10), Buoyancy::exact);
  for (int n = 0; n < 3; ++n) given.step(0.02);
  CHECK(given.body_velocity(0).norm() < 1e-12);
  CHECK(given.body_hydrodynamic_load(0).norm() < 1e-12);
}
