#pragma once
/// \file physics/affine_forms.hpp
/// Element matrices of the Stokes-type bilinear forms on affine simplices, from reference
/// integrals computed once: no quadrature loop per cell.
///
/// On an affine cell K with Jacobian J (reference -> physical, columns x_i - x_0) the physical
/// gradient of a shape function is grad phi = J^-T grad^ phi^, so every integral of a product of
/// two gradients (or of a value and a gradient) is a contraction of a *reference* integral with
/// entries of J^-1 and det J:
///   int_K d_k phi_a d_l phi_b = det J  sum_{m,n} Jinv(m,k) S_ab(m,n) Jinv(n,l),
///       S_ab(m,n) = int_ref d^_m phi^_a d^_n phi^_b,
///   int_K psi_b d_i phi_a     = det J  sum_m E_ab(m) Jinv(m,i),  E_ab(m) = int_ref psi^_b d^_m phi^_a,
///   int_K phi_a phi_b         = det J  M_ab,                     M_ab = int_ref phi^_a phi^_b.
/// (det J signed, as in the quadrature kernels: w_q det J.) The reference integrals are formed
/// with a quadrature rule exact for them (degree 2k), once per (D, pair) and cached.
///
/// Storage is "structure of arrays" over the symmetric pairs a <= b (p = index of (a, b) in
/// row-major upper-triangle order), padded to a multiple of 4 lanes, so that the per-cell
/// contraction is D^3 + D^3 fused multiply-adds on short fixed-size arrays (Eigen vectorises
/// them). Flop counts per cell are given with each function (one multiply-add = 2 flops).
///
///     const auto& f = alefsi::AffineStokesForms<2, alefsi::TaylorHood>::get();
///     A.setZero();
///     f.add_viscous(Jinv, detJ, mu, A);             // 2 mu (D(u), D(v))
///     f.add_divergence(Jinv, detJ, -1.0, -1.0, A);  // -(p, div v) - (q, div u)
#include <array>

#include "alefsi/core/types.hpp"
#include "alefsi/fem/concepts.hpp"
#include "alefsi/fem/quadrature.hpp"

namespace alefsi {

namespace detail {
/// The pairs (a, b), 0 <= a <= b < N, in row-major upper-triangle order.
template <int N>
struct SymmetricPairs {
  std::array<int, N * (N + 1) / 2> a{}, b{};
  constexpr SymmetricPairs() {
    int p = 0;
    for (int i = 0; i < N; ++i)
      for (int j = i; j < N; ++j) {
        a[p] = i;
        b[p] = j;
        ++p;
      }
  }
};
template <int N>
inline constexpr SymmetricPairs<N> symmetric_pairs{};
}  // namespace detail

template <int D, ElementPair Pair>
class AffineStokesForms {
 public:
  using V = typename Pair::template Velocity<D>;
  using P = typename Pair::template Pressure<D>;
  static constexpr int nv = V::n_dofs, np = P::n_dofs, n_local = D * nv + np;
  static constexpr int n_pairs = nv * (nv + 1) / 2;             ///< velocity pairs a <= b
  static constexpr int n_lanes = (n_pairs + 3) / 4 * 4;          ///< padded
  static constexpr int n_vp = (nv * np + 3) / 4 * 4;             ///< velocity x pressure, padded
  using PairArray = Eigen::Array<Real, n_lanes, 1>;
  using VpArray = Eigen::Array<Real, n_vp, 1>;
  using LocalMat = Eigen::Matrix<Real, n_local, n_local>;
  /// Per velocity pair p: the physical integrals int_K d_k phi_a d_l phi_b, entry [k * D + l].
  using GradPairs = std::array<PairArray, D * D>;

  /// The cached instance (built on first use; thread-safe).
  static const AffineStokesForms& get() {
    static const AffineStokesForms forms;
    return forms;
  }

  /// The velocity nodes (a, b), a <= b, of pair index p.
  static constexpr int pair_a(int p) { return detail::symmetric_pairs<nv>.a[p]; }
  static constexpr int pair_b(int p) { return detail::symmetric_pairs<nv>.b[p]; }

  /// out[k D + l][p] = int_K d_k phi_a d_l phi_b for every pair p = (a <= b).
  /// 2 D^3 multiply-adds per lane (4 D^3 n_pairs flops, plus D^2 for det J J^-1).
  void gradient_pairs(const Mat<D>& Jinv, Real detJ, GradPairs& out) const {
    const Mat<D> Js = detJ * Jinv;
    std::array<PairArray, D * D> T;  // T(m, l) = sum_n S(m, n) Js(n, l)
    for (int m = 0; m < D; ++m)
      for (int l = 0; l < D; ++l) {
        PairArray t = S_[m * D] * Js(0, l);
        for (int n = 1; n < D; ++n) t += S_[m * D + n] * Js(n, l);
        T[m * D + l] = t;
      }
    for (int k = 0; k < D; ++k)
      for (int l = 0; l < D; ++l) {
        PairArray o = T[l] * Jinv(0, k);
        for (int m = 1; m < D; ++m) o += T[m * D + l] * Jinv(m, k);
        out[k * D + l] = o;
      }
  }

  /// A(D a + i, D b + j) += s int_K (grad phi_a . grad phi_b delta_ij + d_j phi_a d_i phi_b),
  /// i.e. the matrix of s (grad u + grad u^T, grad v) = 2 s (D(u), D(v)), from `gradient_pairs`.
  /// Fills both triangles (the block is symmetric). (D^2 + D) n_pairs flops.
  void add_viscous(const GradPairs& g, Real s, LocalMat& A) const {
    for (int p = 0; p < n_pairs; ++p) {
      const int a = pair_a(p), b = pair_b(p);
      Real tr = g[0][p];
      for (int k = 1; k < D; ++k) tr += g[k * D + k][p];
      tr *= s;
      for (int i = 0; i < D; ++i)
        for (int j = 0; j < D; ++j) {
          const Real v = (i == j ? tr : Real(0)) + s * g[j * D + i][p];
          A(D * a + i, D * b + j) += v;
          if (a != b) A(D * b + j, D * a + i) += v;
        }
    }
  }
  void add_viscous(const Mat<D>& Jinv, Real detJ, Real s, LocalMat& A) const {
    GradPairs g;
    gradient_pairs(Jinv, detJ, g);
    add_viscous(g, s, A);
  }

  /// A(D a + i, D nv + b) += s_vp int_K psi_b d_i phi_a   (the (p, div v) block, s_vp = -1), and
  /// A(D nv + b, D a + i) += s_pv int_K psi_b d_i phi_a   (the (q, div u) block).
  /// 2 D^2 nv np flops for the contraction, 4 D nv np for the two updates.
  void add_divergence(const Mat<D>& Jinv, Real detJ, Real s_vp, Real s_pv, LocalMat& A) const {
    std::array<VpArray, D> dv;  // dv[i][a np + b] = int_K psi_b d_i phi_a
    for (int i = 0; i < D; ++i) {
      VpArray t = E_[0] * (detJ * Jinv(0, i));
      for (int m = 1; m < D; ++m) t += E_[m] * (detJ * Jinv(m, i));
      dv[i] = t;
    }
    for (int a = 0; a < nv; ++a)
      for (int b = 0; b < np; ++b)
        for (int i = 0; i < D; ++i) {
          const Real v = dv[i][a * np + b];
          A(D * a + i, D * nv + b) += s_vp * v;
          A(D * nv + b, D * a + i) += s_pv * v;
        }
  }

  /// A(D nv + a, D nv + b) += s int_K grad psi_a . grad psi_b (pressure Laplacian, for PSPG):
  /// with G = det J J^-1 J^-T (symmetric), a contraction sum_{m,n} G(m,n) Sp_ab(m,n).
  void add_pressure_laplacian(const Mat<D>& Jinv, Real detJ, Real s, LocalMat& A) const {
    const Mat<D> G = (s * detJ) * (Jinv * Jinv.transpose());
    for (int a = 0; a < np; ++a)
      for (int b = a; b < np; ++b) {
        Real v = 0;
        for (int m = 0; m < D; ++m)
          for (int n = 0; n < D; ++n) v += G(m, n) * Sp_[a][b](m, n);
        A(D * nv + a, D * nv + b) += v;
        if (a != b) A(D * nv + b, D * nv + a) += v;
      }
  }

  /// A(D a + i, D b + i) += s int_K phi_a phi_b (velocity mass matrix, every component).
  void add_mass(Real detJ, Real s, LocalMat& A) const {
    const Real f = s * detJ;
    for (int p = 0; p < n_pairs; ++p) {
      const int a = pair_a(p), b = pair_b(p);
      const Real v = f * M_[p];
      for (int i = 0; i < D; ++i) {
        A(D * a + i, D * b + i) += v;
        if (a != b) A(D * b + i, D * a + i) += v;
      }
    }
  }

 private:
  AffineStokesForms() {
    const auto& rule = simplex_quadrature<D>(2 * V::degree);
    for (auto& s : S_) s.setZero();
    for (auto& e : E_) e.setZero();
    M_.setZero();
    for (auto& row : Sp_)
      for (auto& s : row) s.setZero();
    for (int q = 0; q < rule.size(); ++q) {
      const Real w = rule.weights[q];
      const auto phv = V::values(rule.points[q]);
      const auto dv = V::gradients(rule.points[q]);
      const auto php = P::values(rule.points[q]);
      const auto dp = P::gradients(rule.points[q]);
      for (int p = 0; p < n_pairs; ++p) {
        const int a = pair_a(p), b = pair_b(p);
        M_[p] += w * phv[a] * phv[b];
        for (int m = 0; m < D; ++m)
          for (int n = 0; n < D; ++n) S_[m * D + n][p] += w * dv(a, m) * dv(b, n);
      }
      for (int a = 0; a < nv; ++a)
        for (int b = 0; b < np; ++b)
          for (int m = 0; m < D; ++m) E_[m][a * np + b] += w * php[b] * dv(a, m);
      for (int a = 0; a < np; ++a)
        for (int b = 0; b < np; ++b) Sp_[a][b] += w * dp.row(a).transpose() * dp.row(b);
    }
  }

  std::array<PairArray, D * D> S_;  // S_[m D + n][p] = int_ref d^_m phi_a d^_n phi_b
  std::array<VpArray, D> E_;        // E_[m][a np + b] = int_ref psi_b d^_m phi_a
  PairArray M_;                     // M_[p] = int_ref phi_a phi_b
  std::array<std::array<Mat<D>, np>, np> Sp_;  // Sp_[a][b](m, n) = int_ref d^_m psi_a d^_n psi_b
};

}  // namespace alefsi
