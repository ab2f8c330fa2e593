#pragma once
/// \file sim/ale_flow.hpp
/// Incompressible flow on a moving mesh, advanced by one of the five ALE schemes.
///
/// `AleFlow<D, Pair, Scheme, Convection>` owns the mesh and the time histories (positions X,
/// velocities U, the mesh velocity V^n) and advances them, one `step(dt)` at a time, exactly as
/// section 4 of the paper prescribes (see time/schemes.hpp for the table):
///   1. X^ = sum_k e_k X^{n-k}, U^ likewise (the scheme's extrapolation);
///   2. the mesh velocity at the scheme's level, on X^: from the elasticity problem with the
///      boundary mesh velocities (`set_mesh_velocity`, default 0), or from an analytic field
///      (`set_prescribed_mesh_velocity`, for verification);
///   3. X^{n+1} from delta_lg X^{n+1} = dt V;
///   4. the flow at n+theta on X^{n+theta} (physics/navier_stokes.hpp): Newton with the exact
///      Jacobian until the residual drops below the tolerance, or one semi-implicit linear solve.
/// Dirichlet velocities (`set_velocity`) are imposed at t^{n+1} on the DOF positions of X^{n+1}.
/// When every boundary facet has a Dirichlet velocity, pressure DOF 0 is pinned and the pressure
/// shifted to zero mean after each step (as in physics/stokes.hpp).
///
/// Start-up: a scheme that reads past levels the history does not have yet takes MR/AB steps
/// (self-starting, local error O(dt^3), so BDF3 keeps its order); the very first MR/AB step
/// takes X^{-1} = X^0 - dt V^0 with V^0 solved on X^0, and U^{-1} = U^0.
///
///     AleFlow<2, TaylorHood, BDF3_BDF3E> flow(mesh, {.rho = 1, .mu = 0.01});
///     flow.set_velocity(tags::top, [](const Vec<2>& x, Real t) { ... });
///     flow.set_initial_velocity(u0);
///     for (int n = 0; n < 100; ++n) flow.step(0.01);
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/constraints.hpp"
#include "alefsi/fem/dofmap.hpp"
#include "alefsi/la/assembler.hpp"
#include "alefsi/la/solvers.hpp"
#include "alefsi/mesh/mesh.hpp"
#include "alefsi/physics/mesh_motion.hpp"
#include "alefsi/physics/navier_stokes.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/time/schemes.hpp"

namespace alefsi {

struct FlowOptions {
  Real rho = 1, mu = 1;
  Linearisation linearisation = Linearisation::newton;
  int max_newton = 25;
  Real newton_tolerance = 1e-10;  ///< on the residual's max norm, relative to its first value (+ absolute 1e-13)
};

struct StepReport {
  int newton_iterations = 0;
  std::vector<Real> residuals;  ///< max-norm residual before each Newton update
  bool startup = false;
  /// Wall time (s) of the step's phases: mesh-velocity solve, assembly (all Newton
  /// iterations), numeric factorisation (incl. the one-off symbolic analysis), triangular solves.
  Real t_mesh_velocity = 0, t_assembly = 0, t_factorize = 0, t_solve = 0;
};

template <int D, ElementPair Pair, TimeScheme Scheme, bool Convection = true, LinearSolver Solver = SparseLu<>>
class AleFlow {
 public:
  using Space = MixedSpace<D, Pair>;
  using Kernel = AleNavierStokesKernel<D, Pair, Convection>;
  using TimeFunction = std::function<Vec<D>(const Vec<D>&, Real)>;

  AleFlow(Mesh<D> mesh, FlowOptions opt)
      : mesh_(std::move(mesh)), opt_(opt), space_(mesh_), kernel_(space_, opt.rho, opt.mu, opt.linearisation),
        motion_(mesh_) {
    ALEFSI_CHECK_ARG(opt.max_newton >= 1, "max_newton", "must be >= 1");
    X_[0] = mesh_.coordinates();
    U_[0] = VecX::Zero(space_.n_field());
  }

  AleFlow(const AleFlow&) = delete;  // the space and kernels point into the owned mesh
  AleFlow& operator=(const AleFlow&) = delete;

  const Mesh<D>& mesh() const { return mesh_; }
  const Space& space() const { return space_; }
  Real time() const { return t_; }
  /// u^n and p^n (p at the scheme's level n - 1 + theta) as a field vector.
  const VecX& field() const { return U_[0]; }
  /// Mesh velocity at level n (per node).
  const std::vector<Vec<D>>& mesh_velocity() const { return Vn_; }

  void set_velocity(int tag, TimeFunction g) {
    require_not_started("set_velocity");
    ALEFSI_CHECK_ARG(g != nullptr, "g", "boundary velocity function is empty");
    ALEFSI_CHECK_ARG(!space_.velocity().boundary_dofs(tag).empty(), "tag", "no boundary facet has tag ", tag);
    dirichlet_[tag] = std::move(g);
  }
  void set_mesh_velocity(int tag, TimeFunction g) {
    ALEFSI_CHECK_ARG(!mesh_.boundary_nodes(tag).empty(), "tag", "no boundary facet has tag ", tag);
    mesh_bc_[tag] = std::move(g);
  }
  void set_prescribed_mesh_velocity(TimeFunction v) { prescribed_ = std::move(v); }
  /// Gravity: body force rho_f g on the fluid and M g on every free body.
  void set_gravity(const Vec<D>& g) { gravity_ = g; }
  /// Adds a rigid body (2D). Its surface facets carry `body.tag`; returns its index.
  std::size_t add_body(const RigidBody2D& body)
    requires(D == 2)  // 3D bodies (6 DOF, quaternions) are not implemented yet
  {
    require_not_started("add_body");
    body.validate(bodies_.size());
    ALEFSI_CHECK_ARG(!mesh_.boundary_nodes(body.tag).empty(), "body.tag", "no boundary facet has tag ", body.tag);
    ALEFSI_CHECK_ARG(!dirichlet_.count(body.tag), "body.tag", "tag ", body.tag, " already has a Dirichlet velocity");
    Body b;
    b.data = body;
    b.xg.fill(body.centre);
    b.th.fill(body.angle);
    b.Z.fill(body.prescribed ? body.prescribed(t_) : body.velocity);
    b.nodes = mesh_.boundary_nodes(body.tag);
    for (Index v : b.nodes) b.r0.push_back(mesh_.node(v) - body.centre);
    bodies_.push_back(std::move(b));
    return bodies_.size() - 1;
  }
  /// Body k's centre of mass, angle and velocity Z = (V1, V2, w3) at t^n.
  Vec<D> body_centre(std::size_t k) const { return bodies_.at(k).xg[0]; }
  Real body_angle(std::size_t k) const { return bodies_.at(k).th[0]; }
  Vec<3> body_velocity(std::size_t k) const { return bodies_.at(k).Z[0]; }
  /// Hydrodynamic force and torque (F1, F2, T3) on free body k over the last step, from its
  /// momentum balance: M delta_l Z / dt - M g - external load.
  Vec<3> body_hydrodynamic_load(std::size_t k) const { return bodies_.at(k).load; }
  void set_force(TimeFunction f) { force_ = std::move(f); }
  void set_initial_velocity(const std::function<Vec<D>(const Vec<D>&)>& u0, Real t0 = 0) {
    require_not_started("set_initial_velocity");
    t_ = t0;
    for (Index i = 0; i < space_.velocity().n_dofs(); ++i) {
      const Vec<D> val = u0(space_.velocity().point(i));
      for (int k = 0; k < D; ++k) U_[0][space_.velocity_field(i, k)] = val[k];
    }
  }

  /// Advances from t^n to t^n + dt.
  StepReport step(Real dt) {
    ALEFSI_CHECK_ARG(dt > 0 && std::isfinite(dt), "dt", "time step must be positive and finite, got ", dt);
    if (!cons_) setup();
    if (levels_ == 0) {
      set_body_mesh_velocity(X_[0], {1.0, 0.0, 0.0}, t_);
      Vn_ = solve_mesh_velocity(X_[0], U_[0], t_);
    }
    StepReport rep;
    if (levels_ < history_levels<Scheme>()) {
      rep = step_with<MR_AB>(dt);
      rep.startup = true;
    } else {
      rep = step_with<Scheme>(dt);
    }
    return rep;
  }

 private:
  void require_not_started(const char* what) const {
    if (cons_) throw Error(std::string("AleFlow::") + what + " after the first step");
  }

  void setup() {
    cons_ = std::make_unique<DofConstraints>(space_.n_field());
    const auto& vel = space_.velocity();
    std::vector<char> done(vel.n_dofs(), 0);
    dirichlet_dofs_ = fix_velocity_on_tags(space_, dirichlet_, *cons_, done);
    if constexpr (D == 2)
      for (auto& b : bodies_) {
        if (b.data.free()) b.extra = cons_->add_unknowns(3);
        for (Index i : vel.boundary_dofs(b.data.tag)) {
          ALEFSI_CHECK_ARG(!done[i], "body.tag", "body surface (tag ", b.data.tag, ") touches a Dirichlet wall or another body");
          done[i] = 1;
          b.dofs.push_back(i);
          for (int k = 0; k < D; ++k) {
            const Index f = space_.velocity_field(i, k);
            if (b.data.free()) {
              const Index ex[] = {b.extra, b.extra + 1, b.extra + 2};
              const Real w[] = {0.0, 0.0, 0.0};
              cons_->link(f, ex, w, 0.0);
            } else {
              cons_->fix(f, 0.0);
            }
          }
        }
      }
    // every boundary velocity prescribed (walls or bodies): p is defined up to a constant
    pinned_ = whole_boundary_prescribed(mesh_, [&](int tag) {
      bool body = false;
      for (const auto& b : bodies_) body |= b.data.tag == tag;
      return body || dirichlet_.count(tag) > 0;
    });
    if (pinned_) cons_->fix(space_.pressure_field(0), 0.0);
    cons_->finalize();
    asmb_ = std::make_unique<Assembler<Space::n_local>>(
        mesh_.n_cells(), [&](Index c) { return space_.cell_field_dofs(c); }, *cons_);
  }

  // DOF position of scalar velocity DOF i on geometry x.
  Vec<D> dof_point(Index i, const std::vector<Vec<D>>& x) const {
    if (i < mesh_.n_nodes()) return x[i];
    const auto& e = mesh_.edge(i - mesh_.n_nodes());
    return 0.5 * (x[e[0]] + x[e[1]]);
  }

  std::vector<Vec<D>> solve_mesh_velocity(const std::vector<Vec<D>>& x, const VecX& /*u_hat*/, Real t) {
    if (prescribed_) {
      std::vector<Vec<D>> v(x.size());
      for (std::size_t i = 0; i < x.size(); ++i) v[i] = prescribed_(x[i], t);
      return v;
    }
    // boundary data: a body's rigid velocity, else the tag's function, else 0
    std::vector<const TimeFunction*> node_fn(mesh_.n_nodes(), nullptr);
    for (const auto& [tag, g] : mesh_bc_)
      for (Index v : mesh_.boundary_nodes(tag)) node_fn[v] = &g;
    return motion_.solve(x, [&](Index v, const Vec<D>& xv) {
      if (!body_v_.empty() && body_has_v_[v]) return body_v_[v];
      return node_fn[v] ? (*node_fn[v])(xv, t) : Vec<D>(Vec<D>::Zero());
    });
  }

  // Rigid velocities of the body nodes on geometry x for the mesh-velocity problem: the bodies'
  // extrapolated state (weights w over levels n, n-1, n-2), or the prescribed motion at t.
  void set_body_mesh_velocity(const std::vector<Vec<D>>& x, const std::array<Real, 3>& w, Real t) {
    if constexpr (D == 2) {
      if (bodies_.empty()) return;
      body_v_.assign(mesh_.n_nodes(), Vec<D>::Zero());
      body_has_v_.assign(mesh_.n_nodes(), 0);
      for (auto& b : bodies_) {
        Vec<2> xg = Vec<2>::Zero();
        Vec<3> Z = Vec<3>::Zero();
        for (int k = 0; k < 3; ++k) xg += w[k] * b.xg[k], Z += w[k] * b.Z[k];
        if (!b.data.free()) Z = b.data.prescribed(t);
        b.Zhat = Z;
        for (Index v : b.nodes) {
          body_v_[v] = rigid_velocity(Z, x[v] - xg);
          body_has_v_[v] = 1;
        }
      }
    }
  }


  template <TimeScheme S>
  StepReport step_with(Real dt) {
    // the first MR/AB step: X^{-1} = X^0 - dt V^0, U^{-1} = U^0
    if (levels_ == 0 && history_levels<S>() > 0) {
      X_[1] = X_[0];
      for (std::size_t i = 0; i < X_[1].size(); ++i) X_[1][i] -= dt * Vn_[i];
      U_[1] = U_[0];
      for (auto& b : bodies_) {
        b.xg[1] = b.xg[0] - dt * b.Z[0].template head<D>();
        b.th[1] = b.th[0] - dt * b.Z[0][2];
        b.Z[1] = b.Z[0];
      }
    }
    // 1. extrapolated geometry and flow
    std::vector<Vec<D>> Xh(X_[0].size(), Vec<D>::Zero());
    VecX Uh = VecX::Zero(U_[0].size());
    for (int k = 0; k < 3; ++k)
      if (S::extrapolation[k] != 0) {
        for (std::size_t i = 0; i < Xh.size(); ++i) Xh[i] += S::extrapolation[k] * X_[k][i];
        Uh += S::extrapolation[k] * U_[k];
      }
    // 2. mesh velocity
    const Real tV = S::velocity_level == VelocityLevel::n ? t_ : S::velocity_level == VelocityLevel::n_half ? t_ + dt / 2 : t_ + dt;
    StepReport rep;
    auto clock = std::chrono::steady_clock::now();
    auto lap = [&clock](Real& acc) {
      const auto now = std::chrono::steady_clock::now();
      acc += std::chrono::duration<Real>(now - clock).count();
      clock = now;
    };
    set_body_mesh_velocity(Xh, S::extrapolation, tV);
    const std::vector<Vec<D>> Vs = solve_mesh_velocity(Xh, Uh, tV);
    lap(rep.t_mesh_velocity);
    // 3. positions
    const auto b = bdf_coefficients(S::position_bdf);
    std::vector<Vec<D>> Xn1(X_[0].size());
    for (std::size_t i = 0; i < Xn1.size(); ++i) {
      Vec<D> s = dt * Vs[i];
      for (int k = 1; k <= S::position_bdf; ++k) s -= b[k] * X_[k - 1][i];
      Xn1[i] = s / b[0];
    }
    // bodies: centre and angle by the same formula with the extrapolated rigid velocity;
    // their surface nodes are placed by the exact rigid motion
    if constexpr (D == 2)
      for (auto& body : bodies_) {
        Vec<D> xs = dt * body.Zhat.template head<D>();
        Real ts = dt * body.Zhat[2];
        for (int k = 1; k <= S::position_bdf; ++k) xs -= b[k] * body.xg[k - 1], ts -= b[k] * body.th[k - 1];
        body.xg_next = xs / b[0];
        body.th_next = ts / b[0];
        for (std::size_t j = 0; j < body.nodes.size(); ++j)
          Xn1[body.nodes[j]] = body.xg_next + rotate(body.r0[j], body.th_next - body.data.angle);
      }
    // mesh velocity the flow sees, and V^{n+1} for the next step
    std::vector<Vec<D>> Vflow = Vs, Vnext = Vs;
    if (S::velocity_level == VelocityLevel::n_half)
      for (std::size_t i = 0; i < Vs.size(); ++i) Vnext[i] = 2 * Vs[i] - Vn_[i];
    if (S::flow_velocity == FlowMeshVelocity::ab2) Vflow = Vnext;
    // 4. flow geometry X^{n+theta}
    std::vector<Vec<D>> Xth(Xn1.size());
    for (std::size_t i = 0; i < Xth.size(); ++i) Xth[i] = S::theta * Xn1[i] + (1 - S::theta) * X_[0][i];
    mesh_.set_coordinates(Xth);
    // Dirichlet values at t^{n+1} on X^{n+1}
    const Real t1 = t_ + dt;
    for (const auto& [i, tag] : dirichlet_dofs_) {
      const Vec<D> val = dirichlet_.at(tag)(dof_point(i, Xn1), t1);
      for (int k = 0; k < D; ++k) cons_->set_fixed_value(space_.velocity_field(i, k), val[k]);
    }
    // body surface velocities at t^{n+1} on X^{n+1}: u = H Z + u_s
    if constexpr (D == 2)
      for (auto& body : bodies_) {
        const Real rot = body.th_next - body.data.angle;
        const Vec<3> Zp = body.data.free() ? Vec<3>::Zero() : body.data.prescribed(t1);
        for (Index i : body.dofs) {
          const Vec<2> r = dof_point(i, Xn1) - body.xg_next;
          const Vec<2> us = body.data.slip ? rotate(body.data.slip(rotate(r, -rot)), rot) : Vec<2>::Zero();
          const auto H = rigid_rows(r);
          for (int k = 0; k < 2; ++k) {
            const Index f = space_.velocity_field(i, k);
            if (body.data.free()) cons_->set_link(f, {H[k].data(), 3}, us[k]);
            else cons_->set_fixed_value(f, H[k].dot(Zp) + us[k]);
          }
        }
      }
    // history of the BDF time derivative and the extrapolated convecting velocity
    const auto a = bdf_coefficients(S::flow_bdf);
    VecX hist = VecX::Zero(U_[0].size());
    for (int k = 1; k <= S::flow_bdf; ++k) hist += a[k] * U_[k - 1];
    const auto ew = extrapolation_weights(S::theta < 1 ? 2 : S::flow_bdf, S::theta < 1);
    VecX ustar = VecX::Zero(U_[0].size());
    for (int k = 0; k < 3; ++k)
      if (ew[k] != 0) ustar += ew[k] * U_[k];
    StepInputs<D> in;
    in.dt = dt;
    in.theta = S::theta;
    in.a0 = a[0];
    in.history = &hist;
    in.previous = &U_[0];
    in.extrapolated = &ustar;
    in.mesh_velocity = &Vflow;
    const Real tf = t_ + S::theta * dt;
    if (force_ || gravity_.squaredNorm() > 0)
      in.force = [this, tf](const Vec<D>& x) {
        Vec<D> f = opt_.rho * gravity_;
        if (force_) f += force_(x, tf);
        return f;
      };
    kernel_.set_step(in);
    // 5. Newton (or one semi-implicit solve)
    clock = std::chrono::steady_clock::now();
    VecX u = cons_->restrict_free(U_[0]);
    for (const auto& body : bodies_)
      if (body.data.free()) u.template segment<3>(cons_->extra_unknown(body.extra)) = body.Z[0];
    VecX field = cons_->expand(u);
    VecX r;
    Real r0 = -1;
    const bool newton = opt_.linearisation == Linearisation::newton;
    try {
      for (int it = 0;; ++it) {
        asmb_->assemble(kernel_, field, &J_, &r);
        add_body_rows<S>(dt, u, r);
        lap(rep.t_assembly);
        const Real rn = r.size() ? r.lpNorm<Eigen::Infinity>() : 0.0;
        rep.residuals.push_back(rn);
        if (!std::isfinite(rn)) throw SolverError("non-finite residual at Newton iteration " + std::to_string(it));
        if (r0 < 0) r0 = rn;
        if (newton && it > 0 && rn <= opt_.newton_tolerance * r0 + 1e-13) break;
        if (newton && it == opt_.max_newton)
          throw SolverError("Newton did not converge in " + std::to_string(it) + " iterations (residual " +
                            std::to_string(rn) + ", first " + std::to_string(r0) + ")");
        if (!analysed_) {
          solver_.analyze(J_);
          analysed_ = true;
        }
        solver_.factorize(J_);
        lap(rep.t_factorize);
        u -= solver_.solve(r);
        lap(rep.t_solve);
        field = cons_->expand(u);
        ++rep.newton_iterations;
        if (!newton) break;
      }
    } catch (...) {
      mesh_.set_coordinates(X_[0]);  // the step is rejected: the state stays at t^n
      throw;
    }
    if (pinned_) shift_pressure_to_zero_mean(space_, field);
    for (auto& body : bodies_) {
      const Vec<3> Zn1 = body.data.free() ? Vec<3>(u.template segment<3>(cons_->extra_unknown(body.extra))) : body.data.prescribed(t1);
      if (body.data.free()) body.load = body_inertia<S>(body, Zn1, dt) - body_weight(body) - body.data_external();
      body.Z[2] = body.Z[1], body.Z[1] = body.Z[0], body.Z[0] = Zn1;
      body.xg[2] = body.xg[1], body.xg[1] = body.xg[0], body.xg[0] = body.xg_next;
      body.th[2] = body.th[1], body.th[1] = body.th[0], body.th[0] = body.th_next;
    }
    // 6. shift histories
    U_[2] = U_[1];
    U_[1] = U_[0];
    U_[0] = field;
    X_[2] = X_[1];
    X_[1] = X_[0];
    X_[0] = Xn1;
    Vn_ = Vnext;
    mesh_.set_coordinates(Xn1);
    t_ = t1;
    ++levels_;
    return rep;
  }

  struct Body {
    RigidBody2D data;
    std::array<Vec<D>, 3> xg;
    std::array<Real, 3> th{};
    std::array<Vec<3>, 3> Z;
    Vec<3> Zhat = Vec<3>::Zero(), load = Vec<3>::Zero();
    Vec<D> xg_next = Vec<D>::Zero();
    Real th_next = 0;
    Index extra = -1;           // first of its 3 extra unknowns (free bodies)
    std::vector<Index> nodes;   // surface mesh nodes
    std::vector<Vec<D>> r0;     // their offsets from the centre at t0
    std::vector<Index> dofs;    // surface velocity DOFs
    Vec<3> data_external() const { return data.external_load; }
  };

  // M delta_l Z^{n+1} / dt for body b.
  template <TimeScheme S>
  static Vec<3> body_inertia(const Body& b, const Vec<3>& Zn1, Real dt) {
    const auto a = bdf_coefficients(S::flow_bdf);
    Vec<3> dZ = a[0] * Zn1;
    for (int k = 1; k <= S::flow_bdf; ++k) dZ += a[k] * b.Z[k - 1];
    return Vec<3>(b.data.mass, b.data.mass, b.data.inertia).cwiseProduct(dZ) / dt;
  }
  Vec<3> body_weight(const Body& b) const {
    Vec<3> w = Vec<3>::Zero();
    w.template head<D>() = b.data.mass * gravity_;
    return w;
  }
  // Body rows (eq. 11): M delta_l Z / dt - M g - external load, added to the fluid terms.
  template <TimeScheme S>
  void add_body_rows(Real dt, const VecX& u, VecX& r) {
    const Real a0 = bdf_coefficients(S::flow_bdf)[0];
    for (const auto& body : bodies_) {
      if (!body.data.free()) continue;
      const Index e = cons_->extra_unknown(body.extra);
      const Vec<3> Z = u.template segment<3>(e);
      r.template segment<3>(e) += body_inertia<S>(body, Z, dt) - body_weight(body) - body.data_external();
      const Vec<3> m(body.data.mass, body.data.mass, body.data.inertia);
      for (int C = 0; C < 3; ++C) J_.coeffRef(e + C, e + C) += m[C] * a0 / dt;
    }
  }

  Mesh<D> mesh_;
  FlowOptions opt_;
  Space space_;
  Kernel kernel_;
  ElasticMeshMotion<D> motion_;
  std::map<int, TimeFunction> dirichlet_, mesh_bc_;
  TimeFunction prescribed_, force_;
  Vec<D> gravity_ = Vec<D>::Zero();
  std::vector<Body> bodies_;
  std::vector<Vec<D>> body_v_;
  std::vector<char> body_has_v_;
  std::vector<std::pair<Index, int>> dirichlet_dofs_;
  std::unique_ptr<DofConstraints> cons_;
  std::unique_ptr<Assembler<Space::n_local>> asmb_;
  SparseMatrix J_;
  Solver solver_;
  bool analysed_ = false, pinned_ = false;
  Real t_ = 0;
  int levels_ = 0;  // steps taken (history levels available)
  std::array<std::vector<Vec<D>>, 3> X_;
  std::array<VecX, 3> U_;
  std::vector<Vec<D>> Vn_;
};

}  // namespace alefsi
