#pragma once
/// \file sim/flow_state.hpp
/// The state of an ALE flow between two steps: everything a step reads from the past and
/// everything a checkpoint writes — and nothing else (the discretisation, the boundary data and
/// the bodies' descriptions are rebuilt from the scene's configuration).
///
///   time      the step-size history (time/history.hpp): t^n, the last step sizes, the levels
///   X[k]      node positions at t^{n-k}, k = 0..3 (X[0] is the mesh's; the others empty until
///             taken)
///   U[k]      field vectors at t^{n-k} (MixedSpace layout: velocity interleaved, then pressure;
///             the pressure at the scheme's level n - 1 + theta)
///   V         mesh velocity at t^n (per node)
///   bodies[b] centre, orientation and velocity Z per level, the last step's hydrodynamic load
///             and contact force and moment (read back also from files that hold only the force,
///             written before contact moments), and the surface node offsets (body frame of the rigid-body
///             model, one per surface node in the order of the body's surface node list)
///   stats     steps taken, remeshes, history restarts (and the last step's active contacts,
///             not written)
///   remesh    what the remesh trigger remembers of the last remesh
///   control   what the step-size controller remembers (the next dt, the last error, the steps
///             since the last remesh)
///
/// `write_state` / `read_state` put it in / take it from a checkpoint (sim/checkpoint.hpp);
/// `backfill`, `richardson` and `start_history` are the state algebra of the start-up
/// procedures (time/stepper.hpp).
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "alefsi/core/types.hpp"
#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/sim/checkpoint.hpp"
#include "alefsi/sim/remesher.hpp"
#include "alefsi/time/history.hpp"

namespace alefsi {

/// One rigid body's part of the flow state (levels n ... n-3).
template <int D, RigidBodyModel M>
struct BodyState {
  using Velocity = typename M::Velocity;
  using Orientation = typename M::Orientation;
  Levels<Vec<D>> centre;
  Levels<Orientation> orientation;
  Levels<Velocity> velocity;  ///< Z
  Velocity load = Velocity::Zero();  ///< hydrodynamic force and torque over the last step
  Velocity contact = Velocity::Zero();  ///< contact force and moment in the last step
  std::vector<Vec<D>> surface;       ///< surface node offsets from the centre, model frame
};

/// What an adaptive time loop (sim/driver.hpp) remembers between steps, kept with the state so
/// that a run continued from a checkpoint takes the steps the uninterrupted run takes.
struct StepControlMemory {
  Real next_dt = 0;     ///< the step the controller chose for the next step (0: none yet)
  Real last_error = 0;  ///< the last accepted step's scaled error estimate (0: none)
  /// Steps since the last remesh (-1: none yet). The levels before it were interpolated onto
  /// the new mesh: a step whose predictor reads one of them has no error estimate (what the
  /// remesh changed is a spatial error, not the step's).
  int steps_since_remesh = -1;
};

/// What the flow did so far (for logs).
struct FlowStats {
  int steps = 0, remeshes = 0, history_restarts = 0;
  /// Curved edges that remeshes left straight (their cells' maps too near to folding).
  Index straightened = 0;
  int contacts = 0;  ///< active contacts in the last step (not checkpointed)
};

template <int D, RigidBodyModel M>
struct FlowState {
  TimeHistory time;
  Levels<std::vector<Vec<D>>> X;
  Levels<VecX> U;
  std::vector<Vec<D>> V;
  std::vector<BodyState<D, M>> bodies;
  FlowStats stats;
  RemeshMemory remesh;
  StepControlMemory control;
};

/// The first step after a (re)start of a scheme that reads level n-1: X^{n-1} = X^n - dt V^n,
/// U^{n-1} = U^n, each body's centre x^n - dt V^n, orientation stepped back, Z^{n-1} = Z^n.
template <int D, RigidBodyModel M>
void backfill(FlowState<D, M>& s, Real dt) {
  s.X[1] = s.X[0];
  for (std::size_t i = 0; i < s.X[1].size(); ++i) s.X[1][i] -= dt * s.V[i];
  s.U[1] = s.U[0];
  for (auto& b : s.bodies) {
    b.centre[1] = b.centre[0] - dt * b.velocity[0].template head<D>();
    b.orientation[1] = M::step_back(b.orientation[0], b.velocity[0], dt);
    b.velocity[1] = b.velocity[0];
  }
}

/// Richardson extrapolation of level n: `coarse` (error ~2e) := 2 fine - coarse (positions,
/// field, bodies' centre and velocity; the orientation by M::extrapolate), the last step's
/// loads and contact forces from `fine`. The bodies' surface nodes of X^n are left to the
/// caller (their exact rigid map at the extrapolated place).
template <int D, RigidBodyModel M>
void richardson(FlowState<D, M>& coarse, const FlowState<D, M>& fine) {
  for (std::size_t i = 0; i < coarse.X[0].size(); ++i) coarse.X[0][i] = 2 * fine.X[0][i] - coarse.X[0][i];
  coarse.U[0] = 2 * fine.U[0] - coarse.U[0];
  for (std::size_t k = 0; k < coarse.bodies.size(); ++k) {
    auto& b = coarse.bodies[k];
    const auto& f = fine.bodies[k];
    b.centre[0] = 2 * f.centre[0] - b.centre[0];
    b.velocity[0] = 2 * f.velocity[0] - b.velocity[0];
    b.orientation[0] = M::extrapolate(f.orientation[0], b.orientation[0]);
    b.load = f.load, b.contact = f.contact;
  }
}

/// After a start-up procedure took `s` from `s0` (at t^n) to t^n + dt by other means (substeps):
/// the history is t^n + dt with one past level, s0's level 0 (the older levels are not read
/// with one level; they hold the same).
template <int D, RigidBodyModel M>
void start_history(FlowState<D, M>& s, const FlowState<D, M>& s0, Real dt) {
  for (int k = 1; k < s.X.size(); ++k) s.X[k] = s0.X[0], s.U[k] = s0.U[0];
  for (std::size_t i = 0; i < s.bodies.size(); ++i)
    for (int k = 1; k < s.X.size(); ++k) {
      s.bodies[i].centre[k] = s0.bodies[i].centre[0];
      s.bodies[i].orientation[k] = s0.bodies[i].orientation[0];
      s.bodies[i].velocity[k] = s0.bodies[i].velocity[0];
    }
  const auto& past = s0.time.steps();
  s.time.assign(s0.time.now() + dt, 1, {dt, past[0], past[1]});
}

namespace detail {
template <int D>
std::vector<Real> flatten(const std::vector<Vec<D>>& x) {
  std::vector<Real> out(D * x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int c = 0; c < D; ++c) out[D * i + c] = x[i][c];
  return out;
}
template <int D>
std::vector<Vec<D>> unflatten(const std::vector<Real>& v) {
  std::vector<Vec<D>> out(v.size() / D);
  for (std::size_t i = 0; i < out.size(); ++i)
    for (int c = 0; c < D; ++c) out[i][c] = v[D * i + c];
  return out;
}
template <class V>
std::vector<Real> coefficients(const V& v) {
  return std::vector<Real>(v.data(), v.data() + v.size());
}
// A body's orientation: the angle (2D), the quaternion (x, y, z, w) (3D).
inline void put_orientation(CheckpointWriter& w, Real th) { w.put(th); }
inline void put_orientation(CheckpointWriter& w, const Eigen::Quaternion<Real>& q) {
  w.put_vector(std::vector<Real>(q.coeffs().data(), q.coeffs().data() + 4));
}
inline void get_orientation(CheckpointReader& r, Real& th) { th = r.get<Real>("body angle"); }
inline void get_orientation(CheckpointReader& r, Eigen::Quaternion<Real>& q) {
  const auto c = r.get_vector<Real>("body orientation");
  if (c.size() != 4) r.fail("bad body record");
  q = Eigen::Quaternion<Real>(c[3], c[0], c[1], c[2]);
}
}  // namespace detail

/// Writes sections "state" and "bodies" (`tags`: the bodies' tags, checked on reading).
template <int D, RigidBodyModel M>
void write_state(CheckpointWriter& w, const FlowState<D, M>& s, const std::vector<int>& tags) {
  w.section("state");
  w.put(s.time.now());
  for (Real dt : s.time.steps()) w.put(dt);
  w.put(std::int32_t(s.time.levels()));
  const auto count = s.time.count();
  w.put(count.anchor), w.put(count.dt), w.put(count.steps);
  w.put(std::int32_t(s.stats.steps));
  w.put(std::int32_t(s.stats.remeshes));
  w.put(std::int32_t(s.stats.history_restarts));
  w.put(std::int64_t(s.stats.straightened));
  w.put(s.remesh.quality);
  w.put(s.remesh.deviation);
  w.put(s.remesh.curved);
  w.put(s.control.next_dt);
  w.put(s.control.last_error);
  w.put(std::int32_t(s.control.steps_since_remesh));
  for (int k = 1; k < s.X.size(); ++k) w.put_vector(detail::flatten(s.X[k]));
  for (int k = 0; k < s.U.size(); ++k) w.put_vector(s.U[k]);
  w.put_vector(detail::flatten(s.V));
  w.section("bodies");
  w.put(std::uint64_t(s.bodies.size()));
  for (std::size_t b = 0; b < s.bodies.size(); ++b) {
    const auto& body = s.bodies[b];
    w.put(std::int32_t(tags.at(b)));
    for (int k = 0; k < body.centre.size(); ++k) {
      w.put_vector(detail::coefficients(body.centre[k]));
      detail::put_orientation(w, body.orientation[k]);
      w.put_vector(detail::coefficients(body.velocity[k]));
    }
    w.put_vector(detail::coefficients(body.load));
    w.put_vector(detail::coefficients(body.contact));
    w.put_vector(detail::flatten(body.surface));
  }
}

/// Reads what write_state wrote into `s`, whose bodies are already registered (their count and
/// tags must match). X[0] is left to the caller (the mesh's nodes); `n_field` is the size the
/// fields must have.
template <int D, RigidBodyModel M>
void read_state(CheckpointReader& r, FlowState<D, M>& s, const std::vector<int>& tags, Index n_field) {
  r.section("state");
  const Real t = r.get<Real>("t");
  std::array<Real, TimeHistory::depth> steps{};
  for (Real& dt : steps) dt = r.get<Real>("step size");
  const int levels = r.get<std::int32_t>("levels");
  if (levels < 0) r.fail("negative number of history levels");
  if (!std::isfinite(t)) r.fail("non-finite time");
  s.time.assign(t, levels, steps);
  TimeHistory::Count count;
  count.anchor = r.get<Real>("time counter"), count.dt = r.get<Real>("time counter");
  count.steps = r.get<std::int64_t>("time counter");
  if (!std::isfinite(count.anchor) || !std::isfinite(count.dt) || count.steps < 0) r.fail("invalid time counter");
  s.time.set_count(count);
  s.stats.steps = r.get<std::int32_t>("steps");
  s.stats.remeshes = r.get<std::int32_t>("remeshes");
  s.stats.history_restarts = r.get<std::int32_t>("history restarts");
  s.stats.straightened = Index(r.get<std::int64_t>("straightened edges"));
  if (s.stats.straightened < 0) r.fail("negative number of straightened edges");
  s.remesh.quality = r.get<Real>("remesh state");
  s.remesh.deviation = r.get<Real>("remesh state");
  s.remesh.curved = r.get<Real>("remesh state");
  s.control.next_dt = r.get<Real>("step control");
  s.control.last_error = r.get<Real>("step control");
  s.control.steps_since_remesh = r.get<std::int32_t>("step control");
  if (!(s.control.next_dt >= 0) || !(s.control.last_error >= 0) || s.control.steps_since_remesh < -1)
    r.fail("invalid step-control state");
  for (int k = 1; k < s.X.size(); ++k) s.X[k] = detail::unflatten<D>(r.get_vector<Real>("positions"));
  for (int k = 0; k < s.U.size(); ++k) s.U[k] = r.get_vecx("field");
  s.V = detail::unflatten<D>(r.get_vector<Real>("mesh velocity"));
  if (s.U[0].size() != n_field) r.fail("field size does not match the mesh");
  r.section("bodies");
  if (r.get<std::uint64_t>("body count") != s.bodies.size()) r.fail("another number of bodies than this flow's");
  for (std::size_t b = 0; b < s.bodies.size(); ++b) {
    auto& body = s.bodies[b];
    if (r.get<std::int32_t>("body tag") != tags.at(b)) r.fail("body tags differ from this flow's");
    for (int k = 0; k < body.centre.size(); ++k) {
      const auto xg = r.get_vector<Real>("body centre");
      detail::get_orientation(r, body.orientation[k]);
      const auto Z = r.get_vector<Real>("body velocity");
      if (xg.size() != std::size_t(D) || Z.size() != std::size_t(M::n_dof)) r.fail("bad body record");
      for (int c = 0; c < D; ++c) body.centre[k][c] = xg[c];
      for (int c = 0; c < M::n_dof; ++c) body.velocity[k][c] = Z[c];
    }
    const auto load = r.get_vector<Real>("body load");
    const auto contact = r.get_vector<Real>("body contact");
    const std::size_t n_surface = body.surface.size();
    body.surface = detail::unflatten<D>(r.get_vector<Real>("body surface"));
    // the contact: force and moment, or (checkpoints written before contact moments) the force
    if (load.size() != std::size_t(M::n_dof) || (contact.size() != std::size_t(D) && contact.size() != std::size_t(M::n_dof)) ||
        body.surface.size() != n_surface)
      r.fail("bad body record");
    for (int c = 0; c < M::n_dof; ++c) body.load[c] = load[c];
    body.contact.setZero();
    for (std::size_t c = 0; c < contact.size(); ++c) body.contact[Index(c)] = contact[c];
  }
}

}  // namespace alefsi
