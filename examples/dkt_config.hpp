#pragma once
// dkt's compile-time configuration, shared by dkt.cpp (the program: options, run, analysis) and
// dkt_flow.cpp, where what the program does not change is compiled once: the flow for this
// configuration (alefsi/sim/instantiate.hpp) and the scene's mesh and set-up. Element pair and
// scheme come from the CMake options ALEFSI_DKT_PAIR and ALEFSI_DKT_SCHEME.
#include <alefsi/scenes/settling.hpp>
#include <alefsi/sim/instantiate.hpp>

#ifndef ALEFSI_DKT_PAIR
#define ALEFSI_DKT_PAIR P1P1Gls
#endif
#ifndef ALEFSI_DKT_SCHEME
#define ALEFSI_DKT_SCHEME BDF2_BDF2E
#endif

// SparseLU with the saddle-point AMD ordering (FlowConfig's default): on this scene's ~10^4
// unknowns it factorises as fast as UMFPACK and solves 7x faster (no iterative refinement);
// docs/results.md
using DktConfig = alefsi::FlowConfig<2, alefsi::ALEFSI_DKT_PAIR, alefsi::ALEFSI_DKT_SCHEME>;
ALEFSI_EXTERN_FLOW(DktConfig)

/// The scene's mesh (graded from h_body at the disks to h_far), compiled in dkt_flow.cpp.
alefsi::Mesh<2> dkt_mesh(const alefsi::scenes::SettlingDisks& scene, alefsi::Real h_body, alefsi::Real h_far);
/// The scene's set-up of the flow (walls, disks, gravity, collisions, remeshing): in dkt_flow.cpp.
extern template void alefsi::scenes::SettlingDisks::configure<alefsi::AleFlow<DktConfig>>(alefsi::AleFlow<DktConfig>&,
                                                                                          alefsi::Real, alefsi::Real) const;
