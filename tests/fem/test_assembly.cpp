// DOF maps, the constraint-aware local-to-global map and the sparse assembler: the assembled
// Jacobian and residual equal T^T (sum_c P_c^T A_c P_c) T computed densely, for free, fixed and
// linked (rigid-body-like) DOFs. The Stokes and Navier-Stokes kernels against their quadrature
// oracles (tests/support/oracle_kernels.hpp), GLS terms included.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <set>
#include <type_traits>
#include <vector>

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/partition.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/navier_stokes.hpp"
#include "alefsi/physics/stokes.hpp"

#include "../support/oracle_kernels.hpp"

using namespace alefsi;

namespace {
template <int N>
struct PseudoRandomKernel {  // deterministic, cell-dependent, non-symmetric
  void cell(Index c, const Eigen::Matrix<Real, N, 1>& u, Eigen::Matrix<Real, N, N>& A,
            Eigen::Matrix<Real, N, 1>& r) const {
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) A(i, j) = std::sin(0.37 * c + 1.3 * i + 0.71 * j * j);
    for (int i = 0; i < N; ++i) r[i] = std::cos(0.5 * c + i);
    r += A * u;
  }
};

// The unit square / cube with every node moved by a smooth, non-affine map (cells stay
// valid and become non-similar): no two cells share a Jacobian.
template <int D>
Mesh<D> distorted_mesh(int n) {
  Mesh<D> mesh = [&] {
    if constexpr (D == 2) return rectangle_mesh(n, n);
    else return box_mesh(n, n, n);
  }();
  std::vector<Vec<D>> x = mesh.coordinates();
  for (auto& p : x) {
    Vec<D> s = p;
    for (int i = 0; i < D; ++i) s[i] += 0.08 * std::sin(3.1 * p[(i + 1) % D] + 0.7 * i) * std::sin(2.3 * p[i]);
    p = 1.7 * s;  // and not the unit size
  }
  mesh.set_coordinates(std::move(x));
  return mesh;
}
}  // namespace

TEST_CASE("DofMap numbers vertices then edges; MixedSpace interleaves velocity", "[fem][dofs][quick]") {
  const auto mesh = rectangle_mesh(3, 2);
  MixedSpace<2, TaylorHood> th(mesh);
  CHECK(th.velocity().n_dofs() == mesh.n_nodes() + mesh.n_edges());
  CHECK(th.pressure().n_dofs() == mesh.n_nodes());
  CHECK(th.n_field() == 2 * (mesh.n_nodes() + mesh.n_edges()) + mesh.n_nodes());
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    const auto& d = th.velocity().cell_dofs(c);
    for (int e = 0; e < 3; ++e) {
      // the P2 DOF point of local edge e is the midpoint of that edge's vertices
      const auto& ab = SimplexTopology<2>::edges[e];
      const Vec<2> mid = 0.5 * (mesh.node(mesh.cell(c)[ab[0]]) + mesh.node(mesh.cell(c)[ab[1]]));
      CHECK((th.velocity().point(d[3 + e]) - mid).norm() < 1e-15);
    }
    const auto f = th.cell_field_dofs(c);
    CHECK(f[2 * 4 + 1] == 2 * d[4] + 1);
    CHECK(f[12] == th.pressure_field(mesh.cell(c)[0]));
  }
  // boundary DOFs of the top side: 4 nodes + 3 edges
  CHECK(th.velocity().boundary_dofs(tags::top).size() == 7);
}

TEST_CASE("constraints: expand, reduce and invalid use", "[fem][constraints][quick]") {
  DofConstraints c(5);
  const Index z = c.add_unknowns(2);
  c.fix(1, 3.0);
  const Index ex[] = {z, z + 1};
  const Real w[] = {2.0, -1.0};
  c.link(3, ex, w, 0.5);
  REQUIRE_THROWS_AS(c.fix(1, 0.0), InvalidArgument);  // already constrained
  REQUIRE_THROWS_AS(c.fix(9, 0.0), InvalidArgument);  // out of range
  REQUIRE_THROWS_AS(c.expand(VecX::Zero(5)), Error);   // before finalize
  c.finalize();
  CHECK(c.n_free() == 3);
  CHECK(c.n_unknowns() == 5);
  VecX u(5);
  u << 1, 2, 3, 10, 20;  // free DOFs 0, 2, 4 then extras
  const VecX f = c.expand(u);
  CHECK(f[0] == 1);
  CHECK(f[1] == 3.0);
  CHECK(f[2] == 2);
  CHECK(f[3] == Approx(2 * 10 - 20 + 0.5));
  CHECK(f[4] == 3);
  VecX rf(5);
  rf << 1, 1, 1, 1, 1;
  const VecX ru = c.reduce(rf);
  CHECK(ru[3] == 2.0);
  CHECK(ru[4] == -1.0);
  REQUIRE_THROWS_AS(c.add_unknowns(1), Error);  // structure is frozen
}

TEMPLATE_TEST_CASE("assembly equals the dense T^T A T for free, fixed and linked DOFs", "[la][assembly][quick]",
                   TaylorHood, P1P1Gls) {
  const auto mesh = annulus_mesh(0.3, 1.0, 3, 16);
  using Space = MixedSpace<2, TestType>;
  Space space(mesh);
  DofConstraints cons(space.n_field());
  // outer wall fixed, inner circle linked to a "rigid body" Z = (V1, V2, w): u = V + w x r
  const Index z = cons.add_unknowns(3);
  for (Index i : space.velocity().boundary_dofs(tags::outer))
    for (int k = 0; k < 2; ++k) cons.fix(space.velocity_field(i, k), 0.1 * (k + 1));
  for (Index i : space.velocity().boundary_dofs(tags::inner)) {
    const Vec<2> x = space.velocity().point(i);
    const Index ex[] = {z, z + 1, z + 2};
    const Real w0[] = {1.0, 0.0, -x[1]}, w1[] = {0.0, 1.0, x[0]};
    cons.link(space.velocity_field(i, 0), ex, w0, 0.01);
    cons.link(space.velocity_field(i, 1), ex, w1, -0.02);
  }
  cons.fix(space.pressure_field(0), 0.0);
  cons.finalize();
  Assembler<Space::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
  CHECK(asmb.n_linked_cells() > 0);

  VecX field(space.n_field());
  for (Index f = 0; f < field.size(); ++f) field[f] = std::sin(1.7 * f);
  PseudoRandomKernel<Space::n_local> k;
  SparseMatrix J;
  VecX r;
  asmb.assemble(k, field, &J, &r);

  // dense reference
  const Index nf = space.n_field(), nu = cons.n_unknowns();
  MatX T = MatX::Zero(nf, nu), Af = MatX::Zero(nf, nf);
  VecX rf = VecX::Zero(nf);
  for (Index f = 0; f < nf; ++f)
    for (std::size_t e = 0; e < cons.indices(f).size(); ++e) T(f, cons.indices(f)[e]) = cons.weights(f)[e];
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    const auto d = space.cell_field_dofs(c);
    typename Assembler<Space::n_local>::LocalMat A;
    typename Assembler<Space::n_local>::LocalVec re;
    k.cell(c, asmb.gather(c, field), A, re);
    for (int i = 0; i < Space::n_local; ++i) {
      rf[d[i]] += re[i];
      for (int j = 0; j < Space::n_local; ++j) Af(d[i], d[j]) += A(i, j);
    }
  }
  const MatX Jref = T.transpose() * Af * T;
  const VecX rref = T.transpose() * rf;
  const MatX Jd = MatX(J);
  CHECK((Jd - Jref).norm() <= 1e-12 * Jref.norm());
  CHECK((r - rref).norm() <= 1e-12 * rref.norm());
  // the pattern holds every nonzero of the reference and its row indices are sorted
  for (Index col = 0; col < nu; ++col) {
    for (Index p = J.outerIndexPtr()[col] + 1; p < J.outerIndexPtr()[col + 1]; ++p)
      CHECK(J.innerIndexPtr()[p] > J.innerIndexPtr()[p - 1]);
    for (Index row = 0; row < nu; ++row)
      if (std::abs(Jref(row, col)) > 1e-14) CHECK(J.coeff(row, col) != 0.0);
  }
  // assembling twice gives the same values (the matrix is reset, not accumulated)
  SparseMatrix J2 = J;
  asmb.assemble(k, field, &J2, nullptr);
  CHECK((MatX(J2) - Jd).norm() == 0.0);
}

TEMPLATE_TEST_CASE("Stokes kernel from reference integrals equals the quadrature kernel", "[la][assembly][stokes][quick]",
                   TaylorHood, P1P1Gls) {
  auto check = [](auto dim_tag) {
    constexpr int D = decltype(dim_tag)::value;
    const auto mesh = distorted_mesh<D>(D == 2 ? 5 : 2);
    using Space = MixedSpace<D, TestType>;
    Space space(mesh);
    auto force = [](const Vec<D>& x) {
      Vec<D> f;
      for (int i = 0; i < D; ++i) f[i] = std::cos(1.3 * x[i] + i) * std::exp(0.4 * x[(i + 1) % D]);
      return f;
    };
    const Real mu = 0.37;
    const StokesKernel<D, TestType> fast(space, mu, force);
    const testing::StokesQuadratureKernel<D, TestType> ref(space, mu, force);
    using LocalVec = Eigen::Matrix<Real, Space::n_local, 1>;
    using LocalMat = Eigen::Matrix<Real, Space::n_local, Space::n_local>;
    Real worst_A = 0, worst_r = 0;
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      LocalVec u;
      for (int i = 0; i < Space::n_local; ++i) u[i] = std::sin(0.9 * c + 1.1 * i);
      LocalMat A1, A2;
      LocalVec r1, r2;
      fast.cell(c, u, A1, r1);
      ref.cell(c, u, A2, r2);
      worst_A = std::max(worst_A, (A1 - A2).norm() / A2.norm());
      worst_r = std::max(worst_r, (r1 - r2).norm() / r2.norm());
      CHECK((A1 - A1.transpose()).norm() <= 1e-14 * A1.norm());
    }
    INFO("D = " << D << ", worst relative differences: A " << worst_A << ", r " << worst_r);
    CHECK(worst_A <= 1e-12);
    CHECK(worst_r <= 1e-12);
    // and the assembled systems
    DofConstraints cons(space.n_field());
    for (Index i : space.velocity().boundary_dofs(1))
      for (int k = 0; k < D; ++k) cons.fix(space.velocity_field(i, k), 0.3 * k + 0.1);
    cons.finalize();
    Assembler<Space::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
    VecX field(space.n_field());
    for (Index f = 0; f < field.size(); ++f) field[f] = std::cos(0.3 * f);
    field = cons.expand(cons.restrict_free(field));
    SparseMatrix J1, J2;
    VecX s1, s2;
    asmb.assemble(fast, field, &J1, &s1);
    asmb.assemble(ref, field, &J2, &s2);
    const MatX d = MatX(J1) - MatX(J2);
    CHECK(d.norm() <= 1e-12 * MatX(J2).norm());
    CHECK((s1 - s2).norm() <= 1e-12 * s2.norm());
  };
  check(std::integral_constant<int, 2>{});
  check(std::integral_constant<int, 3>{});
}

TEST_CASE("gls_tau: one parameter, its steady and small-dt limits; the kernels take it from their policy",
          "[la][assembly][stabilisation][quick]") {
  const Real h = 0.37, mu = 0.05, rho = 1.3;
  // steady Stokes: computed as h^2 / (c1 mu), the limit of the general form
  CHECK(gls_tau({.h = h, .mu = mu}) == h * h / (4 * mu));
  CHECK(gls_tau({.h = h, .mu = mu}, 3.0) == h * h / (3 * mu));
  CHECK(gls_tau({.h = h, .mu = mu, .rho = rho, .dt = 1e30}) == Approx(h * h / (4 * mu)).epsilon(1e-15));
  CHECK(gls_tau({.h = h, .mu = mu, .rho = rho, .dt = 1e-9}) == Approx(1e-9 / (2 * rho)).epsilon(1e-9));
  // convection lowers it: (2 rho |a| / h)^2 added under the root
  const Real t_conv = gls_tau({.h = h, .mu = mu, .rho = rho, .dt = 0.1, .a_norm = 2.0});
  CHECK(t_conv == Approx(1 / std::sqrt(std::pow(2 * rho / 0.1, 2) + std::pow(2 * rho * 2.0 / h, 2) +
                                       std::pow(4 * mu / (h * h), 2))).epsilon(1e-15));
  // the kernels
  const auto mesh = distorted_mesh<2>(3);
  MixedSpace<2, P1P1Gls> p1(mesh);
  MixedSpace<2, TaylorHood> th(mesh);
  const StokesKernel<2, P1P1Gls> stokes_gls(p1, mu);
  const StokesKernel<2, TaylorHood> stokes_th(th, mu);
  AleNavierStokesKernel<2, P1P1Gls> ns(p1, rho, mu);
  StepInputs<2> in;
  in.dt = 0.1;
  ns.set_step(in);
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    const Real hc = mesh.diameter(c);
    CHECK(stokes_gls.tau(c) == gls_tau({.h = hc, .mu = mu}));
    CHECK(stokes_th.tau(c) == 0);
    CHECK(ns.tau(c, Vec<2>(2.0, 0.0)) == gls_tau({.h = hc, .mu = mu, .rho = rho, .dt = 0.1, .a_norm = 2.0}));
  }
  // no stabilisation: an empty policy with nothing to call at run time
  STATIC_REQUIRE(std::is_empty_v<StokesKernel<3, TaylorHood>::Stabilisation>);
  STATIC_REQUIRE(std::is_empty_v<AleNavierStokesKernel<3, TaylorHood>::Stabilisation>);
  STATIC_REQUIRE(std::is_same_v<AleNavierStokesKernel<2, P1P1Gls, false>::Stabilisation,
                                NavierStokesStabilisation<2, P1P1Gls, false, GlsStabilisation>>);
}

TEST_CASE("threaded assembly is bit-identical to one thread; a throwing kernel is reported", "[la][assembly][threads][quick]") {
  const auto mesh = annulus_mesh(0.3, 1.0, 14, 96);  // 2688 cells: several chunks and colours
  using Space = MixedSpace<2, TaylorHood>;
  Space space(mesh);
  DofConstraints cons(space.n_field());
  const Index z = cons.add_unknowns(3);
  for (Index i : space.velocity().boundary_dofs(tags::outer))
    for (int k = 0; k < 2; ++k) cons.fix(space.velocity_field(i, k), 0.1 * (k + 1));
  for (Index i : space.velocity().boundary_dofs(tags::inner)) {
    const Vec<2> x = space.velocity().point(i);
    const Index ex[] = {z, z + 1, z + 2};
    const Real w0[] = {1.0, 0.0, -x[1]}, w1[] = {0.0, 1.0, x[0]};
    cons.link(space.velocity_field(i, 0), ex, w0, 0.01);
    cons.link(space.velocity_field(i, 1), ex, w1, -0.02);
  }
  cons.finalize();
  Assembler<Space::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
  REQUIRE(asmb.n_colours() >= 2);
  VecX field(space.n_field());
  for (Index f = 0; f < field.size(); ++f) field[f] = std::sin(1.7 * f);
  PseudoRandomKernel<Space::n_local> k;
  SparseMatrix J1, Jt;
  VecX r1, rt;
  asmb.assemble(k, field, &J1, &r1);
  // a plain loop over the cells in cell order agrees to round-off
  SparseMatrix Jp = asmb.matrix();
  std::fill(Jp.valuePtr(), Jp.valuePtr() + Jp.nonZeros(), 0.0);
  VecX rp = VecX::Zero(asmb.n_unknowns());
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    typename Assembler<Space::n_local>::LocalMat A;
    typename Assembler<Space::n_local>::LocalVec re;
    k.cell(c, asmb.gather(c, field), A, re);
    asmb.scatter(c, A, re, Jp.valuePtr(), &rp);
  }
  CHECK((MatX(Jp) - MatX(J1)).norm() <= 1e-13 * MatX(J1).norm());
  CHECK((rp - r1).norm() <= 1e-13 * r1.norm());
  for (int t : {2, 3, 5}) {
    asmb.set_threads(t);
    asmb.assemble(k, field, &Jt, &rt);
    INFO("threads = " << t);
    REQUIRE(Jt.nonZeros() == J1.nonZeros());
    CHECK(std::equal(Jt.valuePtr(), Jt.valuePtr() + Jt.nonZeros(), J1.valuePtr()));
    CHECK(std::equal(rt.data(), rt.data() + rt.size(), r1.data()));
  }
  // a kernel that throws on some cell: the exception reaches the caller, no thread hangs
  struct Throwing {
    void cell(Index c, const Eigen::Matrix<Real, Space::n_local, 1>&, Eigen::Matrix<Real, Space::n_local, Space::n_local>& A,
              Eigen::Matrix<Real, Space::n_local, 1>& r) const {
      if (c == 1000) throw SolverError("bad cell");
      A.setZero();
      r.setZero();
    }
  };
  for (int t : {1, 2}) {
    asmb.set_threads(t);
    CHECK_THROWS_AS(asmb.assemble(Throwing{}, field, &Jt, &rt), SolverError);
  }
  CHECK_THROWS_AS(asmb.set_threads(0), InvalidArgument);
}

namespace {
// Step inputs with every member set (theta < 1, history, u*, mesh velocity, force), smooth
// fields on a mesh with nf field unknowns. `in` points into the members: not copyable.
template <int D>
struct FullStepInputs {
  VecX prev, hist, ustar;
  std::vector<Vec<D>> vmesh;
  StepInputs<D> in;

  FullStepInputs(const Mesh<D>& mesh, Index nf) : prev(nf), hist(nf), ustar(nf), vmesh(mesh.n_nodes()) {
    for (Index f = 0; f < nf; ++f) {
      prev[f] = std::sin(0.7 * f + 0.2);
      hist[f] = std::cos(0.3 * f);
      ustar[f] = std::sin(1.9 * f) + 0.3;
    }
    for (Index v = 0; v < mesh.n_nodes(); ++v)
      for (int k = 0; k < D; ++k) vmesh[v][k] = 0.2 * std::sin(2.0 * mesh.node(v)[(k + 1) % D] + k);
    in.dt = 0.05, in.theta = 0.5, in.a0 = 1.5;
    in.previous = &prev, in.history = &hist, in.extrapolated = &ustar, in.mesh_velocity = &vmesh;
    in.force = [](const Vec<D>& x) {
      Vec<D> f;
      for (int i = 0; i < D; ++i) f[i] = std::cos(1.3 * x[i] + i) * std::exp(0.4 * x[(i + 1) % D]);
      return f;
    };
  }
  FullStepInputs(const FullStepInputs&) = delete;
  FullStepInputs& operator=(const FullStepInputs&) = delete;
};

// Compares AleNavierStokesKernel with its oracle AleNavierStokesQuadratureKernel cell by cell on a
// distorted mesh, with every step input set.
template <int D, class Pair, bool Convection>
void compare_ns_kernels(Linearisation lin) {
  const auto mesh = distorted_mesh<D>(D == 2 ? 4 : 2);
  using Space = MixedSpace<D, Pair>;
  Space space(mesh);
  const FullStepInputs<D> step(mesh, space.n_field());
  AleNavierStokesKernel<D, Pair, Convection> fast(space, 1.3, 0.05, lin);
  testing::AleNavierStokesQuadratureKernel<D, Pair, Convection> ref(space, 1.3, 0.05, lin);
  fast.set_step(step.in);
  ref.set_step(step.in);
  Real worst_A = 0, worst_r = 0;
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    Eigen::Matrix<Real, Space::n_local, 1> u, r1, r2;
    Eigen::Matrix<Real, Space::n_local, Space::n_local> A1, A2;
    for (int i = 0; i < Space::n_local; ++i) u[i] = std::sin(0.9 * c + 1.1 * i);
    fast.cell(c, u, A1, r1);
    ref.cell(c, u, A2, r2);
    worst_A = std::max(worst_A, (A1 - A2).norm() / A2.norm());
    worst_r = std::max(worst_r, (r1 - r2).norm() / r2.norm());
  }
  INFO(D << "D " << Pair::name << (Convection ? "" : " (no convection)")
         << (lin == Linearisation::newton ? " Newton" : " semi-implicit") << ": worst relative differences A "
         << worst_A << ", r " << worst_r);
  CHECK(worst_A <= 1e-12);
  CHECK(worst_r <= 1e-12);
}
}  // namespace

TEST_CASE("Navier-Stokes kernel (reference integrals, exact-degree rule) equals the quadrature kernel",
          "[la][assembly][navier_stokes][quick]") {
  for (auto lin : {Linearisation::newton, Linearisation::semi_implicit}) {
    compare_ns_kernels<2, TaylorHood, true>(lin);
    compare_ns_kernels<2, P1P1Gls, true>(lin);
    compare_ns_kernels<3, TaylorHood, true>(lin);
    compare_ns_kernels<3, P1P1Gls, true>(lin);
  }
  compare_ns_kernels<2, TaylorHood, false>(Linearisation::newton);
  compare_ns_kernels<2, P1P1Gls, false>(Linearisation::newton);
  compare_ns_kernels<3, TaylorHood, false>(Linearisation::newton);
}

namespace {
// The element matrix of the Navier-Stokes kernel is the exact derivative of its element residual:
// central differences of r, exact for a residual quadratic in u (Newton: u_th . grad u_th, the
// SUPG test function (a . grad) w with a = u_th - v) and linear (semi-implicit), up to round-off.
// Independent of the quadrature oracle, which shares the kernels' formulas.
template <int D, class Pair>
void check_ns_jacobian_by_differences(Linearisation lin) {
  const auto mesh = distorted_mesh<D>(D == 2 ? 3 : 1);
  using Space = MixedSpace<D, Pair>;
  Space space(mesh);
  const FullStepInputs<D> step(mesh, space.n_field());
  AleNavierStokesKernel<D, Pair, true> k(space, 1.3, 0.05, lin);
  k.set_step(step.in);
  using LV = Eigen::Matrix<Real, Space::n_local, 1>;
  using LM = Eigen::Matrix<Real, Space::n_local, Space::n_local>;
  Real worst = 0;
  const Real eps = 1e-4;
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    LV u, r, rp, rm;
    LM A, dummy;
    for (int i = 0; i < Space::n_local; ++i) u[i] = std::sin(0.9 * c + 1.1 * i);
    k.cell(c, u, A, r);
    for (int j = 0; j < Space::n_local; ++j) {
      LV up = u, um = u;
      up[j] += eps, um[j] -= eps;
      k.cell(c, up, dummy, rp);
      k.cell(c, um, dummy, rm);
      worst = std::max(worst, ((rp - rm) / (2 * eps) - A.col(j)).norm() / A.norm());
    }
  }
  INFO(D << "D " << Pair::name << (lin == Linearisation::newton ? " Newton" : " semi-implicit")
         << ": worst relative difference of a column " << worst);
  CHECK(worst <= 1e-9);
}
}  // namespace

TEST_CASE("Navier-Stokes kernel: the element matrix is the derivative of the element residual (GLS included)",
          "[la][assembly][navier_stokes][quick]") {
  for (auto lin : {Linearisation::newton, Linearisation::semi_implicit}) {
    check_ns_jacobian_by_differences<2, P1P1Gls>(lin);
    check_ns_jacobian_by_differences<2, TaylorHood>(lin);
    check_ns_jacobian_by_differences<3, P1P1Gls>(lin);
  }
}

namespace {
// The annulus's constraints for the assembly tests: component 0 fixed on the outer circle
// (component 1 free: blocks of one), the inner circle linked to 6 extra unknowns (a block of 6:
// the generic scatter path), pressure free; finalized.
DofConstraints fixed_and_linked(const MixedSpace<2, TaylorHood>& space) {
  DofConstraints cons(space.n_field());
  const Index z = cons.add_unknowns(6);
  for (Index i : space.velocity().boundary_dofs(tags::outer)) cons.fix(space.velocity_field(i, 0), 0.3);
  for (Index i : space.velocity().boundary_dofs(tags::inner)) {
    const Vec<2> x = space.velocity().point(i);
    const Index ex[] = {z, z + 1, z + 2, z + 3, z + 4, z + 5};
    const Real w0[] = {1.0, 0.0, -x[1], x[0] * x[0], 0.5, -x[0] * x[1]};
    const Real w1[] = {0.0, 1.0, x[0], 0.2, x[1] * x[1], x[0]};
    cons.link(space.velocity_field(i, 0), ex, w0, 0.01);
    cons.link(space.velocity_field(i, 1), ex, w1, -0.02);
  }
  cons.finalize();
  return cons;
}

}  // namespace

TEST_CASE("assembly with partly fixed nodes and a 6-unknown link equals the dense T^T A T", "[la][assembly][quick]") {
  // fixed_and_linked: a fixed component, and a 6-unknown link on the inner circle
  const auto mesh = annulus_mesh(0.3, 1.0, 4, 20);
  using Space = MixedSpace<2, TaylorHood>;
  Space space(mesh);
  const DofConstraints cons = fixed_and_linked(space);
  Assembler<Space::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
  VecX field(space.n_field());
  for (Index f = 0; f < field.size(); ++f) field[f] = std::sin(1.3 * f);
  PseudoRandomKernel<Space::n_local> k;
  SparseMatrix J;
  VecX r;
  asmb.assemble(k, field, &J, &r);
  const Index nf = space.n_field(), nu = cons.n_unknowns();
  MatX T = MatX::Zero(nf, nu), Af = MatX::Zero(nf, nf);
  VecX rf = VecX::Zero(nf);
  for (Index f = 0; f < nf; ++f)
    for (std::size_t e = 0; e < cons.indices(f).size(); ++e) T(f, cons.indices(f)[e]) = cons.weights(f)[e];
  for (Index c = 0; c < mesh.n_cells(); ++c) {
    const auto d = space.cell_field_dofs(c);
    typename Assembler<Space::n_local>::LocalMat A;
    typename Assembler<Space::n_local>::LocalVec re;
    k.cell(c, asmb.gather(c, field), A, re);
    for (int i = 0; i < Space::n_local; ++i) {
      rf[d[i]] += re[i];
      for (int j = 0; j < Space::n_local; ++j) Af(d[i], d[j]) += A(i, j);
    }
  }
  const MatX Jref = T.transpose() * Af * T;
  CHECK((MatX(J) - Jref).norm() <= 1e-12 * Jref.norm());
  CHECK((r - T.transpose() * rf).norm() <= 1e-12 * r.norm());
  // fewer stored positions than DOF pairs (blocks of 2 on the interior nodes)
  CHECK(asmb.n_positions() < std::size_t(mesh.n_cells()) * Space::n_local * Space::n_local / 2);
}

namespace {
// Assembles the Navier-Stokes Newton Jacobian and residual (every step input set) on 1 and 2
// threads: the results must be bit-identical (same summation order, see la/assembler.hpp).
template <int D, class Pair>
void check_ns_threads(int n) {
  const auto mesh = distorted_mesh<D>(n);
  using Space = MixedSpace<D, Pair>;
  Space space(mesh);
  DofConstraints cons(space.n_field());
  for (Index i : space.velocity().boundary_dofs(1))
    for (int k = 0; k < D; ++k) cons.fix(space.velocity_field(i, k), 0.2 * k + 0.1);
  cons.finalize();
  const Index nf = space.n_field();
  VecX field(nf);
  for (Index f = 0; f < nf; ++f) field[f] = std::cos(0.3 * f);
  field = cons.expand(cons.restrict_free(field));
  FullStepInputs<D> step(mesh, nf);
  step.in.theta = 1;
  step.in.force = {};
  AleNavierStokesKernel<D, Pair> k(space, 1.3, 0.05, Linearisation::newton);
  k.set_step(step.in);
  Assembler<Space::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
  REQUIRE(asmb.n_colours() >= 2);
  SparseMatrix J1, J2;
  VecX r1, r2;
  asmb.assemble(k, field, &J1, &r1);
  asmb.set_threads(2);
  asmb.assemble(k, field, &J2, &r2);
  INFO(D << "D " << Pair::name << ", " << mesh.n_cells() << " cells, " << asmb.n_colours() << " colours");
  REQUIRE(J2.nonZeros() == J1.nonZeros());
  CHECK(std::equal(J1.outerIndexPtr(), J1.outerIndexPtr() + J1.cols() + 1, J2.outerIndexPtr()));
  CHECK(std::equal(J1.innerIndexPtr(), J1.innerIndexPtr() + J1.nonZeros(), J2.innerIndexPtr()));
  CHECK(std::equal(J1.valuePtr(), J1.valuePtr() + J1.nonZeros(), J2.valuePtr()));
  CHECK(std::equal(r1.data(), r1.data() + r1.size(), r2.data()));
  // matrix(): the same pattern, zero values
  const SparseMatrix& M = asmb.matrix();
  REQUIRE(M.nonZeros() == J1.nonZeros());
  CHECK(std::equal(M.innerIndexPtr(), M.innerIndexPtr() + M.nonZeros(), J1.innerIndexPtr()));
  CHECK(std::all_of(M.valuePtr(), M.valuePtr() + M.nonZeros(), [](Real v) { return v == 0.0; }));
}
}  // namespace

TEST_CASE("Navier-Stokes assembly on two threads is bit-identical to one thread", "[la][assembly][threads][quick]") {
  check_ns_threads<2, TaylorHood>(24);  // 1152 cells: 5 chunks
  check_ns_threads<2, P1P1Gls>(24);
  check_ns_threads<3, TaylorHood>(6);   // 1296 cells
  check_ns_threads<3, P1P1Gls>(6);
}

namespace {
// Checks an assembler's pattern and scatter positions against a reference built directly from
// the cells and the constraints, with no groups, blocks or classes: the rows of column j are
// the unknowns of the cells whose unknowns include j (a cell's unknowns: those its field DOFs
// depend on). Positions: each cell alone scatters a matrix and a residual with distinct
// entries into zero values, which must receive exactly T_e^T A_e T_e and T_e^T r_e (simple
// cells: every entry exactly once, so compared exactly), and nothing else (every value is
// zero again once the expected entries are cleared).
// Returns the bytes per stored position (1 when all are 8-bit).
template <int N>
double check_pattern_and_positions(const std::vector<std::array<Index, N>>& cells, const DofConstraints& cons) {
  const Index nc = Index(cells.size()), nu = cons.n_unknowns();
  Assembler<N> asmb(nc, [&](Index c) { return cells[c]; }, cons);
  std::vector<std::set<Index>> rows(nu);
  for (const auto& d : cells) {
    std::set<Index> us;
    for (Index f : d)
      for (Index u : cons.indices(f)) us.insert(u);
    for (Index j : us) rows[j].insert(us.begin(), us.end());
  }
  std::size_t nnz = 0;
  for (const auto& r : rows) nnz += r.size();
  SparseMatrix M = asmb.matrix();
  REQUIRE(M.rows() == nu);
  REQUIRE(M.cols() == nu);
  REQUIRE(M.isCompressed());
  REQUIRE(std::size_t(M.nonZeros()) == nnz);
  REQUIRE(std::size_t(asmb.n_nonzeros()) == nnz);
  Index bad_columns = 0;
  for (Index j = 0; j < nu; ++j) {
    const Index b = M.outerIndexPtr()[j], e = M.outerIndexPtr()[j + 1];
    bad_columns += std::size_t(e - b) != rows[j].size() || !std::equal(rows[j].begin(), rows[j].end(), M.innerIndexPtr() + b);
  }
  CHECK(bad_columns == 0);
  // a matrix given to assemble receives the same pattern
  struct Zero {
    void cell(Index, const Eigen::Matrix<Real, N, 1>&, Eigen::Matrix<Real, N, N>& A, Eigen::Matrix<Real, N, 1>& r) const {
      A.setZero();
      r.setZero();
    }
  };
  SparseMatrix J;
  VecX r;
  asmb.assemble(Zero{}, VecX::Zero(cons.n_field()), &J, &r);
  REQUIRE(J.nonZeros() == M.nonZeros());
  CHECK(std::equal(J.outerIndexPtr(), J.outerIndexPtr() + nu + 1, M.outerIndexPtr()));
  CHECK(std::equal(J.innerIndexPtr(), J.innerIndexPtr() + J.nonZeros(), M.innerIndexPtr()));
  // positions, cell by cell
  std::fill(M.valuePtr(), M.valuePtr() + M.nonZeros(), 0.0);
  r.setZero();
  typename Assembler<N>::LocalMat A;
  typename Assembler<N>::LocalVec re;
  for (int i = 0; i < N; ++i) {
    re[i] = 1 + i;
    for (int j = 0; j < N; ++j) A(i, j) = 1 + i + N * j;
  }
  Index bad_values = 0, bad_residuals = 0;
  for (Index c = 0; c < nc; ++c) {
    asmb.scatter(c, A, re, M.valuePtr(), &r);
    std::map<std::pair<Index, Index>, Real> ref;  // (row, column) -> value
    std::map<Index, Real> rref;
    bool simple = true;
    for (int i = 0; i < N; ++i) {
      const auto ui = cons.indices(cells[c][i]);
      const auto wi = cons.weights(cells[c][i]);
      simple &= cons.kind(cells[c][i]) != DofConstraints::Kind::linked;
      for (std::size_t a = 0; a < ui.size(); ++a) {
        rref[ui[a]] += wi[a] * re[i];
        for (int j = 0; j < N; ++j) {
          const auto uj = cons.indices(cells[c][j]);
          const auto wj = cons.weights(cells[c][j]);
          for (std::size_t b = 0; b < uj.size(); ++b) ref[{ui[a], uj[b]}] += wi[a] * wj[b] * A(i, j);
        }
      }
    }
    const Real tol = simple ? 0.0 : 1e-12;
    for (const auto& [rc, v] : ref) {
      Real& m = M.coeffRef(rc.first, rc.second);  // in the pattern (checked above)
      bad_values += std::abs(m - v) > tol * std::abs(v);
      m = 0;
    }
    for (const auto& [u, v] : rref) {
      bad_residuals += std::abs(r[u] - v) > tol * std::abs(v);
      r[u] = 0;
    }
  }
  CHECK(bad_values == 0);
  CHECK(bad_residuals == 0);
  CHECK(std::all_of(M.valuePtr(), M.valuePtr() + M.nonZeros(), [](Real v) { return v == 0.0; }));
  CHECK(r.isZero(0.0));
  return double(asmb.position_bytes()) / double(asmb.n_positions());
}

// Rigid-body link of velocity DOF (node x, component k) to the body's extra unknowns
// z .. z + n (2D: V1, V2, w; 3D: V1, V2, V3, w1, w2, w3): u = V + w x r.
template <int D>
void link_rigid(DofConstraints& cons, Index f, const Vec<D>& x, int k, Index z, Real offset) {
  if constexpr (D == 2) {
    const Index ex[] = {z, z + 1, z + 2};
    const Real w[] = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 0 ? -x[1] : x[0]};
    cons.link(f, ex, w, offset);
  } else {
    const Index ex[] = {z, z + 1, z + 2, z + 3, z + 4, z + 5};
    Real w[6] = {0, 0, 0, 0, 0, 0};
    w[k] = 1;
    // (w x r)_k: k = 0: w2 r3 - w3 r2; k = 1: w3 r1 - w1 r3; k = 2: w1 r2 - w2 r1
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    w[3 + a] = x[b];
    w[3 + b] = -x[a];
    cons.link(f, ex, w, offset);
  }
}

template <int D, class Pair>
void check_space_pattern(const Mesh<D>& mesh, int linked_tag, int half_fixed_tag, bool linked_region) {
  using Space = MixedSpace<D, Pair>;
  Space space(mesh);
  const auto& vel = space.velocity();
  DofConstraints cons(space.n_field());
  const Index z = cons.add_unknowns(D == 2 ? 3 : 6);
  std::vector<char> done(vel.n_dofs(), 0);
  for (Index i : vel.boundary_dofs(linked_tag)) {
    done[i] = 1;
    for (int k = 0; k < D; ++k) link_rigid<D>(cons, space.velocity_field(i, k), vel.point(i), k, z, 0.01 * k);
  }
  if (linked_region)  // a large body: every velocity DOF left of x = 0.7
    for (Index i = 0; i < vel.n_dofs(); ++i)
      if (!done[i] && vel.point(i)[0] < 0.7) {
        done[i] = 1;
        for (int k = 0; k < D; ++k) link_rigid<D>(cons, space.velocity_field(i, k), vel.point(i), k, z, 0.0);
      }
  for (Index i : vel.boundary_dofs(half_fixed_tag))  // one component fixed: blocks of one
    if (!done[i]) {
      done[i] = 1;
      cons.fix(space.velocity_field(i, 1), 0.5);
    }
  cons.fix(space.pressure_field(0), 0.0);
  cons.finalize();
  std::vector<std::array<Index, Space::n_local>> cells(mesh.n_cells());
  for (Index c = 0; c < mesh.n_cells(); ++c) cells[c] = space.cell_field_dofs(c);
  INFO(D << "D " << Pair::name << ", " << mesh.n_cells() << " cells, " << cons.n_unknowns() << " unknowns");
  const double bytes = check_pattern_and_positions<Space::n_local>(cells, cons);
  // wider positions in 3D (columns longer than 256) and on the cells of a large body
  if (D == 3 || linked_region) CHECK(bytes > 1.0);
}
}  // namespace

TEMPLATE_TEST_CASE("assembler pattern and positions equal a direct construction", "[la][assembly][pattern][quick]",
                   TaylorHood, P1P1Gls) {
  SECTION("2D annulus: inner circle linked to a rigid body, outer circle half fixed") {
    check_space_pattern<2, TestType>(annulus_mesh(0.3, 1.0, 4, 20), tags::inner, tags::outer, false);
  }
  SECTION("3D box: face xmin linked to a rigid body, face ymin half fixed") {
    check_space_pattern<3, TestType>(box_mesh(3, 3, 3), tags::xmin, tags::ymin, false);
  }
  SECTION("2D square with a large body (32-bit positions on its cells)") {
    check_space_pattern<2, TestType>(rectangle_mesh(100, 100), tags::left, tags::bottom, true);
  }
}

TEST_CASE("assembler pattern and positions on random cells: split, reversed and shared node groups",
          "[la][assembly][pattern][quick]") {
  // 15 two-DOF "nodes" (field DOFs 2a, 2a + 1) and 6 single DOFs (30 + s); a cell lists two
  // nodes and two singles in random order, each node's DOFs in random order (reversed or
  // apart: blocks that do not start at their group's first unknown, groups split over blocks),
  // some DOFs fixed, some linked to 1 to 3 of 4 extra unknowns
  std::uint64_t state = 12345;
  auto next = [&](std::uint64_t m) {  // deterministic LCG, uniform enough in [0, m)
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (state >> 33) % m;
  };
  for (int trial = 0; trial < 40; ++trial) {
    constexpr int nn = 15, ns = 6, nfield = 2 * nn + ns;
    std::vector<std::array<Index, 6>> cells;
    std::vector<int> node_order(nn), single_order(ns);
    std::iota(node_order.begin(), node_order.end(), 0);
    std::iota(single_order.begin(), single_order.end(), 0);
    const int ncells = 12 + int(next(20));
    for (int c = 0; c < ncells; ++c) {
      std::array<Index, 6> d{};
      int nodes[2], singles[2];
      if (c < 8) {  // the first cells cover every node and single
        nodes[0] = (2 * c) % nn, nodes[1] = (2 * c + 1) % nn;
        singles[0] = c % ns, singles[1] = (c + 3) % ns;
      } else {
        nodes[0] = int(next(nn));
        do nodes[1] = int(next(nn)); while (nodes[1] == nodes[0]);
        singles[0] = int(next(ns));
        do singles[1] = int(next(ns)); while (singles[1] == singles[0]);
      }
      std::vector<Index> items;
      for (int q = 0; q < 2; ++q) {
        const bool rev = next(3) == 0;
        items.push_back(2 * nodes[q] + (rev ? 1 : 0));
        items.push_back(2 * nodes[q] + (rev ? 0 : 1));
      }
      for (int q = 0; q < 2; ++q) items.push_back(2 * nn + singles[q]);
      if (next(2)) std::swap(items[1], items[2 + int(next(4))]);  // a node's DOFs apart
      if (next(2)) std::rotate(items.begin(), items.begin() + int(next(6)), items.end());
      std::copy(items.begin(), items.end(), d.begin());
      cells.push_back(d);
    }
    DofConstraints cons(nfield);
    const Index z = cons.add_unknowns(4);
    for (Index f = 0; f < nfield; ++f) {
      const auto roll = next(10);
      if (f < 4 || roll < 2) {  // linked (f < 4: every extra unknown is used)
        std::vector<Index> ex;
        std::vector<Real> w;
        const int ne = f < 4 ? 1 : 1 + int(next(3));
        for (int q = 0; q < ne; ++q) {
          const Index e = f < 4 ? Index(f) : Index(next(4));
          if (std::find(ex.begin(), ex.end(), z + e) != ex.end()) continue;
          ex.push_back(z + e);
          w.push_back(0.5 + 0.25 * q + 0.125 * f);
        }
        cons.link(f, ex, w, 0.1);
      } else if (roll < 4) {
        cons.fix(f, 1.0);
      }
    }
    cons.finalize();
    INFO("trial " << trial);
    check_pattern_and_positions<6>(cells, cons);
  }
}

namespace {
template <int N>
struct CheapKernel {  // deterministic, cell-dependent, non-symmetric; no transcendental calls
  void cell(Index c, const Eigen::Matrix<Real, N, 1>& u, Eigen::Matrix<Real, N, N>& A, Eigen::Matrix<Real, N, 1>& r) const {
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < N; ++i) A(i, j) = Real((7 * c + 3 * i + 5 * j * j) % 11) - 5 + 0.125 * i;
    r = A * u;
    for (int i = 0; i < N; ++i) r[i] += Real((c + i) % 5);
  }
};

// A 2D P2/P1 problem: the inner circle of an annulus linked to a rigid body (linked cells),
// or the unit square cut into 2 n^2 triangles with the left side fixed (large enough at
// n = 150 for arrays of 4 MB and more, mapped on their own: the blocks, the row groups)
struct RebuildProblem {
  using Space = MixedSpace<2, TaylorHood>;
  Mesh<2> mesh;
  Space space;
  DofConstraints cons;
  explicit RebuildProblem(Mesh<2> m, bool body) : mesh(std::move(m)), space(mesh), cons(space.n_field()) {
    const auto& vel = space.velocity();
    if (body) {
      const Index z = cons.add_unknowns(3);
      for (Index i : vel.boundary_dofs(tags::inner))
        for (int k = 0; k < 2; ++k) link_rigid<2>(cons, space.velocity_field(i, k), vel.point(i), k, z, 0.01 * k);
      for (Index i : vel.boundary_dofs(tags::outer)) cons.fix(space.velocity_field(i, 0), 0.5);
    } else {
      for (Index i : vel.boundary_dofs(tags::left))
        for (int k = 0; k < 2; ++k) cons.fix(space.velocity_field(i, k), 0.25 * k);
    }
    cons.fix(space.pressure_field(0), 0.0);
    cons.finalize();
  }
  auto dofs() const {
    return [this](Index c) { return space.cell_field_dofs(c); };
  }
};

// `rebuilt` (after rebuild) against a new assembler on the same problem: the same structure,
// pattern, positions, schedule, and bit-identical assembled values on one and two threads.
// J: a matrix that had the previous pattern (given the new one through assemble).
void check_rebuilt(Assembler<RebuildProblem::Space::n_local>& rebuilt, const RebuildProblem& p, SparseMatrix& J) {
  constexpr int N = RebuildProblem::Space::n_local;
  Assembler<N> fresh(p.mesh.n_cells(), p.dofs(), p.cons);
  CHECK(rebuilt.n_cells() == fresh.n_cells());
  CHECK(rebuilt.n_unknowns() == fresh.n_unknowns());
  CHECK(rebuilt.n_nonzeros() == fresh.n_nonzeros());
  CHECK(rebuilt.n_positions() == fresh.n_positions());
  CHECK(rebuilt.position_bytes() == fresh.position_bytes());
  CHECK(rebuilt.n_colours() == fresh.n_colours());
  CHECK(rebuilt.n_linked_cells() == fresh.n_linked_cells());
  const SparseMatrix& M = fresh.matrix();
  const SparseMatrix& R = rebuilt.matrix();  // built anew for the new pattern
  REQUIRE(R.nonZeros() == M.nonZeros());
  CHECK(std::equal(R.outerIndexPtr(), R.outerIndexPtr() + M.outerSize() + 1, M.outerIndexPtr()));
  CHECK(std::equal(R.innerIndexPtr(), R.innerIndexPtr() + M.nonZeros(), M.innerIndexPtr()));
  VecX field(p.space.n_field());
  for (Index f = 0; f < field.size(); ++f) field[f] = std::sin(0.3 * f);
  SparseMatrix Jf;
  VecX rf, r;
  fresh.assemble(CheapKernel<N>{}, field, &Jf, &rf);
  for (int t : {1, 2}) {
    rebuilt.set_threads(t);
    rebuilt.assemble(CheapKernel<N>{}, field, &J, &r);
    REQUIRE(J.nonZeros() == Jf.nonZeros());
    CHECK(std::equal(J.innerIndexPtr(), J.innerIndexPtr() + J.nonZeros(), Jf.innerIndexPtr()));
    CHECK(std::equal(J.valuePtr(), J.valuePtr() + J.nonZeros(), Jf.valuePtr()));
    CHECK(std::equal(r.data(), r.data() + r.size(), rf.data()));
  }
  rebuilt.set_threads(1);
}
}  // namespace

TEST_CASE("Assembler::rebuild gives what a new assembler gives, and keeps its and the matrix's storage",
          "[la][assembly][pattern][quick]") {
  const RebuildProblem annulus(annulus_mesh(0.3, 1.0, 6, 40), true), square(rectangle_mesh(150, 150), false);
  Assembler<RebuildProblem::Space::n_local> asmb(annulus.mesh.n_cells(), annulus.dofs(), annulus.cons);
  SparseMatrix J;
  asmb.take_pattern(J);
  // larger (fresh arrays), smaller (the larger ones reused), larger again (reused)
  asmb.rebuild(square.mesh.n_cells(), square.dofs(), square.cons);
  check_rebuilt(asmb, square, J);
  const Index* inner = J.innerIndexPtr();
  const Real* values = J.valuePtr();
  asmb.rebuild(annulus.mesh.n_cells(), annulus.dofs(), annulus.cons);
  check_rebuilt(asmb, annulus, J);
  asmb.rebuild(square.mesh.n_cells(), square.dofs(), square.cons);
  check_rebuilt(asmb, square, J);
  // the matrix took the smaller pattern and the larger again in its storage
  CHECK(J.innerIndexPtr() == inner);
  CHECK(J.valuePtr() == values);
  // take_pattern into a matrix large enough keeps its storage too
  asmb.take_pattern(J);
  CHECK(J.innerIndexPtr() == inner);
}

TEST_CASE("detail::UninitArray: sizes, kept contents, storage reuse, on the heap and mapped", "[la][quick]") {
  // 1000 ints come from the heap, 3 M (12 MB) are mapped on their own
  for (std::size_t n : {std::size_t(1000), std::size_t(3) << 20}) {
    INFO(n << " ints");
    detail::UninitArray<Index> a;
    CHECK(a.empty());
    Index* p = a.resize_for_overwrite(n);
    REQUIRE(a.size() == n);
    std::iota(p, p + n, 0);
    auto is_iota = [&](std::size_t m) {  // a[i] == i for i < m
      bool ok = true;
      for (std::size_t i = 0; i < m; ++i) ok &= a[i] == Index(i);
      return ok;
    };
    // larger, contents kept (the 1000 go from the heap to a mapping)
    a.resize_keep(4 * n);
    REQUIRE(a.size() == 4 * n);
    CHECK(is_iota(n));
    std::iota(a.begin(), a.end(), 0);
    const Index* q = a.data();
    // smaller, then larger within the capacity: the storage is kept (and the values)
    CHECK(a.resize_for_overwrite(n) == q);
    a.resize_keep(2 * n);
    CHECK(a.data() == q);
    CHECK(is_iota(n));
    // larger than the capacity: new storage, contents kept
    a.resize_keep(8 * n);
    CHECK(is_iota(n));
#if defined(__linux__)
    if (n * sizeof(Index) >= detail::huge_array_bytes)  // mapped on 2 MB boundaries
      CHECK(reinterpret_cast<std::uintptr_t>(a.data()) % detail::huge_page_bytes == 0);
#endif
    a.assign(n, 7);
    CHECK(std::all_of(a.begin(), a.end(), [](Index v) { return v == 7; }));
    detail::UninitArray<Index> b(std::move(a));
    CHECK(a.empty());
    CHECK(b.size() == n);
    CHECK(b[n - 1] == 7);
    a = std::move(b);
    CHECK(a.size() == n);
    a.clear();
    CHECK(a.empty());
  }
}

TEST_CASE("cells in Morton parts: balanced, a cube cut on its mid-plane, and the parts' assemblies sum to the whole",
          "[la][assembly][partition][quick]") {
  // a structured cube in two parts is cut on x = 1/2 (the Morton key's leading bit): the parts
  // share exactly the (n+1)^2 nodes of that plane
  const int n = 4;
  const Mesh<3> cube = box_mesh(n, n, n);
  const std::vector<int> halves = partition_cells(cube, 2);
  std::vector<int> seen(std::size_t(cube.n_nodes()), 0);
  for (Index c = 0; c < cube.n_cells(); ++c)
    for (Index v : cube.cell(c)) seen[std::size_t(v)] |= 1 << halves[std::size_t(c)];
  int shared = 0;
  for (Index v = 0; v < cube.n_nodes(); ++v)
    if (seen[std::size_t(v)] == 3) {
      ++shared;
      CHECK(cube.node(v)[0] == Approx(0.5));
    }
  CHECK(shared == (n + 1) * (n + 1));
  // balance: part sizes differ by at most one cell, and every cell has a part
  for (int parts : {1, 3, 7}) {
    const std::vector<int> part = partition_cells(cube, parts);
    std::vector<Index> size(std::size_t(parts), 0);
    for (int p : part) ++size[std::size_t(p)];
    CHECK(*std::max_element(size.begin(), size.end()) - *std::min_element(size.begin(), size.end()) <= 1);
    CHECK(std::accumulate(size.begin(), size.end(), Index(0)) == cube.n_cells());
  }
  CHECK_THROWS_AS(partition_cells(cube, 0), InvalidArgument);

  // the annulus with a fixed component and a 6-unknown link (the test above): three parts'
  // Jacobians and residuals sum to the whole assembly; unknowns a part does not touch have
  // empty rows and columns there (refused when an assembler covers all cells)
  const auto mesh = annulus_mesh(0.3, 1.0, 4, 20);
  using Space = MixedSpace<2, TaylorHood>;
  Space space(mesh);
  const DofConstraints cons = fixed_and_linked(space);
  VecX field(space.n_field());
  for (Index f = 0; f < field.size(); ++f) field[f] = std::sin(1.3 * f);
  PseudoRandomKernel<Space::n_local> k;
  Assembler<Space::n_local> whole(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); }, cons);
  SparseMatrix J;
  VecX r;
  whole.assemble(k, field, &J, &r);
  const std::vector<int> part = partition_cells(mesh, 3);
  SparseMatrix sum(J.rows(), J.cols());
  VecX rsum = VecX::Zero(r.size());
  Index nnz = 0;
  for (int p = 0; p < 3; ++p) {
    const std::vector<Index> cells = cells_of_part(part, p);
    Assembler<Space::n_local> mine(
        Index(cells.size()), [&](Index i) { return space.cell_field_dofs(cells[std::size_t(i)]); }, cons,
        AssembledCells::part);
    SparseMatrix Jp;
    VecX rp;
    mine.assemble(PartKernel<PseudoRandomKernel<Space::n_local>>{&k, &cells}, field, &Jp, &rp);
    CHECK(Jp.rows() == J.rows());
    CHECK(Jp.nonZeros() < J.nonZeros());
    nnz += Jp.nonZeros();
    sum += Jp, rsum += rp;
  }
  CHECK(nnz > J.nonZeros());  // the parts overlap on their interface
  CHECK((MatX(sum) - MatX(J)).norm() <= 1e-13 * MatX(J).norm());
  CHECK((rsum - r).norm() <= 1e-13 * r.norm());
  const std::vector<Index> first = cells_of_part(part, 0);
  CHECK_THROWS_AS(Assembler<Space::n_local>(
                      Index(first.size()), [&](Index i) { return space.cell_field_dofs(first[std::size_t(i)]); }, cons),
                  SolverError);
}
