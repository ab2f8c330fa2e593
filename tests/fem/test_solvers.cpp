// Linear-solver policies (la/solvers.hpp, la/suitesparse.hpp) and the saddle-point ordering
// (la/ordering.hpp): every direct policy solves a driven-cavity Stokes system (P2/P1 and
// P1/P1-GLS) to a small residual and agrees with SparseLU+COLAMD; analysis is reused across
// factorisations; the ordering's conventions and its zero-diagonal rule hold; SPD policies
// give the same mesh velocity.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/amg.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/gmres.hpp"
#include "alefsi/la/krylov.hpp"
#include "alefsi/la/ordering.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/la/suitesparse.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/mesh/io/gmsh.hpp"
#include "alefsi/physics/mesh_motion.hpp"
#include "alefsi/physics/stokes.hpp"
#include "alefsi/sim/ale_flow.hpp"
#include "../support/stokes_systems.hpp"

using namespace alefsi;
using alefsi::testing::cavity3d;
using alefsi::testing::SaddleSystem;

namespace {

struct LinearSystem {
  SparseMatrix A;
  VecX b;
};

// Driven cavity on the unit square, N x N squares cut in two: every boundary velocity fixed
// (lid (1, 0)), pressure DOF 0 pinned, mu = 1; b = -r at the zero field.
template <class Pair>
LinearSystem stokes_system(int n) {
  const Mesh<2> mesh = rectangle_mesh(n, n);
  MixedSpace<2, Pair> space(mesh);
  StokesKernel<2, Pair> kernel(space, 1.0);
  DofConstraints cons(space.n_field());
  const auto& vel = space.velocity();
  std::vector<char> done(vel.n_dofs(), 0);
  std::vector<int> tags_in_order{tags::top};
  for (int t = 1; t <= 4; ++t)
    if (t != tags::top) tags_in_order.push_back(t);
  for (int t : tags_in_order)
    for (Index i : vel.boundary_dofs(t)) {
      if (done[i]) continue;
      done[i] = 1;
      for (int k = 0; k < 2; ++k) cons.fix(space.velocity_field(i, k), (t == tags::top && k == 0) ? 1.0 : 0.0);
    }
  cons.fix(space.pressure_field(0), 0.0);
  cons.finalize();
  Assembler<MixedSpace<2, Pair>::n_local> asmb(mesh.n_cells(), [&](Index c) { return space.cell_field_dofs(c); },
                                               cons);
  LinearSystem s;
  VecX r;
  asmb.assemble(kernel, cons.expand(VecX::Zero(cons.n_unknowns())), &s.A, &r);
  s.b = -r;
  return s;
}

Real relative_residual(const SparseMatrix& A, const VecX& x, const VecX& b) { return (A * x - b).norm() / b.norm(); }

template <class Solver>
VecX solve_with(const SparseMatrix& A, const VecX& b, Solver solver = Solver{}) {
  solver.analyze(A);
  solver.factorize(A);
  return solver.solve(b);
}

using Colamd = SparseLu<Eigen::COLAMDOrdering<Index>>;

#ifdef ALEFSI_HAVE_SUITESPARSE
using DirectSolvers = std::tuple<SparseLu<>, SparseLu<Eigen::AMDOrdering<Index>>, Colamd, UmfPackLu>;
using ReusableSolvers = std::tuple<SparseLu<>, Colamd, UmfPackLu>;
using SpdSolvers = std::tuple<SimplicialLlt, CholmodLlt>;
#else
using DirectSolvers = std::tuple<SparseLu<>, SparseLu<Eigen::AMDOrdering<Index>>, Colamd>;
using ReusableSolvers = std::tuple<SparseLu<>, Colamd>;
using SpdSolvers = std::tuple<SimplicialLlt>;
#endif

}  // namespace

TEST_CASE("factorisation reuse: GMRES on an earlier matrix's factors solves later matrices to its tolerance, and "
          "refactorises when they drift too far",
          "[la][solvers][reuse][quick]") {
  const LinearSystem s = stokes_system<TaylorHood>(8);
  // later matrices: the velocity block plus a mass-like diagonal term that grows (as 1/dt
  // changes from step to step), the pattern unchanged
  const Index nu = s.A.rows() - 81 + 1;  // the pressure unknowns (81 minus the pinned one) come last
  auto drifted = [&](Real eps) {
    SparseMatrix A = s.A;
    for (Index k = 0; k < nu; ++k) A.coeffRef(k, k) *= 1 + eps;
    return A;
  };
  LinearSolve<SparseLu<>> lin;
  lin.set_reuse({.enabled = true, .max_iterations = 16, .refactor_above = 8, .tolerance = 1e-13});
  LinearSolveCounts counts;
  SparseMatrix A0 = drifted(0);
  lin.factorize(A0);
  ++counts.factorisations;
  CHECK(relative_residual(A0, lin.solve(A0, s.b, counts), s.b) < 1e-13);  // the fresh factors: direct
  CHECK(counts.reused == 0);
  for (Real eps : {0.001, 0.002}) {
    const SparseMatrix A = drifted(eps);
    REQUIRE(lin.reusable());
    const VecX x = lin.solve(A, s.b, counts);
    CHECK(relative_residual(A, x, s.b) < 1e-12);
    CHECK((x - solve_with<SparseLu<>>(A, s.b)).norm() < 1e-10 * x.norm());
  }
  CHECK(counts.factorisations == 1);
  CHECK(counts.reused == 2);
  CHECK(counts.krylov_iterations <= 2 * 8);
  // far from the factorised matrix: GMRES misses in 16 iterations and the matrix is factorised
  const SparseMatrix far = drifted(3.0);
  const VecX x = lin.solve(far, s.b, counts);
  CHECK(relative_residual(far, x, s.b) < 1e-12);
  CHECK(counts.factorisations == 2);
  // an iterative solver never reuses
  LinearSolve<BiCgStabIlut> iterative;
  iterative.set_reuse({.enabled = true});
  CHECK(!iterative.reuse().enabled);
  // a checkpoint's restore gives the same factors: the next reused solve is the same, bit for bit
  LinearSolve<SparseLu<>> again;
  again.set_reuse(lin.reuse());
  SparseMatrix pattern = s.A;
  again.restore(pattern, lin.analysed_values(), lin.factored_values(), lin.refactor_next());
  const SparseMatrix next = drifted(3.02);
  LinearSolveCounts c1, c2;
  CHECK(lin.solve(next, s.b, c1) == again.solve(next, s.b, c2));
  CHECK(c1.krylov_iterations == c2.krylov_iterations);
}

TEST_CASE("a coupling beside the pattern: LinearSolve solves (J + C) x = r on J's factors, fresh or kept, in at most "
          "rank(C) + 1 GMRES iterations when fresh",
          "[la][solvers][reuse][quick]") {
  const LinearSystem s = stokes_system<TaylorHood>(8);
  const Index n = s.A.rows();
  // a dense 6 x 6 block of rank 2 on six velocity unknowns spread over the system
  BlockCoupling C;
  C.index = {3, 4, 40, 41, 90, 91};
  VecX a(6), b(6);
  a << 1, -2, 0.5, 3, -1, 2;
  b << 0.3, 1, -0.7, 0.2, 0.5, -1;
  C.block = 2.0 * a * b.transpose() + 1.5 * b * a.transpose();
  auto with_c = [&](const SparseMatrix& A) {  // J + C assembled, for the reference solve
    SparseMatrix S = A;
    for (Index i = 0; i < 6; ++i)
      for (Index j = 0; j < 6; ++j) S.coeffRef(C.index[std::size_t(i)], C.index[std::size_t(j)]) += C.block(i, j);
    S.makeCompressed();
    return S;
  };
  const VecX reference = solve_with<SparseLu<>>(with_c(s.A), s.b);
  // the operator
  const VecX x0 = VecX::LinSpaced(n, -1, 1);
  CHECK(((CoupledMatrix<SparseMatrix>{s.A, C} * x0) - with_c(s.A) * x0).norm() <= 1e-14 * (s.A * x0).norm());
  for (bool reuse : {false, true}) {
    LinearSolve<SparseLu<>> lin;
    lin.set_reuse({.enabled = reuse});
    lin.set_coupling(&C);
    LinearSolveCounts counts;
    lin.factorize(s.A);
    ++counts.factorisations;
    const VecX x = lin.solve(s.A, s.b, counts);
    INFO("reuse " << reuse << ": GMRES iterations " << counts.krylov_iterations);
    CHECK(relative_residual(with_c(s.A), x, s.b) < 1e-12);
    CHECK((x - reference).norm() <= 1e-10 * reference.norm());
    CHECK(counts.krylov_iterations <= 2 + 1);  // rank(C) + 1
    CHECK(counts.factorisations == 1);
    if (reuse) {  // a later matrix on the kept factors
      SparseMatrix A = s.A;
      for (Index k = 0; k < 20; ++k) A.coeffRef(k, k) *= 1.001;
      REQUIRE(lin.reusable());
      const VecX y = lin.solve(A, s.b, counts);
      CHECK(relative_residual(with_c(A), y, s.b) < 1e-12);
      CHECK(counts.reused == 1);
      CHECK(counts.factorisations == 1);
    }
    // without the coupling, J alone
    lin.set_coupling(nullptr);
    lin.factorize(s.A);
    CHECK(relative_residual(s.A, lin.solve(s.A, s.b, counts), s.b) < 1e-13);
  }
}

TEST_CASE("Eigen's AMDOrdering convention; the SparseLU orderings are the right way round", "[la][solvers][quick]") {
  // arrowhead: unknown 0 is coupled to every other one, so AMD eliminates it last
  const Index n = 6;
  std::vector<Eigen::Triplet<Real, Index>> t;
  for (Index i = 0; i < n; ++i) t.emplace_back(i, i, 4.0);
  for (Index i = 1; i < n; ++i) t.emplace_back(0, i, 1.0), t.emplace_back(i, 0, 1.0);
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, Index> p;
  Eigen::AMDOrdering<Index>{}(A, p);
  CHECK(p.indices()[n - 1] == 0);  // AMDOrdering: position -> old index
  SymmetricAmdOrdering<Index>{}(A, p);
  CHECK(p.indices()[0] == n - 1);  // SparseLU's convention: old index -> position
  SaddlePointAmdOrdering<Index>{}(A, p);
  CHECK(p.indices()[0] == n - 1);
}

TEST_CASE("saddle-point ordering: each zero-diagonal unknown follows a neighbour with a nonzero diagonal",
          "[la][solvers][quick]") {
  const auto s = stokes_system<TaylorHood>(8);
  const auto order = SaddlePointAmdOrdering<Index>::order(s.A);
  const Index n = s.A.cols();
  REQUIRE(Index(order.size()) == n);
  std::vector<Index> position(n, -1);
  for (Index k = 0; k < n; ++k) position[order[k]] = k;
  REQUIRE(std::count(position.begin(), position.end(), -1) == 0);  // a permutation
  const SparseMatrix At = s.A.transpose();
  const VecX diag = s.A.diagonal();
  Index n_weak = 0;
  for (Index j = 0; j < n; ++j) {
    if (diag[j] != 0) continue;
    ++n_weak;
    bool preceded = false;
    for (const SparseMatrix* M : {&s.A, &At})
      for (SparseMatrix::InnerIterator it(*M, j); it; ++it)
        preceded |= it.row() != j && it.value() != 0 && diag[it.row()] != 0 && position[it.row()] < position[j];
    CHECK(preceded);
  }
  CHECK(n_weak == 80);  // the P1 pressures (81 vertices) less the pinned one
}

TEMPLATE_LIST_TEST_CASE("direct solver policies solve Stokes systems and agree with SparseLU+COLAMD",
                        "[la][solvers][quick]", DirectSolvers) {
  static_assert(LinearSolver<TestType>);
  for (int pair = 0; pair < 2; ++pair) {
    CAPTURE(pair);
    const auto s = pair == 0 ? stokes_system<TaylorHood>(12) : stokes_system<P1P1Gls>(12);
    const VecX reference = solve_with<Colamd>(s.A, s.b);
    const VecX x = solve_with<TestType>(s.A, s.b);
    CHECK(relative_residual(s.A, x, s.b) < 1e-12);
    CHECK((x - reference).norm() <= 1e-10 * reference.norm());
  }
}

#ifdef ALEFSI_HAVE_SUITESPARSE
TEST_CASE("UMFPACK strategies agree; a singular matrix throws", "[la][solvers][suitesparse][quick]") {
  const auto s = stokes_system<TaylorHood>(10);
  const VecX reference = solve_with<Colamd>(s.A, s.b);
  for (auto st : {UmfPackLu::Strategy::automatic, UmfPackLu::Strategy::symmetric, UmfPackLu::Strategy::unsymmetric}) {
    const VecX x = solve_with<UmfPackLu>(s.A, s.b, UmfPackLu(st));
    CHECK(relative_residual(s.A, x, s.b) < 1e-12);
    CHECK((x - reference).norm() <= 1e-10 * reference.norm());
  }
  UmfPackLu lu;
  lu.analyze(s.A);
  lu.factorize(s.A);
  CHECK(lu.factor_nonzeros() > s.A.nonZeros());
  SparseMatrix singular = s.A;
  singular.coeffRef(3, 3) = 0;
  for (SparseMatrix::InnerIterator it(singular, 3); it; ++it) it.valueRef() = 0;  // a zero column
  UmfPackLu lu2;
  lu2.analyze(singular);
  CHECK_THROWS_AS(lu2.factorize(singular), SolverError);
}

TEST_CASE("UMFPACK keeps its own copy of the factorised matrix; another pattern is analysed again; move-only",
          "[la][solvers][suitesparse][quick]") {
  const auto s10 = stokes_system<TaylorHood>(10), s12 = stokes_system<TaylorHood>(12);
  UmfPackLu lu;
  {
    SparseMatrix A = s10.A;  // factorised, then changed and destroyed before the solve
    lu.factorize(A);
    A *= 2;
  }
  const VecX x = lu.solve(s10.b);  // iterative refinement multiplies by the copy, not the dead matrix
  CHECK(relative_residual(s10.A, x, s10.b) < 1e-12);
  lu.factorize(s12.A);  // a larger system, no analyze: analysed again
  CHECK(relative_residual(s12.A, lu.solve(s12.b), s12.b) < 1e-12);
  UmfPackLu moved = std::move(lu);
  CHECK(relative_residual(s12.A, moved.solve(s12.b), s12.b) < 1e-12);
  CHECK_THROWS_AS(moved.solve(s10.b), SolverError);  // wrong size: named, not read out of bounds
  CHECK_THROWS_AS(UmfPackLu().solve(s10.b), SolverError);  // before any factorisation
  CHECK_THROWS_WITH(UmfPackLu().factorize(SparseMatrix(3, 4)), Catch::Contains("not square"));
  // a later matrix of the same pattern (velocity diagonal +0.1 %): the factors of s12.A alone
  // leave a residual of the size of the change; refined against the later matrix, UMFPACK's
  // iterative refinement (at most 2 steps, each contracting by about the change) takes it down
  SparseMatrix later = s12.A;
  for (Index j = 0; j < later.cols(); ++j)
    for (SparseMatrix::InnerIterator it(later, j); it; ++it)
      if (it.row() == j) it.valueRef() *= 1.001;
  const Real plain = relative_residual(later, moved.solve(s12.b), s12.b);
  const Real refined = relative_residual(later, moved.solve_refined_against(later, s12.b), s12.b);
  INFO("residual against the later matrix: factors alone " << plain << ", refined against it " << refined);
  CHECK(plain > 1e-4);
  CHECK(refined < 1e-2 * plain);
  CHECK_THROWS_AS(moved.solve_refined_against(s10.A, s12.b), SolverError);  // another pattern
}
#endif

TEMPLATE_LIST_TEST_CASE("one analysis serves several factorisations of the same pattern", "[la][solvers][quick]",
                        ReusableSolvers) {
  const auto s = stokes_system<TaylorHood>(10);
  TestType solver;
  solver.analyze(s.A);
  for (int step = 0; step < 3; ++step) {
    // another matrix of the same pattern: a velocity "mass" shift and a rescaled pressure
    SparseMatrix A = s.A;
    const VecX diag = s.A.diagonal();
    for (Index j = 0; j < A.cols(); ++j)
      for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
        if (it.row() == j && diag[j] != 0) it.valueRef() += 10.0 * step;
        if (diag[j] == 0 || diag[it.row()] == 0) it.valueRef() *= 1.0 + step;
      }
    solver.factorize(A);
    const VecX x = solver.solve(s.b);
    CHECK(relative_residual(A, x, s.b) < 1e-12);
  }
}

TEST_CASE("saddle-point AMD fills less than COLAMD on P2/P1 Stokes", "[la][solvers][quick]") {
  const auto s = stokes_system<TaylorHood>(24);
  SparseLu<> saddle;
  Colamd colamd;
  saddle.analyze(s.A);
  saddle.factorize(s.A);
  colamd.analyze(s.A);
  colamd.factorize(s.A);
  CHECK(2 * saddle.factor_nonzeros() < colamd.factor_nonzeros());
  CHECK_THROWS_AS(SparseLu<>(2.0), InvalidArgument);
}

TEMPLATE_LIST_TEST_CASE("SPD policies: same mesh velocity; an indefinite matrix throws", "[la][solvers][quick]",
                        SpdSolvers) {
  const Mesh<2> mesh = rectangle_mesh(12, 12);
  // move the node positions a little so that mu = 1/|K| varies, and rotate the walls
  std::vector<Vec<2>> x = mesh.coordinates();
  for (auto& p : x) p += 0.02 * Vec<2>(std::sin(3 * p[1]), std::cos(2 * p[0])).cwiseProduct(p.cwiseProduct(Vec<2>::Ones() - p));
  auto g = [](Index, const Vec<2>& p) { return Vec<2>(-(p[1] - 0.5), p[0] - 0.5); };
  ElasticMeshMotion<2, SimplicialLlt> reference(mesh);
  ElasticMeshMotion<2, TestType> motion(mesh);
  const auto v0 = reference.solve(x, g);
  for (int rep = 0; rep < 2; ++rep) {  // the second solve reuses the analysis
    const auto v = motion.solve(x, g);
    Real diff = 0, norm = 0;
    for (std::size_t i = 0; i < v.size(); ++i) diff = std::max(diff, (v[i] - v0[i]).norm()), norm = std::max(norm, v0[i].norm());
    CHECK(diff <= 1e-12 * norm);
  }
  // an indefinite symmetric matrix
  SparseMatrix A(3, 3);
  std::vector<Eigen::Triplet<Real, Index>> t{{0, 0, 1.0}, {1, 1, -1.0}, {2, 2, 1.0}, {0, 1, 0.5}, {1, 0, 0.5}};
  A.setFromTriplets(t.begin(), t.end());
  TestType solver;
  solver.analyze(A);
  CHECK_THROWS_AS(solver.factorize(A), SolverError);
}

TEST_CASE("mesh velocity with factorisation reuse: the same velocities as a factorisation per solve",
          "[la][solvers][reuse][quick]") {
  // a sequence of geometries moving a little per solve, as the extrapolated positions of steps
  const Mesh<2> mesh = rectangle_mesh(16, 16);
  auto geometry = [&](Real s) {
    std::vector<Vec<2>> x = mesh.coordinates();
    for (auto& p : x)
      p += (0.02 + 0.01 * s) * Vec<2>(std::sin(3 * p[1] + s), std::cos(2 * p[0])).cwiseProduct(p.cwiseProduct(Vec<2>::Ones() - p));
    return x;
  };
  auto g = [](Index, const Vec<2>& p) { return Vec<2>(-(p[1] - 0.5), p[0] - 0.5); };
  ElasticMeshMotion<2> fresh(mesh), reused(mesh);
  reused.set_reuse({.enabled = true});
  Real worst = 0;
  for (int k = 0; k < 12; ++k) {
    const auto x = geometry(0.01 * k);
    const auto a = fresh.solve(x, g), b = reused.solve(x, g);
    Real diff = 0, norm = 0;
    for (std::size_t i = 0; i < a.size(); ++i) diff = std::max(diff, (a[i] - b[i]).norm()), norm = std::max(norm, a[i].norm());
    worst = std::max(worst, diff / norm);
  }
  CHECK(worst <= 1e-11);  // GMRES stops at a relative residual of 1e-13
  CHECK(fresh.counts().factorisations == 12);
  CHECK(reused.counts().reused >= 9);  // the first solve factorises; the geometry moves little
  CHECK(reused.counts().factorisations + reused.counts().reused == 12);
}

// ---- the iterative path for 3D (la/amg.hpp, la/krylov.hpp) ----------------------------------

namespace {

template <class Pair>
int krylov_iterations(const SaddleSystem& s, KrylovOptions opt, bool blocks) {
  SaddlePointGmres<3> k(opt);
  if (blocks) k.set_blocks(s.blocks);
  k.analyze(s.A);
  k.factorize(s.A);
  const VecX x = k.solve(s.b);
  CHECK(relative_residual(s.A, x, s.b) <= opt.tolerance);
  return k.iterations();
}

}  // namespace

TEST_CASE("AMG V-cycle: CG iterations on the 3D Laplacian stay bounded under refinement", "[la][krylov][quick]") {
  // scalar P1 Laplacian on box_mesh(n, n, n), Dirichlet boundary (the velocity block of
  // P1/P1-GLS per component): a multigrid preconditioner makes the count mesh-independent
  std::vector<int> its;
  for (int n : {12, 20, 28}) {
    const Mesh<3> mesh = box_mesh(n, n, n);
    std::vector<char> boundary(mesh.n_nodes(), 0);
    for (int t = 1; t <= 6; ++t)
      for (Index v : mesh.boundary_nodes(t)) boundary[v] = 1;
    std::vector<Index> id(mesh.n_nodes(), -1);
    Index nu = 0;
    for (Index v = 0; v < mesh.n_nodes(); ++v)
      if (!boundary[v]) id[v] = nu++;
    std::vector<Eigen::Triplet<Real, Index>> t;
    for (Index c = 0; c < mesh.n_cells(); ++c) {
      const Mat<3> Jinv = mesh.jacobian(c).inverse();
      Eigen::Matrix<Real, 4, 3> G;
      G << -1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1;
      G = G * Jinv;
      const Real vol = mesh.measure(c);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          const Index i = id[mesh.cell(c)[a]], j = id[mesh.cell(c)[b]];
          if (i >= 0 && j >= 0) t.emplace_back(i, j, vol * G.row(a).dot(G.row(b)));
        }
    }
    RowSparseMatrix A(nu, nu);
    A.setFromTriplets(t.begin(), t.end());
    SmoothedAggregationAmg amg;
    amg.compute(A);
    CHECK(amg.n_levels() >= 2);
    CHECK(amg.operator_complexity() < 2.0);
    // preconditioned CG to 1e-8
    const VecX b = VecX::Ones(nu);
    VecX x = VecX::Zero(nu), r = b, z = amg.apply(r), p = z;
    Real rz = r.dot(z);
    int k = 0;
    for (; k < 200 && r.norm() > 1e-8 * b.norm(); ++k) {
      const VecX q = A * p;
      const Real alpha = rz / p.dot(q);
      x += alpha * p;
      r -= alpha * q;
      z = amg.apply(r);
      const Real rz1 = r.dot(z);
      p = z + (rz1 / rz) * p;
      rz = rz1;
    }
    its.push_back(k);
  }
  std::cout << "AMG-CG iterations, 3D P1 Laplacian, n = 12, 20, 28: " << its[0] << " " << its[1] << " " << its[2] << "\n";
  // measured 9, 9, 10 iterations (1,331 to 19,683 unknowns)
  CHECK(its[2] <= 15);
  CHECK(its[2] <= its[0] + 3);
}

TEST_CASE("SaddlePointGmres solves 3D Stokes (P2/P1, P1/P1-GLS) and agrees with the direct solve",
          "[la][solvers][krylov][quick]") {
  static_assert(LinearSolver<SaddlePointGmres<3>>);
  KrylovOptions opt;
  opt.tolerance = 1e-11;
  for (int pair = 0; pair < 2; ++pair) {
    const auto s = pair == 0 ? cavity3d<TaylorHood>(6) : cavity3d<P1P1Gls>(8);
    const VecX reference = solve_with<SparseLu<>>(s.A, s.b);
    for (bool blocks : {false, true}) {
      CAPTURE(pair, blocks);
      SaddlePointGmres<3> k(opt);
      if (blocks) k.set_blocks(s.blocks);
      k.analyze(s.A);
      k.factorize(s.A);
      CHECK(k.n_pressure() == s.blocks.n_pressure);  // the diagonal's sign finds the pressures
      CHECK(k.n_extra() == 0);
      CHECK(k.pressure_mass() == blocks);
      for (int rep = 0; rep < 2; ++rep) {  // a second factorisation with the same analysis
        if (rep == 1) k.factorize(s.A);
        const VecX x = k.solve(s.b);
        CHECK(relative_residual(s.A, x, s.b) <= opt.tolerance);
        CHECK(k.residual() <= opt.tolerance);
        // ||x - x*|| <= ||K^-1|| ||r||: the pinned-pressure system has ||K^-1|| ||K|| ~ 1e4 here
        CHECK((x - reference).norm() <= 1e-6 * reference.norm());
      }
    }
  }
  // bad input
  CHECK_THROWS_AS(SaddlePointGmres<3>(KrylovOptions{.tolerance = 0}), InvalidArgument);
  SaddlePointGmres<3> one_pressure;
  one_pressure.set_pressure_null_space(true);
  SparseMatrix tiny(2, 2);  // [1 1; 1 0]: one velocity, one pressure
  tiny.insert(0, 0) = 1, tiny.insert(0, 1) = 1, tiny.insert(1, 0) = 1;
  CHECK_THROWS_WITH(one_pressure.analyze(tiny), Catch::Contains("too few for a pressure null space"));
  CHECK_THROWS_WITH(SaddlePointGmres<3>(KrylovOptions{.augment = -1}), Catch::Contains("augment"));
  SaddlePointGmres<3> k;
  SparseMatrix spd(2, 2);
  spd.insert(0, 0) = 1, spd.insert(1, 1) = 2;
  CHECK_THROWS_AS(k.analyze(spd), SolverError);  // no saddle point: nothing to call pressure
}

TEST_CASE("SaddlePointGmres takes a closed domain's system unpinned: the constant pressure is its null space",
          "[la][solvers][krylov][quick]") {
  // The cavity (every boundary velocity given) assembled with and without the pin of pressure
  // DOF 0. Unpinned, K [0; 1] = 0 exactly (Bt 1 = 0, the GLS terms act on grad q); the solver
  // returns the pinned system's solution up to the constant, with zero pressure sum, in fewer
  // iterations (the pin's near-null vector, the constant on the free pressures, is gone).
  KrylovOptions opt;
  opt.tolerance = 1e-10;
  for (int pair = 0; pair < 2; ++pair) {
    const auto pinned = pair == 0 ? cavity3d<TaylorHood>(6) : cavity3d<P1P1Gls>(8);
    const auto open = pair == 0 ? cavity3d<TaylorHood>(6, 0, 1, 0, false) : cavity3d<P1P1Gls>(8, 0, 1, 0, false);
    const Index n = pinned.A.rows(), np = open.blocks.n_pressure, nu = open.A.rows() - np;
    REQUIRE(open.A.rows() == n + 1);
    REQUIRE(np == pinned.blocks.n_pressure + 1);
    VecX e = VecX::Zero(n + 1);
    e.segment(nu, np).setOnes();
    CHECK((open.A * e).norm() <= 1e-12 * open.A.norm());
    CHECK((open.A.transpose() * e).norm() <= 1e-12 * open.A.norm());
    const VecX reference = solve_with<SparseLu<>>(pinned.A, pinned.b);
    for (bool blocks : {false, true}) {
      CAPTURE(pair, blocks);
      SaddlePointGmres<3> with_pin(opt), with_null(opt);
      with_null.set_pressure_null_space(true);
      if (blocks) with_pin.set_blocks(pinned.blocks), with_null.set_blocks(open.blocks);
      with_pin.analyze(pinned.A), with_pin.factorize(pinned.A);
      with_null.analyze(open.A), with_null.factorize(open.A);
      with_pin.solve(pinned.b);
      const VecX x = with_null.solve(open.b);
      CHECK(relative_residual(open.A, x, open.b) <= opt.tolerance);
      CHECK(with_null.pressure_defect() <= 1e-14);  // the cavity's data conserve mass
      CHECK(std::abs(x.segment(nu, np).sum()) <= 1e-12 * x.segment(nu, np).norm());
      // velocities alike; pressures alike up to a constant (on DOFs 1.., the pinned unknowns)
      CHECK((x.head(nu) - reference.head(nu)).norm() <= 1e-8 * reference.head(nu).norm());
      VecX p = x.tail(n - nu), p_ref = reference.tail(n - nu);
      p.array() -= p.mean(), p_ref.array() -= p_ref.mean();
      CHECK((p - p_ref).norm() <= 1e-7 * p_ref.norm());  // tolerance x cond(K on range(K)), ~1e2 here
      INFO("iterations: pinned " << with_pin.iterations() << ", null space " << with_null.iterations());
      CHECK(with_null.iterations() < with_pin.iterations());
      // a b along e (data that do not conserve mass): taken off and reported, x unchanged
      const Real c = 1e-3 * open.b.norm() / std::sqrt(Real(np));
      const VecX x_defect = with_null.solve(open.b + c * e);
      CHECK(with_null.pressure_defect() == Approx(c * std::sqrt(Real(np)) / (open.b + c * e).norm()).epsilon(1e-6));
      CHECK((x_defect - x).norm() <= 1e-8 * x.norm());
    }
  }
  // Stokes::solve hands it the system unpinned too: the same field as the pinned direct solve
  const Mesh<3> mesh = box_mesh(4, 4, 4);
  Stokes<3, TaylorHood> stokes(mesh, 1.0, [](const Vec<3>& x) { return Vec<3>(0, x[2], x[0] * x[1]); });
  for (Index f : mesh.boundary_facets())
    stokes.set_velocity(mesh.facet_tag(f), [](const Vec<3>& x) { return Vec<3>(x[1], x[2], 0); });
  const VecX direct = stokes.solve();
  const VecX krylov = stokes.solve(SaddlePointGmres<3>({.tolerance = 1e-11}));
  CHECK(stokes.pressure_pinned());
  CHECK((krylov - direct).norm() <= 1e-8 * direct.norm());
}

TEST_CASE("SaddlePointGmres keeps its set-up for later matrices of the same pattern (LinearSolve)",
          "[la][solvers][krylov][reuse][quick]") {
  static_assert(ReusableSetUp<SaddlePointGmres<3>>);
  static_assert(!ReusableSetUp<BiCgStabIlut> && !ReusableSetUp<SparseLu<>>);
  const auto s = cavity3d<TaylorHood>(4);
  const Index nu = s.A.rows() - s.blocks.n_pressure;  // velocities first, then the pressures
  auto drifted = [&](Real eps) {  // a mass-like term that changes, the pattern unchanged
    SparseMatrix A = s.A;
    for (Index k = 0; k < nu; ++k) A.coeffRef(k, k) *= 1 + eps;
    return A;
  };
  KrylovOptions opt;
  opt.tolerance = 1e-10;
  LinearSolve<SaddlePointGmres<3>> lin(opt);
  lin.solver().set_blocks(s.blocks);
  lin.set_reuse({.enabled = true});
  REQUIRE(lin.reuse().enabled);
  LinearSolveCounts counts;
  const SparseMatrix A0 = drifted(0);
  lin.factorize(A0);
  CHECK(relative_residual(A0, lin.solve(A0, s.b, counts), s.b) <= opt.tolerance);
  CHECK(counts.iterative_solves == 1);
  const int fresh = counts.iterative_iterations;
  for (Real eps : {0.01, 0.02}) {
    const SparseMatrix A = drifted(eps);
    REQUIRE(lin.reusable());
    const VecX x = lin.solve(A, s.b, counts);  // the products with A, the preconditioner of A0
    CHECK(relative_residual(A, x, s.b) <= opt.tolerance);
    const VecX reference = solve_with<SparseLu<>>(A, s.b);
    CHECK((x - reference).norm() <= 1e-7 * reference.norm());
  }
  std::cout << "SaddlePointGmres, one set-up for three matrices: " << fresh << " iterations, then "
            << counts.iterative_iterations - fresh << " for the two others\n";
  CHECK(counts.factorisations == 0);  // (the first one was called directly)
  CHECK(counts.reused == 2);
  CHECK(counts.iterative_solves == 3);
  CHECK(lin.factored_values().size() == 0);  // nothing for a checkpoint: the flow drops it per step
  lin.drop();
  CHECK(!lin.reusable());
  // another pattern is refused by name
  const SparseMatrix small = s.A.topLeftCorner(nu, nu);
  CHECK_THROWS_WITH(lin.solver().solve(small, VecX::Ones(nu)), Catch::Contains("pattern"));
}

TEST_CASE("SaddlePointGmres with a coupling among the extra unknowns: the solve is with A + C, the body "
          "elimination includes C",
          "[la][solvers][krylov][quick]") {
  // the 3D cavity with two extra unknowns appended (as two bodies' would be), each linked to a
  // velocity unknown; C couples the two extras, as a contact couples two bodies' rows
  const auto s = cavity3d<TaylorHood>(3);
  const Index n0 = s.A.rows(), n = n0 + 2;
  std::vector<Eigen::Triplet<Real>> t;
  for (Index c = 0; c < s.A.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(s.A, c); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
  using Link = std::tuple<Index, Index, Real>;  // extra unknown, its velocity unknown, its diagonal
  for (const auto& [e, u, diag] : {Link{n0, 0, 2.0}, Link{n0 + 1, 7, 3.0}}) {
    t.emplace_back(e, e, diag);
    t.emplace_back(e, u, 0.1), t.emplace_back(u, e, 0.1);
  }
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  VecX b(n);
  b << s.b, 1.0, -2.0;
  SaddlePointBlocks blocks = s.blocks;
  blocks.n_extra = 2;
  BlockCoupling C;
  C.index = {n0, n0 + 1};
  C.block = MatX{{0.0, 0.7}, {-0.4, 0.0}};
  SparseMatrix AC = A;
  AC.coeffRef(n0, n0 + 1) += 0.7, AC.coeffRef(n0 + 1, n0) -= 0.4;
  const VecX reference = solve_with<SparseLu<>>(AC, b);
  KrylovOptions opt;
  opt.tolerance = 1e-10;
  auto run = [&](const BlockCoupling* c, const SparseMatrix& M, int& its) {
    LinearSolve<SaddlePointGmres<3>> lin(opt);
    lin.solver().set_blocks(blocks);
    lin.set_coupling(c);
    lin.factorize(A);
    LinearSolveCounts counts;
    const VecX x = lin.solve(A, b, counts);
    its = counts.iterative_iterations;
    CHECK(relative_residual(M, x, b) <= opt.tolerance);
    return x;
  };
  int coupled = 0, plain = 0;
  const VecX x = run(&C, AC, coupled);
  CHECK((x - reference).norm() <= 1e-7 * reference.norm());
  CHECK(std::abs(x[n0 + 1] - reference[n0 + 1]) <= 1e-7 * std::abs(reference[n0 + 1]));
  run(nullptr, A, plain);
  INFO("GMRES iterations with C " << coupled << ", without " << plain);
  CHECK(coupled <= plain + 2);  // C is eliminated exactly with the extras: no more iterations
  // a coupling on a velocity unknown is refused by name
  BlockCoupling bad;
  bad.index = {0, n0};
  bad.block = MatX::Identity(2, 2);
  LinearSolve<SaddlePointGmres<3>> lin(opt);
  lin.solver().set_blocks(blocks);
  lin.set_coupling(&bad);
  CHECK_THROWS_WITH(lin.factorize(A), Catch::Contains("coupling"));
}

TEST_CASE("SaddlePointGmres: iteration counts under refinement (Schur approximations are mesh-independent)",
          "[la][solvers][krylov][quick]") {
  // Taylor–Hood with exact velocity solves (the AMG's coarsest level holds the whole block):
  // the count then measures S~^-1 S alone, which theory bounds independently of h
  // (inf-sup): measured 28, 30, 30 (lumped) and 35, 37, 37 (pressure mass) for n = 4, 5, 6.
  KrylovOptions exact;
  exact.amg.coarse_size = 5000;
  exact.restart = 200;
  for (bool blocks : {false, true}) {
    std::vector<int> its;
    for (int n : {4, 5, 6}) its.push_back(krylov_iterations<TaylorHood>(cavity3d<TaylorHood>(n), exact, blocks));
    std::cout << "GMRES iterations, P2/P1, exact velocity solves, " << (blocks ? "pressure mass" : "lumped Schur")
              << ", n = 4, 5, 6: " << its[0] << " " << its[1] << " " << its[2] << "\n";
    CHECK(its[2] <= its[0] + 4);
    CHECK(its[2] <= 45);
  }
  // P1/P1-GLS with the AMG V-cycle (the practical path): measured 17, 23, 29 (n = 8, 16, 24)
  // with the pressure mass, 15, 23, 30 lumped. The growth comes from the V-cycle, not the
  // Schur approximation; no theorem fixes it, so this is a regression bound, not a rate.
  KrylovOptions amg;
  amg.restart = 200;
  for (bool blocks : {false, true}) {
    std::vector<int> its;
    for (int n : {8, 16, 24}) its.push_back(krylov_iterations<P1P1Gls>(cavity3d<P1P1Gls>(n), amg, blocks));
    std::cout << "GMRES iterations, P1/P1-GLS, AMG, " << (blocks ? "pressure mass" : "lumped Schur")
              << ", n = 8, 16, 24: " << its[0] << " " << its[1] << " " << its[2] << "\n";
    CHECK(its[2] <= 40);
  }
}

TEST_CASE("AleFlow with SaddlePointGmres: a 3D Navier–Stokes step with a free sphere matches the direct solve",
          "[la][solvers][krylov][bodies3d][quick]") {
  // a free, neutrally buoyant sphere in simple shear (tests/physics/test_bodies3d.cpp), Navier–
  // Stokes (convection on), two BDF2 steps: body velocities are 6 extra unknowns eliminated
  // around the V-cycle; the pressures are found from the Jacobian's diagonal
  const Real a = 0.2, gamma = 1.0;
  auto run = [&](auto& flow) {
    flow.set_velocity(1, [&](const Vec<3>& x, Real) { return Vec<3>(gamma * x[1], 0.0, 0.0); });
    flow.add_body(sphere_body(5, Vec<3>::Zero(), a, 1.0));
    flow.set_initial_velocity([&](const Vec<3>& x) { return Vec<3>(gamma * x[1], 0.0, 0.0); });
    StepReport rep;
    for (int n = 0; n < 2; ++n) rep = flow.step(0.05);
    return rep;
  };
  const Mesh<3> mesh = read_gmsh<3>(std::string(ALEFSI_TEST_DATA_DIR) + "/gmsh/sphere_in_box3d.msh").mesh;
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E>> direct(mesh, FlowOptions{1.0, 1.0});
  AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E, NavierStokes, SaddlePointGmres<3>>> krylov(mesh, FlowOptions{1.0, 1.0});
  run(direct);
  const StepReport rep = run(krylov);
  CHECK(rep.newton_iterations <= 4);  // GMRES to 1e-8 per Newton update, Newton to 1e-10
  // the preconditioner is set up at the step's first Newton iteration and serves the others
  CHECK(rep.newton_iterations >= 2);
  CHECK(rep.linear.factorisations == 1);
  CHECK(rep.linear.reused == rep.newton_iterations - 1);
  CHECK(rep.linear.iterative_solves == rep.newton_iterations);
  CHECK(rep.linear.iterative_iterations >= rep.linear.iterative_solves);
  const VecX& u0 = direct.field();
  const VecX& u1 = krylov.field();
  CHECK((u1 - u0).norm() <= 1e-7 * u0.norm());
  CHECK((krylov.body_velocity(0) - direct.body_velocity(0)).norm() <= 1e-7 * direct.body_velocity(0).norm());
}

namespace {
// 1D convection–diffusion, -u'' + c u' on n interior nodes of (0, 1) (upwind differences): a
// nonsymmetric matrix on which Jacobi-preconditioned GMRES(10) needs many cycles
SparseMatrix convection_diffusion_1d(Index n, Real c) {
  const Real h = 1.0 / Real(n + 1);
  std::vector<Eigen::Triplet<Real>> t;
  for (Index i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2 / (h * h) + c / h);
    if (i > 0) t.emplace_back(i, i - 1, -1 / (h * h) - c / h);
    if (i + 1 < n) t.emplace_back(i, i + 1, -1 / (h * h));
  }
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}
}  // namespace

TEST_CASE("gmres with augment (LGMRES): the corrections keep what a short restart loses; the answer is the "
          "direct one",
          "[la][krylov][quick]") {
  const Index n = 400;
  const SparseMatrix A = convection_diffusion_1d(n, 20);
  const VecX b = VecX::Ones(n), inv_diag = A.diagonal().cwiseInverse();
  auto jacobi = [&](const VecX& v) { return VecX(inv_diag.cwiseProduct(v)); };
  Eigen::SparseLU<SparseMatrix> lu(A);
  const VecX x_direct = lu.solve(b);
  auto solve = [&](int augment) {
    VecX x;
    GmresWork work;
    const GmresResult res =
        gmres(A, b, jacobi, {.tolerance = 1e-10, .max_iterations = 5000, .restart = 10, .augment = augment}, x, work);
    CHECK(res.converged);
    CHECK((b - A * x).norm() <= 1e-10 * b.norm());
    CHECK(res.residual <= 1e-10);
    CHECK((x - x_direct).norm() <= 1e-6 * x_direct.norm());
    return res.iterations;
  };
  const int plain = solve(0), one = solve(1), two = solve(2);
  INFO("GMRES(10) " << plain << ", LGMRES(10,1) " << one << ", LGMRES(10,2) " << two << " iterations");
  CHECK(two < plain);
  CHECK(one < plain);
  // a system solved within the first cycle: the corrections never enter, the iterate is GMRES's
  VecX x0, x1;
  GmresWork w0, w1;
  const GmresResult r0 = gmres(A, b, jacobi, {.tolerance = 1e-6, .restart = 1000}, x0, w0);
  const GmresResult r1 = gmres(A, b, jacobi, {.tolerance = 1e-6, .restart = 1000, .augment = 2}, x1, w1);
  CHECK(r0.iterations == r1.iterations);
  CHECK(x0 == x1);
}

TEST_CASE("gmres with flexible (FGMRES): the iterate of plain GMRES for a fixed preconditioner, one application "
          "fewer per cycle; with single-precision factors as the preconditioner it keeps double-precision "
          "convergence where plain GMRES loses it",
          "[la][krylov][quick]") {
  const Index n = 400;
  const SparseMatrix A = convection_diffusion_1d(n, 20);
  const VecX b = VecX::LinSpaced(n, 1, 2), inv_diag = A.diagonal().cwiseInverse();
  int applications = 0;
  auto jacobi = [&](const VecX& v) {
    ++applications;
    return VecX(inv_diag.cwiseProduct(v));
  };
  // a fixed linear preconditioner: in one cycle the same Krylov space, so the same iterate and
  // steps; plain GMRES applies P^-1 once more per cycle (to V y), flexible GMRES never
  for (int restart : {1000, 25}) {
    VecX xp, xf;
    GmresWork wp, wf;
    applications = 0;
    const GmresResult rp = gmres(A, b, jacobi, {.tolerance = 1e-10, .max_iterations = 5000, .restart = restart}, xp, wp);
    const int plain_applications = applications;
    applications = 0;
    const GmresResult rf = gmres(A, b, jacobi,
                                 {.tolerance = 1e-10, .max_iterations = 5000, .restart = restart, .flexible = true}, xf, wf);
    INFO("restart " << restart << ": plain " << rp.iterations << " steps, " << plain_applications
                    << " applications; flexible " << rf.iterations << " steps, " << applications << " applications");
    REQUIRE(rp.converged);
    REQUIRE(rf.converged);
    CHECK((b - A * xf).norm() <= 1e-10 * b.norm());
    CHECK(applications == rf.iterations);
    const int cycles = (rp.iterations + restart - 1) / restart;
    CHECK(plain_applications - rp.iterations >= cycles);  // one more per cycle (a short last one possible)
    if (restart >= n) {  // one cycle (restarts let rounding steer the two apart)
      CHECK(rf.iterations == rp.iterations);
      CHECK((xf - xp).norm() <= 1e-10 * xp.norm());
    }
  }
  // single-precision LU factors: P^-1 = A^-1 up to float rounding, which is not one linear map.
  // To 1e-11 (the double-precision LU's own residual is 7e-13 here): plain GMRES puts the
  // rounding of its last application back into each cycle's iterate; flexible GMRES minimises
  // over the directions as applied. (Iterative refinement with these factors, gaining
  // delta = ||v - A P^-1 v|| / ||v|| per application, would need about log(tol) / log(delta)
  // applications: printed for comparison, not a bound, P^-1 being nonlinear.)
  using SpF = Eigen::SparseMatrix<float, Eigen::ColMajor, Index>;
  Eigen::SparseLU<SpF> luf(A.cast<float>());
  REQUIRE(luf.info() == Eigen::Success);
  auto single = [&](const VecX& v) {
    ++applications;
    return VecX(luf.solve(v.cast<float>()).cast<Real>());
  };
  const Real tolerance = 1e-11, delta = (b - A * single(b)).norm() / b.norm();
  REQUIRE(delta < 1e-2);
  const int refinement_steps = int(std::ceil(std::log(tolerance) / std::log(delta)));
  VecX xp, xf;
  GmresWork wp, wf;
  applications = 0;
  const GmresResult rp = gmres(A, b, single, {.tolerance = tolerance, .max_iterations = 100, .restart = 100}, xp, wp);
  const int plain_applications = applications;
  applications = 0;
  const GmresResult rf =
      gmres(A, b, single, {.tolerance = tolerance, .max_iterations = 100, .restart = 100, .flexible = true}, xf, wf);
  INFO("single-precision factors (delta " << delta << ") to " << tolerance << ": plain " << plain_applications
                                          << " applications in " << rp.iterations << " steps, flexible "
                                          << applications << "; refinement would need " << refinement_steps);
  REQUIRE(rp.converged);
  REQUIRE(rf.converged);
  CHECK((b - A * xf).norm() <= tolerance * b.norm());
  CHECK(applications < plain_applications);
}

TEST_CASE("gmres breakdown: a preconditioner that returns zero or NaN, or is singular on the Krylov space, ends "
          "the solve at the best iterate it allows, finite, without spinning to max_iterations",
          "[la][krylov][quick]") {
  SparseMatrix I(4, 4);
  I.setIdentity();
  const VecX b = VecX::Ones(4);
  for (bool flexible : {false, true}) {
    CAPTURE(flexible);
    const GmresOptions opt{.tolerance = 1e-10, .max_iterations = 100, .restart = 10, .flexible = flexible};
    VecX x;
    GmresWork work;
    // P^-1 = 0 and P^-1 = NaN: no direction at all; x stays 0
    for (Real value : {Real(0), std::numeric_limits<Real>::quiet_NaN()}) {
      CAPTURE(value);
      const GmresResult res = gmres(I, b, [&](const VecX& v) { return VecX(VecX::Constant(v.size(), value)); }, opt, x, work);
      CHECK(res.breakdown);
      CHECK_FALSE(res.converged);
      CHECK(res.iterations == 1);
      CHECK(res.residual == 1);
      CHECK(x == VecX::Zero(4));
    }
    // P^-1 = the projection on the first two unknowns: A x = b is solvable only there. The
    // first cycle's second step, P^-1 v_1 = P^-1 v_0, adds nothing (exactly, in these binary
    // fractions); the cycle ends with x = (1, 1, 0, 0), the least-squares optimum over range(P^-1),
    // residual 1 / sqrt(2); the next cycle's first step is zero and ends the solve: 3 steps in
    // exact arithmetic. (Plain GMRES's x = P^-1 (V y) may leave a residual of round-off size on
    // the first two unknowns, which costs one more cycle of two steps.)
    const GmresResult res = gmres(
        I, b, [](const VecX& v) { return VecX((VecX(4) << v[0], v[1], 0, 0).finished()); }, opt, x, work);
    CHECK(res.breakdown);
    CHECK_FALSE(res.converged);
    CHECK(res.iterations >= 3);
    CHECK(res.iterations <= 5);
    CHECK(std::abs(res.residual - 1 / std::sqrt(Real(2))) <= 1e-15);
    CHECK((x - VecX((VecX(4) << 1, 1, 0, 0).finished())).norm() <= 1e-15);
  }
}

namespace {

// SaddlePointGmres without `set_pressure_null_space`: a flow pins pressure DOF 0 for it, as it
// does for a direct solver (what the library did before the null space)
struct PinnedSaddlePointGmres {
  static constexpr const char* name = "GMRES+block(AMG, Schur), pinned";
  SaddlePointGmres<3> s;
  explicit PinnedSaddlePointGmres(KrylovOptions o = {}) : s(o) {}
  void set_blocks(SaddlePointBlocks b) { s.set_blocks(std::move(b)); }
  void analyze(const SparseMatrix& A) { s.analyze(A); }
  void factorize(const SparseMatrix& A) { s.factorize(A); }
  VecX solve(const VecX& b) { return s.solve(b); }
  VecX solve(const SparseMatrix& A, const VecX& b) { return s.solve(A, b); }
  int iterations() const { return s.iterations(); }
  Real residual() const { return s.residual(); }
};

}  // namespace

TEST_CASE("SaddlePointGmres on a graded mesh with a free sphere: with the pin GMRES(60) stagnates; with the "
          "null space it converges, restarted or not, to the same answer",
          "[la][solvers][krylov][bodies3d][quick]") {
  // A free sphere (radius 1/4) pushed by a unit force inside a fixed concentric sphere (radius 2),
  // Stokes, Taylor–Hood. The shell mesh's layers are pulled towards the body, r = r1 + (r2 - r1) t^5
  // (cells from about 0.01 at the body to 0.26 outside): the small version of a graded gmsh mesh
  // on which GMRES(60) stopped at 1000 iterations (docs/solvers.md, "A closed domain: the
  // pressure's null space"). The domain is closed: a pin of pressure DOF 0 leaves K a near-null
  // vector, which the restarts lose and find again; the unpinned system has none.
  const Real r1 = 0.25, r2 = 2.0;
  Mesh<3> mesh = spherical_shell_mesh(r1, r2, 3);
  std::vector<Vec<3>> x = mesh.coordinates();
  for (Vec<3>& p : x) {
    const Real r = p.norm(), t = (r - r1) / (r2 - r1);
    p *= (r1 + (r2 - r1) * std::pow(t, 5)) / r;
  }
  mesh.set_coordinates(std::move(x));
  auto solve = [&]<class Solver>(KrylovOptions opt) {
    using Flow = AleFlow<FlowConfig<3, TaylorHood, BSS, UnsteadyStokes, Solver>>;
    constexpr FlowOptions stokes{.rho = 1e-12, .mu = 1, .linearisation = Linearisation::semi_implicit};
    std::unique_ptr<Flow> flow;
    if constexpr (DirectSolver<Solver>)
      flow = std::make_unique<Flow>(mesh, stokes);
    else
      flow = std::make_unique<Flow>(mesh, stokes, opt);
    flow->set_velocity(tags::outer, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
    flow->set_prescribed_mesh_velocity([](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
    RigidBody3D body = sphere_body(tags::inner, Vec<3>::Zero(), r1, 1.0);
    body.external_load << 0, 0, -1, 0, 0, 0;
    flow->add_body(body);
    flow->step(1.0);
    return flow;
  };
  // pinned, plain restarted GMRES: the residual falls by a constant factor per cycle, short of 1e-8
  try {
    solve.operator()<PinnedSaddlePointGmres>({.augment = 0});
    FAIL("GMRES(60) with the pin was expected to stop short on this mesh");
  } catch (const SolverError& e) {
    const std::string what = e.what();
    CHECK(what.find("1000 iterations") != std::string::npos);
    CHECK(what.find("e-0") != std::string::npos);  // the residual in scientific notation
  }
  const auto direct = solve.operator()<SparseLu<>>({});  // the reference (pinned; exact to round-off)
  const auto pinned = solve.operator()<PinnedSaddlePointGmres>({.restart = 1000, .augment = 0});
  const auto gmres60 = solve.operator()<SaddlePointGmres<3>>({.augment = 0});
  const auto lgmres = solve.operator()<SaddlePointGmres<3>>({});  // LGMRES(60, 2), the default
  const auto full = solve.operator()<SaddlePointGmres<3>>({.restart = 1000, .augment = 0});
  CHECK(!pinned->pressure_null_space());
  CHECK(full->pressure_null_space());
  INFO("null space: GMRES(60) " << gmres60->solver().iterations() << ", LGMRES(60,2) "
                                << lgmres->solver().iterations() << ", GMRES without restarts "
                                << full->solver().iterations() << " iterations; pinned, without restarts "
                                << pinned->solver().iterations());
  CHECK(full->solver().iterations() < pinned->solver().iterations());
  // errors against the direct solve (both shifted to zero mean pressure): velocity, pressure
  const Index nv = direct->space().pressure_field(0);  // velocities first, then pressures
  const VecX& ref = direct->field();
  auto error = [&](const auto& f) {
    const VecX d = f->field() - ref;
    const Index np = d.size() - nv;
    return std::pair{d.head(nv).norm() / ref.head(nv).norm(), d.tail(np).norm() / ref.tail(np).norm()};
  };
  const auto [u_pin, p_pin] = error(pinned);
  INFO("pinned GMRES: velocity error " << u_pin << ", pressure error " << p_pin);
  for (const auto* f : {gmres60.get(), lgmres.get(), full.get()}) {
    const auto [u_err, p_err] = error(f);
    INFO("null space: velocity error " << u_err << ", pressure error " << p_err);
    CHECK(f->solver().residual() <= 1e-8);
    CHECK((f->body_velocity(0) - direct->body_velocity(0)).norm() <= 1e-6 * direct->body_velocity(0).norm());
    CHECK(u_err <= 1e-6);
    CHECK(p_err <= 1e-6);
    // the pinned solve's error along its near-null vector (the constant on all pressures but
    // DOF 0) is left at DOF 0 after the shift to zero mean
    CHECK(p_err < p_pin);
  }
  CHECK(full->body_velocity(0)[2] < 0);  // the sphere moves with the force
}
