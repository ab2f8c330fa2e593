// Linear-solver policies (la/solvers.hpp, la/suitesparse.hpp) and the saddle-point ordering
// (la/ordering.hpp): every direct policy solves a driven-cavity Stokes system (P2/P1 and
// P1/P1-GLS) to a small residual and agrees with SparseLU+COLAMD; analysis is reused across
// factorisations; the ordering's conventions and its zero-diagonal rule hold; SPD policies
// give the same mesh velocity.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/ordering.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/la/suitesparse.hpp"
#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/physics/mesh_motion.hpp"
#include "alefsi/physics/stokes.hpp"

using namespace alefsi;

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
