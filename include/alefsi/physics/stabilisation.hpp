#pragma once
/// \file physics/stabilisation.hpp
/// Stabilisation policies of the Stokes and ALE Navier–Stokes kernels, chosen at compile time
/// by the pair's tag `Pair::Stabilisation` (fem/element_pair.hpp).
///
/// A policy owns what its terms need (constants, quadrature tables) and is called by the kernel
/// at fixed points of `cell`, with the kernel's local data; the kernels never test which policy
/// they have. `NoStabilisation`: every call is an empty inline function (nothing at run time).
/// `GlsStabilisation` (P1/P1): GLS as SUPG + PSPG with one cell parameter, `gls_tau`:
///
///   tau_K = [ (2 rho / dt)^2 + (2 rho |a*| / h_K)^2 + (c1 mu / h_K^2)^2 ]^(-1/2),   c1 = 4,
///
/// h_K the longest edge of K [m], mu [Pa s], rho [kg/m^3], dt [s], a* = u* - v at the centroid
/// [m/s] (extrapolated: tau does not depend on the unknowns); tau_K in [m^3 s / kg]. Steady
/// Stokes (no transient, no convection) is the limit h_K^2 / (c1 mu) (Codina 2001).
///
/// The hooks, per kernel (LocalMat / LocalVec: the kernel's element matrix and residual, local
/// order of `MixedSpace`: velocity node a, component i at D a + i, then the pressure nodes):
///   StokesStabilisation<D, Pair>(mu, c1)
///     tau(mesh, c)                              tau_K (0 without stabilisation)
///     add_matrix(forms, Jinv, detJ, tau, A)     the stabilisation block of A
///     add_load(tables, q, Jinv, w, tau, f, F)   its part of the load at force point q
///   NavierStokesStabilisation<D, Pair, Convection>(rho, mu)
///     tau(cell)                                 tau_K from the cell's u* and mesh velocity
///     add_cell(cell, tau, A, r)                 every term without the body force
///     add_force(cell, tau, tables, q, w, f, A, r)  the body-force terms at force point q
/// Adding a stabilisation: a tag (an empty type with a `name`, fem/concepts.hpp
/// `StabilisationTag`), a pair with `using Stabilisation = Tag;`, and a specialisation of both
/// classes below for `Tag` with these hooks.
///
///     alefsi::StokesStabilisation<2, alefsi::P1P1Gls> gls(/*mu=*/1.0, /*c1=*/4.0);
///     const Real tau = gls.tau(mesh, c);   // h_K^2 / (4 mu)
///     gls.add_matrix(forms, Jinv, detJ, tau, A);
#include <cmath>
#include <limits>

#include "alefsi/core/types.hpp"
#include "alefsi/fem/concepts.hpp"
#include "alefsi/fem/element_pair.hpp"
#include "alefsi/fem/lagrange.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/physics/affine_forms.hpp"

namespace alefsi {

/// What tau_K depends on, SI units. Defaults: steady (dt infinite), no convection.
struct GlsTauInputs {
  Real h;                                             ///< h_K, the longest edge of K [m]
  Real mu;                                            ///< dynamic viscosity [Pa s]
  Real rho = 0;                                       ///< density [kg/m^3]
  Real dt = std::numeric_limits<Real>::infinity();    ///< time step [s]; infinite: steady
  Real a_norm = 0;                                    ///< |a*| [m/s]; 0: no convection
};

/// The one GLS parameter tau_K (see the file comment), c1 = 4 by default.
/// The exact limit, steady Stokes (dt infinite and a_norm = 0), is computed as h^2 / (c1 mu):
/// the general form would give 1 / sqrt((c1 mu / h^2)^2), equal in exact arithmetic but not
/// always to the last bit, and the Stokes kernel has always used h^2 / (c1 mu) (its results
/// are kept bit for bit). Every finite dt takes the general form.
///
///     Real tau = alefsi::gls_tau({.h = h, .mu = mu, .rho = rho, .dt = dt, .a_norm = a.norm()});
///     Real tau_stokes = alefsi::gls_tau({.h = h, .mu = mu});   // == h * h / (4 * mu)
inline Real gls_tau(const GlsTauInputs& in, Real c1 = 4) {
  if (std::isinf(in.dt) && in.a_norm == 0) return in.h * in.h / (c1 * in.mu);
  const Real t1 = 2 * in.rho / in.dt, t2 = 2 * in.rho * in.a_norm / in.h, t3 = c1 * in.mu / (in.h * in.h);
  return 1.0 / std::sqrt(t1 * t1 + t2 * t2 + t3 * t3);
}

namespace detail {
template <class>
inline constexpr bool no_policy_for_tag = false;
}  // namespace detail

// ---- steady Stokes ------------------------------------------------------------------------

/// The stabilisation of `StokesKernel` for the tag `Tag` (specialised per tag below).
template <int D, ElementPair Pair, class Tag = typename Pair::Stabilisation>
class StokesStabilisation {
  static_assert(detail::no_policy_for_tag<Tag>,
                "StokesKernel has no policy for this stabilisation tag: specialise StokesStabilisation<D, Pair, Tag> "
                "(physics/stabilisation.hpp)");
};

template <int D, ElementPair Pair>
class StokesStabilisation<D, Pair, NoStabilisation> {
 public:
  using LocalMat = typename AffineStokesForms<D, Pair>::LocalMat;
  using LocalVec = Eigen::Matrix<Real, LocalMat::RowsAtCompileTime, 1>;
  StokesStabilisation(Real /*mu*/, Real /*c1*/) {}
  static constexpr Real tau(const Mesh<D>&, Index) { return 0; }
  static void add_matrix(const AffineStokesForms<D, Pair>&, const Mat<D>&, Real, Real, LocalMat&) {}
  static void add_load(const ReferenceTables<D, Pair>&, int, const Mat<D>&, Real, Real, const Vec<D>&, LocalVec&) {}
};

/// PSPG for steady Stokes: -sum_K tau_K (grad p - f, grad q)_K (lap u_h = 0 on P1 cells), with
/// tau_K = h_K^2 / (c1 mu). The pressure block -tau (grad p, grad q) from reference integrals.
template <int D, ElementPair Pair>
class StokesStabilisation<D, Pair, GlsStabilisation> {
 public:
  using Forms = AffineStokesForms<D, Pair>;
  using LocalMat = typename Forms::LocalMat;
  using LocalVec = Eigen::Matrix<Real, LocalMat::RowsAtCompileTime, 1>;
  static constexpr int nv = Forms::nv, np = Forms::np;

  StokesStabilisation(Real mu, Real c1) : mu_(mu), c1_(c1) {}

  Real tau(const Mesh<D>& mesh, Index c) const { return gls_tau({.h = mesh.diameter(c), .mu = mu_}, c1_); }

  /// A(p, p) += -tau (grad psi_a, grad psi_b)_K.
  static void add_matrix(const Forms& forms, const Mat<D>& Jinv, Real detJ, Real tau, LocalMat& A) {
    forms.add_pressure_laplacian(Jinv, detJ, -tau, A);
  }

  /// F(pressure row a) -= w tau f . grad psi_a at point q of `tab` (w: weight times det J).
  static void add_load(const ReferenceTables<D, Pair>& tab, int q, const Mat<D>& Jinv, Real w, Real tau,
                       const Vec<D>& fq, LocalVec& F) {
    const Eigen::Matrix<Real, np, D> Gp = tab.dphi_p[q] * Jinv;
    for (int a = 0; a < np; ++a) F[D * nv + a] -= w * tau * fq.dot(Gp.row(a));
  }

 private:
  Real mu_, c1_;
};

// ---- ALE Navier–Stokes ----------------------------------------------------------------------

/// What `AleNavierStokesKernel` has gathered on one cell for its stabilisation: nodal values
/// (row = velocity node, local order of the element), SI units. Views: valid during `cell`.
template <int D, ElementPair Pair>
struct NavierStokesCell {
  static constexpr int nv = Pair::template Velocity<D>::n_dofs, np = Pair::template Pressure<D>::n_dofs;
  using Nodal = Eigen::Matrix<Real, nv, D>;
  const Mesh<D>& mesh;
  Index c;
  const Mat<D>& Jinv;  ///< J^-1 of the cell (reference -> physical)
  Real detJ;
  const Nodal& U;    ///< u^{n+1} (the unknowns)
  const Nodal& Uth;  ///< u_th = theta u^{n+1} + (1 - theta) u^n
  const Nodal& H;    ///< BDF history sum_{k>=1} a_k u^{n+1-k}
  const Nodal& Us;   ///< u*, the scheme's extrapolation
  const Eigen::Matrix<Real, D + 1, D>& Vm;  ///< mesh velocity at the D + 1 vertices, at n + theta
  const Eigen::Matrix<Real, np, 1>& Pl;     ///< pressure p^{n+theta}
  Real dt, theta, a0;
  Real tau_dt;  ///< the step in tau's transient term (dt, or a fixed one: StepInputs::tau_dt)
  bool newton;  ///< convection linearised by Newton (c = u_th), not semi-implicitly (c = u*)
};

/// The stabilisation of `AleNavierStokesKernel` for the tag `Tag` (specialised per tag below).
template <int D, ElementPair Pair, bool Convection, class Tag = typename Pair::Stabilisation>
class NavierStokesStabilisation {
  static_assert(detail::no_policy_for_tag<Tag>,
                "AleNavierStokesKernel has no policy for this stabilisation tag: specialise "
                "NavierStokesStabilisation<D, Pair, Convection, Tag> (physics/stabilisation.hpp)");
};

template <int D, ElementPair Pair, bool Convection>
class NavierStokesStabilisation<D, Pair, Convection, NoStabilisation> {
 public:
  using Cell = NavierStokesCell<D, Pair>;
  static constexpr int n_local = D * Cell::nv + Cell::np;
  using LocalMat = Eigen::Matrix<Real, n_local, n_local>;
  using LocalVec = Eigen::Matrix<Real, n_local, 1>;
  NavierStokesStabilisation(Real /*rho*/, Real /*mu*/) {}
  static constexpr Real tau(const Cell&) { return 0; }
  static void add_cell(const Cell&, Real, LocalMat&, LocalVec&) {}
  static void add_force(const Cell&, Real, const ReferenceTables<D, Pair>&, int, Real, const Vec<D>&, LocalMat&,
                        LocalVec&) {}
};

/// GLS for ALE Navier–Stokes (P1 velocity: no second derivatives), for test functions (w, q):
///   + sum_K tau_K (R, rho (a . grad) w)_K   [SUPG, with convection]
///   - sum_K tau_K (R, grad q)_K             [PSPG]
/// R = rho (D_t u + (a . grad) u_th) + grad p - f, a = c - v, and their exact Jacobian (tau
/// frozen). Without the body force by the rule of the exact degree of the (polynomial)
/// integrands, 3k - 1 with convection (P1: 3 points in 2D, 4 in 3D), 2k without; the body-force
/// terms at the kernel's force points. The hooks are always inlined into the kernel's `cell`:
/// one function, as before the policy existed (same code and speed; with FMA contraction,
/// -march=native, the compiler's fusing of a * b + c is decided per function).
template <int D, ElementPair Pair, bool Convection>
class NavierStokesStabilisation<D, Pair, Convection, GlsStabilisation> {
 public:
  using Cell = NavierStokesCell<D, Pair>;
  using V = typename Pair::template Velocity<D>;
  static constexpr int nv = Cell::nv, np = Cell::np, n_local = D * nv + np;
  using LocalMat = Eigen::Matrix<Real, n_local, n_local>;
  using LocalVec = Eigen::Matrix<Real, n_local, 1>;
  /// Degree of the rule of `add_cell` (exact for its integrands).
  static constexpr int degree = Convection ? 3 * V::degree - 1 : 2 * V::degree;

  NavierStokesStabilisation(Real rho, Real mu) : rho_(rho), mu_(mu), tab_(degree) {}

  /// tau_K with a* = u* - v at the centroid.
  [[gnu::always_inline]] Real tau(const Cell& l) const {
    const Vec<D> xi_c = Vec<D>::Constant(1.0 / (D + 1));
    const auto phic = V::values(xi_c);
    Vec<D> a_star = (l.Us.transpose() * phic) - l.Vm.transpose() * P1<D>::values(xi_c);
    return gls_tau({.h = l.mesh.diameter(l.c), .mu = mu_, .rho = rho_, .dt = l.tau_dt,
                    .a_norm = Convection ? a_star.norm() : 0.0});
  }

  /// SUPG + PSPG without the body force, into A and r.
  [[gnu::always_inline]] void add_cell(const Cell& l, Real tau_c, LocalMat& A, LocalVec& r) const {
    const Real th = l.theta, dt = l.dt, a0 = l.a0;
    const bool newton = l.newton;
    const auto& rule = *tab_.rule;
    for (int q = 0; q < rule.size(); ++q) {
      const Real w = rule.weights[q] * l.detJ;
      const Eigen::Matrix<Real, nv, D> G = tab_.dphi_v[q] * l.Jinv;
      const auto& phv = tab_.phi_v[q];
      const Vec<D> uq = l.U.transpose() * phv;
      const Vec<D> hq = l.H.transpose() * phv;
      const Mat<D> gu = l.Uth.transpose() * G;  // (i, j) = d u_th,i / d x_j
      const Vec<D> aq = convecting(l, rule.points[q], phv);
      const Eigen::Matrix<Real, nv, 1> adg = G * aq;  // a . grad phi_a
      const Vec<D> dtu = (a0 * uq + hq) / dt;
      const Vec<D> conv = gu * aq;
      const Eigen::Matrix<Real, np, D> Gp = tab_.dphi_p[q] * l.Jinv;
      const Vec<D> gp = Gp.transpose() * l.Pl;
      const Vec<D> R = rho_ * (dtu + conv) + gp;  // - f: add_force
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

  /// The body force's part of R (SUPG and PSPG) at point q of `ft` (w: weight times det J,
  /// fq: force per unit volume there).
  [[gnu::always_inline]] void add_force(const Cell& l, Real tau_c, const ReferenceTables<D, Pair>& ft, int q, Real w,
                                        const Vec<D>& fq, LocalMat& A, LocalVec& r) const {
    const Real wt = w * tau_c;
    const Eigen::Matrix<Real, np, D> Gp = ft.dphi_p[q] * l.Jinv;
    if constexpr (Convection) {
      const auto& phv = ft.phi_v[q];
      const Eigen::Matrix<Real, nv, D> G = ft.dphi_v[q] * l.Jinv;
      const Eigen::Matrix<Real, nv, 1> adg = G * convecting(l, ft.rule->points[q], phv);
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < D; ++i) {
          r[D * a + i] -= wt * rho_ * adg[a] * fq[i];
          if (l.newton)
            for (int b = 0; b < nv; ++b)
              for (int j = 0; j < D; ++j) A(D * a + i, D * b + j) -= wt * rho_ * l.theta * phv[b] * G(a, j) * fq[i];
        }
    }
    for (int a = 0; a < np; ++a) r[D * nv + a] += wt * fq.dot(Gp.row(a));
  }

 private:
  /// The convecting velocity a = c - v at reference point xi (c = u_th for Newton, else u*);
  /// 0 without convection.
  [[gnu::always_inline]] static Vec<D> convecting(const Cell& l, const Vec<D>& xi,
                                                   const Eigen::Matrix<Real, nv, 1>& phv) {
    Vec<D> aq = Vec<D>::Zero();
    if constexpr (Convection) {
      const Vec<D> vq = l.Vm.transpose() * P1<D>::values(xi);
      aq = (l.newton ? Vec<D>(l.Uth.transpose() * phv) : Vec<D>(l.Us.transpose() * phv)) - vq;
    }
    return aq;
  }

  Real rho_, mu_;
  ReferenceTables<D, Pair> tab_;  // at the points of the rule of degree `degree`
};

}  // namespace alefsi
