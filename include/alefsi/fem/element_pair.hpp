#pragma once
/// \file fem/element_pair.hpp
/// Velocity/pressure element pairs as types: the compile-time choice of a scene.
///
///   TaylorHood: continuous P2 velocity, continuous P1 pressure; inf-sup stable, no stabilisation.
///   P1P1Gls:    continuous P1 velocity and pressure, stabilised by GLS/PSPG (physics/ adds
///               the terms; the pair only says that it needs them).
///
///     using Pair = alefsi::TaylorHood;
///     using V = Pair::Velocity<2>;   // alefsi::Lagrange<2, 2>
#include "alefsi/fem/concepts.hpp"
#include "alefsi/fem/lagrange.hpp"

namespace alefsi {

struct TaylorHood {
  template <int D>
  using Velocity = Lagrange<D, 2>;
  template <int D>
  using Pressure = Lagrange<D, 1>;
  static constexpr bool stabilised = false;
  static constexpr const char* name = "P2/P1";
};

struct P1P1Gls {
  template <int D>
  using Velocity = Lagrange<D, 1>;
  template <int D>
  using Pressure = Lagrange<D, 1>;
  static constexpr bool stabilised = true;
  static constexpr const char* name = "P1/P1-GLS";
};

static_assert(ElementPair<TaylorHood>, "TaylorHood must model ElementPair");
static_assert(ElementPair<P1P1Gls>, "P1P1Gls must model ElementPair");

}  // namespace alefsi
