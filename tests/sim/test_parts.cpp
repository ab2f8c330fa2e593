// The parts of sim/ alone, each without a flow: the rigid-body model concept (every member is
// required), the body rows against finite differences, the Newton driver on a small residual,
// the 2D contact model's forces (formula, momentum balance, overlaps, gaps), the remesh trigger
// with hysteresis and the transfer of a state (exact for fields the spaces contain), and the
// flow state's checkpoint round trip.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "alefsi/app/options.hpp"
#include "alefsi/app/run.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/mesh/io/gmsh.hpp"
#include "alefsi/mesh/generate/mesher2d.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/mass_properties.hpp"
#include "alefsi/physics/stokes.hpp"
#include "alefsi/scenes/oscillating_cylinder.hpp"
#include "alefsi/sim/body_system.hpp"
#include "alefsi/sim/collision_contact.hpp"
#include "alefsi/sim/flow_state.hpp"
#include "alefsi/sim/newton.hpp"
#include "alefsi/sim/remesher2d.hpp"

using namespace alefsi;

// ---- the rigid-body model concept: a model lacking any one member is rejected ---------------
namespace {
// RigidBodyTraits<2> with member number `Omit` removed (-1: none).
template <int Omit>
struct PartialModel {
  using T = RigidBodyTraits<2>;
  using Body = T::Body;
  using Velocity = T::Velocity;
  using Orientation = T::Orientation;
  static constexpr int dim = 2, n_dof = 3;
  static constexpr const char* name = "partial";
  static constexpr auto orientation_columns = T::orientation_columns;
  static constexpr auto velocity_columns = T::velocity_columns;
  static constexpr auto load_columns = T::load_columns;
  // clang-format off
  static int tag(const Body& b) requires(Omit != 0) { return T::tag(b); }
  static bool is_free(const Body& b) requires(Omit != 1) { return T::is_free(b); }
  static void validate(const Body& b, std::size_t i) requires(Omit != 2) { T::validate(b, i); }
  static Vec<2> initial_centre(const Body& b) requires(Omit != 3) { return T::initial_centre(b); }
  static Velocity initial_velocity(const Body& b, Real t) requires(Omit != 4) { return T::initial_velocity(b, t); }
  static Velocity prescribed_velocity(const Body& b, Real t) requires(Omit != 5) { return T::prescribed_velocity(b, t); }
  static bool has_slip(const Body& b) requires(Omit != 6) { return T::has_slip(b); }
  static Vec<2> slip(const Body& b, const Vec<2>& r) requires(Omit != 7) { return T::slip(b, r); }
  static Real mass(const Body& b) requires(Omit != 8) { return T::mass(b); }
  static Velocity external_load(const Body& b) requires(Omit != 9) { return T::external_load(b); }
  static Real radius(const Body& b) requires(Omit != 10) { return T::radius(b); }
  static Orientation initial_orientation(const Body& b) requires(Omit != 11) { return T::initial_orientation(b); }
  static Vec<2> initial_offset(const Vec<2>& r, const Body& b) requires(Omit != 12) { return T::initial_offset(r, b); }
  static Vec<2> to_world(const Vec<2>& r, Orientation th, const Body& b) requires(Omit != 13) { return T::to_world(r, th, b); }
  static Vec<2> to_body(const Vec<2>& r, Orientation th, const Body& b) requires(Omit != 14) { return T::to_body(r, th, b); }
  static std::array<Velocity, 2> rows(const Vec<2>& r) requires(Omit != 15) { return T::rows(r); }
  static Vec<2> velocity(const Velocity& Z, const Vec<2>& r) requires(Omit != 16) { return T::velocity(Z, r); }
  static Orientation step_back(Orientation th, const Velocity& Z, Real dt) requires(Omit != 17) { return T::step_back(th, Z, dt); }
  static Orientation advance(const std::array<Orientation, 3>& th, const Velocity& Z, const std::array<Real, 4>& b, int l,
                             Real dt) requires(Omit != 18) { return T::advance(th, Z, b, l, dt); }
  static Orientation extrapolate(Orientation a, Orientation b) requires(Omit != 19) { return T::extrapolate(a, b); }
  static Velocity inertia(const Body& b, Orientation th, const Velocity& Z, const Velocity& dZ, Real dt) requires(Omit != 20) {
    return T::inertia(b, th, Z, dZ, dt);
  }
  static Mat<3> inertia_jacobian(const Body& b, Orientation th, const Velocity& Z, Real a0, Real dt) requires(Omit != 21) {
    return T::inertia_jacobian(b, th, Z, a0, dt);
  }
  static std::array<Real, 1> orientation_values(Orientation th) requires(Omit != 22) { return T::orientation_values(th); }
  // clang-format on
};
constexpr int n_members = 23;
template <int... K>
constexpr bool all_rejected(std::integer_sequence<int, K...>) {
  return (!RigidBodyModel<PartialModel<K>> && ...);
}
}  // namespace

TEST_CASE("RigidBodyModel: the complete model is accepted, one lacking any single member is rejected", "[sim][bodies][quick]") {
  STATIC_REQUIRE(RigidBodyModel<PartialModel<-1>>);
  STATIC_REQUIRE(all_rejected(std::make_integer_sequence<int, n_members>{}));
  STATIC_REQUIRE(RigidBodyModel<RigidBodyTraits<3>>);
}

// ---- body rows -----------------------------------------------------------------------------
namespace {
template <int D, class Space, class Bodies, class States>
void check_body_jacobian(const Space& space, Bodies& bodies, States& states, const ContactModel<D>& contact,
                         const StepCoefficients& c, const Vec<D>& g) {
  DofConstraints cons(space.n_field());
  std::vector<char> taken(std::size_t(space.velocity().n_dofs()), 0);
  bodies.constrain(space, cons, taken);
  cons.finalize();
  const Index n = cons.n_unknowns();
  VecX u = VecX::Zero(n);
  for (Index i = 0; i < n; ++i) u[i] = 0.3 * std::sin(1.7 * i + 0.4);
  BlockCoupling C;  // the blocks between two bodies (beside the pattern)
  auto rows = [&](const VecX& uu, SparseMatrix& J) {
    VecX r = VecX::Zero(n);
    J.resize(n, n);
    J.setZero();
    bodies.add_rows(states, c, cons, uu, r, J, g, contact, 0.1, nullptr, &C);
    return r;
  };
  SparseMatrix J;
  const VecX r = rows(u, J);
  // the Jacobian among the free bodies' unknowns (after the flow's): J's and C's
  constexpr int nd = Bodies::n_dof;
  const Index e0 = cons.n_free(), ne = n - e0;
  MatX Jb = MatX(J.block(e0, e0, ne, ne));
  for (Index a = 0; a < C.size(); ++a)
    for (Index b = 0; b < C.size(); ++b) Jb(C.index[std::size_t(a)] - e0, C.index[std::size_t(b)] - e0) += C.block(a, b);
  const BlockCoupling C0 = C;
  Real worst = 0, coupled = 0;  // coupled: the largest derivative of one body's rows in another's velocity
  for (Index j = 0; j < ne; ++j) {
    const Real h = 1e-6;
    VecX up = u, um = u;
    up[e0 + j] += h, um[e0 + j] -= h;
    SparseMatrix Jp;
    const VecX fd = VecX((rows(up, Jp) - rows(um, Jp)) / (2 * h)).segment(e0, ne);
    for (Index i = 0; i < ne; ++i) {
      worst = std::max(worst, std::abs(Jb(i, j) - fd[i]) / (1 + std::abs(fd[i])));
      if (i / nd != j / nd) coupled = std::max(coupled, std::abs(fd[i]));
    }
  }
  INFO(D << "D worst relative difference of the bodies' Jacobian " << worst << ", coupling " << coupled);
  CHECK(worst < 1e-7);
  CHECK(r.allFinite());
  // a contact between two bodies puts its coupling beside the pattern, and nothing else does
  CHECK((C0.size() > 0) == (coupled > 0));
}
}  // namespace

namespace {
// The bodies attached to `mesh` and moved through one step of dt by Scheme (first step) from the
// velocities their states hold: where the step's contacts are found. Returns the step's
// coefficients.
template <int D, class Scheme = BDF2_BDF2E>
StepCoefficients place_after_step(BodySystem<D, RigidBodyTraits<D>>& bodies,
                                  std::vector<BodyState<D, RigidBodyTraits<D>>>& states, const Mesh<D>& mesh,
                                  Real dt = 0.01) {
  bodies.attach(mesh);
  const StepCoefficients c = step_coefficients<Scheme>(dt, TimeHistory{});
  NodeVelocities<D> nodes;
  bodies.mesh_velocity_data(states, mesh.coordinates(), c.extrapolation, dt, nodes);
  std::vector<Vec<D>> x = mesh.coordinates();
  bodies.advance(states, c, x);
  return c;
}
}  // namespace

TEST_CASE("body rows: the body blocks of add_rows match finite differences (2D with contact forces, 3D gyroscopic)",
          "[sim][bodies][quick]") {
  SECTION("2D: two disks within the contact range") {
    const Real R = 0.25;
    const std::vector<Circle> disks = {{Vec<2>(0.7, 1), R, 5}, {Vec<2>(1.27, 1.01), R, 6}};
    const Mesh<2> mesh = channel_with_disks(2, 2, disks, 0.05, 0.3);
    MixedSpace<2, TaylorHood> space(mesh);
    BodySystem<2, RigidBodyTraits<2>> bodies;
    std::vector<BodyState<2, RigidBodyTraits<2>>> states;
    for (const auto& d : disks) bodies.add(disk_body(d.tag, d.centre, R, 1.5), mesh, 0.0, states);
    states[0].velocity.fill(Vec<3>(0.4, 0.1, 0.3));
    states[1].velocity.fill(Vec<3>(-0.5, 0.2, -0.1));
    const StepCoefficients c = place_after_step(bodies, states, mesh);
    CollisionContact2D contact(CollisionOptions{.range = 0.5, .spring_range = 0.1, .spring_force = 3});
    contact.set_walls(mesh, bodies.tags());
    REQUIRE(contact.find(bodies.contact_bodies(states, -1), 0.01) == 1);
    check_body_jacobian<2>(space, bodies, states, contact, c, Vec<2>(0, -9.81));
    // momentum balance: the contact forces on the two bodies cancel
    CHECK((states[0].contact + states[1].contact).norm() <= 1e-14 * states[0].contact.norm());
    CHECK(states[0].contact.norm() > 0);
  }
  SECTION("2D: three disks in contact pairwise, the middle one of the list driven") {
    // free A, driven D, free B: the pairs A-B (free-free: coupled), A-D and D-B (a driven side:
    // no unknowns to couple to), the free bodies' unknowns in slots 0 and 1
    const Real R = 0.25;
    const std::vector<Circle> disks = {{Vec<2>(0.7, 1), R, 5}, {Vec<2>(0.985, 1.5), R, 6}, {Vec<2>(1.27, 1.0), R, 7}};
    const Mesh<2> mesh = channel_with_disks(2, 2.2, disks, 0.05, 0.3);
    MixedSpace<2, TaylorHood> space(mesh);
    BodySystem<2, RigidBodyTraits<2>> bodies;
    std::vector<BodyState<2, RigidBodyTraits<2>>> states;
    for (const auto& d : disks) {
      RigidBody2D b = disk_body(d.tag, d.centre, R, 1.5);
      if (d.tag == 6) b.prescribed = [](Real) { return Vec<3>(0.2, -0.3, 0.5); };
      bodies.add(b, mesh, 0.0, states);
    }
    states[0].velocity.fill(Vec<3>(0.4, 0.1, 0.3));
    states[2].velocity.fill(Vec<3>(-0.5, 0.2, -0.1));
    const StepCoefficients c = place_after_step(bodies, states, mesh);
    CollisionContact2D contact(CollisionOptions{.range = 0.5, .spring_range = 0.1, .spring_force = 3});
    contact.set_walls(mesh, bodies.tags());
    REQUIRE(contact.find(bodies.contact_bodies(states, -1), 0.01) == 3);
    REQUIRE(!bodies.is_free(1));
    check_body_jacobian<2>(space, bodies, states, contact, c, Vec<2>(0, -9.81));
    // action = reaction over the three
    CHECK((states[0].contact + states[1].contact + states[2].contact).head<2>().norm() <= 1e-14 * states[0].contact.norm());
  }
  SECTION("2D: two squares, a corner near an edge away from the centre (a contact moment)") {
    // square A = [0.5, 0.9] x [0.8, 1.2]; square B of the same size about (1.2, 1.1) turned by
    // 30 degrees: its leftmost corner (0.927, 1.173) is 0.027 from A's right edge, 0.17 above
    // A's centre: the force on A pushes it to the left at a point above its centre
    auto square = [](const Vec<2>& c, Real angle, int tag) {
      Polyline p{.points = {}, .tag = tag};
      const Eigen::Rotation2D<Real> rot(angle);
      for (const Vec<2>& v : {Vec<2>(-0.2, -0.2), Vec<2>(0.2, -0.2), Vec<2>(0.2, 0.2), Vec<2>(-0.2, 0.2)})
        p.points.push_back(c + rot * v);
      return p;
    };
    const std::vector<Polyline> squares = {square(Vec<2>(0.7, 1), 0, 5), square(Vec<2>(1.2, 1.1), std::numbers::pi / 6, 6)};
    const Mesh<2> mesh = generate_mesh({Polyline{{Vec<2>(0, 0), Vec<2>(2, 0), Vec<2>(2, 2), Vec<2>(0, 2)}, 1},
                                        {squares[0], squares[1]}},
                                       {.size = [](const Vec<2>&) { return 0.05; }});
    MixedSpace<2, TaylorHood> space(mesh);
    BodySystem<2, RigidBodyTraits<2>> bodies;
    std::vector<BodyState<2, RigidBodyTraits<2>>> states;
    for (const auto& p : squares) bodies.add(free_body(p.tag, mass_properties(p, 1.5)), mesh, 0.0, states);
    states[0].velocity.fill(Vec<3>(0.4, 0.1, 0.3));
    states[1].velocity.fill(Vec<3>(-0.5, 0.2, -0.1));
    const StepCoefficients c = place_after_step(bodies, states, mesh);
    CollisionContact2D contact(CollisionOptions{.range = 0.5, .spring_range = 0.05, .spring_force = 3});
    contact.set_walls(mesh, bodies.tags());
    const auto placed = bodies.contact_bodies(states, -1);
    REQUIRE(contact.find(placed, 0.01) == 1);
    const Contact<2> k = contact.contacts()[0];  // a copy: find() below replaces the list
    CHECK(k.gap > 0.01);  // 0.0268 less the step's approach (about 0.009)
    CHECK(k.gap < 0.0268);
    CHECK(std::abs(k.normal[0]) > 0.99);     // across A's right edge
    check_body_jacobian<2>(space, bodies, states, contact, c, Vec<2>(0, -9.81));
    // the forces cancel, and so do their moments about the origin (the same point of action)
    auto moment = [](const Vec<2>& x0, const Vec<3>& G) { return G[2] + x0[0] * G[1] - x0[1] * G[0]; };
    CHECK((states[0].contact + states[1].contact).head<2>().norm() <= 1e-14 * states[0].contact.norm());
    CHECK(std::abs(moment(placed[0].centre, states[0].contact) + moment(placed[1].centre, states[1].contact)) <=
          1e-14 * states[0].contact.norm());
    // the moment on A is its arm (0.17 above the centre, 0.21 to the right) times the force:
    // pushed to the left above its centre, A turns anticlockwise
    const Vec<2> F = states[0].contact.head<2>();
    CHECK(F[0] < 0);
    CHECK(std::abs(k.arm_k[1] - 0.173) < 0.01);
    CHECK(states[0].contact[2] == Approx(k.arm_k[0] * F[1] - k.arm_k[1] * F[0]).epsilon(1e-14));
    CHECK(states[0].contact[2] > 0);

    // The same squares given their exact shapes (convex polygons in the body frame; the second
    // body's angle is its 30 degrees, so its shape is the unturned square): GJK on the shapes,
    // moved by the step's rigid motion, finds the facet model's contact (exact for polygons).
    BodySystem<2, RigidBodyTraits<2>> shaped;
    std::vector<BodyState<2, RigidBodyTraits<2>>> shaped_states;
    for (std::size_t i = 0; i < squares.size(); ++i) {
      RigidBody2D body = free_body(squares[i].tag, mass_properties(squares[i], 1.5));
      body.angle = i == 0 ? 0 : std::numbers::pi / 6;
      body.shape = convex::support_of<2>(convex::Polytope<2>{{Vec<2>(-0.2, -0.2), Vec<2>(0.2, -0.2), Vec<2>(0.2, 0.2), Vec<2>(-0.2, 0.2)}});
      shaped.add(body, mesh, 0.0, shaped_states);
    }
    shaped_states[0].velocity.fill(Vec<3>(0.4, 0.1, 0.3));
    shaped_states[1].velocity.fill(Vec<3>(-0.5, 0.2, -0.1));
    place_after_step(shaped, shaped_states, mesh);
    const auto with_shapes = shaped.contact_bodies(shaped_states, -1);
    CHECK(with_shapes[1].surface.empty());  // the shape replaces the facets
    REQUIRE(contact.find(with_shapes, 0.01) == 1);
    const auto& s = contact.contacts()[0];
    CHECK(s.gap == Approx(k.gap).epsilon(1e-10));
    CHECK((s.normal - k.normal).norm() < 1e-10);
    CHECK((s.arm_k - k.arm_k).norm() < 1e-10);
    CHECK((s.arm_j - k.arm_j).norm() < 1e-10);
  }
  SECTION("3D: a free anisotropic body turning off its principal axes") {
    const Mesh<3> mesh = read_gmsh<3>(std::string(ALEFSI_TEST_DATA_DIR) + "/gmsh/sphere_in_box3d.msh").mesh;
    MixedSpace<3, P1P1Gls> space(mesh);
    BodySystem<3, RigidBodyTraits<3>> bodies;
    std::vector<BodyState<3, RigidBodyTraits<3>>> states;
    RigidBody3D body = sphere_body(5, Vec<3>::Zero(), 0.2, 2.0);
    body.inertia = Vec<3>(0.01, 0.02, 0.035).asDiagonal();
    body.orientation = Eigen::Quaternion<Real>(Eigen::AngleAxis<Real>(0.4, Vec<3>(1, 2, 3).normalized()));
    bodies.add(body, mesh, 0.0, states);
    Vec<6> Z;
    Z << 0.1, -0.2, 0.3, 1.5, -0.7, 2.0;
    states[0].velocity.fill(Z);
    const StepCoefficients c = place_after_step<3, BDF3_BDF3E>(bodies, states, mesh, 0.02);
    NoContact<3> none;
    check_body_jacobian<3>(space, bodies, states, none, c, Vec<3>(0, 0, -1));

    // A shape is given in the body frame, which the orientation turns to the world: the contact
    // body's support is x_g + R(q) s(R(q)^T d) (checked at t^n, where q is the initial one).
    BodySystem<3, RigidBodyTraits<3>> shaped;
    std::vector<BodyState<3, RigidBodyTraits<3>>> shaped_states;
    RigidBody3D ellipsoid = body;
    ellipsoid.radius = 0;
    const convex::Ellipsoid<3> e{{0.2, 0.1, 0.15}};
    ellipsoid.shape = convex::support_of<3>(e);
    shaped.add(ellipsoid, mesh, 0.0, shaped_states);
    const auto placed = shaped.contact_bodies(shaped_states, 0);
    REQUIRE(placed[0].convex);
    const Mat<3> R = body.orientation.toRotationMatrix();
    for (const Vec<3>& d : {Vec<3>(1, 0, 0), Vec<3>(0.3, -0.8, 0.5), Vec<3>(-0.2, 0.1, -1)})
      CHECK((placed[0].convex.support(d) - (body.centre + R * e.support(Vec<3>(R.transpose() * d)))).norm() < 1e-14);
  }
}

// ---- Newton --------------------------------------------------------------------------------
namespace {
struct DenseLu {  // a LinearSolver for tiny systems
  static constexpr const char* name = "dense LU";
  Eigen::PartialPivLU<MatX> lu;
  void analyze(const SparseMatrix&) {}
  void factorize(const SparseMatrix& A) { lu.compute(MatX(A)); }
  VecX solve(const VecX& b) { return lu.solve(b); }
};
}  // namespace

TEST_CASE("newton_solve: quadratic convergence on a small system, typed failures", "[sim][newton][quick]") {
  // r(u) = (u0^2 + u1^2 - 4, u0 - u1^3 + 1): root near (1.69, 1.08)
  auto residual = [](const VecX& u, SparseMatrix& J, VecX& r) {
    r.resize(2);
    r << u[0] * u[0] + u[1] * u[1] - 4, u[0] - u[1] * u[1] * u[1] + 1;
    MatX Jd(2, 2);
    Jd << 2 * u[0], 2 * u[1], 1, -3 * u[1] * u[1];
    J = Jd.sparseView();
  };
  LinearSolve<DenseLu> lin;
  VecX u(2);
  u << 1, 1;
  SparseMatrix J;
  const NewtonReport rep = newton_solve(residual, lin, J, u, {.tolerance = 1e-14});
  const auto& e = rep.residuals;
  REQUIRE(e.size() >= 4);
  CHECK(e.back() < 1e-13);
  // quadratic: e_{k+1} / e_k^2 bounded once close
  CHECK(e[e.size() - 2] < 10 * e[e.size() - 3] * e[e.size() - 3]);
  VecX r;
  residual(u, J, r);
  CHECK(r.norm() < 1e-13);
  // linear mode: exactly one update
  VecX v(2);
  v << 1, 1;
  CHECK(newton_solve(residual, lin, J, v, {.linear = true}).iterations == 1);
  // failures: too few iterations, a non-finite residual
  VecX w(2);
  w << 1, 1;
  CHECK_THROWS_WITH(newton_solve(residual, lin, J, w, {.max_iterations = 1, .tolerance = 1e-14}),
                    Catch::Contains("did not converge in 1 iterations") && Catch::Contains("e-"));
  VecX bad(2);
  bad << std::nan(""), 1;
  CHECK_THROWS_AS(newton_solve(residual, lin, J, bad, {}), SolverError);
}

// ---- the 2D contact model --------------------------------------------------------------------
namespace {
ContactBody<2> disk_at(Vec<2> c, Real r, Vec<2> v = Vec<2>::Zero()) {
  ContactBody<2> b;
  b.centre = c, b.velocity = v, b.radius = b.r_in = b.r_out = r;
  return b;
}
}  // namespace

TEST_CASE("CollisionContact2D: eq. (24) + spring through the seam, momentum balance, overlaps and gaps",
          "[sim][collision][quick]") {
  const Real R = 0.125, mu = 0.01, d = 0.01;
  const Mesh<2> box = rectangle_mesh(4, 4, 0, 2, 0, 2);
  CollisionContact2D model({.range = 0.1, .spring_range = 0.02, .spring_force = 7});
  model.set_walls(box, {});
  std::vector<ContactBody<2>> b = {disk_at({1, 1}, R), disk_at({1, 1 + 2 * R + d}, R)};
  REQUIRE(model.find(b, mu) == 1);
  const std::vector<Vec<2>> v = {Vec<2>(0, 3), Vec<2>(0, -2)};
  std::vector<Vec<2>> F(2, Vec<2>::Zero());
  int visits = 0;
  model.forces(v, [&](int k, const Vec<2>& f, const Mat<2>&, const Vec<2>& arm, int) {
    F[k] += f, ++visits;
    CHECK(arm.norm() == 0.0);  // disks: through the centres
  });
  CHECK(visits == 2);
  const Real s = 1 - d / 0.02;
  const Real expected = mu * std::pow(4 * R / d, 1.5) * 5.0 + 7 * s * s;
  CHECK(F[1].norm() == Approx(expected).epsilon(1e-12));
  CHECK(F[1][1] > 0);                    // repulsive: the upper disk is pushed up
  CHECK((F[0] + F[1]).norm() == 0.0);    // action = reaction
  // overlaps between bodies, gaps to bodies and walls
  CHECK(model.overlaps(b).empty());
  b[1].centre[1] = 1 + 2 * R - 1e-3;
  const auto o = model.overlaps(b);
  REQUIRE(o.size() == 1);
  CHECK(o[0].gap == Approx(-1e-3).epsilon(1e-9));
  b = {disk_at({1, 0.3}, R), disk_at({1, 1.5}, R)};
  const auto g = model.gaps(b);
  CHECK(g[0] == Approx(0.3 - R).epsilon(1e-12));          // the bottom wall
  CHECK(g[1] == Approx(2 - 1.5 - R).epsilon(1e-12));      // the top wall
  // times to contact: gap / closing speed, over what each body approaches
  b[0].velocity = Vec<2>(0, -2);                          // falls toward the floor
  b[1].velocity = Vec<2>(0.5, -3);                        // chases it, and drifts right
  auto tc = model.times_to_contact(b);
  const Real between = 1.5 - 0.3 - 2 * R;                 // closing at 1 (3 - 2)
  CHECK(tc[0] == Approx((0.3 - R) / 2).epsilon(1e-12));  // the floor first
  CHECK(between / 1.0 < (2 - 1 - R) / 0.5);              // the other disk before the right wall,
  CHECK(tc[1] == Approx((1.5 - R) / 3).epsilon(1e-12));  // but the floor (not the nearest wall) first
  b[0].velocity = Vec<2>::Zero(), b[1].velocity = Vec<2>(0, -1);
  tc = model.times_to_contact(b);
  CHECK(tc[1] == Approx(between / 1.0).epsilon(1e-12));  // now the disk first, for both
  CHECK(tc[0] == tc[1]);
  b[0].velocity = Vec<2>(0, -2);  // the lower one falls faster: the floor for the upper one
  CHECK(model.times_to_contact(b)[1] == Approx((1.5 - R) / 1.0).epsilon(1e-12));
  // toward the right wall, mid-height (closest points on the other walls approach more slowly)
  CHECK(model.times_to_contact({disk_at({1, 1}, R, Vec<2>(0.5, 0))})[0] == Approx((2 - 1 - R) / 0.5).epsilon(1e-12));
  b[0].velocity = b[1].velocity = Vec<2>::Zero();
  CHECK(model.times_to_contact(b)[0] == std::numeric_limits<Real>::infinity());
  // geometry only: no forces
  CollisionContact2D geometry;
  geometry.set_walls(box, {});
  CHECK(geometry.find(b, mu) == 0);
  CHECK(NoContact<3>().gaps(std::vector<ContactBody<3>>(2))[1] == std::numeric_limits<Real>::infinity());
}

TEST_CASE("CollisionContact<3>: spheres in a box through the seam, momentum balance, overlaps, gaps and times",
          "[sim][collision][quick]") {
  const Real R = 0.5, mu = 0.3, d = 0.01;
  const Mesh<3> box = box_mesh(3, 3, 4, Vec<3>::Zero(), Vec<3>(4, 4, 6));
  CollisionContact<3> model({.range = 0.1, .spring_range = 0.03, .spring_force = 2});
  model.set_walls(box, {});
  auto sphere = [](const Vec<3>& c, Real r, const Vec<3>& v) {
    ContactBody<3> b;
    b.centre = c, b.velocity = v, b.radius = b.r_in = b.r_out = r;
    return b;
  };
  // two spheres nearly touching along a diagonal, the lower one near the floor
  const Vec<3> n = Vec<3>(1, 1, 2).normalized();
  std::vector<ContactBody<3>> b = {sphere(Vec<3>(1.5, 1.5, R + 0.02), R, Vec<3>::Zero()),
                                   sphere(Vec<3>(1.5, 1.5, R + 0.02) + (2 * R + d) * n, R, Vec<3>::Zero())};
  REQUIRE(model.find(b, mu) == 2);  // the pair and the floor
  const std::vector<Vec<3>> v = {Vec<3>(0.1, 0, -0.4), Vec<3>(-0.2, 0.1, -1)};
  std::vector<Vec<3>> F(2, Vec<3>::Zero());
  std::vector<Mat<3>> dF(2, Mat<3>::Zero());
  model.forces(v, [&](int k, const Vec<3>& f, const Mat<3>& df, const Vec<3>& arm, int) {
    F[k] += f, dF[k] += df;
    CHECK(arm.norm() == 0.0);  // spheres: through the centres
  });
  const Real s_pair = 1 - d / 0.03, s_floor = 1 - 0.02 / 0.03;
  // eq. (24) in 3D: mu Rbar (4 Rbar / d)^{3/2} |V^J - V^K| (physics/collision.hpp)
  const Real pair = mu * R * std::pow(4 * R / d, 1.5) * (v[1] - v[0]).norm() + 2 * s_pair * s_pair;
  const Real floor = mu * R * std::pow(4 * R / 0.02, 1.5) * v[0].norm() + 2 * s_floor * s_floor;
  CHECK((F[1] - pair * n).norm() < 1e-12 * pair);               // the upper sphere: pushed along n
  CHECK((F[0] + pair * n - floor * Vec<3>::UnitZ()).norm() < 1e-12 * pair);  // the lower: -n, and up from the floor
  CHECK((F[0] + F[1] - floor * Vec<3>::UnitZ()).norm() < 1e-12 * pair);      // action = reaction between them
  // each body's dF/dV against finite differences of the total force on it
  const Real h = 1e-6;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j) {
      auto vp = v, vm = v;
      vp[k][j] += h, vm[k][j] -= h;
      Vec<3> fp = Vec<3>::Zero(), fm = Vec<3>::Zero();
      model.forces(vp, [&](int i, const Vec<3>& f, const Mat<3>&, const Vec<3>&, int) { if (i == k) fp += f; });
      model.forces(vm, [&](int i, const Vec<3>& f, const Mat<3>&, const Vec<3>&, int) { if (i == k) fm += f; });
      for (int i = 0; i < 3; ++i) CHECK(dF[k](i, j) == Approx((fp[i] - fm[i]) / (2 * h)).epsilon(1e-6).margin(1e-5));
    }
  // overlaps, gaps, and times to contact
  CHECK(model.overlaps(b).empty());
  b[1].centre = b[0].centre + (2 * R - 1e-3) * n;
  const auto o = model.overlaps(b);
  REQUIRE(o.size() == 1);
  CHECK(o[0].gap == Approx(-1e-3).epsilon(1e-9));
  b = {sphere(Vec<3>(2, 2, 1), R, Vec<3>(0, 0, -2)), sphere(Vec<3>(2, 2, 3), R, Vec<3>(0, 0, -4))};
  const auto g = model.gaps(b);
  CHECK(g[0] == Approx(1 - R).epsilon(1e-12));        // the floor
  CHECK(g[1] == Approx(2 - 2 * R).epsilon(1e-12));    // the other sphere (the side walls are at 2 - R)
  const auto t = model.times_to_contact(b);
  CHECK(t[0] == Approx((1 - R) / 2).epsilon(1e-12));  // the floor
  CHECK(t[1] == Approx((2 - 2 * R) / 2).epsilon(1e-12));  // the other sphere (closing at 2) before the floor (2.5 / 4)
  // geometry only: no forces, but the gaps
  CollisionContact<3> geometry;
  geometry.set_walls(box, {});
  CHECK(geometry.find(b, mu) == 0);
  CHECK(geometry.gaps(b)[0] == Approx(1 - R).epsilon(1e-12));
}

// ---- the remesher ----------------------------------------------------------------------------
TEST_CASE("Remesher2D: the trigger's hysteresis, and a transferred state exact for fields the spaces contain",
          "[sim][remesh][quick]") {
  const Real R = 0.2;
  const std::vector<Circle> disks = {{Vec<2>(1, 1), R, 5}};
  Mesh<2> mesh = channel_with_disks(2, 2, disks, 0.08, 0.3);
  Remesher2D remesher({.walls = {channel_outline(2, 2)},
                       .size = [](const std::vector<Circle>& c) { return graded_size(c, 0.03, 0.12); },
                       .adapt = {}});
  const std::vector<RemeshBody<2>> bodies = {{5, Vec<2>(1, 1), R}};
  // a size function far from the mesh's: triggered; what the adaptation could not fix does not
  // trigger again unless it gets 10 % worse
  const RemeshMemory fresh{};
  CHECK(remesher.needed(mesh, bodies, fresh));
  const RemeshMemory m = remesher.measure(mesh, bodies);
  CHECK(!remesher.needed(mesh, bodies, {m.quality, m.deviation}));
  CHECK(remesher.needed(mesh, bodies, {m.quality, m.deviation / 1.2}));

  using Space = MixedSpace<2, TaylorHood>;
  const Space old_space(mesh);
  auto out = remesher.adapt(mesh, bodies, 2);
  REQUIRE(out);
  const Space new_space(out->mesh);
  // velocity quadratic, pressure affine, positions and mesh velocity affine
  auto u_of = [](const Vec<2>& x) { return Vec<2>(x[0] * x[1] - 0.3 * x[1] * x[1], 1 + x[0] * x[0]); };
  auto p_of = [](const Vec<2>& x) { return 2 * x[0] - x[1] + 0.5; };
  auto fill = [&](const Space& sp, VecX& f) {
    f.resize(sp.n_field());
    for (Index i = 0; i < sp.velocity().n_dofs(); ++i)
      for (int c = 0; c < 2; ++c) f[sp.velocity_field(i, c)] = u_of(sp.velocity().point(i))[c];
    for (Index i = 0; i < sp.pressure().n_dofs(); ++i) f[sp.pressure_field(i)] = p_of(sp.pressure().point(i));
  };
  auto affine = [](const Vec<2>& x) { return Vec<2>(0.5 * x[0] + 0.1, -x[1] + 2 * x[0]); };
  FlowState<2, RigidBodyTraits<2>> s;
  fill(old_space, s.U[0]);
  s.U[1] = s.U[0];
  for (const auto& x : mesh.coordinates()) s.X[1].push_back(affine(x)), s.V.push_back(affine(x));
  transfer_levels(s, old_space, *out->transfer, out->mesh.coordinates());
  VecX exact;
  fill(new_space, exact);
  // inside the old mesh the transfer is exact; new nodes on the circle lie O(h^2) outside it
  Real worst_u = 0, worst_x = 0;
  for (Index i = 0; i < new_space.velocity().n_dofs(); ++i) {
    const Vec<2> x = new_space.velocity().point(i);
    if ((x - Vec<2>(1, 1)).norm() < R + 0.02) continue;
    for (int c = 0; c < 2; ++c)
      worst_u = std::max(worst_u, std::abs(s.U[0][new_space.velocity_field(i, c)] - exact[new_space.velocity_field(i, c)]));
  }
  for (Index v = 0; v < out->mesh.n_nodes(); ++v) {
    const Vec<2> x = out->mesh.node(v);
    if ((x - Vec<2>(1, 1)).norm() < R + 0.02) continue;
    worst_x = std::max({worst_x, (s.X[1][v] - affine(x)).norm(), (s.V[v] - affine(x)).norm()});
  }
  CHECK(worst_u < 1e-12);
  CHECK(worst_x < 1e-12);
  CHECK(s.U[1] == s.U[0]);
  CHECK(s.X[2].empty());  // a level not yet taken stays empty
  // a mesh at rest stays at rest: the past positions go as displacements from X^n, so every new
  // node, those on the circle outside the old polygon too, has X^{n-1} = its own position
  FlowState<2, RigidBodyTraits<2>> rest;
  rest.X[1] = mesh.coordinates();
  transfer_levels(rest, old_space, *out->transfer, out->mesh.coordinates());
  CHECK(rest.X[1] == out->mesh.coordinates());
}

// ---- the flow state in a checkpoint ------------------------------------------------------------
TEST_CASE("FlowState: write_state / read_state round trip, and a mismatched body tag is refused", "[sim][checkpoint][quick]") {
  using State = FlowState<3, RigidBodyTraits<3>>;
  State s;
  s.time.advance(0.1), s.time.advance(0.05);
  s.X[1] = {Vec<3>(1, 2, 3), Vec<3>(4, 5, 6)};
  s.U[0] = VecX::LinSpaced(7, 0, 1), s.U[1] = VecX::Constant(7, 2), s.U[2] = VecX();
  s.V = {Vec<3>(0, 1, 0), Vec<3>(1, 0, 0)};
  s.stats.steps = 2, s.stats.remeshes = 1;
  s.remesh = {0.4, 0.8};
  BodyState<3, RigidBodyTraits<3>> b;
  b.centre.fill(Vec<3>(0.1, 0.2, 0.3));
  b.orientation.fill(Eigen::Quaternion<Real>(Eigen::AngleAxis<Real>(0.3, Vec<3>::UnitZ())));
  b.velocity.fill(Vec<6>::LinSpaced(6, 1, 6));
  b.load = Vec<6>::Constant(-1);
  b.surface = {Vec<3>(0.2, 0, 0)};
  s.bodies.push_back(b);
  const auto file = std::filesystem::temp_directory_path() / "alefsi_test_state.bin";
  {
    CheckpointWriter w(file);
    write_state(w, s, {7});
    w.commit();
  }
  State r;
  r.bodies.resize(1);
  r.bodies[0].surface.resize(1);
  {
    CheckpointReader rd(file);
    read_state(rd, r, {7}, 7);
    rd.finish();
  }
  CHECK(r.time.now() == s.time.now());
  CHECK(r.time.levels() == 2);
  CHECK(r.time.steps() == s.time.steps());
  CHECK(r.X[1] == s.X[1]);
  CHECK(r.U[0] == s.U[0]);
  CHECK(r.U[1] == s.U[1]);
  CHECK(r.V == s.V);
  CHECK(r.stats.steps == 2);
  CHECK(r.remesh.deviation == 0.8);
  CHECK(r.bodies[0].orientation[2].coeffs() == b.orientation[2].coeffs());
  CHECK(r.bodies[0].velocity[1] == b.velocity[1]);
  CHECK(r.bodies[0].load == b.load);
  State wrong;
  wrong.bodies.resize(1);
  wrong.bodies[0].surface.resize(1);
  CheckpointReader rd(file);
  CHECK_THROWS_WITH(read_state(rd, wrong, {8}, 7), Catch::Contains("body tags"));
  std::filesystem::remove(file);
}

TEST_CASE("checkpoint mesh: boundary and interior facet tags round-trip", "[sim][checkpoint][quick]") {
  const auto g = read_gmsh<2>(ALEFSI_TEST_DATA_DIR "/gmsh/groups2d_msh41.msh");  // an embedded sensor line
  REQUIRE(!g.mesh.tagged_interior_facets().empty());
  const auto file = std::filesystem::temp_directory_path() / "alefsi_test_mesh.bin";
  {
    CheckpointWriter w(file);
    write_mesh(w, g.mesh);
    w.commit();
  }
  CheckpointReader rd(file);
  const Mesh<2> m = read_mesh<2>(rd);
  rd.finish();
  std::filesystem::remove(file);
  REQUIRE(m.n_facets() == g.mesh.n_facets());
  CHECK(m.cells() == g.mesh.cells());
  CHECK(m.cell_tags() == g.mesh.cell_tags());
  for (Index f = 0; f < m.n_facets(); ++f) {
    REQUIRE(m.facet(f) == g.mesh.facet(f));
    REQUIRE(m.facet_tag(f) == g.mesh.facet_tag(f));
  }
  CHECK(m.tagged_interior_facets() == g.mesh.tagged_interior_facets());
}

TEST_CASE("oscillating cylinder: Morison's coefficients of a force that follows Morison's equation", "[sim][scenes][quick]") {
  // F = -1/2 D C_D u|u| - (pi D^2 / 4) C_I du/dt (rho = 1) sampled over three periods, fitted
  // over the middle one: the projections recover C_D and C_I up to the trapezoidal rule's error
  scenes::OscillatingCylinder s;
  s.diameter = 0.5, s.max_speed = 2, s.kc = 4;
  const Real cd = 2.09, ci = 1.45;
  std::vector<Real> t, F;
  const int n = 400;
  for (int k = 0; k <= 3 * n; ++k) {
    const Real tk = k * s.period() / n, u = s.velocity(tk), a = s.acceleration(tk);
    t.push_back(tk);
    F.push_back(-0.5 * s.diameter * cd * u * std::abs(u) - std::numbers::pi * s.diameter * s.diameter / 4 * ci * a);
  }
  CHECK(s.amplitude() == Approx(s.kc * s.diameter / (2 * std::numbers::pi)));
  CHECK(s.position(0.3) == Approx(-s.amplitude() * std::sin(s.omega() * 0.3)));
  const auto m = s.morison(t, F, s.period());
  CHECK(m.drag == Approx(cd).epsilon(1e-4));
  CHECK(m.inertia == Approx(ci).epsilon(1e-4));
  // a window starting between samples
  const auto m2 = s.morison(t, F, 1.3 * s.period());
  CHECK(m2.drag == Approx(cd).epsilon(1e-4));
  CHECK(m2.inertia == Approx(ci).epsilon(1e-4));
  // a pure drag force has no inertia part, and the reverse
  std::vector<Real> drag_only(F.size()), inertia_only(F.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    const Real u = s.velocity(t[k]);
    drag_only[k] = -0.5 * s.diameter * cd * u * std::abs(u);
    inertia_only[k] = F[k] - drag_only[k];
  }
  CHECK(std::abs(s.morison(t, drag_only, s.period()).inertia) < 1e-4);
  CHECK(std::abs(s.morison(t, inertia_only, s.period()).drag) < 1e-4);
  CHECK_THROWS_AS(s.morison(t, F, 2.5 * s.period()), InvalidArgument);  // the window leaves the samples
}

TEST_CASE("options: numbers, lists, flags and positionals; a bad value names its option", "[sim][app][quick]") {
  std::string mode;
  Real dt = 1e-3;
  int n = 3;
  bool newton = false;
  std::vector<Real> mus{1, 0.01};
  std::vector<std::string> names{"a"};
  auto make = [&] {
    Options o("prog", "test");
    o.positional("mode", mode, "the mode").add("dt", dt, "step").add("n", n, "count").add("mu", mus, "viscosities");
    o.add("names", names, "names").flag("newton", newton, "Newton");
    return o;
  };
  auto parse = [&](std::vector<const char*> args) {
    args.insert(args.begin(), "prog");
    std::ostringstream out;
    return make().parse(int(args.size()), args.data(), &out);
  };
  REQUIRE(parse({"fig7", "--dt", "0.5", "--n=7", "--mu", "2,0.25,1e-3", "--names", "x,y", "--newton"}));
  CHECK(mode == "fig7");
  CHECK(dt == 0.5);
  CHECK(n == 7);
  CHECK(mus == std::vector<Real>{2, 0.25, 1e-3});
  CHECK(names == std::vector<std::string>{"x", "y"});
  CHECK(newton);
  auto param_of = [&](std::vector<const char*> args) {
    try {
      parse(args);
    } catch (const InvalidArgument& e) {
      return e.parameter();
    }
    return std::string("<no throw>");
  };
  CHECK(param_of({"--mu", "1,x"}) == "--mu");    // an item that is not a number
  CHECK(param_of({"--mu", "1,inf"}) == "--mu");  // nor a finite one
  CHECK(param_of({"--n", "2.5"}) == "--n");
  CHECK(param_of({"--dt", ""}) == "--dt");
  // --help lists every option with its default, and parse returns false
  std::ostringstream help;
  const char* h[] = {"prog", "--help"};
  mus = {1, 0.01};
  CHECK_FALSE(make().parse(2, h, &help));
  CHECK_THAT(help.str(), Catch::Contains("--mu") && Catch::Contains("(default 1,0.01)") && Catch::Contains("--newton"));
}

TEST_CASE("print_run: the run's summary shows dt as it was, whatever the stream's format", "[sim][app][quick]") {
  RunSummary sum;
  sum.steps = 2600, sum.dt_smallest = 5e-4, sum.dt_largest = 5e-4, sum.worst_quality = 0.353;
  std::ostringstream out;
  out << std::fixed << std::setprecision(4) << 1.0;  // a caller's fixed format, left on the stream
  app::print_run(out, sum, 1.0, 1.0);
  // before the fix, setprecision(3) on a fixed stream printed 5e-4 as 0.001
  CHECK_THAT(out.str(), Catch::Contains("dt 0.0005 to 0.0005") && Catch::Contains("worst quality 0.353"));
  CHECK((out.flags() & std::ios::floatfield) == std::ios::fixed);  // the caller's format is given back
}
