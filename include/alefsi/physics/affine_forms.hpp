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
/// `ReferenceTables` holds the element values and reference gradients at the points of a rule,
/// for the terms still integrated by quadrature (body force, GLS).
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
#include <vector>

#include "alefsi/core/types.hpp"
#include "alefsi/fem/concepts.hpp"
#include "alefsi/fem/lagrange.hpp"
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

/// Element tables of a velocity/pressure pair at the points of a quadrature rule on the
/// reference simplex (affine cells: physical gradients are reference gradients times J^-1).
template <int D, ElementPair Pair>
struct ReferenceTables {
  using V = typename Pair::template Velocity<D>;
  using P = typename Pair::template Pressure<D>;
  explicit ReferenceTables(int degree) : rule(&simplex_quadrature<D>(degree)) {
    for (int q = 0; q < rule->size(); ++q) {
      phi_v.push_back(V::values(rule->points[q]));
      dphi_v.push_back(V::gradients(rule->points[q]));
      phi_p.push_back(P::values(rule->points[q]));
      dphi_p.push_back(P::gradients(rule->points[q]));
    }
  }
  const QuadratureRule<D>* rule;
  std::vector<typename V::Values> phi_v;
  std::vector<typename V::Gradients> dphi_v;
  std::vector<typename P::Values> phi_p;
  std::vector<typename P::Gradients> dphi_p;
};

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
    const auto dv = divergence(Jinv, detJ);
    for (int a = 0; a < nv; ++a)
      for (int b = 0; b < np; ++b)
        for (int i = 0; i < D; ++i) {
          const Real v = dv[i][a * np + b];
          A(D * a + i, D * nv + b) += s_vp * v;
          A(D * nv + b, D * a + i) += s_pv * v;
        }
  }

  /// dv[i][a np + b] = int_K psi_b d_i phi_a. 2 D^2 nv np flops.
  std::array<VpArray, D> divergence(const Mat<D>& Jinv, Real detJ) const {
    std::array<VpArray, D> dv;
    for (int i = 0; i < D; ++i) {
      VpArray t = E_[0] * (detJ * Jinv(0, i));
      for (int m = 1; m < D; ++m) t += E_[m] * (detJ * Jinv(m, i));
      dv[i] = t;
    }
    return dv;
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


/// The velocity-velocity block of the Navier–Stokes Jacobian on affine simplices, from
/// reference integrals computed once (exact rule), no quadrature per cell. Every quantity is an
/// array over *all* velocity pairs (a, b), lane a + nv b (padded to 8 lanes), i.e. an nv x nv
/// column-major matrix per component pair (i, j): the block is formed with whole-array
/// operations and written into the element matrix once.
///   gradient pairs  G_kl(a, b) = int_K d_k phi_a d_l phi_b = det J sum_mn Jinv(m,k) S_ab(m,n) Jinv(n,l)
///   mass            M(a, b)    = int_K phi_a phi_b = det J M^_ab
///   convection      C(a, b)    = int_K phi_a (a . grad phi_b) = sum_{c,m} T_ab(c, m) at_(c,m),
///       T_ab(c, m) = int_ref phi^_a phi^_c d^_m phi^_b,   at_(c,m) = det J sum_j Jinv(m, j) a_c,j,
///     for a convecting velocity a of the velocity space with nodal values a_c (the P1 mesh
///     velocity is interpolated into it exactly, `p1_at_nodes`): nv^3 D multiply-adds.
///   Newton term     N_ij(a, b) = int_K phi_a phi_b d_j u_i: the gradient of a velocity of
///     degree <= 2 is linear, so it equals its P1 interpolant sum_k (d_j u_i)(x_k) psi_k and
///     N_ij(a, b) = det J sum_k (d_j u_i)(x_k) M3_ab(k),  M3_ab(k) = int_ref phi^_a phi^_b psi^_k.
///
///     const auto& f = alefsi::AffineNavierStokesForms<2, alefsi::TaylorHood>::get();
///     typename decltype(f)::Block g;  f.gradient_pairs(Jinv, detJ, g);
///     typename decltype(f)::AbArray c; f.convection(Jinv, detJ, a_nodal, c);
template <int D, ElementPair Pair>
class AffineNavierStokesForms {
 public:
  using V = typename Pair::template Velocity<D>;
  static constexpr int nv = V::n_dofs;
  static constexpr int n_ab = (nv * nv + 7) / 8 * 8;  ///< all pairs (a, b), lane a + nv b, padded
  using AbArray = Eigen::Array<Real, n_ab, 1>;
  /// One AbArray per component pair: [i D + j].
  using Block = std::array<AbArray, D * D>;
  using Nodal = Eigen::Matrix<Real, nv, D>;  ///< nodal values of a vector field, row = node
  /// The physical gradient of a velocity field at the D + 1 vertices: [k](i, j) = d_j u_i (x_k).
  using VertexGradients = std::array<Mat<D>, D + 1>;

  static const AffineNavierStokesForms& get() {
    static const AffineNavierStokesForms forms;
    return forms;
  }

  /// psi_k(node c) for the P1 basis psi_k at the velocity nodes (row c): the nodal values of a
  /// P1 field with vertex values W are p1_at_nodes() * W.
  const Eigen::Matrix<Real, nv, D + 1>& p1_at_nodes() const { return p1_nodes_; }
  /// The reference mass integrals int_ref phi^_a phi^_b (times det J: the cell's).
  const AbArray& reference_mass() const { return M_; }

  /// out[k D + l](a, b) = int_K d_k phi_a d_l phi_b. 2 D^3 array multiply-adds.
  void gradient_pairs(const Mat<D>& Jinv, Real detJ, Block& out) const {
    const Mat<D> Js = detJ * Jinv;
    Block T;  // T(m, l) = sum_n S(m, n) Js(n, l)
    for (int m = 0; m < D; ++m)
      for (int l = 0; l < D; ++l) {
        AbArray t = S_[m * D] * Js(0, l);
        for (int n = 1; n < D; ++n) t += S_[m * D + n] * Js(n, l);
        T[m * D + l] = t;
      }
    for (int k = 0; k < D; ++k)
      for (int l = 0; l < D; ++l) {
        AbArray o = T[l] * Jinv(0, k);
        for (int m = 1; m < D; ++m) o += T[m * D + l] * Jinv(m, k);
        out[k * D + l] = o;
      }
  }

  /// C(a, b) = int_K phi_a (a . grad phi_b) for the field with nodal values `a` (rows).
  /// nv D^2 + nv D array multiply-adds.
  void convection(const Mat<D>& Jinv, Real detJ, const Nodal& a, AbArray& C) const {
    const Eigen::Matrix<Real, D, nv> at = (detJ * Jinv) * a.transpose();  // at(m, c)
    C = T_[0] * at(0, 0);
    for (int k = 1; k < nv * D; ++k) C += T_[k] * at(k % D, k / D);
  }

  /// [k](i, j) = d_j u_i at reference vertex k, for the velocity with nodal values U (rows).
  VertexGradients vertex_gradients(const Mat<D>& Jinv, const Nodal& U) const {
    VertexGradients g;
    for (int k = 0; k <= D; ++k) g[k] = (U.transpose() * dphi_vertex_[k]) * Jinv;
    return g;
  }

  /// out[i D + j](a, b) = int_K phi_a phi_b d_j u_i from `vertex_gradients`.
  /// D^2 (D + 1) array multiply-adds.
  void newton(const VertexGradients& g, Real detJ, Block& out) const {
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) {
        AbArray n = M3_[0] * (detJ * g[0](i, j));
        for (int k = 1; k <= D; ++k) n += M3_[k] * (detJ * g[k](i, j));
        out[i * D + j] = n;
      }
  }

 private:
  AffineNavierStokesForms() {
    const auto& rule = simplex_quadrature<D>(3 * V::degree);  // phi phi dphi: 3k - 1; phi phi psi: 2k + 1
    for (auto& t : T_) t.setZero();
    for (auto& m : M3_) m.setZero();
    for (auto& t : S_) t.setZero();
    M_.setZero();
    for (int q = 0; q < rule.size(); ++q) {
      const Real w = rule.weights[q];
      const auto phv = V::values(rule.points[q]);
      const auto dv = V::gradients(rule.points[q]);
      const auto psi = P1<D>::values(rule.points[q]);
      for (int a = 0; a < nv; ++a)
        for (int b = 0; b < nv; ++b) {
          const int ab = a + nv * b;
          M_[ab] += w * phv[a] * phv[b];
          for (int m = 0; m < D; ++m)
            for (int n = 0; n < D; ++n) S_[m * D + n][ab] += w * dv(a, m) * dv(b, n);
          for (int k = 0; k <= D; ++k) M3_[k][ab] += w * phv[a] * phv[b] * psi[k];
          for (int c = 0; c < nv; ++c)
            for (int m = 0; m < D; ++m) T_[c * D + m][ab] += w * phv[a] * phv[c] * dv(b, m);
        }
    }
    for (int c = 0; c < nv; ++c) p1_nodes_.row(c) = P1<D>::values(V::node(c)).transpose();
    for (int k = 0; k <= D; ++k) dphi_vertex_[k] = V::gradients(reference_vertex<D>(k));
  }

  std::array<AbArray, D * D> S_;      // S_[m D + n](a, b) = int_ref d^_m phi_a d^_n phi_b
  AbArray M_;                         // M_(a, b) = int_ref phi_a phi_b
  std::array<AbArray, nv * D> T_;     // T_[c D + m](a, b) = int_ref phi_a phi_c d^_m phi_b
  std::array<AbArray, D + 1> M3_;     // M3_[k](a, b) = int_ref phi_a phi_b psi_k
  Eigen::Matrix<Real, nv, D + 1> p1_nodes_;
  std::array<typename V::Gradients, D + 1> dphi_vertex_;
};

}  // namespace alefsi
