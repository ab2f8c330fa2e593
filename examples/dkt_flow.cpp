// What the dkt program does not change, compiled here once: the flow for its configuration
// (alefsi/sim/instantiate.hpp) and the scene's mesh and set-up. Editing dkt.cpp recompiles only
// the program (docs/performance.md, compile time).
#include "dkt_config.hpp"

ALEFSI_INSTANTIATE_FLOW(DktConfig)

template void alefsi::scenes::SettlingDisks::configure<alefsi::AleFlow<DktConfig>>(alefsi::AleFlow<DktConfig>&,
                                                                                   alefsi::Real, alefsi::Real) const;

alefsi::Mesh<2> dkt_mesh(const alefsi::scenes::SettlingDisks& scene, alefsi::Real h_body, alefsi::Real h_far) {
  return scene.mesh(h_body, h_far);
}
