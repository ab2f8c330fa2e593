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
template class AleFlow<2, TaylorHood, BDF3_BDF3E>;
template class AleFlow<2, P1P1Gls, BDF2_BDF2E>;
template class AleFlow<3, TaylorHood, MR_AB, false>;
template class SparseLu<Eigen::AMDOrdering<Index>>;
}  // namespace alefsi

TEST_CASE("curated configurations instantiate", "[fem][quick]") { SUCCEED("compiled"); }
