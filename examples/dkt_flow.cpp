// The flow of the dkt example, compiled here once (alefsi/sim/instantiate.hpp): editing dkt.cpp
// recompiles only the program, about half the compile time of the whole scene.
#include "dkt_config.hpp"

ALEFSI_INSTANTIATE_FLOW(DktConfig)
