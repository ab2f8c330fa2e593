#pragma once
/// \file physics/navier_stokes.hpp
/// The ALE Navier–Stokes element kernel: residual and exact Jacobian of one time step
/// (eq. 10 and 12 after the time discretisation of section 4).
///
/// The kernel is evaluated on the geometry X^{n+theta} (the stepper sets the mesh coordinates)
/// with unknowns u^{n+1} (velocity) and p^{n+theta} (pressure). With
///   u_th = theta u^{n+1} + (1 - theta) u^n,   D_t u = (a_0 u^{n+1} + h) / dt,
///   h = sum_{k >= 1} a_k u^{n+1-k} (the BDF history, nodal), a = c - v,
/// where v is the mesh velocity at n+theta (P1, nodal) and c the convecting velocity: c = u_th
/// for the fully implicit (Newton) form, c = u* (the scheme's extrapolation) for the
/// semi-implicit form, the momentum and continuity residuals for test functions (w, q) are
///   rho (D_t u + (a . grad) u_th, w) + 2 mu (D(u_th), D(w)) - (p, div w) - (f, w)
///     + sum_K tau_K (R, rho (a . grad) w)_K                                [SUPG]
///   -(q, div u_th) - sum_K tau_K (R, grad q)_K                             [PSPG]
/// with the strong residual R = rho (D_t u + (a . grad) u_th) + grad p - f (P1 velocities have no
/// second derivatives; GLS terms only for stabilised pairs) and
///   tau_K = [ (2 rho / dt)^2 + (2 rho |a*| / h_K)^2 + (4 mu / h_K^2)^2 ]^(-1/2),
/// a* = u* - v at the cell centroid (extrapolated, so tau does not depend on the unknowns and
/// the Jacobian below is exact), h_K the longest edge. With no convection and dt -> infinity
/// tau reduces to the Stokes value h^2 / (4 mu); as dt -> 0, tau -> dt / (2 rho), so the
/// stabilised operator depends on dt and a temporal error is dt^p F(tau(dt)), F the error
/// constant at frozen tau (measured rates p + dlnF/dlntau; see the P1/P1-GLS temporal-order
/// test in tests/physics/test_ale.cpp).
/// `Convection = false` drops every convective term at compile time (unsteady Stokes).
#include <cmath>
#include <functional>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/physics/affine_forms.hpp"
#include "alefsi/physics/stokes.hpp"

namespace alefsi {

enum class Linearisation { newton, semi_implicit };

template <int D>
struct StepInputs {
  Real dt = 1, theta = 1, a0 = 1;
  const VecX* history = nullptr;     ///< field vector, velocity entries: sum_{k>=1} a_k u^{n+1-k}
  const VecX* previous = nullptr;    ///< u^n (field vector), used when theta < 1
  const VecX* extrapolated = nullptr;///< u* (field vector): convecting velocity / tau
  const std::vector<Vec<D>>* mesh_velocity = nullptr;  ///< per mesh node, at n+theta
  VectorFunction<D> force;           ///< body force per unit volume at t^{n+theta} (may be empty)
};

/// The ALE Navier–Stokes element kernel (affine cells).
/// - Mass, viscous, convection, Newton and divergence terms of the Jacobian and of the residual
///   from precomputed reference integrals (`AffineNavierStokesForms`, `AffineStokesForms`), no
///   quadrature: the velocity block is formed per component pair as nv x nv arrays and
///   written into A once; the residual of these terms is their matrix times (u_th, p), plus
///   the mass matrix times (a0 u + h) / dt.
/// - GLS terms (stabilised pairs) by the quadrature rule of the exact degree of their
///   (polynomial) integrands: 3k - 1 with convection (P1/P1: 3 points in 2D, 4 in 3D), 2k
///   without.
/// - The body-force terms (not polynomial) with the former rule of degree 3k + 1.
/// Equal to `AleNavierStokesQuadratureKernel` to round-off. `cell` is const and thread-safe
/// (so must the force function be).
template <int D, ElementPair Pair, bool Convection = true>
class AleNavierStokesKernel {
 public:
  using Space = MixedSpace<D, Pair>;
  using V = typename Space::VelocityElement;
  using P = typename Space::PressureElement;
  using Forms = AffineStokesForms<D, Pair>;
  using NsForms = AffineNavierStokesForms<D, Pair>;
  static constexpr int nv = V::n_dofs, np = P::n_dofs, n_local = Space::n_local;
  using Nodal = Eigen::Matrix<Real, nv, D>;  ///< nodal values of a velocity, row = node
  /// Degree of the quadrature of the polynomial terms (exact) and of the body-force terms.
  static constexpr int degree = Convection ? 3 * V::degree - 1 : 2 * V::degree;
  static constexpr int force_degree = 3 * V::degree + 1;
  using LocalVec = Eigen::Matrix<Real, n_local, 1>;
  using LocalMat = Eigen::Matrix<Real, n_local, n_local>;

  AleNavierStokesKernel(const Space& space, Real rho, Real mu, Linearisation lin = Linearisation::newton)
      : space_(&space), rho_(rho), mu_(mu), lin_(lin), forms_(&Forms::get()), nsforms_(&NsForms::get()),
        tab_(degree), ftab_(force_degree) {
    ALEFSI_CHECK_ARG(rho > 0 && std::isfinite(rho), "rho", "fluid density must be positive and finite, got ", rho);
    ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "viscosity must be positive and finite, got ", mu);
  }

  void set_step(const StepInputs<D>& s) { s_ = s; }
  Linearisation linearisation() const { return lin_; }

  Real tau(Index c, const Vec<D>& a_star) const {
    const Real h = space_->mesh().diameter(c);
    const Real t1 = 2 * rho_ / s_.dt, t2 = Convection ? 2 * rho_ * a_star.norm() / h : 0.0, t3 = 4 * mu_ / (h * h);
    return 1.0 / std::sqrt(t1 * t1 + t2 * t2 + t3 * t3);
  }

  void cell(Index c, const LocalVec& u, LocalMat& A, LocalVec& r) const {
    const auto& mesh = space_->mesh();
    const Mat<D> J = mesh.jacobian(c);
    const Mat<D> Jinv = J.inverse();
    const Real detJ = J.determinant();
    const auto& fd = space_->cell_field_dofs(c);
    const Real th = s_.theta, dt = s_.dt, a0 = s_.a0;
    const bool newton = Convection && lin_ == Linearisation::newton;
    // local nodal data
    Nodal U, Uth, H, Us;
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
    if constexpr (Pair::stabilised) {
      const Vec<D> xi_c = Vec<D>::Constant(1.0 / (D + 1));
      const auto phic = V::values(xi_c);
      Vec<D> a_star = (Us.transpose() * phic) - Vm.transpose() * P1<D>::values(xi_c);
      tau_c = tau(c, a_star);
    }
    // --- velocity-velocity block, from reference integrals (no quadrature) --------------------
    // Per component pair (i, j) an nv x nv array over (a, b) (lane a + nv b):
    //   L_ij = mu (G_ji + delta_ij tr G) + delta_ij rho C   (viscous + convection, acting on u_th)
    //   residual   r_(a,i) = sum_j (L_ij u_th,j)_a + rho / dt (M (a0 u + h))_(a,i) - (p, d_i phi_a)
    //   Jacobian   theta L_ij + delta_ij rho a0 / dt M + (Newton) theta rho N_ij
    using AbArray = typename NsForms::AbArray;
    using NvMat = Eigen::Matrix<Real, nv, nv>;
    auto as_mat = [](const AbArray& x) { return Eigen::Map<const NvMat>(x.data()); };
    typename NsForms::Block L;
    nsforms_->gradient_pairs(Jinv, detJ, L);  // L[k D + l] = G_kl for now
    {
      AbArray diag = L[0];
      for (int k = 1; k < D; ++k) diag += L[k * D + k];
      diag *= mu_;
      if constexpr (Convection) {
        // convecting velocity a = c - v in the velocity space (c = u_th for Newton, else u*)
        const Nodal Anod = (newton ? Uth : Us) - nsforms_->p1_at_nodes() * Vm;
        AbArray C;
        nsforms_->convection(Jinv, detJ, Anod, C);
        diag += rho_ * C;
      }
      for (int i = 0; i < D; ++i)
        for (int j = i + 1; j < D; ++j) std::swap(L[i * D + j], L[j * D + i]);  // G_ji
      for (int k = 0; k < D * D; ++k) L[k] *= mu_;
      for (int i = 0; i < D; ++i) L[i * D + i] += diag;
    }
    const AbArray mass = (detJ * rho_ / dt) * nsforms_->reference_mass();
    Nodal rv = as_mat(mass) * (a0 * U + H);
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) rv.col(i).noalias() += as_mat(L[i * D + j]) * Uth.col(j);
    typename NsForms::Block Jb;
    if (newton) {
      nsforms_->newton(nsforms_->vertex_gradients(Jinv, Uth), detJ, Jb);
      for (int k = 0; k < D * D; ++k) Jb[k] = th * (L[k] + rho_ * Jb[k]);
    } else {
      for (int k = 0; k < D * D; ++k) Jb[k] = th * L[k];
    }
    for (int i = 0; i < D; ++i) Jb[i * D + i] += a0 * mass;
    A.setZero();
    for (int b = 0; b < nv; ++b)
      for (int j = 0; j < D; ++j) {
        Real* col = A.col(D * b + j).data();
        for (int a = 0; a < nv; ++a)
          for (int i = 0; i < D; ++i) col[D * a + i] = Jb[i * D + j][a + nv * b];
      }
    // --- divergence: -(p, div w) and -(q, div u_th) -------------------------------------------
    {
      const auto dv = forms_->divergence(Jinv, detJ);  // dv[i][a np + b] = int_K psi_b d_i phi_a
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < D; ++i)
          for (int b = 0; b < np; ++b) {
            const Real v = dv[i][a * np + b];
            A(D * a + i, D * nv + b) = -v;
            A(D * nv + b, D * a + i) = -th * v;
            rv(a, i) -= v * Pl[b];
          }
      for (int b = 0; b < np; ++b) {
        Real d = 0;
        for (int a = 0; a < nv; ++a)
          for (int i = 0; i < D; ++i) d += dv[i][a * np + b] * Uth(a, i);
        r[D * nv + b] = -d;
      }
    }
    for (int a = 0; a < nv; ++a)
      for (int i = 0; i < D; ++i) r[D * a + i] = rv(a, i);
    // --- GLS: SUPG + PSPG (P1 velocity: no second derivatives), by the exact-degree rule -------
    // convecting velocity a = c - v at a point (c = u_th for Newton, else u*)
    auto convecting = [&](const Vec<D>& xi, const Eigen::Matrix<Real, nv, 1>& phv) {
      Vec<D> aq = Vec<D>::Zero();
      if constexpr (Convection) {
        const Vec<D> vq = Vm.transpose() * P1<D>::values(xi);
        aq = (lin_ == Linearisation::newton ? Vec<D>(Uth.transpose() * phv) : Vec<D>(Us.transpose() * phv)) - vq;
      }
      return aq;
    };
    if constexpr (Pair::stabilised) {
      const auto& rule = *tab_.rule;
      for (int q = 0; q < rule.size(); ++q) {
        const Real w = rule.weights[q] * detJ;
        const Eigen::Matrix<Real, nv, D> G = tab_.dphi_v[q] * Jinv;
        const auto& phv = tab_.phi_v[q];
        const Vec<D> uq = U.transpose() * phv;
        const Vec<D> hq = H.transpose() * phv;
        const Mat<D> gu = Uth.transpose() * G;  // (i, j) = d u_th,i / d x_j
        const Vec<D> aq = convecting(rule.points[q], phv);
        const Eigen::Matrix<Real, nv, 1> adg = G * aq;  // a . grad phi_a
        const Vec<D> dtu = (a0 * uq + hq) / dt;
        const Vec<D> conv = gu * aq;
        const Eigen::Matrix<Real, np, D> Gp = tab_.dphi_p[q] * Jinv;
        const Vec<D> gp = Gp.transpose() * Pl;
        const Vec<D> R = rho_ * (dtu + conv) + gp;  // - f: below
        const Real wt = w * tau_c;
        // dR_i / du_(b,j) = rho (a0/dt phi_b delta_ij + th [delta_ij adg_b + (newton) phi_b gu_ij])
        auto dR = [&](int i, int b, int j) {
          Real s = (i == j) ? rho_ * (a0 / dt * phv[b] + (Convection ? th * adg[b] : 0.0)) : 0.0;
          if (newton) s += rho_ * th * phv[b] * gu(i, j);
          return s;
        };
        for (int a = 0; a < nv; ++a)
          for (int i = 0; i < D; ++i) {
            if constexpr (Convection) {
              r[D * a + i] += wt * rho_ * adg[a] * R[i];
              for (int b = 0; b < nv; ++b)
                for (int j = 0; j < D; ++j) {
                  Real s = wt * rho_ * adg[a] * dR(i, b, j);
                  if (newton) s += wt * rho_ * th * phv[b] * G(a, j) * R[i];
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
    // --- body force: -(f, w), and its part of the GLS residual R (rule of degree 3k + 1) -------
    if (!s_.force) return;
    const Vec<D> x0 = mesh.node(mesh.cell(c)[0]);
    const auto& frule = *ftab_.rule;
    for (int q = 0; q < frule.size(); ++q) {
      const Real w = frule.weights[q] * detJ;
      const Vec<D> fq = s_.force(x0 + J * frule.points[q]);
      const auto& phv = ftab_.phi_v[q];
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < D; ++i) r[D * a + i] -= w * fq[i] * phv[a];
      if constexpr (Pair::stabilised) {
        const Real wt = w * tau_c;
        const Eigen::Matrix<Real, np, D> Gp = ftab_.dphi_p[q] * Jinv;
        if constexpr (Convection) {
          const Eigen::Matrix<Real, nv, D> G = ftab_.dphi_v[q] * Jinv;
          const Eigen::Matrix<Real, nv, 1> adg = G * convecting(frule.points[q], phv);
          for (int a = 0; a < nv; ++a)
            for (int i = 0; i < D; ++i) {
              r[D * a + i] -= wt * rho_ * adg[a] * fq[i];
              if (newton)
                for (int b = 0; b < nv; ++b)
                  for (int j = 0; j < D; ++j) A(D * a + i, D * b + j) -= wt * rho_ * th * phv[b] * G(a, j) * fq[i];
            }
        }
        for (int a = 0; a < np; ++a) r[D * nv + a] += wt * fq.dot(Gp.row(a));
      }
    }
  }

 private:
  const Space* space_;
  Real rho_, mu_;
  Linearisation lin_;
  const Forms* forms_;
  const NsForms* nsforms_;
  ReferenceTables<D, Pair> tab_, ftab_;
  StepInputs<D> s_;
};

/// The ALE Navier–Stokes kernel by quadrature of degree 3k + 1, every term at every point: the
/// reference implementation `AleNavierStokesKernel` is tested against (same interface, same
/// results to round-off, several times slower).
template <int D, ElementPair Pair, bool Convection = true>
class AleNavierStokesQuadratureKernel {
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

  Real tau(Index c, const Vec<D>& a_star) const {
    const Real h = space_->mesh().diameter(c);
    const Real t1 = 2 * rho_ / s_.dt, t2 = Convection ? 2 * rho_ * a_star.norm() / h : 0.0, t3 = 4 * mu_ / (h * h);
    return 1.0 / std::sqrt(t1 * t1 + t2 * t2 + t3 * t3);
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
    if constexpr (Pair::stabilised) {
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
      if constexpr (Pair::stabilised) {
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

}  // namespace alefsi
