#pragma once
/// \file reference/annulus.hpp
/// Finite-difference reference solution of the paper's reduced annulus problem (eq. 25-26):
/// azimuthal flow u(r, t) between a free inner cylinder (radius a, inertia I per unit length)
/// and an outer cylinder (radius b) turning at a given angular velocity w2(t),
///
///     rho du/dt = mu d/dr( (1/r) d(r u)/dr ) + f(r, t)          a < r < b,
///     I dw/dt   = 2 pi a^2 mu [r d(u/r)/dr]_{r=a} + T_ext(t),
///     u(b, t) = b w2(t),   u(a, t) = a w(t),
///
/// with f and T_ext zero unless given (they exist for manufactured solutions). Everything is
/// per unit length of the cylinders, in any consistent units (the paper's: cm, g, s).
///
/// Space: nodes r_i = a + i h, i = 0..N, h = (b - a) / N, in the conservative (angular momentum)
/// form rho r^2 du/dt = d/dr(r^2 tau) + r^2 f, tau = mu r d(u/r)/dr. The torque through r_{i+1/2},
/// T_{i+1/2} = 2 pi mu r_{i+1/2}^3 (u_{i+1}/r_{i+1} - u_i/r_i) / h, is second-order accurate; row i
/// is 2 pi rho r_i^2 h du_i/dt = T_{i+1/2} - T_{i-1/2} + 2 pi r_i^2 h f_i. The inner cylinder and
/// the half cell next to it form one row for w = u_0 / a:
///     (I + pi rho a^3 h) dw/dt = T_{1/2} + T_ext + pi a^3 h f(a) / a,
/// an O(h^2)-consistent torque balance (the half cell's angular momentum is O(h) and its
/// quadrature error O(h^2)); it stays well posed for I -> 0.
/// Time: Crank-Nicolson, with Rannacher's start (the first `rannacher_steps` CN steps are each
/// replaced by two backward-Euler half steps), which damps the stiff modes an impulsive start
/// excites, so the error at a fixed t > 0 stays O(dt^2) for non-smooth data. Each step is one
/// tridiagonal (Thomas) solve: O(N) work.
/// Orders measured in tests/physics/test_annulus.cpp: 2 in space, 2 in time, against a
/// manufactured solution, the steady Couette solution and (impulsive start) self-convergence.
///
///     alefsi::reference::AnnulusProblem p{.r1 = 0.25, .r2 = 1, .rho = 1, .mu = 0.01,
///                                         .inertia = 1.25 * pi * std::pow(0.25, 4) / 2};
///     alefsi::reference::AnnulusSolver fd(p, {.cells = 4000, .dt = 1e-4});
///     fd.advance_to(0.8);  // fd.velocity(r), fd.omega(), fd.l2_norm_squared(...)
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/core/types.hpp"

namespace alefsi::reference {

/// The reduced annulus problem (26) in physical variables.
struct AnnulusProblem {
  Real r1 = 0.25, r2 = 1.0;  ///< inner (body) and outer radius
  Real rho = 1, mu = 1;      ///< fluid density and dynamic viscosity
  Real inertia = 1;          ///< I_33 of the inner cylinder per unit length (>= 0)
  /// Angular velocity of the outer cylinder w2(t); empty: 1 (impulsive start from rest at t = 0+).
  std::function<Real(Real t)> outer_omega;
  /// Initial velocity u(r, 0) and inner angular velocity; empty: at rest.
  std::function<Real(Real r)> u0;
  Real omega0 = 0;
  /// Azimuthal body force per unit volume f(r, t) and external torque on the inner cylinder
  /// (for manufactured solutions); empty: zero.
  std::function<Real(Real r, Real t)> force;
  std::function<Real(Real t)> torque;
};

struct AnnulusOptions {
  int cells = 1000;         ///< N: radial cells
  Real dt = 1e-3;           ///< time step
  int rannacher_steps = 2;  ///< initial CN steps done as 2 backward-Euler half steps each (0: plain CN)
};

/// Time stepper for AnnulusProblem (see the file comment for the discretisation).
class AnnulusSolver {
 public:
  AnnulusSolver(AnnulusProblem p, AnnulusOptions o) : p_(std::move(p)), o_(o) {
    ALEFSI_CHECK_ARG(p_.r1 > 0 && p_.r2 > p_.r1 && std::isfinite(p_.r2), "r1, r2", "need 0 < r1 < r2 < inf");
    ALEFSI_CHECK_ARG(p_.rho > 0 && p_.mu > 0, "rho, mu", "must be positive");
    ALEFSI_CHECK_ARG(p_.inertia >= 0 && std::isfinite(p_.inertia), "inertia", "must be >= 0 and finite, got ", p_.inertia);
    ALEFSI_CHECK_ARG(o_.cells >= 2, "cells", "must be >= 2, got ", o_.cells);
    ALEFSI_CHECK_ARG(o_.dt > 0 && std::isfinite(o_.dt), "dt", "must be positive and finite, got ", o_.dt);
    ALEFSI_CHECK_ARG(o_.rannacher_steps >= 0, "rannacher_steps", "must be >= 0");
    const int N = o_.cells;
    h_ = (p_.r2 - p_.r1) / N;
    r_.resize(N + 1);
    for (int i = 0; i <= N; ++i) r_[i] = p_.r1 + i * h_;
    r_[N] = p_.r2;
    u_.assign(N + 1, 0.0);
    if (p_.u0)
      for (int i = 1; i < N; ++i) u_[i] = p_.u0(r_[i]);
    u_[0] = p_.r1 * p_.omega0;
    u_[N] = p_.u0 ? p_.u0(p_.r2) : 0.0;
    // mass (row 0: the body plus its half cell, in units of torque per du_0/dt)
    const Real pi = std::numbers::pi;
    m_.resize(N);
    m_[0] = p_.inertia / p_.r1 + pi * p_.rho * p_.r1 * p_.r1 * h_;
    for (int i = 1; i < N; ++i) m_[i] = 2 * pi * p_.rho * r_[i] * r_[i] * h_;
    c_.resize(N);  // c_[i] = c_{i+1/2}
    for (int i = 0; i < N; ++i) {
      const Real rm = 0.5 * (r_[i] + r_[i + 1]);
      c_[i] = 2 * pi * p_.mu * rm * rm * rm / h_;
    }
  }

  const AnnulusProblem& problem() const { return p_; }
  const AnnulusOptions& options() const { return o_; }
  Real time() const { return t_; }
  int steps() const { return n_; }
  /// Nodal radii r_0 = r1 .. r_N = r2 and velocities u_i (u_N = r2 w2(t), u_0 = r1 w(t)).
  const std::vector<Real>& radii() const { return r_; }
  const std::vector<Real>& velocities() const { return u_; }
  /// Angular velocity of the inner cylinder.
  Real omega() const { return u_[0] / p_.r1; }
  Real outer_omega(Real t) const { return p_.outer_omega ? p_.outer_omega(t) : 1.0; }

  /// u(r) at the current time by cubic Lagrange interpolation of the four nearest nodes
  /// (O(h^4)); outside [r1, r2] the rigid rotation of the nearer wall (FE meshes of a disk
  /// hole are polygons, so their points reach slightly inside r1).
  Real velocity(Real r) const {
    const int N = o_.cells;
    if (r <= p_.r1) return u_[0] * r / p_.r1;
    if (r >= p_.r2) return u_[N] * r / p_.r2;
    int j = int((r - p_.r1) / h_) - 1;  // stencil j .. j+3
    j = std::max(0, std::min(j, N - 3));
    Real s = 0;
    for (int a = 0; a < 4; ++a) {
      Real l = 1;
      for (int b = 0; b < 4; ++b)
        if (b != a) l *= (r - r_[j + b]) / (r_[j + a] - r_[j + b]);
      s += l * u_[j + a];
    }
    return s;
  }

  /// Advances one step of size options().dt.
  void step() {
    const Real dt = o_.dt;
    if (n_ < o_.rannacher_steps) {
      theta_step(0.5 * dt, 1.0);
      theta_step(0.5 * dt, 1.0);
    } else {
      theta_step(dt, 0.5);
    }
    ++n_;
  }
  /// Steps until time() >= T - dt/1000; T should be a multiple of dt.
  void advance_to(Real T) {
    while (t_ < T - 1e-3 * o_.dt) step();
  }

 private:
  // Residual part A u + b(t) of row i, with u_N = r2 w2(t) (the boundary value).
  Real force_row(int i, Real t) const {
    const Real pi = std::numbers::pi;
    Real s = 0;
    if (p_.force) {
      const Real f = p_.force(r_[i], t);
      s += i == 0 ? pi * r_[0] * r_[0] * h_ * f : 2 * pi * r_[i] * r_[i] * h_ * f;
    }
    if (i == 0 && p_.torque) s += p_.torque(t);
    return s;
  }
  // Flux rows: (A u)_i for nodal values v (v[N] is the boundary value).
  Real apply_row(const std::vector<Real>& v, int i) const {
    const Real right = c_[i] * (v[i + 1] / r_[i + 1] - v[i] / r_[i]);
    const Real left = i == 0 ? 0.0 : c_[i - 1] * (v[i] / r_[i] - v[i - 1] / r_[i - 1]);
    return right - left;
  }
  // (M/k - th A) u^{n+1} = (M/k + (1-th) A) u^n + th b^{n+1} + (1-th) b^n.
  void theta_step(Real k, Real th) {
    const int N = o_.cells;
    const Real t1 = t_ + k;
    const Real uN1 = p_.r2 * outer_omega(t1);
    std::vector<Real> lo(N, 0), di(N, 0), up(N, 0), rhs(N, 0);
    for (int i = 0; i < N; ++i) {
      rhs[i] = m_[i] / k * u_[i] + (1 - th) * (apply_row(u_, i) + force_row(i, t_)) + th * force_row(i, t1);
      di[i] = m_[i] / k + th * c_[i] / r_[i] + (i > 0 ? th * c_[i - 1] / r_[i] : 0.0);
      if (i > 0) lo[i] = -th * c_[i - 1] / r_[i - 1];
      if (i + 1 < N) up[i] = -th * c_[i] / r_[i + 1];
    }
    rhs[N - 1] += th * c_[N - 1] * uN1 / r_[N];
    // Thomas algorithm (the matrix is diagonally dominant: M/k > 0 plus an M-matrix)
    for (int i = 1; i < N; ++i) {
      const Real w = lo[i] / di[i - 1];
      di[i] -= w * up[i - 1];
      rhs[i] -= w * rhs[i - 1];
    }
    u_[N - 1] = rhs[N - 1] / di[N - 1];
    for (int i = N - 2; i >= 0; --i) u_[i] = (rhs[i] - up[i] * u_[i + 1]) / di[i];
    u_[N] = uN1;
    t_ = t1;
  }

  AnnulusProblem p_;
  AnnulusOptions o_;
  Real h_ = 0, t_ = 0;
  int n_ = 0;
  std::vector<Real> r_, u_, m_, c_;
};

/// Discrete L2 norm over the annulus, (int 2 pi r g(r)^2 dr)^(1/2), of g given at the solver's
/// nodes (trapezoidal rule). Per unit length: the 2D L2 norm of the field g(r) e_theta.
inline Real annulus_l2(const std::vector<Real>& r, const std::vector<Real>& g) {
  ALEFSI_CHECK_ARG(r.size() == g.size() && r.size() >= 2, "g", "needs one value per node");
  Real s = 0;
  for (std::size_t i = 0; i + 1 < r.size(); ++i)
    s += 0.5 * (r[i + 1] - r[i]) * (r[i] * g[i] * g[i] + r[i + 1] * g[i + 1] * g[i + 1]);
  return std::sqrt(2 * std::numbers::pi * s);
}

}  // namespace alefsi::reference
