#pragma once
/// \file fem/element_pair.hpp
/// Velocity/pressure element pairs as types: the compile-time choice of a scene.
///
/// A pair composes a velocity element (one scalar Lagrange element per component, (P_kv)^D)
/// with a pressure element, and names as a type the stabilisation it needs on top:
///
///   TaylorHood = LagrangePair<2, 1>:                   P2 velocity, P1 pressure; inf-sup stable,
///                                                      `Stabilisation = NoStabilisation`.
///   P1P1Gls    = LagrangePair<1, 1, GlsStabilisation>: P1 velocity and pressure; not inf-sup
///                                                      stable alone, stabilised by GLS/PSPG.
///
/// The tags only say *which* stabilisation; its terms and its parameter tau are physics and
/// live in physics/stabilisation.hpp (fem does not include physics). A new stabilisation is a
/// new tag here (or in user code) plus its policy there.
///
///     using Pair = alefsi::TaylorHood;
///     using V = Pair::Velocity<2>;              // alefsi::Lagrange<2, 2>
///     using S = Pair::Stabilisation;            // alefsi::NoStabilisation
#include "alefsi/fem/concepts.hpp"
#include "alefsi/fem/lagrange.hpp"

namespace alefsi {

/// Stabilisation tags (`StabilisationTag`): no stabilisation term.
struct NoStabilisation {
  static constexpr const char* name = "none";
};
/// Galerkin/least-squares: SUPG + PSPG terms with one cell parameter tau_K.
struct GlsStabilisation {
  static constexpr const char* name = "GLS";
};
static_assert(StabilisationTag<NoStabilisation>, "NoStabilisation must model StabilisationTag");
static_assert(StabilisationTag<GlsStabilisation>, "GlsStabilisation must model StabilisationTag");

/// Continuous Lagrange velocity of degree `VelocityDegree` (every component) and pressure of
/// degree `PressureDegree`, with the stabilisation `Stab` on top. A named pair derives from it
/// and adds its `name`.
template <int VelocityDegree, int PressureDegree, StabilisationTag Stab = NoStabilisation>
struct LagrangePair {
  template <int D>
  using Velocity = Lagrange<D, VelocityDegree>;
  template <int D>
  using Pressure = Lagrange<D, PressureDegree>;
  using Stabilisation = Stab;
};

struct TaylorHood : LagrangePair<2, 1> {
  static constexpr const char* name = "P2/P1";
};

struct P1P1Gls : LagrangePair<1, 1, GlsStabilisation> {
  static constexpr const char* name = "P1/P1-GLS";
};

static_assert(ElementPair<TaylorHood>, "TaylorHood must model ElementPair");
static_assert(ElementPair<P1P1Gls>, "P1P1Gls must model ElementPair");

}  // namespace alefsi
