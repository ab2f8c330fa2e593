#pragma once
// Test oracles: the Stokes and ALE Navier–Stokes element kernels computed by quadrature, every
// term at every point (the library's former kernels). tests/fem/test_assembly.cpp compares the
// library's kernels with them cell by cell, bench/bench_assembly.cpp times them for reference.
// Not part of the library (not installed); namespace alefsi::testing.
//
// The Galerkin terms are integrated here point by point, independently of the fast kernels'
// reference integrals. The GLS terms (SUPG, PSPG) are the former kernel's loops, from which
// physics/stabilisation.hpp's policy was extracted: the same formulas, branching here on the
// pair's tag. For them a comparison checks that the policy kept the former kernel's terms, not
// the terms themselves (an independent check, e.g. against finite differences of the residual,
// is still owed). The parameter tau is shared (alefsi::gls_tau).
// Pairs: any `ElementPair` whose `Stabilisation` is NoStabilisation or GlsStabilisation.
//
//     alefsi::testing::StokesQuadratureKernel<2, alefsi::P1P1Gls> ref(space, mu, force);
//     ref.cell(c, u, A, r);   // as StokesKernel::cell
#include <cmath>
#include <concepts>
#include <utility>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/physics/affine_forms.hpp"
#include "alefsi/physics/navier_stokes.hpp"
#include "alefsi/physics/stabilisation.hpp"
#include "alefsi/physics/stokes.hpp"

namespace alefsi::testing {

namespace detail {
/// True for GLS, false for no stabilisation; any other tag has no oracle.
template <ElementPair Pair>
constexpr bool stabilisation_is_gls() {
  using S = typename Pair::Stabilisation;
  static_assert(std::same_as<S, NoStabilisation> || std::same_as<S, GlsStabilisation>,
                "the oracle kernels know no stabilisation but NoStabilisation and GlsStabilisation");
  return std::same_as<S, GlsStabilisation>;
}
template <ElementPair Pair>
inline constexpr bool oracle_gls = stabilisation_is_gls<Pair>();
}  // namespace detail

/// The Stokes element kernel by quadrature (degree 2k + 2, every term at every point, PSPG
/// included): the oracle `StokesKernel` is tested against (same interface, same results to
/// round-off, 5-10x slower).
template <int D, ElementPair Pair>
class StokesQuadratureKernel {
  static constexpr bool gls = detail::oracle_gls<Pair>;

 public:
  using Space = MixedSpace<D, Pair>;
  using V = typename Space::VelocityElement;
  using P = typename Space::PressureElement;
  static constexpr int nv = V::n_dofs, np = P::n_dofs, n_local = Space::n_local;
  using LocalVec = Eigen::Matrix<Real, n_local, 1>;
  using LocalMat = Eigen::Matrix<Real, n_local, n_local>;

  /// `force` may be empty (no body force).
  StokesQuadratureKernel(const Space& space, Real mu, VectorFunction<D> force = {}, Real c1 = 4.0)
      : space_(&space), mu_(mu), c1_(c1), f_(std::move(force)), tab_(2 * V::degree + 2) {
    ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "viscosity must be positive and finite, got ", mu);
    ALEFSI_CHECK_ARG(c1 > 0, "c1", "GLS constant must be positive");
  }

  /// GLS/PSPG parameter of cell c (0 for stable pairs): the library's `gls_tau`, steady.
  Real tau(Index c) const {
    if constexpr (!gls) return 0;
    return gls_tau({.h = space_->mesh().diameter(c), .mu = mu_}, c1_);
  }

  void cell(Index c, const LocalVec& u, LocalMat& A, LocalVec& r) const {
    const auto& mesh = space_->mesh();
    const Mat<D> J = mesh.jacobian(c);
    const Mat<D> Jinv = J.inverse();
    const Real detJ = J.determinant();
    const Vec<D> x0 = mesh.node(mesh.cell(c)[0]);
    const Real tau_c = tau(c);
    A.setZero();
    LocalVec F = LocalVec::Zero();
    const auto& rule = *tab_.rule;
    for (int q = 0; q < rule.size(); ++q) {
      const Real w = rule.weights[q] * detJ;
      const Eigen::Matrix<Real, nv, D> G = tab_.dphi_v[q] * Jinv;  // physical gradients
      const auto& phv = tab_.phi_v[q];
      const auto& php = tab_.phi_p[q];
      for (int a = 0; a < nv; ++a)
        for (int b = 0; b < nv; ++b) {
          const Real gg = w * mu_ * G.row(a).dot(G.row(b));
          for (int i = 0; i < D; ++i) {
            A(D * a + i, D * b + i) += gg;
            for (int j = 0; j < D; ++j) A(D * a + i, D * b + j) += w * mu_ * G(a, j) * G(b, i);
          }
        }
      for (int a = 0; a < nv; ++a)
        for (int b = 0; b < np; ++b)
          for (int i = 0; i < D; ++i) {
            const Real bdiv = -w * php[b] * G(a, i);
            A(D * a + i, D * nv + b) += bdiv;
            A(D * nv + b, D * a + i) += bdiv;
          }
      Vec<D> fq = Vec<D>::Zero();
      if (f_) {
        fq = f_(x0 + J * rule.points[q]);
        for (int a = 0; a < nv; ++a)
          for (int i = 0; i < D; ++i) F[D * a + i] += w * fq[i] * phv[a];
      }
      if constexpr (gls) {
        const Eigen::Matrix<Real, np, D> Gp = tab_.dphi_p[q] * Jinv;
        for (int a = 0; a < np; ++a) {
          for (int b = 0; b < np; ++b) A(D * nv + a, D * nv + b) -= w * tau_c * Gp.row(a).dot(Gp.row(b));
          F[D * nv + a] -= w * tau_c * fq.dot(Gp.row(a));
        }
      }
    }
    r = A * u - F;
  }

 private:
  const Space* space_;
  Real mu_, c1_;
  VectorFunction<D> f_;
  ReferenceTables<D, Pair> tab_;
};

/// The ALE Navier–Stokes kernel by quadrature of degree 3k + 1, every term at every point
/// (SUPG and PSPG included): the oracle `AleNavierStokesKernel` is tested against (same
/// interface, same results to round-off, several times slower).
template <int D, ElementPair Pair, bool Convection = true>
class AleNavierStokesQuadratureKernel {
  static constexpr bool gls = detail::oracle_gls<Pair>;

 public:
  using Space = MixedSpace<D, Pair>;
  using V = typename Space::VelocityElement;
  using P = typename Space::PressureElement;
  static constexpr int nv = V::n_dofs, np = P::n_dofs, n_local = Space::n_local;
  using LocalVec = Eigen::Matrix<Real, n_local, 1>;
  using LocalMat = Eigen::Matrix<Real, n_local, n_local>;

  AleNavierStokesQuadratureKernel(const Space& space, Real rho, Real mu, Linearisation lin = Linearisation::newton)
      : space_(&space), rho_(rho), mu_(mu), lin_(lin), tab_(3 * V::degree + 1) {
    ALEFSI_CHECK_ARG(rho > 0 && std::isfinite(rho), "rho", "fluid density must be positive and finite, got ", rho);
    ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "viscosity must be positive and finite, got ", mu);
  }

  void set_step(const StepInputs<D>& s) { s_ = s; }
  Linearisation linearisation() const { return lin_; }

  /// The library's `gls_tau` of cell c for the convecting velocity a_star.
  Real tau(Index c, const Vec<D>& a_star) const {
    return gls_tau({.h = space_->mesh().diameter(c), .mu = mu_, .rho = rho_, .dt = s_.dt,
                    .a_norm = Convection ? a_star.norm() : 0.0});
  }

  void cell(Index c, const LocalVec& u, LocalMat& A, LocalVec& r) const {
    const auto& mesh = space_->mesh();
    const Mat<D> J = mesh.jacobian(c);
    const Mat<D> Jinv = J.inverse();
    const Real detJ = J.determinant();
    const Vec<D> x0 = mesh.node(mesh.cell(c)[0]);
    const auto& fd = space_->cell_field_dofs(c);
    const Real th = s_.theta, dt = s_.dt, a0 = s_.a0;
    // local nodal data
    Eigen::Matrix<Real, nv, D> U, Uth, H, Us;
    Eigen::Matrix<Real, np, 1> Pl;
    for (int a = 0; a < nv; ++a)
      for (int i = 0; i < D; ++i) {
        const int l = D * a + i;
        U(a, i) = u[l];
        const Real un = s_.previous ? (*s_.previous)[fd[l]] : u[l];
        Uth(a, i) = th * u[l] + (1 - th) * un;
        H(a, i) = s_.history ? (*s_.history)[fd[l]] : 0.0;
        Us(a, i) = s_.extrapolated ? (*s_.extrapolated)[fd[l]] : Uth(a, i);
      }
    for (int b = 0; b < np; ++b) Pl[b] = u[D * nv + b];
    Eigen::Matrix<Real, D + 1, D> Vm = Eigen::Matrix<Real, D + 1, D>::Zero();  // mesh velocity at vertices
    if (s_.mesh_velocity)
      for (int a = 0; a <= D; ++a) Vm.row(a) = (*s_.mesh_velocity)[mesh.cell(c)[a]].transpose();
    Real tau_c = 0;
    if constexpr (gls) {
      const Vec<D> xi_c = Vec<D>::Constant(1.0 / (D + 1));
      const auto phic = V::values(xi_c);
      Vec<D> a_star = (Us.transpose() * phic) - Vm.transpose() * P1<D>::values(xi_c);
      tau_c = tau(c, a_star);
    }
    A.setZero();
    r.setZero();
    const auto& rule = *tab_.rule;
    for (int q = 0; q < rule.size(); ++q) {
      const Real w = rule.weights[q] * detJ;
      const Eigen::Matrix<Real, nv, D> G = tab_.dphi_v[q] * Jinv;
      const auto& phv = tab_.phi_v[q];
      const auto& php = tab_.phi_p[q];
      const Vec<D> uq = U.transpose() * phv;
      const Vec<D> uthq = Uth.transpose() * phv;
      const Vec<D> hq = H.transpose() * phv;
      const Mat<D> gu = Uth.transpose() * G;  // (i, j) = d u_th,i / d x_j
      const Real pq = php.dot(Pl);
      Vec<D> fq = Vec<D>::Zero();
      if (s_.force) fq = s_.force(x0 + J * rule.points[q]);
      Vec<D> aq = Vec<D>::Zero();
      if constexpr (Convection) {
        const Vec<D> vq = Vm.transpose() * P1<D>::values(rule.points[q]);
        aq = (lin_ == Linearisation::newton ? uthq : Vec<D>(Us.transpose() * phv)) - vq;
      }
      const Eigen::Matrix<Real, nv, 1> adg = G * aq;  // a . grad phi_a
      const Vec<D> dtu = (a0 * uq + hq) / dt;
      const Vec<D> conv = gu * aq;
      const Real divu = gu.trace();
      // --- residual -----------------------------------------------------------------------
      const Mat<D> sigma = mu_ * (gu + gu.transpose());
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < D; ++i)
          r[D * a + i] += w * (rho_ * (dtu[i] + conv[i]) * phv[a] + sigma.row(i).dot(G.row(a)) - pq * G(a, i) -
                               fq[i] * phv[a]);
      for (int b = 0; b < np; ++b) r[D * nv + b] -= w * php[b] * divu;
      // --- Jacobian -------------------------------------------------------------------------
      for (int a = 0; a < nv; ++a)
        for (int b = 0; b < nv; ++b) {
          const Real mass = w * rho_ * a0 / dt * phv[a] * phv[b];
          const Real visc = w * th * mu_ * G.row(a).dot(G.row(b));
          const Real adv = Convection ? w * th * rho_ * adg[b] * phv[a] : 0.0;
          for (int i = 0; i < D; ++i) {
            A(D * a + i, D * b + i) += mass + visc + adv;
            for (int j = 0; j < D; ++j) {
              A(D * a + i, D * b + j) += w * th * mu_ * G(a, j) * G(b, i);
              if (Convection && lin_ == Linearisation::newton)
                A(D * a + i, D * b + j) += w * th * rho_ * phv[b] * gu(i, j) * phv[a];
            }
          }
        }
      for (int a = 0; a < nv; ++a)
        for (int b = 0; b < np; ++b)
          for (int i = 0; i < D; ++i) {
            A(D * a + i, D * nv + b) -= w * php[b] * G(a, i);
            A(D * nv + b, D * a + i) -= w * th * php[b] * G(a, i);
          }
      // --- GLS: SUPG + PSPG (P1 velocity: no second derivatives) ------------------------------
      if constexpr (gls) {
        const Eigen::Matrix<Real, np, D> Gp = tab_.dphi_p[q] * Jinv;
        const Vec<D> gp = Gp.transpose() * Pl;
        const Vec<D> R = rho_ * (dtu + conv) + gp - fq;
        const Real wt = w * tau_c;
        // dR_i / du_(b,j) = rho (a0/dt phi_b delta_ij + th [delta_ij adg_b + (newton) phi_b gu_ij])
        auto dR = [&](int i, int b, int j) {
          Real s = (i == j) ? rho_ * (a0 / dt * phv[b] + (Convection ? th * adg[b] : 0.0)) : 0.0;
          if (Convection && lin_ == Linearisation::newton) s += rho_ * th * phv[b] * gu(i, j);
          return s;
        };
        for (int a = 0; a < nv; ++a)
          for (int i = 0; i < D; ++i) {
            if constexpr (Convection) {
              r[D * a + i] += wt * rho_ * adg[a] * R[i];
              for (int b = 0; b < nv; ++b)
                for (int j = 0; j < D; ++j) {
                  Real s = wt * rho_ * adg[a] * dR(i, b, j);
                  if (lin_ == Linearisation::newton) s += wt * rho_ * th * phv[b] * G(a, j) * R[i];
                  A(D * a + i, D * b + j) += s;
                }
              for (int b = 0; b < np; ++b) A(D * a + i, D * nv + b) += wt * rho_ * adg[a] * Gp(b, i);
            }
          }
        for (int a = 0; a < np; ++a) {
          r[D * nv + a] -= wt * R.dot(Gp.row(a));
          for (int b = 0; b < nv; ++b)
            for (int j = 0; j < D; ++j) {
              Real s = 0;
              for (int i = 0; i < D; ++i) s += dR(i, b, j) * Gp(a, i);
              A(D * nv + a, D * b + j) -= wt * s;
            }
          for (int b = 0; b < np; ++b) A(D * nv + a, D * nv + b) -= wt * Gp.row(a).dot(Gp.row(b));
        }
      }
    }
  }

 private:
  const Space* space_;
  Real rho_, mu_;
  Linearisation lin_;
  ReferenceTables<D, Pair> tab_;
  StepInputs<D> s_;
};

}  // namespace alefsi::testing
