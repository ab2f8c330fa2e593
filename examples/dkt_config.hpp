#pragma once
// dkt's compile-time configuration, shared by dkt.cpp (the program) and dkt_flow.cpp (where its
// flow is compiled, once: alefsi/sim/instantiate.hpp). Element pair and scheme come from the
// CMake options ALEFSI_DKT_PAIR and ALEFSI_DKT_SCHEME.
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
