#pragma once
/// \file physics/mesh_motion.hpp
/// Mesh velocity from the elasticity problem of eq. (15)-(16).
///
/// Find the nodal mesh velocity v (P1, one vector per mesh node) with v given on every
/// boundary node and
///     int_Omega [ lambda_e (div v) I + 2 mu_e D(v) ] : D(w) = 0   for all w vanishing there,
/// with element-wise constants mu_e = 1/|K| (stiffer small cells) and
///     2D: lambda_e = -mu_e (the paper's choice). Then 2 D(v):D(v) - (div v)^2 =
///         (v1,x - v2,y)^2 + (v1,y + v2,x)^2 >= 0: a conformal energy, SPD with Dirichlet data;
///     3D: lambda_e = 0. With lambda = -mu the 3D integrand is indefinite (D v = I gives
///         6 - 9 < 0), and with mu jumping between cells nothing guarantees a definite system
///         (DESIGN.md); lambda = 0 keeps it SPD.
/// The geometry is the one passed to `solve` (the scheme's extrapolated positions), not the
/// mesh's current coordinates. The sparsity pattern and the symbolic Cholesky analysis are
/// done once per mesh topology; each solve assembles, and factorises numerically unless
/// factorisation reuse is on (`set_reuse`, la/linear_solve.hpp): the matrix then changes
/// with the positions from step to step only slightly, and is solved by GMRES preconditioned by
/// the factors of an earlier one (refactorised when that needs too many iterations). The SPD
/// solver is a policy: by default Eigen's SimplicialLLT in 2D, and in 3D CHOLMOD when alefsi
/// was built with SuiteSparse, else SimplicialLLT (la/suitesparse.hpp, `DefaultSpdSolverFor<D>`).
///
///     ElasticMeshMotion<2> motion(mesh);
///     auto v = motion.solve(X_hat, [&](Index node, const Vec<2>& x) { return wall_velocity(x); });
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "alefsi/core/eigen_sparse.hpp"
#include "alefsi/fem/constraints.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/linear_solve.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/la/suitesparse.hpp"
#include "alefsi/mesh/mesh.hpp"

namespace alefsi {

template <int D, LinearSolver Solver = DefaultSpdSolverFor<D>>
class ElasticMeshMotion {
 public:
  static constexpr int n_local = D * (D + 1);
  using BoundaryData = std::function<Vec<D>(Index node, const Vec<D>& x)>;

  explicit ElasticMeshMotion(const Mesh<D>& mesh) : mesh_(&mesh), cons_(D * mesh.n_nodes()) {
    std::vector<char> on_boundary(mesh.n_nodes(), 0);
    for (Index f : mesh.boundary_facets())
      for (Index v : mesh.facet(f)) on_boundary[v] = 1;
    for (Index v = 0; v < mesh.n_nodes(); ++v)
      if (on_boundary[v]) {
        boundary_.push_back(v);
        for (int k = 0; k < D; ++k) cons_.fix(D * v + k, 0.0);
      }
    cons_.finalize();
    asmb_ = std::make_unique<Assembler<n_local>>(
        mesh.n_cells(),
        [&](Index c) {
          std::array<Index, n_local> d;
          for (int a = 0; a <= D; ++a)
            for (int k = 0; k < D; ++k) d[D * a + k] = D * mesh.cell(c)[a] + k;
          return d;
        },
        cons_);
  }

  /// Factorisation reuse across solves (off by default; ignored by iterative solvers).
  void set_reuse(const FactorisationReuse& r) { ls_.set_reuse(r); }
  /// The factorisations and reused solves so far.
  const LinearSolveCounts& counts() const { return counts_; }
  /// The solver and its kept matrices (checkpoints), and the matrix of the last solve, whose
  /// pattern `restore` needs.
  LinearSolve<Solver>& linear_solve() { return ls_; }
  const LinearSolve<Solver>& linear_solve() const { return ls_; }
  /// The matrix with the elasticity pattern (values of the last solve; the pattern alone
  /// before the first).
  SparseMatrix& matrix() {
    if (J_.nonZeros() == 0) asmb_->take_pattern(J_);
    return J_;
  }

  /// Nodes whose mesh velocity is prescribed (every boundary node).
  const std::vector<Index>& boundary_nodes() const { return boundary_; }

  /// Solves on the geometry `x` (one position per node) with boundary velocities from `g`.
  std::vector<Vec<D>> solve(const std::vector<Vec<D>>& x, const BoundaryData& g) {
    for (Index v : boundary_) {
      const Vec<D> val = g(v, x[v]);
      for (int k = 0; k < D; ++k) cons_.set_fixed_value(D * v + k, val[k]);
    }
    std::vector<Vec<D>> out(x.size());
    if (cons_.n_unknowns() == 0) {
      for (Index v : boundary_) out[v] = g(v, x[v]);
      return out;
    }
    Kernel k{mesh_, &x};
    const VecX field0 = cons_.expand(VecX::Zero(cons_.n_unknowns()));
    VecX r;
    asmb_->assemble(k, field0, &J_, &r);
    VecX sol;
    try {
      sol = ls_.solve(J_, VecX(-r), counts_);  // factorises J_ unless earlier factors are reused
    } catch (const SolverError& e) {
      throw SolverError(std::string("mesh-velocity (elasticity) matrix: ") + e.what() +
                        " (is the extrapolated mesh valid?)");
    }
    const VecX field = cons_.expand(sol);
    for (std::size_t v = 0; v < x.size(); ++v)
      for (int kk = 0; kk < D; ++kk) out[v][kk] = field[D * Index(v) + kk];
    return out;
  }

 private:
  struct Kernel {
    const Mesh<D>* mesh;
    const std::vector<Vec<D>>* x;
    void cell(Index c, const Eigen::Matrix<Real, n_local, 1>& u, Eigen::Matrix<Real, n_local, n_local>& A,
              Eigen::Matrix<Real, n_local, 1>& r) const {
      const auto& cv = mesh->cell(c);
      Mat<D> J;
      for (int i = 0; i < D; ++i) J.col(i) = (*x)[cv[i + 1]] - (*x)[cv[0]];
      const Real vol = std::abs(J.determinant()) * reference_measure<D>;
      const Mat<D> Jinv = J.inverse();
      Eigen::Matrix<Real, D + 1, D> G;  // gradients of the P1 basis
      G.row(0) = -Jinv.colwise().sum();
      G.bottomRows(D) = Jinv;
      const Real mu = 1.0 / vol, lambda = D == 2 ? -mu : 0.0;
      for (int a = 0; a <= D; ++a)
        for (int b = 0; b <= D; ++b) {
          const Real gg = G.row(a).dot(G.row(b));
          for (int i = 0; i < D; ++i)
            for (int j = 0; j < D; ++j)
              A(D * a + i, D * b + j) =
                  vol * (lambda * G(a, i) * G(b, j) + mu * ((i == j ? gg : 0.0) + G(a, j) * G(b, i)));
        }
      r = A * u;
    }
  };

  const Mesh<D>* mesh_;
  DofConstraints cons_;
  std::vector<Index> boundary_;
  std::unique_ptr<Assembler<n_local>> asmb_;
  SparseMatrix J_;
  LinearSolve<Solver> ls_;
  LinearSolveCounts counts_;
};

}  // namespace alefsi
