// Explicit instantiation of the curated configurations, so that member functions no test
// calls still compile (deal.II .inst.in style). Adding a configuration here is how a new
// combination becomes supported.
#include <catch2/catch.hpp>

#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/physics/stokes.hpp"
#include "alefsi/sim/ale_flow.hpp"

namespace alefsi {
template class Mesh<2>;
template class Mesh<3>;
template class DofMap<Lagrange<2, 1>>;
template class DofMap<Lagrange<2, 2>>;
template class DofMap<Lagrange<3, 1>>;
template class DofMap<Lagrange<3, 2>>;
template class MixedSpace<2, TaylorHood>;
template class MixedSpace<2, P1P1Gls>;
template class MixedSpace<3, TaylorHood>;
template class MixedSpace<3, P1P1Gls>;
template class StokesKernel<2, TaylorHood>;
template class StokesKernel<2, P1P1Gls>;
template class StokesKernel<3, TaylorHood>;
template class StokesKernel<3, P1P1Gls>;
template class Stokes<2, TaylorHood>;
template class Stokes<2, P1P1Gls>;
template class Stokes<3, TaylorHood>;
template class Stokes<3, P1P1Gls>;
template VecX Stokes<2, TaylorHood>::solve<SparseLu<>>(SparseLu<>);
template VecX Stokes<3, P1P1Gls>::solve<BiCgStabIlut>(BiCgStabIlut);
template class SparseLu<>;
template class ElasticMeshMotion<2>;
template class ElasticMeshMotion<3>;
template class AleNavierStokesKernel<2, TaylorHood>;
template class AleNavierStokesKernel<2, P1P1Gls>;
template class AleNavierStokesKernel<3, TaylorHood, false>;
template class AleFlow<FlowConfig<2, TaylorHood, BDF3_BDF3E>>;
template class AleFlow<FlowConfig<2, P1P1Gls, BDF2_BDF2E>>;
template class AleFlow<FlowConfig<3, TaylorHood, MR_AB, UnsteadyStokes>>;
template class SparseLu<Eigen::AMDOrdering<Index>>;
}  // namespace alefsi

TEST_CASE("curated configurations instantiate", "[fem][quick]") { SUCCEED("compiled"); }

namespace {
// Wrong types, each short of a model by what its comment says.
struct SchemeWithoutExtrapolation {  // no `extrapolation`
  static constexpr const char* name = "broken";
  static constexpr int order = 2, flow_bdf = 2, position_bdf = 2;
  static constexpr alefsi::Real theta = 1;
  static constexpr auto velocity_level = alefsi::VelocityLevel::n_one;
  static constexpr auto flow_velocity = alefsi::FlowMeshVelocity::solved;
};
struct SchemeWithZeroTheta : alefsi::BDF2_BDF2E {  // theta must lie in (0, 1]
  static constexpr alefsi::Real theta = 0;
};
struct SchemeWithBdf4 : alefsi::BDF3_BDF3E {  // BDF orders 1..3 only
  static constexpr int flow_bdf = 4;
};
struct SolverWithoutFactorize {
  static constexpr const char* name = "broken";
  void analyze(const alefsi::SparseMatrix&) {}
  alefsi::VecX solve(const alefsi::VecX& b) { return b; }
};
struct BodyModelWithFourDof : alefsi::RigidBodyTraits<2> {  // 2D bodies have 3 rigid DOFs
  static constexpr int n_dof = 4;
};
struct BodyModelWithoutOperations {  // the types of a 2D model, none of its operations
  using Base = alefsi::RigidBodyTraits<2>;
  using Body = Base::Body;
  using Velocity = Base::Velocity;
  using Orientation = Base::Orientation;
  static constexpr int dim = 2, n_dof = 3;
};
}  // namespace

TEST_CASE("the concepts reject a type that misses a requirement", "[fem][quick]") {
  using namespace alefsi;
  STATIC_REQUIRE(TimeScheme<MR_AB>);
  STATIC_REQUIRE(!TimeScheme<SchemeWithoutExtrapolation>);
  STATIC_REQUIRE(!TimeScheme<SchemeWithZeroTheta>);
  STATIC_REQUIRE(!TimeScheme<SchemeWithBdf4>);
  STATIC_REQUIRE(LinearSolver<SparseLu<>>);
  STATIC_REQUIRE(!LinearSolver<SolverWithoutFactorize>);
  STATIC_REQUIRE(RigidBodyModel<RigidBodyTraits<2>>);
  STATIC_REQUIRE(RigidBodyModel<RigidBodyTraits<3>>);
  STATIC_REQUIRE(!RigidBodyModel<BodyModelWithFourDof>);
  STATIC_REQUIRE(!RigidBodyModel<BodyModelWithoutOperations>);
}
