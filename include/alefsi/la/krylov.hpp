#pragma once
/// \file la/krylov.hpp
/// An iterative solver policy for the flow systems: GMRES preconditioned by a block-triangular
/// saddle-point preconditioner, for the 3D systems where a direct factorisation runs out of
/// memory or time (numbers: docs/solvers.md, "Iterative path for 3D").
///
/// The unknowns of a flow system (fem/constraints.hpp over fem/dofmap.hpp's field order) come
/// as [u | p | z]: the free velocity components (interleaved, all D components of a node
/// together: every constraint of the library fixes or links whole nodes), the free pressures,
/// then the extra unknowns (rigid-body velocities, d(d+1)/2 per free body). With v = [u; z]
///     K = [ A   Bt ]        preconditioner  P = [ A~  Bt  ]
///         [ B  -C  ]                            [ 0  -S~  ],
/// C = 0 for Taylor–Hood, the GLS/PSPG pressure block for P1/P1-GLS. Applying P^-1:
/// p = -S~^-1 r_p, then v = A~^-1 (r_v - Bt p), inside restarted GMRES (right preconditioning:
/// the residual it monitors is the true one). P^-1 is a fixed linear operator.
///   - A~^-1: one smoothed-aggregation AMG V-cycle (la/amg.hpp) on the velocity-velocity block
///     A_uu (components labelled, so aggregates do not mix them); the few body unknowns z are
///     eliminated exactly around it: with M = the V-cycle, Y = M A_uz (one V-cycle per body
///     unknown at set-up) and the dense body Schur complement S_z = A_zz - A_zu Y,
///     u' = M r_u, z = S_z^-1 (r_z - A_zu u'), u = u' - Y z.
///   - S~ approximates the Schur complement S = B A^-1 Bt + C:
///       * with `SaddlePointBlocks` from the space (`saddle_point_blocks`), the Cahouet–Chabard
///         form S~^-1 = mu M_p^-1 + L^-1, M_p the pressure mass matrix (inverted by a few
///         Jacobi–Chebyshev steps) and, when the velocity block holds gamma M_u (a time step:
///         gamma = rho a_0 / (theta dt)), L = B (gamma M_u,lumped)^-1 Bt + C (one AMG V-cycle);
///         `AleFlow` hands them over for every step (sim/discretisation.hpp);
///       * without them (the policy used on its own, no `set_blocks`), algebraically:
///         S~ = diag(B diag(A_uu)^-1 Bt) + diag(C), a lumped stand-in for M_p / mu. It is
///         spectrally equivalent to M_p / mu on shape-regular meshes (steady Stokes: mesh-independent
///         iteration counts), but it has no Cahouet–Chabard part: with a dominant rho/dt mass
///         the counts grow with refinement. The pressure unknowns are then found from the
///         matrix: the contiguous range of unknowns whose diagonal entry is <= 0 (zero for
///         Taylor–Hood, -C_ii < 0 for GLS; every velocity and body diagonal is > 0).
///
/// A closed domain (every boundary velocity given) defines the pressure up to a constant. The
/// direct solvers need it pinned (one pressure DOF fixed), but a pin leaves K a near-null vector:
/// the constant on the free pressures, with K v = the pinned DOF's column of Bt, of the size of
/// one basis function's. GMRES resolves that mode slowly and, at 1e-8, sometimes not at all (ten
/// Cate's E1 at D / 12 stagnated at 1.1-1.8e-8 after 1000 iterations with |x| = 221 for
/// |b| = 1.4e-10; docs/solvers.md). So this solver takes the system unpinned
/// (`set_pressure_null_space(true)`, as `Discretisation` does for a closed domain): then K's
/// null space, and K^T's, is exactly e = [0; 1; 0], the constant on all pressures (Bt 1 = 0 for
/// a velocity that vanishes or moves rigidly on the whole boundary, and GLS terms act on grad q).
/// `solve` takes b's component along e off (a consistent b has none: it is round-off, or a
/// mass defect of the boundary data, reported as `pressure_defect`), iterates, and returns the
/// x whose pressures have zero sum. GMRES converges on such a singular system: its Krylov space
/// lies in range(K), and P e is not in range(K) (Brown & Walker, SIAM J. Matrix Anal. Appl. 18
/// (1997) 37). The Cahouet–Chabard Laplacian L has the constant as its null space too: its
/// V-cycle is built on L without the first pressure (a pin inside the preconditioner only) and
/// applied to r_p with its mean removed, which solves L p = r_p on the complement of the constant.
///
/// `analyze(A)` finds the block split (once per pattern); `factorize(A)` builds the AMG
/// hierarchies and Schur approximations (values are read: per matrix); `solve(b)` iterates until
/// ||b - K x|| <= tolerance ||b|| and throws `SolverError` when `max_iterations` are spent.
/// Lifetime: `solve` multiplies by the matrix given to `factorize`, which must stay alive and
/// unchanged until the last `solve` (UmfPackLu keeps a copy instead; this solver does not).
/// `set_coupling(C)` (la/coupling.hpp): entries among the extra unknowns that A's pattern lacks
/// (two bodies in contact); the solves are then with A + C, and the set-up's exact elimination
/// of the extra unknowns includes C (the values it had at the set-up).
///
///     alefsi::SaddlePointGmres<3> krylov({.tolerance = 1e-10});
///     krylov.set_blocks(alefsi::saddle_point_blocks(space, cons, mu));   // optional
///     krylov.analyze(J);  krylov.factorize(J);  VecX du = krylov.solve(-r);
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/core/error.hpp"
#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/fem/quadrature.hpp"
#include "alefsi/la/amg.hpp"
#include "alefsi/la/gmres.hpp"
#include "alefsi/la/coupling.hpp"
#include "alefsi/la/saddle_point_blocks.hpp"
#include "alefsi/la/solvers.hpp"

namespace alefsi {

struct KrylovOptions {
  Real tolerance = 1e-8;     ///< on ||b - K x|| / ||b||
  int max_iterations = 1000;
  int restart = 60;          ///< GMRES restart length (memory: restart + 1 vectors)
  int augment = 2;           ///< LGMRES corrections kept across restarts (la/gmres.hpp; 2 vectors each)
  int mass_steps = 3;        ///< Jacobi–Chebyshev steps for M_p^-1 (explicit blocks)
  int velocity_cycles = 1;   ///< AMG V-cycles per velocity solve (stationary iteration: linear)
  AmgOptions amg = {};       ///< velocity block (and Cahouet–Chabard Laplacian) AMG
};

/// Restarted GMRES with the block-triangular AMG/Schur preconditioner (file comment).
/// `D`: the number of velocity components per node (the dimension).
template <int D>
class SaddlePointGmres {
 public:
  static constexpr const char* name = "GMRES+block(AMG, Schur)";

  explicit SaddlePointGmres(KrylovOptions opt = {})
      : opt_(opt), amg_(opt.amg), laplace_amg_(opt.amg), mass_amg_(opt.amg) {
    ALEFSI_CHECK_ARG(opt.tolerance > 0 && opt.tolerance < 1, "tolerance", "must be in (0, 1), got ", opt.tolerance);
    ALEFSI_CHECK_ARG(opt.max_iterations >= 1, "max_iterations", "must be positive");
    ALEFSI_CHECK_ARG(opt.restart >= 1, "restart", "must be positive");
    ALEFSI_CHECK_ARG(opt.augment >= 0, "augment", "must be non-negative");
    ALEFSI_CHECK_ARG(opt.mass_steps >= 1, "mass_steps", "must be positive");
    ALEFSI_CHECK_ARG(opt.velocity_cycles >= 1, "velocity_cycles", "must be positive");
  }

  /// Block layout and Schur data from the space (optional; see the file comment). Takes effect
  /// at the next `analyze`/`factorize`.
  void set_blocks(SaddlePointBlocks blocks) {
    blocks_ = std::move(blocks);
    analyzed_ = false;
  }

  /// Whether K is unpinned with the constant pressure as its null space (file comment). Takes
  /// effect at the next `analyze`/`factorize`.
  void set_pressure_null_space(bool on) {
    null_space_ = on;
    analyzed_ = false;
  }
  bool pressure_null_space() const { return null_space_; }

  /// Entries beside the matrix's pattern among the extra unknowns (la/coupling.hpp: a contact
  /// between two bodies), null for none: the solves are with A + C, and the next set-up
  /// eliminates the extra unknowns exactly with them. `c` must stay alive while it is set.
  void set_coupling(const BlockCoupling* c) { coupling_ = c && !c->empty() ? c : nullptr; }

  /// Finds the split [u | p | z] (from the blocks, or from the diagonal's sign).
  void analyze(const SparseMatrix& A) {
    n_ = A.rows();
    const SaddlePointSplit split = saddle_point_split(A, blocks_ ? &*blocks_ : nullptr, name);
    nu_ = split.n_velocity, np_ = split.n_pressure, ne_ = split.n_extra;
    comp_.clear();
    if (blocks_) {
      comp_ = blocks_->velocity_component;
      ALEFSI_CHECK_ARG(comp_.empty() || Index(comp_.size()) == nu_, "blocks.velocity_component",
                       "needs one label per velocity unknown");
    }
    if (comp_.empty()) {
      comp_.assign(std::size_t(nu_), 0);
      if (nu_ % D == 0)
        for (Index i = 0; i < nu_; ++i) comp_[i] = int(i % D);
    }
    ALEFSI_CHECK_ARG(!null_space_ || np_ >= 2, "A", "has ", np_,
                     " pressure unknowns: too few for a pressure null space");
    analyzed_ = true;
  }

  void factorize(const SparseMatrix& A) {
    if (!analyzed_ || A.rows() != n_) analyze(A);
    A_ = &A;
    const Index p0 = nu_, e0 = nu_ + np_;
    if (coupling_)
      ALEFSI_CHECK_ARG(coupling_->index.front() >= e0 && coupling_->index.back() < n_, "coupling",
                       "must lie among the extra unknowns [", e0, ", ", n_, ")");
    RowSparseMatrix Ar = A;
    RowSparseMatrix Auu = Ar.topLeftCorner(nu_, nu_);
    amg_.compute(std::move(Auu), comp_);
    const RowSparseMatrix Bp = Ar.middleRows(p0, np_);  // [B_u  -C  B_z]
    Auu_ = &amg_.matrix();
    // body unknowns: exact elimination around the V-cycle
    if (ne_ > 0) {
      const MatX Auz = MatX(A.block(0, e0, nu_, ne_));
      Azu_ = MatX(Ar.block(e0, 0, ne_, nu_));
      Y_.resize(nu_, ne_);
      for (Index k = 0; k < ne_; ++k) Y_.col(k) = velocity_solve(Auz.col(k));
      MatX Sz = MatX(Ar.block(e0, e0, ne_, ne_)) - Azu_ * Y_;
      if (coupling_)  // entries beside the pattern (la/coupling.hpp): all among the extra unknowns
        for (Index a = 0; a < coupling_->size(); ++a)
          for (Index b = 0; b < coupling_->size(); ++b)
            Sz(coupling_->index[std::size_t(a)] - e0, coupling_->index[std::size_t(b)] - e0) += coupling_->block(a, b);
      body_lu_.compute(Sz);
    }
    // Schur complement approximation
    const VecX diag_u = A.diagonal().head(nu_);
    VecX minus_c(np_);  // diagonal of the pressure block (-C_ii)
    for (Index i = 0; i < np_; ++i) minus_c[i] = A.coeff(p0 + i, p0 + i);
    use_mass_ = blocks_ && blocks_->pressure_mass.rows() == np_ && np_ > 0;
    use_laplace_ = use_mass_ && blocks_->mass_coefficient > 0 && blocks_->velocity_mass.size() == nu_;
    if (use_mass_) {
      // X = M_p / (2 mu) + C: Jacobi–Chebyshev on M_p when C = 0 (Taylor–Hood), else one AMG
      // V-cycle on X
      const SparseMatrix& M = blocks_->pressure_mass;
      const Real scale = 1 / (2 * blocks_->mu);
      mass_inv_diag_ = M.diagonal().cwiseInverse();
      has_c_ = minus_c.cwiseAbs().maxCoeff() > 0;
      if (has_c_) {
        RowSparseMatrix X = scale * RowSparseMatrix(M);
        X -= RowSparseMatrix(Bp.middleCols(p0, np_));  // + C
        mass_amg_.compute(std::move(X));
      } else {
        // Jacobi–Chebyshev interval: [lambda_max / 5, 1.1 lambda_max] of D^-1 M (P1: [1/2, 5/2] in 3D)
        VecX v = VecX::Ones(np_);
        Real lambda = 1;
        for (int k = 0; k < 20; ++k) {
          VecX w = mass_inv_diag_.cwiseProduct(M * v);
          lambda = w.norm() / v.norm();
          v = w / w.norm();
        }
        cheb_hi_ = 1.1 * lambda;
        cheb_lo_ = lambda / 5;
      }
      mass_scale_ = scale;
      if (use_laplace_) {
        const VecX inv_m = (blocks_->mass_coefficient * blocks_->velocity_mass).cwiseInverse();
        const RowSparseMatrix Bu = Bp.leftCols(nu_);
        const RowSparseMatrix Bt = Ar.block(0, p0, nu_, np_);
        RowSparseMatrix L = Bu * inv_m.asDiagonal() * Bt;
        if (null_space_) L = RowSparseMatrix(L.bottomRightCorner(np_ - 1, np_ - 1));  // L 1 = 0: pinned here
        laplace_amg_.compute(std::move(L));
      }
    } else {
      // s_i = sum_j B_ij Bt_ji / A_jj over velocity unknowns j (B and Bt from the matrix);
      // S~ = diag(s) + C: diagonal when C = 0, else one AMG V-cycle
      VecX sd(np_);
      for (Index i = 0; i < np_; ++i) {
        Real s = 0;
        SparseMatrix::InnerIterator bt(A, p0 + i);  // column p0 + i: Bt_ji, sorted by j
        for (RowSparseMatrix::InnerIterator b(Bp, i); b && b.col() < nu_; ++b) {
          while (bt && bt.row() < b.col()) ++bt;
          if (bt && bt.row() == b.col()) s += b.value() * bt.value() / diag_u[b.col()];
        }
        if (!(s - minus_c[i] > 0))
          throw SolverError(std::string(name) + ": non-positive Schur diagonal at pressure unknown " + std::to_string(i));
        sd[i] = s;
      }
      has_c_ = minus_c.cwiseAbs().maxCoeff() > 0;
      if (has_c_) {
        RowSparseMatrix X = -RowSparseMatrix(Bp.middleCols(p0, np_));  // C
        for (Index i = 0; i < np_; ++i) X.coeffRef(i, i) += sd[i];
        mass_amg_.compute(std::move(X));
      } else {
        schur_inv_diag_ = sd.cwiseInverse();
      }
    }
    work_.V.resize(0, 0);
  }

  /// Solves A x = b with the preconditioner set up for an earlier matrix of the same pattern
  /// (its AMG hierarchies, body elimination and Schur approximation; the products are with A).
  /// A must stay alive and unchanged until the last solve, as for `factorize`.
  VecX solve(const SparseMatrix& A, const VecX& b) {
    ALEFSI_CHECK_ARG(A_ && A.rows() == n_ && A.nonZeros() == A_->nonZeros(), "A",
                     "must have the pattern of the matrix the preconditioner was set up for");
    A_ = &A;
    return solve(b);
  }

  VecX solve(const VecX& b) {
    if (!A_) throw SolverError(std::string(name) + ": solve before factorize");
    ALEFSI_CHECK_ARG(b.size() == n_, "b", "has ", b.size(), " entries, expected ", n_);
    const GmresOptions gopt{.tolerance = opt_.tolerance, .max_iterations = opt_.max_iterations,
                            .restart = opt_.restart, .augment = opt_.augment};
    auto prec = [this](const VecX& v) { return precondition(v); };
    VecX x;
    auto gmres_on = [&](const VecX& rhs, const GmresOptions& o) {
      return coupling_ ? gmres(CoupledMatrix<SparseMatrix>{*A_, *coupling_}, rhs, prec, o, x, work_)
                       : gmres(*A_, rhs, prec, o, x, work_);
    };
    GmresResult res;
    defect_ = 0;
    if (!null_space_) {
      res = gmres_on(b, gopt);
    } else {
      // b without its component along e; the tolerance stays relative to ||b||
      VecX bc = b;
      const Real mean = bc.segment(nu_, np_).mean();
      bc.segment(nu_, np_).array() -= mean;
      const Real bn = b.norm(), cn = bc.norm();
      defect_ = bn > 0 ? std::abs(mean) * std::sqrt(Real(np_)) / bn : 0;
      if (cn <= opt_.tolerance * bn) {
        x = VecX::Zero(n_);
        res.converged = true;
      } else {
        GmresOptions copt = gopt;
        copt.tolerance = opt_.tolerance * bn / cn;
        res = gmres_on(bc, copt);
        res.residual *= cn / bn;
      }
      x.segment(nu_, np_).array() -= x.segment(nu_, np_).mean();
    }
    iterations_ = res.iterations, residual_ = res.residual;
    if (!res.converged)
      throw SolverError(std::string(name) + " did not converge: " + std::to_string(res.iterations) +
                        " iterations, relative residual " + detail::sci(res.residual) + " (tolerance " +
                        detail::sci(opt_.tolerance) + ")" +
                        (res.breakdown ? "; breakdown: the preconditioned operator gave no new direction" : ""));
    return x;
  }

  /// The preconditioner P^-1 r (for tests and diagnostics).
  VecX precondition(const VecX& r) const {
    const Index p0 = nu_;
    VecX z(n_);
    // pressure: p = -S~^-1 r_p
    auto rp = r.segment(p0, np_);
    VecX p;
    if (use_mass_) {
      p = has_c_ ? mass_amg_.apply(rp) : VecX(mass_solve(rp) / mass_scale_);
      if (use_laplace_) {
        if (!null_space_) {
          p += laplace_amg_.apply(rp);
        } else {  // L p = r_p - mean(r_p) with p's first entry 0 (file comment)
          const VecX q = rp.tail(np_ - 1).array() - rp.mean();
          p.tail(np_ - 1) += laplace_amg_.apply(q);
        }
      }
    } else {
      p = has_c_ ? mass_amg_.apply(rp) : VecX(schur_inv_diag_.cwiseProduct(rp));
    }
    p = -p;
    z.segment(p0, np_) = p;
    // velocity and bodies: A~ v = r_v - Bt p
    const VecX t = r - A_->middleCols(p0, np_) * p;
    VecX u = velocity_solve(t.head(nu_));
    if (ne_ > 0) {
      const VecX ze = body_lu_.solve(t.tail(ne_) - Azu_ * u);
      u.noalias() -= Y_ * ze;
      z.tail(ne_) = ze;
    }
    z.head(nu_) = u;
    return z;
  }

  /// GMRES iterations and final relative residual ||b - K x|| / ||b|| of the last solve (with a
  /// pressure null space: of b without its defect).
  int iterations() const { return iterations_; }
  Real residual() const { return residual_; }
  /// With a pressure null space: |b . e| / (|e| ||b||) of the last solve, the part of b that no x
  /// reaches (round-off for a consistent system).
  Real pressure_defect() const { return defect_; }
  Index n_velocity() const { return nu_; }
  Index n_pressure() const { return np_; }
  Index n_extra() const { return ne_; }
  const SmoothedAggregationAmg& velocity_amg() const { return amg_; }
  bool cahouet_chabard() const { return use_laplace_; }
  bool pressure_mass() const { return use_mass_; }

 private:
  // velocity_cycles V-cycles on A_uu x = b from x = 0
  VecX velocity_solve(const VecX& b) const {
    VecX x = amg_.apply(b);
    for (int k = 1; k < opt_.velocity_cycles; ++k) x += amg_.apply(b - *Auu_ * x);
    return x;
  }

  // a few Jacobi–Chebyshev steps for M_p x = r (a fixed polynomial in D^-1 M: linear)
  VecX mass_solve(const VecX& rhs) const {
    const SparseMatrix& M = blocks_->pressure_mass;
    const Real theta = (cheb_hi_ + cheb_lo_) / 2, delta = (cheb_hi_ - cheb_lo_) / 2;
    const Real sigma = theta / delta;
    Real rho = 1 / sigma;
    VecX x = VecX::Zero(rhs.size()), r = rhs;
    VecX d = mass_inv_diag_.cwiseProduct(r) / theta;
    for (int k = 0; k < opt_.mass_steps; ++k) {
      x += d;
      if (k + 1 == opt_.mass_steps) break;
      r.noalias() -= M * d;
      const Real rho_next = 1 / (2 * sigma - rho);
      d *= rho_next * rho;
      d.noalias() += (2 * rho_next / delta) * mass_inv_diag_.cwiseProduct(r);
      rho = rho_next;
    }
    return x;
  }

  KrylovOptions opt_;
  std::optional<SaddlePointBlocks> blocks_;
  bool analyzed_ = false, null_space_ = false, use_mass_ = false, use_laplace_ = false, has_c_ = false;
  Index n_ = 0, nu_ = 0, np_ = 0, ne_ = 0;
  std::vector<int> comp_;
  const SparseMatrix* A_ = nullptr;
  const RowSparseMatrix* Auu_ = nullptr;
  SmoothedAggregationAmg amg_, laplace_amg_, mass_amg_;
  MatX Y_, Azu_;
  Eigen::PartialPivLU<MatX> body_lu_;
  VecX schur_inv_diag_, mass_inv_diag_;
  Real cheb_lo_ = 0.5, cheb_hi_ = 2.5, mass_scale_ = 1;
  GmresWork work_;
  const BlockCoupling* coupling_ = nullptr;  // non-empty, or null
  int iterations_ = 0;
  Real residual_ = 0, defect_ = 0;
};

static_assert(LinearSolver<SaddlePointGmres<3>>, "SaddlePointGmres must model LinearSolver");

}  // namespace alefsi
