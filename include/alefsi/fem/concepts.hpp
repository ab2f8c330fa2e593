#pragma once
/// \file fem/concepts.hpp
/// Concepts of the fem module.
///
/// `ScalarElement`: a scalar finite element on the reference D-simplex — what assembly and
/// DOF maps call. Minimal model: `alefsi::Lagrange<2, 1>`.
///
/// `StabilisationTag`: an empty type that names a stabilisation (`name`, for output). Fem only
/// carries it; the terms are physics (physics/stabilisation.hpp). Models:
/// `alefsi::NoStabilisation`, `alefsi::GlsStabilisation` (fem/element_pair.hpp).
///
/// `ElementPair`: a velocity/pressure pair for incompressible flow — the velocity and pressure
/// elements (as templates of the dimension), the stabilisation it needs (a `StabilisationTag`)
/// and a name. Minimal model:
///
///     struct MyPair : alefsi::LagrangePair<2, 1> { static constexpr const char* name = "P2/P1"; };
///
/// Models: `alefsi::TaylorHood` (P2/P1), `alefsi::P1P1Gls`.
#include <concepts>
#include <type_traits>

#include "alefsi/core/types.hpp"
#include "alefsi/fem/lagrange.hpp"

namespace alefsi {

template <class E>
concept ScalarElement = requires(const Vec<E::dim>& x, int i) {
  { E::dim } -> std::convertible_to<int>;
  { E::degree } -> std::convertible_to<int>;
  { E::n_dofs } -> std::convertible_to<int>;
  { E::values(x) };
  { E::gradients(x) };
  { E::node(i) } -> std::convertible_to<Vec<E::dim>>;
  { E::entity(i) } -> std::same_as<DofEntity>;
};

template <class S>
concept StabilisationTag = std::is_empty_v<S> && requires {
  { S::name } -> std::convertible_to<const char*>;
};

template <class P>
concept ElementPair = requires {
  { P::name } -> std::convertible_to<const char*>;
  typename P::Stabilisation;
} && StabilisationTag<typename P::Stabilisation> && ScalarElement<typename P::template Velocity<2>> &&
                      ScalarElement<typename P::template Velocity<3>> &&
                      ScalarElement<typename P::template Pressure<2>> &&
                      ScalarElement<typename P::template Pressure<3>>;

static_assert(ScalarElement<Lagrange<2, 1>> && ScalarElement<Lagrange<3, 2>>);

}  // namespace alefsi
