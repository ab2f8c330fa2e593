#pragma once
/// \file sim/instantiate.hpp
/// Compile a scene's flow once. `AleFlow<Config>` and `run()` for it are most of what a scene's
/// translation unit costs the compiler (kernels, assembly, Newton, remeshing, checkpoints; with
/// the scene's set-up, 25 of the 43 s that `examples/dkt.cpp` took: docs/performance.md). A
/// scene that is edited often can say that they are compiled in another translation unit,
/// compiled once:
///
///     // scene_config.hpp, included by both files below
///     using MyConfig = alefsi::FlowConfig<2, alefsi::P1P1Gls, alefsi::BDF2_BDF2E>;
///     ALEFSI_EXTERN_FLOW(MyConfig)          // at namespace scope: "compiled elsewhere"
///
///     // scene_flow.cpp: the one place they are compiled
///     #include "scene_config.hpp"
///     ALEFSI_INSTANTIATE_FLOW(MyConfig)
///
///     // scene.cpp: uses AleFlow<MyConfig> and run() as usual; links scene_flow.o
///
/// Without `ALEFSI_EXTERN_FLOW` everything compiles as before (implicit instantiation): the
/// macros change where code is compiled, never what it computes. Members constrained to other
/// configurations (e.g. 2D-only ones in a 3D flow) are not instantiated (C++20 [temp.explicit]).
/// examples/dkt.cpp with examples/dkt_flow.cpp is the worked example.
#include "alefsi/sim/ale_flow.hpp"
#include "alefsi/sim/driver.hpp"

/// Declares that `AleFlow<Config>` (its members, and its constructor without solver arguments)
/// and `run(AleFlow<Config>&, const RunOptions&)` are compiled in another translation unit (by `ALEFSI_INSTANTIATE_FLOW(Config)`). At namespace scope.
#define ALEFSI_EXTERN_FLOW(...)                                                                   \
  extern template class ::alefsi::AleFlow<__VA_ARGS__>;                                           \
  extern template ::alefsi::AleFlow<__VA_ARGS__>::AleFlow(::alefsi::Mesh<__VA_ARGS__::dim>,         \
                                                          ::alefsi::FlowOptions);                 \
  extern template ::alefsi::RunSummary(::alefsi::run<::alefsi::AleFlow<__VA_ARGS__>>)(           \
      ::alefsi::AleFlow<__VA_ARGS__>&, const ::alefsi::RunOptions&);

/// Compiles `AleFlow<Config>` and `run()` for it here. In exactly one translation unit.
#define ALEFSI_INSTANTIATE_FLOW(...)                                                              \
  template class ::alefsi::AleFlow<__VA_ARGS__>;                                                  \
  template ::alefsi::AleFlow<__VA_ARGS__>::AleFlow(::alefsi::Mesh<__VA_ARGS__::dim>,                \
                                                   ::alefsi::FlowOptions);                        \
  template ::alefsi::RunSummary(::alefsi::run<::alefsi::AleFlow<__VA_ARGS__>>)(                  \
      ::alefsi::AleFlow<__VA_ARGS__>&, const ::alefsi::RunOptions&);
