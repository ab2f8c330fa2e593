#pragma once
/// \file fem/quadrature.hpp
/// Quadrature rules on the reference simplex {x_i >= 0, sum x_i <= 1} in D = 1, 2, 3.
///
/// Conventions
/// - D = 1 is the interval [0,1] (facet rules in 2D); D = 2 is the triangle with vertices
///   0, e_1, e_2 (also the facet rule in 3D); D = 3 the tetrahedron 0, e_1, e_2, e_3.
/// - `points` are Cartesian reference coordinates; `weights` include the measure, so they
///   sum to 1/D!, and  integral_{reference simplex} f  ~=  sum_q weights[q] * f(points[q]).
/// - `degree` is the true polynomial degree of the rule: it integrates every polynomial of
///   total degree <= `degree` exactly (up to round-off) and is not exact for some polynomial
///   of degree `degree + 1`.
/// - Every rule here has positive weights and all its points strictly inside the simplex.
///
/// Usage:
///     const auto& q = alefsi::simplex_quadrature<2>(2 * p);   // cached, cheap to call
///     Real s = 0;
///     for (int i = 0; i < q.size(); ++i) s += q.weights[i] * f(q.points[i]);
///
/// Rules provided by `simplex_quadrature<D>(degree)` (the fewest points we have, ties go to
/// the fully symmetric rule):
///   D = 1: Gauss-Legendre with ceil((degree+1)/2) points.
///   D = 2: degree 1: 1 point (centroid); 2: 3 points (Strang & Fix 1973);
///          3, 4: 6 points (Strang & Fix 1973 / Dunavant 1985); 5: 7 points (Radon 1948,
///          Stroud 1971 T2:5-1); 6: 12 points (Dunavant 1985); 7: 12 points, rotationally
///          symmetric only (Gatermann 1988); 8: 16, 9: 19, 10: 25 points (Dunavant 1985);
///          higher: collapsed Gauss-Jacobi, ceil((degree+1)/2)^2 points.
///   D = 3: degree 1: 1 point; 2: 4 points (Stroud 1971 T3:2-1, Keast 1986); 3: 8 points,
///          two 4-point orbits with equal weights (derived here from the moment equations);
///          4, 5: 14 points (the positive 14-point degree-5 rule, e.g. Walkington 2000);
///          6: 24 points (Keast 1986); higher: collapsed Gauss-Jacobi, ceil((degree+1)/2)^3.
/// Sources:
///   D. A. Dunavant, "High degree efficient symmetrical Gaussian quadrature rules for the
///     triangle", Int. J. Numer. Meth. Eng. 21 (1985) 1129-1148.
///   K. Gatermann, "The construction of symmetric cubature formulas for the square and the
///     triangle", Computing 40 (1988) 229-240.
///   P. Keast, "Moderate-degree tetrahedral quadrature formulas", Comput. Methods Appl. Mech.
///     Eng. 55 (1986) 339-348.
///   A. H. Stroud, "Approximate Calculation of Multiple Integrals", Prentice-Hall, 1971.
///   G. Strang, G. Fix, "An Analysis of the Finite Element Method", Prentice-Hall, 1973.
///   N. Walkington, "Quadrature on simplices of arbitrary dimension", CMU report, 2000.
///   G. H. Golub, J. H. Welsch, "Calculation of Gauss quadrature rules", Math. Comp. 23 (1969).
/// Closed forms are evaluated in code where they are short (degree-2 and degree-5 triangle,
/// degree-2 tetrahedron). The other tabulated parameters were re-solved from the moment
/// equations in 40-digit arithmetic, starting from the published values, and are given
/// to 21 significant digits; the tests check every rule's exactness and its exact degree.
#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <mutex>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi {

/// A quadrature rule on the reference D-simplex (see the file comment for conventions).
template <int D>
struct QuadratureRule {
  int degree = 0;              ///< exact for all polynomials of total degree <= degree
  std::vector<Vec<D>> points;  ///< reference coordinates
  std::vector<Real> weights;   ///< sum = 1/D!
  int size() const { return static_cast<int>(points.size()); }
};

/// Largest degree `simplex_quadrature` accepts.
inline constexpr int max_quadrature_degree = 40;

namespace detail {

/// Gauss-Jacobi rule on [-1,1] with weight (1-x)^alpha (1+x)^beta, alpha, beta >= 0:
/// Golub-Welsch (eigenvalues of the Jacobi matrix), then the nodes are polished by Newton on
/// the orthonormal polynomial p_n and the weights taken as 1 / sum_{k<n} p_k(x)^2.
/// Nodes ascending.
inline void gauss_jacobi(int n, Real alpha, Real beta, std::vector<Real>& x, std::vector<Real>& w) {
  ALEFSI_ASSERT(n >= 1 && alpha >= 0 && beta >= 0);
  const Real ab = alpha + beta;
  // Recurrence of the monic polynomials: p_{k+1} = (x - a_k) p_k - b_k p_{k-1}.
  std::vector<Real> a(n), sb(n + 1, 0.0);  // sb[k] = sqrt(b_k), k = 1..n
  for (int k = 0; k < n; ++k) {
    const Real s = 2 * k + ab;
    a[k] = k == 0 ? (beta - alpha) / (ab + 2) : (beta * beta - alpha * alpha) / (s * (s + 2));
  }
  for (int k = 1; k <= n; ++k) {
    const Real s = 2 * k + ab;
    sb[k] = std::sqrt(4 * k * (k + alpha) * (k + beta) * (k + ab) / (s * s * (s + 1) * (s - 1)));
  }
  const Real mu0 = std::pow(Real(2), ab + 1) * std::tgamma(alpha + 1) * std::tgamma(beta + 1) /
                   std::tgamma(ab + 2);
  x.assign(n, 0.0);
  w.assign(n, 0.0);
  if (n == 1) {
    x[0] = a[0];
  } else {
    VecX diag(n), sub(n - 1);
    for (int k = 0; k < n; ++k) diag[k] = a[k];
    for (int k = 0; k + 1 < n; ++k) sub[k] = sb[k + 1];
    Eigen::SelfAdjointEigenSolver<MatX> es;
    es.computeFromTridiagonal(diag, sub, Eigen::EigenvaluesOnly);
    for (int k = 0; k < n; ++k) x[k] = es.eigenvalues()[k];
  }
  // Orthonormal recurrence: sb[k+1] q_{k+1} = (x - a_k) q_k - sb[k] q_{k-1}, q_0 = 1/sqrt(mu0).
  auto eval = [&](Real t, Real& qn, Real& dqn, Real& sum_sq) {
    Real q0 = 0, q1 = 1 / std::sqrt(mu0), d0 = 0, d1 = 0;
    sum_sq = 0;
    for (int k = 0; k < n; ++k) {
      sum_sq += q1 * q1;
      const Real q2 = ((t - a[k]) * q1 - sb[k] * q0) / sb[k + 1];
      const Real d2 = (q1 + (t - a[k]) * d1 - sb[k] * d0) / sb[k + 1];
      q0 = q1, q1 = q2, d0 = d1, d1 = d2;
    }
    qn = q1, dqn = d1;
  };
  for (int i = 0; i < n; ++i) {
    Real qn, dqn, s;
    for (int it = 0; it < 3; ++it) {
      eval(x[i], qn, dqn, s);
      if (dqn != 0) x[i] -= qn / dqn;
    }
    eval(x[i], qn, dqn, s);
    w[i] = 1 / s;
  }
}

/// Gauss-Jacobi rule on [0,1] with weight (1-s)^alpha (n points, exact to degree 2n-1).
inline void gauss_jacobi_01(int n, int alpha, std::vector<Real>& s, std::vector<Real>& w) {
  gauss_jacobi(n, alpha, 0.0, s, w);
  const Real scale = std::ldexp(Real(1), -(alpha + 1));
  for (int i = 0; i < n; ++i) {
    s[i] = (1 + s[i]) / 2;
    w[i] *= scale;
  }
}

/// Symmetry orbits of barycentric points (the missing coordinate makes the sum 1).
enum class Orbit {
  s3,    ///< triangle centroid
  s21,   ///< (a, a, 1-2a), 3 points
  s111,  ///< (a, b, 1-a-b), 6 points
  c3,    ///< (a, b, 1-a-b) and its 2 cyclic shifts only, 3 points
  s4,    ///< tetrahedron centroid
  s31,   ///< (a, a, a, 1-3a), 4 points
  s22,   ///< (a, a, 1/2-a, 1/2-a), 6 points
  s211,  ///< (a, a, b, 1-2a-b), 12 points
};

/// One orbit of a tabulated rule; `w` is the weight of each point relative to the measure.
struct OrbitSpec {
  Orbit orbit;
  Real a, b, w;
};

/// Expands orbits into a rule (weights scaled by 1/D!).
template <int D>
QuadratureRule<D> rule_from_orbits(int degree, std::initializer_list<OrbitSpec> orbits) {
  QuadratureRule<D> rule;
  rule.degree = degree;
  for (const OrbitSpec& o : orbits) {
    std::array<Real, D + 1> l{};
    bool cyclic = false;
    const Real a = o.a, b = o.b;
    if constexpr (D == 2) {
      switch (o.orbit) {
        case Orbit::s3: l = {Real(1) / 3, Real(1) / 3, Real(1) / 3}; break;
        case Orbit::s21: l = {a, a, 1 - 2 * a}; break;
        case Orbit::s111: l = {a, b, 1 - a - b}; break;
        case Orbit::c3:
          l = {a, b, 1 - a - b};
          cyclic = true;
          break;
        default: ALEFSI_ASSERT(false);
      }
    } else {
      static_assert(D == 3, "tabulated rules exist for D = 2, 3 only");
      switch (o.orbit) {
        case Orbit::s4: l = {0.25, 0.25, 0.25, 0.25}; break;
        case Orbit::s31: l = {a, a, a, 1 - 3 * a}; break;
        case Orbit::s22: l = {a, a, Real(0.5) - a, Real(0.5) - a}; break;
        case Orbit::s211: l = {a, a, b, 1 - 2 * a - b}; break;
        default: ALEFSI_ASSERT(false);
      }
    }
    auto add = [&] {
      Vec<D> p;
      for (int i = 0; i < D; ++i) p[i] = l[i + 1];
      rule.points.push_back(p);
      rule.weights.push_back(o.w * reference_measure<D>);
    };
    if (cyclic) {
      for (int r = 0; r <= D; ++r) {
        add();
        std::rotate(l.begin(), l.begin() + 1, l.end());
      }
    } else {
      std::sort(l.begin(), l.end());
      do add();
      while (std::next_permutation(l.begin(), l.end()));
    }
  }
  return rule;
}

/// The tabulated triangle rule of the smallest degree >= `degree`, or an empty rule.
inline QuadratureRule<2> tabulated_triangle(int degree) {
  switch (degree) {
    case 0:
    case 1: return rule_from_orbits<2>(1, {{Orbit::s3, 0, 0, 1}});
    case 2: return rule_from_orbits<2>(2, {{Orbit::s21, Real(1) / 6, 0, Real(1) / 3}});
    case 3:
    case 4:
      return rule_from_orbits<2>(4, {{Orbit::s21, 0.445948490915964886318, 0, 0.223381589678011465695},
                                     {Orbit::s21, 0.0915762135097707434596, 0, 0.109951743655321867638}});
    case 5: {
      const Real r = std::sqrt(Real(15));
      return rule_from_orbits<2>(5, {{Orbit::s3, 0, 0, Real(9) / 40},
                                     {Orbit::s21, (6 - r) / 21, 0, (155 - r) / 1200},
                                     {Orbit::s21, (6 + r) / 21, 0, (155 + r) / 1200}});
    }
    case 6:
      return rule_from_orbits<2>(
          6, {{Orbit::s21, 0.0630890144915022283403, 0, 0.0508449063702068169209},
              {Orbit::s21, 0.249286745170910421292, 0, 0.116786275726379366025},
              {Orbit::s111, 0.0531450498448169473532, 0.310352451033784405417, 0.0828510756183735751936}});
    case 7:
      return rule_from_orbits<2>(
          7, {{Orbit::c3, 0.0552254566569266117375, 0.321502493851981822666, 0.0877628174288921100735},
              {Orbit::c3, 0.304726500868167195918, 0.0343243029450971464696, 0.0575500855699631714769},
              {Orbit::c3, 0.27771616697639178257, 0.206441498670016438173, 0.134986374019605548925},
              {Orbit::c3, 0.0623822650944021181737, 0.0675178670739160854426, 0.0530340563148725028575}});
    case 8:
      return rule_from_orbits<2>(
          8, {{Orbit::s3, 0, 0, 0.144315607677787168251},
              {Orbit::s21, 0.459292588292723156029, 0, 0.0950916342672846247939},
              {Orbit::s21, 0.170569307751760206622, 0, 0.103217370534718250282},
              {Orbit::s21, 0.0505472283170309754584, 0, 0.0324584976231980803109},
              {Orbit::s111, 0.00839477740995760533721, 0.263112829634638113422, 0.0272303141744349942648}});
    case 9:
      return rule_from_orbits<2>(
          9, {{Orbit::s3, 0, 0, 0.0971357962827988338192},
              {Orbit::s21, 0.489682519198737627784, 0, 0.0313347002271390705369},
              {Orbit::s21, 0.43708959149293663727, 0, 0.0778275410047742793167},
              {Orbit::s21, 0.188203535619032730241, 0, 0.0796477389272102530329},
              {Orbit::s21, 0.0447295133944527098651, 0, 0.0255776756586980312617},
              {Orbit::s111, 0.0368384120547362836348, 0.221962989160765695675, 0.0432835393772893772894}});
    case 10:
      return rule_from_orbits<2>(
          10, {{Orbit::s3, 0, 0, 0.0908179903827535800953},
               {Orbit::s21, 0.485577633383657377368, 0, 0.036725957756466704717},
               {Orbit::s21, 0.109481575485037054795, 0, 0.0453210594355279347826},
               {Orbit::s111, 0.141707219414879954757, 0.307939838764120950165, 0.0727579168454201086043},
               {Orbit::s111, 0.025003534762686386074, 0.246672560639902693917, 0.0283272425310574848367},
               {Orbit::s111, 0.00954081540029945758015, 0.0668032510122002657735, 0.00942166696373282345993}});
    default: return {};
  }
}

/// The tabulated tetrahedron rule of the smallest degree >= `degree`, or an empty rule.
inline QuadratureRule<3> tabulated_tetrahedron(int degree) {
  switch (degree) {
    case 0:
    case 1: return rule_from_orbits<3>(1, {{Orbit::s4, 0, 0, 1}});
    case 2: return rule_from_orbits<3>(2, {{Orbit::s31, (5 - std::sqrt(Real(5))) / 20, 0, 0.25}});
    case 3:
      return rule_from_orbits<3>(3, {{Orbit::s31, 0.1129567945125110286951, 0, 0.125},
                                     {Orbit::s31, 0.3288616499302029104003, 0, 0.125}});
    case 4:
    case 5:
      return rule_from_orbits<3>(5, {{Orbit::s31, 0.0927352503108912264023, 0, 0.0734930431163619495437},
                                     {Orbit::s31, 0.310885919263300609797, 0, 0.112687925718015850799},
                                     {Orbit::s22, 0.0455037041256496494919, 0, 0.0425460207770814664381}});
    case 6:
      return rule_from_orbits<3>(
          6, {{Orbit::s31, 0.214602871259152029289, 0, 0.0399227502581674920997},
              {Orbit::s31, 0.0406739585346113531156, 0, 0.010077211055320642948},
              {Orbit::s31, 0.322337890142275510344, 0, 0.0553571815436547220952},
              {Orbit::s211, 0.0636610018750175252992, 0.269672331458315808034, Real(27) / 560}});
    default: return {};
  }
}

}  // namespace detail

/// Gauss-Legendre rule with n >= 1 points on [0,1] (degree 2n-1).
inline QuadratureRule<1> gauss_legendre(int n) {
  ALEFSI_CHECK_ARG(n >= 1, "n", "need at least one point, got ", n);
  std::vector<Real> s, w;
  detail::gauss_jacobi_01(n, 0, s, w);
  QuadratureRule<1> rule;
  rule.degree = 2 * n - 1;
  for (int i = 0; i < n; ++i) {
    rule.points.push_back(Vec<1>::Constant(s[i]));
    rule.weights.push_back(w[i]);
  }
  return rule;
}

/// Collapsed (Duffy / Stroud conical-product) rule with n^D points, degree 2n-1:
/// x_1 = s_1, x_2 = (1-s_1) s_2, x_3 = (1-s_1)(1-s_2) s_3, where s_k runs over the n-point
/// Gauss-Jacobi rule on [0,1] for the weight (1-s)^(D-k). Positive weights, interior points.
template <int D>
QuadratureRule<D> collapsed_gauss_jacobi(int points_per_direction) {
  static_assert(D >= 1 && D <= 3, "D must be 1, 2 or 3");
  const int n = points_per_direction;
  ALEFSI_CHECK_ARG(n >= 1, "points_per_direction", "need at least one point, got ", n);
  std::array<std::vector<Real>, D> s, w;
  for (int k = 0; k < D; ++k) detail::gauss_jacobi_01(n, D - 1 - k, s[k], w[k]);
  QuadratureRule<D> rule;
  rule.degree = 2 * n - 1;
  int total = 1;
  for (int k = 0; k < D; ++k) total *= n;
  rule.points.reserve(total);
  rule.weights.reserve(total);
  for (int flat = 0; flat < total; ++flat) {
    Vec<D> p;
    Real weight = 1, rest = 1;  // rest = prod_{j<k} (1 - s_j)
    int r = flat;
    std::array<int, D> idx{};
    for (int k = D - 1; k >= 0; --k) idx[k] = r % n, r /= n;
    for (int k = 0; k < D; ++k) {
      const Real sk = s[k][idx[k]];
      p[k] = rest * sk;
      rest *= 1 - sk;
      weight *= w[k][idx[k]];
    }
    rule.points.push_back(p);
    rule.weights.push_back(weight);
  }
  return rule;
}

namespace detail {

template <int D>
QuadratureRule<D> build_simplex_quadrature(int degree) {
  if constexpr (D == 2) {
    QuadratureRule<2> t = tabulated_triangle(degree);
    if (t.size() > 0) return t;
  } else if constexpr (D == 3) {
    QuadratureRule<3> t = tabulated_tetrahedron(degree);
    if (t.size() > 0) return t;
  }
  const int n = std::max(1, (degree + 2) / 2);  // ceil((degree + 1) / 2)
  if constexpr (D == 1) return gauss_legendre(n);
  else return collapsed_gauss_jacobi<D>(n);
}

template <int D>
struct QuadratureCache {
  std::array<std::once_flag, max_quadrature_degree + 1> once;
  std::array<QuadratureRule<D>, max_quadrature_degree + 1> rules;
};

}  // namespace detail

/// The rule with the fewest points we provide that is exact to at least `degree`
/// (0 <= degree <= max_quadrature_degree). Built once on first use and cached: the
/// reference stays valid for the program's life, and concurrent calls are safe.
template <int D>
const QuadratureRule<D>& simplex_quadrature(int degree) {
  static_assert(D >= 1 && D <= 3, "D must be 1, 2 or 3");
  ALEFSI_CHECK_ARG(degree >= 0 && degree <= max_quadrature_degree, "degree", "must be in [0, ",
                   max_quadrature_degree, "], got ", degree);
  static detail::QuadratureCache<D> cache;
  std::call_once(cache.once[degree],
                 [degree] { cache.rules[degree] = detail::build_simplex_quadrature<D>(degree); });
  return cache.rules[degree];
}

}  // namespace alefsi
