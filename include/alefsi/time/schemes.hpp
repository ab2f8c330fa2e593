#pragma once
/// \file time/schemes.hpp
/// The five ALE time schemes of the paper (section 4) as constexpr coefficient tables.
///
/// A scheme says, for one step t^n -> t^{n+1}:
///   - the flow: residuals evaluated at t^{n+theta} on the geometry X^{n+theta}
///     (theta-interpolation f^{n+theta} = theta f^{n+1} + (1 - theta) f^n), with the ALE time
///     derivative delta_l u^{n+1} / dt, l = `flow_bdf`;
///   - the mesh velocity: solved (eq. 15-16) at level `velocity_level` on the extrapolated
///     geometry X^ = sum_k extrapolation[k] X^{n-k}, with boundary data from the extrapolated
///     flow U^ (same weights);
///   - the positions: delta_lg X^{n+1} = dt V, lg = `position_bdf`;
///   - the mesh velocity the flow sees: the solved one, or (BDF2/AB) 2 V^{n+1/2} - V^n.
///
/// | scheme      | theta | l | V solved at | X^ weights        | lg | flow sees          | order |
/// |-------------|-------|---|-------------|-------------------|----|--------------------|-------|
/// | MR/AB  (19) | 1/2   | 1 | n+1/2       | 3/2, -1/2         | 1  | V^{n+1/2}          | 2     |
/// | BDF2/BDF2E  | 1     | 2 | n+1         | 2, -1             | 2  | V^{n+1}            | 2     |
/// | BDF2/AB (21)| 1     | 2 | n+1/2       | 3/2, -1/2         | 1  | 2V^{n+1/2} - V^n   | 2     |
/// | BDF3/BDF3E  | 1     | 3 | n+1         | 3, -3, 1          | 3  | V^{n+1}            | 3     |
/// | BSS    (23) | 1     | 1 | n           | 1                 | 1  | V^n                | 1     |
///
/// Adding a sixth scheme is a new struct with these members; nothing else changes.
///
///     using S = alefsi::BDF3_BDF3E;
///     static_assert(alefsi::TimeScheme<S> && S::order == 3);
#include <array>
#include <concepts>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

/// Time level at which a scheme solves the mesh-velocity problem.
enum class VelocityLevel { n, n_half, n_one };
/// The mesh velocity used in the flow residual.
enum class FlowMeshVelocity { solved, ab2 /* 2 V^{n+1/2} - V^n */ };

/// Backward-difference coefficients of eq. (17): delta_l f^{n+1} = sum_k bdf(l)[k] f^{n+1-k}.
constexpr std::array<Real, 4> bdf_coefficients(int l) {
  if (l == 1) return {1.0, -1.0, 0.0, 0.0};
  if (l == 2) return {1.5, -2.0, 0.5, 0.0};
  return {11.0 / 6.0, -3.0, 1.5, -1.0 / 3.0};
}

/// Extrapolation of order k to t^{n+1} from f^n, f^{n-1}, f^{n-2} (k = 1, 2, 3), or to
/// t^{n+1/2} (`half` = true, k <= 2).
constexpr std::array<Real, 3> extrapolation_weights(int k, bool half) {
  if (half) return k == 1 ? std::array<Real, 3>{1.0, 0.0, 0.0} : std::array<Real, 3>{1.5, -0.5, 0.0};
  if (k == 1) return {1.0, 0.0, 0.0};
  if (k == 2) return {2.0, -1.0, 0.0};
  return {3.0, -3.0, 1.0};
}

struct MR_AB {
  static constexpr const char* name = "MR/AB";
  static constexpr int order = 2;
  static constexpr Real theta = 0.5;
  static constexpr int flow_bdf = 1;
  static constexpr VelocityLevel velocity_level = VelocityLevel::n_half;
  static constexpr std::array<Real, 3> extrapolation{1.5, -0.5, 0.0};
  static constexpr int position_bdf = 1;
  static constexpr FlowMeshVelocity flow_velocity = FlowMeshVelocity::solved;
};

struct BDF2_BDF2E {
  static constexpr const char* name = "BDF2/BDF2E";
  static constexpr int order = 2;
  static constexpr Real theta = 1.0;
  static constexpr int flow_bdf = 2;
  static constexpr VelocityLevel velocity_level = VelocityLevel::n_one;
  static constexpr std::array<Real, 3> extrapolation{2.0, -1.0, 0.0};
  static constexpr int position_bdf = 2;
  static constexpr FlowMeshVelocity flow_velocity = FlowMeshVelocity::solved;
};

struct BDF2_AB {
  static constexpr const char* name = "BDF2/AB";
  static constexpr int order = 2;
  static constexpr Real theta = 1.0;
  static constexpr int flow_bdf = 2;
  static constexpr VelocityLevel velocity_level = VelocityLevel::n_half;
  static constexpr std::array<Real, 3> extrapolation{1.5, -0.5, 0.0};
  static constexpr int position_bdf = 1;
  static constexpr FlowMeshVelocity flow_velocity = FlowMeshVelocity::ab2;
};

struct BDF3_BDF3E {
  static constexpr const char* name = "BDF3/BDF3E";
  static constexpr int order = 3;
  static constexpr Real theta = 1.0;
  static constexpr int flow_bdf = 3;
  static constexpr VelocityLevel velocity_level = VelocityLevel::n_one;
  static constexpr std::array<Real, 3> extrapolation{3.0, -3.0, 1.0};
  static constexpr int position_bdf = 3;
  static constexpr FlowMeshVelocity flow_velocity = FlowMeshVelocity::solved;
};

struct BSS {
  static constexpr const char* name = "BSS";
  static constexpr int order = 1;
  static constexpr Real theta = 1.0;
  static constexpr int flow_bdf = 1;
  static constexpr VelocityLevel velocity_level = VelocityLevel::n;
  static constexpr std::array<Real, 3> extrapolation{1.0, 0.0, 0.0};
  static constexpr int position_bdf = 1;
  static constexpr FlowMeshVelocity flow_velocity = FlowMeshVelocity::solved;
};

/// What the step loop reads from a scheme.
template <class S>
concept TimeScheme = requires {
  { S::name } -> std::convertible_to<const char*>;
  { S::order } -> std::convertible_to<int>;
  { S::theta } -> std::convertible_to<Real>;
  { S::flow_bdf } -> std::convertible_to<int>;
  { S::velocity_level } -> std::convertible_to<VelocityLevel>;
  { S::extrapolation } -> std::convertible_to<std::array<Real, 3>>;
  { S::position_bdf } -> std::convertible_to<int>;
  { S::flow_velocity } -> std::convertible_to<FlowMeshVelocity>;
} && (S::theta > 0 && S::theta <= 1) && (S::flow_bdf >= 1 && S::flow_bdf <= 3) &&
                     (S::position_bdf >= 1 && S::position_bdf <= 3);

/// Number of past levels (n-1, n-2, ...) a scheme reads, beyond level n.
template <TimeScheme S>
constexpr int history_levels() {
  int h = S::flow_bdf - 1;
  h = h > S::position_bdf - 1 ? h : S::position_bdf - 1;
  for (int k = 1; k < 3; ++k)
    if (S::extrapolation[k] != 0 && k > h) h = k;
  return h;
}

static_assert(TimeScheme<MR_AB> && TimeScheme<BDF2_BDF2E> && TimeScheme<BDF2_AB> && TimeScheme<BDF3_BDF3E> &&
                  TimeScheme<BSS>,
              "the five schemes of the paper must model TimeScheme");

/// The largest step ratio dt_n / dt_{n-1} under which the variable-step BDF formula of order l
/// is used (larger: the history restarts). Zero-stability with a constant ratio w (the root
/// condition of sum_k a_k(w) z^{l-k} = 0, checked in tests/sim/test_time.cpp) holds for
/// w < 1 + sqrt(2) = 2.414 (l = 2; Grigorieff 1983) and w < (1 + sqrt(5)) / 2 = 1.618 (l = 3);
/// varying ratios are stricter than constant ones, so the bounds keep a margin: 2 and 1.5.
/// Shrinking steps (w < 1) need no bound. l = 1 (and the midpoint rule) is one-step: none.
constexpr Real max_step_ratio(int l) { return l <= 1 ? std::numeric_limits<Real>::infinity() : l == 2 ? 2.0 : 1.5; }
/// The scheme's bound: the smaller of its flow's and its positions' (the extrapolations are
/// explicit and need none).
template <TimeScheme S>
constexpr Real max_step_ratio() {
  const Real a = max_step_ratio(S::flow_bdf), b = max_step_ratio(S::position_bdf);
  return a < b ? a : b;
}

/// A compile-time list of schemes.
template <TimeScheme... S>
struct SchemeList {
  static constexpr std::size_t size = sizeof...(S);
};
/// The paper's five schemes, in the paper's order (BSS last).
using PaperSchemes = SchemeList<MR_AB, BDF2_BDF2E, BDF2_AB, BDF3_BDF3E, BSS>;

/// The display names of the schemes of `List`, comma-separated.
template <class List = PaperSchemes>
std::string scheme_names() {
  return []<TimeScheme... S>(SchemeList<S...>) {
    std::string out;
    ((out += (out.empty() ? "" : ", ") + std::string(S::name)), ...);
    return out;
  }(List{});
}

namespace detail {
/// "BDF2/BDF2E" and "BDF2_BDF2E" name the same scheme (display name, C++ identifier).
inline bool scheme_name_matches(std::string_view display, std::string_view key) {
  if (key.size() != display.size()) return false;
  for (std::size_t i = 0; i < key.size(); ++i)
    if (key[i] != display[i] && !(display[i] == '/' && key[i] == '_')) return false;
  return true;
}
}  // namespace detail

/// Calls `f.template operator()<S>()` for the scheme S of `List` named `name` (its display name,
/// e.g. "BDF2/BDF2E", or its type name, "BDF2_BDF2E"), and returns what f returns. An unknown
/// name throws InvalidArgument naming `parameter` and listing the valid names. This is the one
/// place where a run-time name becomes a compile-time scheme.
///
///     dispatch_scheme(options.get<std::string>("scheme"), [&]<class S>() { run<S>(); });
template <class List = PaperSchemes, class F>
decltype(auto) dispatch_scheme(std::string_view name, F&& f, std::string_view parameter = "scheme") {
  return [&]<TimeScheme... S>(SchemeList<S...>) -> decltype(auto) {
    // the result type from the list's first scheme: probing another would instantiate f for it
    using R = decltype(f.template operator()<std::tuple_element_t<0, std::tuple<S...>>>());
    if constexpr (std::is_void_v<R>) {
      const bool found = ((detail::scheme_name_matches(S::name, name) ? (f.template operator()<S>(), true) : false) || ...);
      if (!found) throw InvalidArgument(std::string(parameter), "unknown scheme '" + std::string(name) + "'; one of " + scheme_names<List>());
    } else {
      std::optional<R> out;
      ((detail::scheme_name_matches(S::name, name) && (out.emplace(f.template operator()<S>()), true)) || ...);
      if (!out) throw InvalidArgument(std::string(parameter), "unknown scheme '" + std::string(name) + "'; one of " + scheme_names<List>());
      return R(std::move(*out));
    }
  }(List{});
}
static_assert(history_levels<BSS>() == 0 && history_levels<MR_AB>() == 1 && history_levels<BDF3_BDF3E>() == 2);

}  // namespace alefsi
