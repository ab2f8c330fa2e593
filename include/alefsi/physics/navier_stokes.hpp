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
///   -(q, div u_th)
/// plus the terms of the pair's stabilisation policy (`NavierStokesStabilisation`,
/// physics/stabilisation.hpp): none for TaylorHood; for P1P1Gls, with the strong residual
/// R = rho (D_t u + (a . grad) u_th) + grad p - f (P1 velocities have no second derivatives),
///     + sum_K tau_K (R, rho (a . grad) w)_K                                [SUPG]
///     - sum_K tau_K (R, grad q)_K                                          [PSPG]
/// and (`gls_tau`)
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
#include <type_traits>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/physics/affine_forms.hpp"
#include "alefsi/physics/stabilisation.hpp"
#include "alefsi/physics/stokes.hpp"

namespace alefsi {

enum class Linearisation { newton, semi_implicit };

template <int D>
struct StepInputs {
  Real dt = 1, theta = 1, a0 = 1;
  /// The step in tau's transient term (`gls_tau`); 0: dt. A fixed value keeps the stabilised
  /// operator from changing with dt (adaptive steps; FlowOptions::tau_dt).
  Real tau_dt = 0;
  const VecX* history = nullptr;     ///< field vector, velocity entries: sum_{k>=1} a_k u^{n+1-k}
  const VecX* previous = nullptr;    ///< u^n (field vector), used when theta < 1
  const VecX* extrapolated = nullptr;///< u* (field vector): convecting velocity / tau
  const std::vector<Vec<D>>* mesh_velocity = nullptr;  ///< per mesh node, at n+theta
  /// Per mesh edge: the mesh velocity at its edge point (curved cells of a `QuadraticGeometry`);
  /// null: the average of the edge's end nodes (the P1 mesh velocity, as on straight cells).
  const std::vector<Vec<D>>* edge_velocity = nullptr;
  VectorFunction<D> force;           ///< body force per unit volume at t^{n+theta} (may be empty)
};

/// The ALE Navier–Stokes element kernel (affine cells).
/// - Mass, viscous, convection, Newton and divergence terms of the Jacobian and of the residual
///   from precomputed reference integrals (`AffineNavierStokesForms`, `AffineStokesForms`), no
///   quadrature: the velocity block is formed per component pair as nv x nv arrays and
///   written into A once; the residual of these terms is their matrix times (u_th, p), plus
///   the mass matrix times (a0 u + h) / dt.
/// - The stabilisation terms from the pair's policy `Stabilisation` (GLS: by the quadrature
///   rule of the exact degree of their polynomial integrands), called once per cell
///   (`add_cell`) and at every force point (`add_force`).
/// - The body-force terms (not polynomial) with the former rule of degree 3k + 1.
/// Equal to the quadrature oracle (tests/support/oracle_kernels.hpp) to round-off.
/// With a `QuadraticGeometry` (Taylor–Hood), curved cells take `curved_cell`: every term by the
/// rule of degree 3k + 1 through the isoparametric map, the mesh velocity interpolated on the
/// geometry's P2 nodes. `cell` is const and thread-safe (so must the force function be).
template <int D, ElementPair Pair, bool Convection = true>
class AleNavierStokesKernel {
 public:
  using Space = MixedSpace<D, Pair>;
  using V = typename Space::VelocityElement;
  using P = typename Space::PressureElement;
  using Forms = AffineStokesForms<D, Pair>;
  using NsForms = AffineNavierStokesForms<D, Pair>;
  static constexpr int nv = V::n_dofs, np = P::n_dofs, n_local = Space::n_local;
  using Stabilisation = NavierStokesStabilisation<D, Pair, Convection>;
  using Nodal = Eigen::Matrix<Real, nv, D>;  ///< nodal values of a velocity, row = node
  /// Degree of the quadrature of the body-force terms.
  static constexpr int force_degree = 3 * V::degree + 1;
  using LocalVec = Eigen::Matrix<Real, n_local, 1>;
  using LocalMat = Eigen::Matrix<Real, n_local, n_local>;

  AleNavierStokesKernel(const Space& space, Real rho, Real mu, Linearisation lin = Linearisation::newton)
      : space_(&space), rho_(rho), mu_(mu), lin_(lin), forms_(&Forms::get()), nsforms_(&NsForms::get()),
        stab_(rho, mu), ftab_(force_degree) {
    ALEFSI_CHECK_ARG(rho > 0 && std::isfinite(rho), "rho", "fluid density must be positive and finite, got ", rho);
    ALEFSI_CHECK_ARG(mu > 0 && std::isfinite(mu), "mu", "viscosity must be positive and finite, got ", mu);
  }

  void set_step(const StepInputs<D>& s) { s_ = s; }

  /// Integrates the curved cells of `g` through their quadratic map (null: every cell affine).
  /// The geometry must be on this kernel's mesh (its nodes where the step's geometry is, as
  /// the mesh's are) and outlive the kernel.
  void set_geometry(const QuadraticGeometry<D>* g)
    requires(V::degree == 2 && std::is_empty_v<Stabilisation>)
  {
    ALEFSI_CHECK_ARG(!g || &g->mesh() == &space_->mesh(), "geometry", "is on another mesh than the space's");
    geom_ = g;
    if (g && geo_dN_.empty())
      for (int q = 0; q < ftab_.rule->size(); ++q) {
        geo_N_.push_back(QuadraticGeometry<D>::Shape::values(ftab_.rule->points[q]));
        geo_dN_.push_back(QuadraticGeometry<D>::Shape::gradients(ftab_.rule->points[q]));
      }
  }
  const QuadraticGeometry<D>* geometry() const { return geom_; }
  Linearisation linearisation() const { return lin_; }

  /// The GLS parameter `gls_tau` of cell c at the current step for the convecting velocity
  /// a_star (ignored without convection), whatever the pair (a stable pair does not use it).
  Real tau(Index c, const Vec<D>& a_star) const {
    return gls_tau({.h = space_->mesh().diameter(c), .mu = mu_, .rho = rho_, .dt = s_.tau_dt > 0 ? s_.tau_dt : s_.dt,
                    .a_norm = Convection ? a_star.norm() : 0.0});
  }

  void cell(Index c, const LocalVec& u, LocalMat& A, LocalVec& r) const {
    if (geom_ && geom_->curved(c)) return curved_cell(c, u, A, r);
    const auto& mesh = space_->mesh();
    const Mat<D> J = mesh.jacobian(c);
    const Mat<D> Jinv = J.inverse();
    const Real detJ = J.determinant();
    const auto& fd = space_->cell_field_dofs(c);
    const Real th = s_.theta, dt = s_.dt, a0 = s_.a0;
    const bool newton = Convection && lin_ == Linearisation::newton;
    Nodal U, Uth, H, Us;
    Eigen::Matrix<Real, np, 1> Pl;
    gather(fd, u, U, Uth, H, Us, Pl);
    Eigen::Matrix<Real, D + 1, D> Vm = Eigen::Matrix<Real, D + 1, D>::Zero();  // mesh velocity at vertices
    if (s_.mesh_velocity)
      for (int a = 0; a <= D; ++a) Vm.row(a) = (*s_.mesh_velocity)[mesh.cell(c)[a]].transpose();
    const typename Stabilisation::Cell local{.mesh = mesh, .c = c, .Jinv = Jinv, .detJ = detJ, .U = U, .Uth = Uth,
                                             .H = H, .Us = Us, .Vm = Vm, .Pl = Pl, .dt = dt, .theta = th, .a0 = a0,
                                             .tau_dt = s_.tau_dt > 0 ? s_.tau_dt : dt, .newton = newton};
    const Real tau_c = stab_.tau(local);
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
    // --- stabilisation (GLS: SUPG + PSPG by the exact-degree rule), without the body force -----
    stab_.add_cell(local, tau_c, A, r);
    // --- body force: -(f, w), and its part of the stabilisation (rule of degree 3k + 1) --------
    if (!s_.force) return;
    const Vec<D> x0 = mesh.node(mesh.cell(c)[0]);
    const auto& frule = *ftab_.rule;
    for (int q = 0; q < frule.size(); ++q) {
      const Real w = frule.weights[q] * detJ;
      const Vec<D> fq = s_.force(x0 + J * frule.points[q]);
      const auto& phv = ftab_.phi_v[q];
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < D; ++i) r[D * a + i] -= w * fq[i] * phv[a];
      stab_.add_force(local, tau_c, ftab_, q, w, fq, A, r);
    }
  }

  /// Cell c through the isoparametric map (Taylor–Hood): at each point of the rule of degree
  /// 3k + 1, J(xi), physical gradients G = dphi J^-1, weight w det J(xi), and with
  /// u_th, u* and p at the point, v the mesh velocity interpolated on the geometry's P2 nodes
  /// (vertices: `mesh_velocity`; edge points: `edge_velocity`), a = c - v:
  ///   r(a, i) += w [rho (D_t u_i + (a . grad) u_th,i) phi_a + mu (d_j u_th,i + d_i u_th,j) G_aj
  ///                 - p G_ai - f_i phi_a],      r(p_b) -= w psi_b div u_th
  ///   A(a i, b j) += w [delta_ij (rho a0 / dt phi_a phi_b + theta (mu G_a . G_b + rho phi_a a . G_b))
  ///                     + theta mu G_aj G_bi + (Newton) theta rho phi_a phi_b d_j u_th,i]
  ///   A(a i, p_b) -= w psi_b G_ai,   A(p_b, a i) -= theta w psi_b G_ai.
  /// Equal to the affine path when the edge points are the midpoints (tested).
  void curved_cell(Index c, const LocalVec& u, LocalMat& A, LocalVec& r) const {
    using Geometry = QuadraticGeometry<D>;
    constexpr int ng = Geometry::n_nodes;
    const auto& mesh = space_->mesh();
    const auto X = geom_->cell_nodes(c);
    const auto& fd = space_->cell_field_dofs(c);
    const Real th = s_.theta, dt = s_.dt, a0 = s_.a0;
    const bool newton = Convection && lin_ == Linearisation::newton;
    Nodal U, Uth, H, Us;
    Eigen::Matrix<Real, np, 1> Pl;
    gather(fd, u, U, Uth, H, Us, Pl);
    const Nodal Dt = (a0 * U + H) / dt;  // nodal D_t u
    Eigen::Matrix<Real, ng, D> Vg = Eigen::Matrix<Real, ng, D>::Zero();  // mesh velocity at the geometry nodes
    if (s_.mesh_velocity) {
      const auto& cv = mesh.cell(c);
      for (int a = 0; a <= D; ++a) Vg.row(a) = (*s_.mesh_velocity)[std::size_t(cv[a])].transpose();
      const auto& ce = mesh.cell_edges(c);
      for (int k = 0; k < Geometry::Shape::n_edge_dofs; ++k) {
        const auto& ab = SimplexTopology<D>::edges[k];
        Vg.row(D + 1 + k) = s_.edge_velocity ? (*s_.edge_velocity)[std::size_t(ce[k])].transpose()
                                             : Eigen::Matrix<Real, 1, D>(0.5 * (Vg.row(ab[0]) + Vg.row(ab[1])));
      }
    }
    A.setZero();
    r.setZero();
    const auto& rule = *ftab_.rule;
    for (int q = 0; q < rule.size(); ++q) {
      const Mat<D> J = Geometry::jacobian(X, geo_dN_[std::size_t(q)]);
      const Real w = rule.weights[q] * J.determinant();
      const Eigen::Matrix<Real, nv, D> G = ftab_.dphi_v[q] * J.inverse();
      const auto& phi = ftab_.phi_v[q];
      const auto& psi = ftab_.phi_p[q];
      const Eigen::Matrix<Real, nv, 1> ph = Eigen::Map<const Eigen::Matrix<Real, nv, 1>>(phi.data());
      const Mat<D> gu = Uth.transpose() * G;  // (i, j) = d_j u_th,i
      const Vec<D> dtu = Dt.transpose() * ph;
      const Real pq = psi.dot(Pl);
      Vec<D> conv = Vec<D>::Zero();
      Eigen::Matrix<Real, nv, 1> aG = Eigen::Matrix<Real, nv, 1>::Zero();  // a . G_b
      if constexpr (Convection) {
        const Vec<D> cq = (newton ? Uth : Us).transpose() * ph;
        const Vec<D> vq = Vg.transpose() * Eigen::Map<const Eigen::Matrix<Real, ng, 1>>(geo_N_[std::size_t(q)].data());
        const Vec<D> aq = cq - vq;
        conv = gu * aq;
        aG = G * aq;
      }
      Vec<D> fq = Vec<D>::Zero();
      if (s_.force) fq = s_.force(Geometry::map(X, geo_N_[std::size_t(q)]));
      const Mat<D> sym = mu_ * (gu + gu.transpose());
      const Vec<D> rhs = rho_ * (dtu + conv) - fq;
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < D; ++i)
          r[D * a + i] += w * (rhs[i] * ph[a] + sym.row(i).dot(G.row(a)) - pq * G(a, i));
      const Real div = gu.trace();
      for (int b = 0; b < np; ++b) r[D * nv + b] -= w * psi[b] * div;
      // Jacobian
      const Eigen::Matrix<Real, nv, nv> diag =
          w * ((rho_ * a0 / dt) * ph * ph.transpose() + th * (mu_ * G * G.transpose() + rho_ * ph * aG.transpose()));
      for (int a = 0; a < nv; ++a)
        for (int b = 0; b < nv; ++b)
          for (int i = 0; i < D; ++i) {
            A(D * a + i, D * b + i) += diag(a, b);
            for (int j = 0; j < D; ++j) {
              Real v = th * mu_ * G(a, j) * G(b, i);
              if (newton) v += th * rho_ * ph[a] * ph[b] * gu(i, j);
              A(D * a + i, D * b + j) += w * v;
            }
          }
      for (int a = 0; a < nv; ++a)
        for (int i = 0; i < D; ++i)
          for (int b = 0; b < np; ++b) {
            const Real v = w * psi[b] * G(a, i);
            A(D * a + i, D * nv + b) -= v;
            A(D * nv + b, D * a + i) -= th * v;
          }
    }
  }

 private:
  /// The cell's nodal data: u^{n+1}, u_th, the history sum, u* and the pressure.
  void gather(const typename Space::CellDofs& fd, const LocalVec& u, Nodal& U, Nodal& Uth, Nodal& H, Nodal& Us,
              Eigen::Matrix<Real, np, 1>& Pl) const {
    const Real th = s_.theta;
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
  }

  const Space* space_;
  Real rho_, mu_;
  Linearisation lin_;
  const Forms* forms_;
  const NsForms* nsforms_;
  [[no_unique_address]] Stabilisation stab_;  // empty without stabilisation
  ReferenceTables<D, Pair> ftab_;
  StepInputs<D> s_;
  const QuadraticGeometry<D>* geom_ = nullptr;
  std::vector<typename QuadraticGeometry<D>::Shape::Values> geo_N_;     // geometry shape values at ftab_'s points
  std::vector<typename QuadraticGeometry<D>::Shape::Gradients> geo_dN_;  // ... and their reference gradients
};

}  // namespace alefsi
