#pragma once
/// \file sim/driver.hpp
/// The time loop a user wants around an `AleFlow` (2D or 3D): progress lines, VTU/PVD
/// output, a CSV time series of every body, atomic checkpoints, and rejection of failed
/// steps with a smaller dt.
///
/// `run(flow, options)` advances from flow.time() to options.t_end, in one of two modes:
///  * adaptive steps (the default for the BDF schemes on a flow with
///    FlowOptions::variable_steps; `tolerance` > 0): `dt` is the first step; each regular step
///    is checked by its local error estimate (time/error_estimate.hpp) against `tolerance`
///    times the flow's velocity scale; a step above it is rejected (StepRejected, the flow stays
///    at t^n) and retried smaller; the next step comes from Söderlind's PI controller
///    (time/step_controller.hpp), within the scheme's step-ratio bound. Events shrink it: no gap
///    between a body and what it approaches (a body, a wall) closes by more than `travel` of
///    itself per step, so collisions are approached in small steps; a step after a remesh does not grow; `dt_max` caps it. Steps
///    land exactly on `land_on` times and on t_end (the step before is shortened, or the rest
///    split in two when shortening would leave a sliver). The controller's memory (next dt,
///    last error) is part of the flow's state, so a run continued from a checkpoint is bit for
///    bit the uninterrupted one. MR/AB is refused (its undamped (-1)^n mode makes it first order
///    under step changes); `tolerance = 0` gives it, or any scheme, a fixed dt.
///  * fixed dt (`tolerance = 0`, MR/AB by default): every step is `dt`.
/// In both, if a step throws SolverError (Newton did not converge, NaN) or MeshError (a cell
///    would invert), the flow is still at t^n (AleFlow guarantees it), so
///    the step is retried with dt / 2, up to `max_retries` halvings; with a fixed dt, after
///    `recover_after` good steps the driver tries twice the dt again, up to the nominal one
///    (each change of dt restarts the multistep history unless the flow has variable steps).
///    If the retries run out, `run` writes a
///    checkpoint of the last good state (when checkpoints are on) and throws Error naming t,
///    dt and the last failure; what was written until then stays valid.
///  * the end of a fixed-dt run: the flow counts its time (t = t_a + k dt, time/history.hpp), so a t_end on the
///    step grid is reached by steps of dt exactly, the last one included (no sliver, no
///    start-up step at the end). Off the grid, a remainder of up to `absorb` dt is taken into
///    the last step (one step of up to (1 + absorb) dt), a larger one is a last, shorter step.
///    A run to T1 continued from its final checkpoint to T2 is then bit for bit the run to T2
///    (for T1 on the grid, and no step being retried at T1).
///  * output (when `output` is set): `<output>/bodies.csv` (one row per step: t, dt, Newton
///    iterations, remeshed, worst quality, the scaled error estimate (0: none), then per body k: the centre (x, y[, z]), the
///    orientation (2D: angle; 3D: quaternion qw, qx, qy, qz), the velocity Z (2D: vx, vy,
///    omega; 3D: vx, vy, vz, wx, wy, wz), the hydrodynamic load (2D: fx, fy, torque; 3D: fx,
///    fy, fz, tx, ty, tz), the contact force (fcx, fcy[, fcz]) and the gap; the column names
///    are the rigid-body model's), `<output>/flow.pvd` + steps every
///    `vtu_every` steps (velocity, pressure, mesh velocity on the P1 nodes),
///    `<output>/checkpoint.bin` every `checkpoint_every` steps and at the end (atomic, the
///    previous one kept as checkpoint.bin.prev; see AleFlow::save_checkpoint). A restarted run (flow.time() > 0) appends to bodies.csv after
///    dropping rows later than the restart time, and starts a new PVD series
///    `flow_from_<step>.pvd`.
///  * a progress line every `progress_every` steps (and at the end) on `log`.
///  * under MPI: only the process with `writer` set (rank 0) writes the CSV, the checkpoints and
///    the log. When the processes assemble parts of the cells (AleFlow::in_parts), each writes
///    its cells' VTU piece `<output>/flow/flow_NNNNNN_pPPPP.vtu` (after a restart in
///    `flow_from_<step>/`) and part 0 writes the step's `.pvtu` and the PVD that lists it
///    (PvdWriter with a VtuPiece): the processes need the same `output`, `vtu_every` and
///    `checkpoint_every` (refused before the first step otherwise) and a folder they all see.
///
///     alefsi::RunOptions opt{.dt = 1e-3, .t_end = 0.5, .output = "out", .vtu_every = 50};
///     alefsi::RunSummary s = alefsi::run(flow, opt);
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "alefsi/core/error.hpp"
#include "alefsi/fem/element_pair.hpp"
#include "alefsi/mesh/io/vtu.hpp"
#include "alefsi/sim/newton.hpp"
#include "alefsi/time/error_estimate.hpp"
#include "alefsi/time/step_controller.hpp"

namespace alefsi {

struct RunOptions {
  Real dt = 1e-3;                   ///< the time step (fixed dt), or the first one (adaptive)
  Real t_end = 1;                   ///< > flow.time()
  /// Adaptive steps: the tolerance on each step's local error estimate, relative to the flow's
  /// velocity scale (time/error_estimate.hpp); 0: a fixed dt. Unset: `default_tolerance` for
  /// the L-stable (BDF) schemes on a flow with FlowOptions::variable_steps, a fixed dt for
  /// MR/AB or without variable steps. Set > 0, it needs both.
  std::optional<Real> tolerance;
  static constexpr Real default_tolerance = 1e-3;
  /// Times that the steps land on exactly (adaptive: the step before one is shortened; fixed
  /// dt: they are met when they are on the step grid), e.g. for samples or VTU output.
  std::vector<Real> land_on;
  Real velocity_scale = 0;          ///< adaptive: floor of the velocity scale (a small velocity; 0: none)
  Real dt_max = 0;                  ///< adaptive: largest step (0: none)
  Real dt_min = 0;                  ///< adaptive: a step below it stops the run (0: 1e-12 dt)
  /// Adaptive: no gap between a body and a body or wall it approaches closes by more than this
  /// fraction of itself in one step (at the current closing speed), so that collisions are
  /// approached in small steps; 0: no limit.
  Real travel = 0.25;
  std::filesystem::path output;     ///< folder for CSV / VTU / checkpoints; empty: no files
  int vtu_every = 0;                ///< 0: no VTU
  int checkpoint_every = 0;         ///< 0: no checkpoints
  int progress_every = 10;          ///< 0: no progress lines
  int max_retries = 6;              ///< dt halvings allowed for one step
  int recover_after = 20;           ///< good steps before trying a larger dt again
  Real absorb = 0.1;                ///< a remainder up to absorb * dt joins the last step; in [0, 1)
  std::ostream* log = &std::cout;   ///< progress and remarks; nullptr: silent
  /// Whether this process writes the files and the log. Under MPI with the shared-mesh model
  /// (la/petsc.hpp) every rank holds the whole state: rank 0 writes (`PetscSession::rank() ==
  /// 0`), the others step in lockstep and write nothing but, in parts, their VTU pieces (file comment). A
  /// checkpoint is then the same on any number of ranks and restarts on any other.
  bool writer = true;
  /// Called after every accepted step (e.g. extra monitoring); may throw to stop the run.
  std::function<void()> on_step = {};
  /// Checked after every accepted step: true ends the run at that step as if it were t_end
  /// (with checkpoints on, one is written there), e.g. once a body has arrived. Under MPI it
  /// must give the same answer on every rank (a function of the flow's state does). Empty: the
  /// run ends at t_end.
  std::function<bool()> stop_when = {};

  void validate() const {
    ALEFSI_CHECK_ARG(dt > 0 && std::isfinite(dt), "dt", "time step must be positive and finite, got ", dt);
    ALEFSI_CHECK_ARG(std::isfinite(t_end), "t_end", "must be finite, got ", t_end);
    ALEFSI_CHECK_ARG(vtu_every >= 0, "vtu_every", "must be >= 0, got ", vtu_every);
    ALEFSI_CHECK_ARG(checkpoint_every >= 0, "checkpoint_every", "must be >= 0, got ", checkpoint_every);
    ALEFSI_CHECK_ARG(progress_every >= 0, "progress_every", "must be >= 0, got ", progress_every);
    ALEFSI_CHECK_ARG(max_retries >= 0, "max_retries", "must be >= 0, got ", max_retries);
    ALEFSI_CHECK_ARG(recover_after >= 1, "recover_after", "must be >= 1, got ", recover_after);
    ALEFSI_CHECK_ARG(absorb >= 0 && absorb < 1, "absorb", "must be in [0, 1), got ", absorb);
    ALEFSI_CHECK_ARG(!tolerance || (*tolerance >= 0 && *tolerance < 1), "tolerance",
                     "must be in [0, 1) (0: fixed dt), got ", tolerance.value_or(0));
    for (Real t : land_on) ALEFSI_CHECK_ARG(std::isfinite(t), "land_on", "times must be finite, got ", t);
    ALEFSI_CHECK_ARG(velocity_scale >= 0 && std::isfinite(velocity_scale), "velocity_scale", "must be >= 0, got ",
                     velocity_scale);
    ALEFSI_CHECK_ARG(dt_max >= 0 && std::isfinite(dt_max), "dt_max", "must be >= 0 (0: none), got ", dt_max);
    ALEFSI_CHECK_ARG(dt_min >= 0 && std::isfinite(dt_min), "dt_min", "must be >= 0, got ", dt_min);
    ALEFSI_CHECK_ARG(travel >= 0 && travel <= 1, "travel", "must be in [0, 1] (0: no limit), got ", travel);
  }
  /// The tolerance in effect for a flow of scheme S (0: fixed dt).
  template <class S>
  Real tolerance_for(bool variable_steps) const {
    if (tolerance) return *tolerance;
    return S::theta == 1 && variable_steps ? default_tolerance : 0;
  }
};

struct RunSummary {
  int steps = 0, rejected = 0, remeshes = 0;
  int error_rejections = 0;  ///< adaptive: steps rejected by the error estimate (part of `rejected`)
  Real dt_smallest = std::numeric_limits<Real>::infinity(), dt_largest = 0;  ///< accepted steps
  /// The accepted steps' linear solves: factorisations, solves that reused one, GMRES iterations
  LinearSolveCounts linear;
  Real t = 0, wall_seconds = 0;
  Real worst_quality = 1;   ///< smallest worst-cell quality seen after any step
  Real min_gap = std::numeric_limits<Real>::infinity();  ///< smallest body gap seen (bodies or walls)
  Real t_mesh_velocity = 0, t_assembly = 0, t_factorize = 0, t_solve = 0, t_remesh = 0;  ///< sums (s)
};

namespace detail {

/// P1 nodal values of the flow's velocity (D components) and pressure, and the mesh velocity,
/// for VTU output.
template <class Flow>
void nodal_fields(const Flow& flow, std::vector<Real>& u, std::vector<Real>& p, std::vector<Real>& w) {
  constexpr int D = Flow::Space::dim;
  const auto& sp = flow.space();
  const Index nn = flow.mesh().n_nodes();
  u.assign(std::size_t(D) * nn, 0);
  p.assign(std::size_t(nn), 0);
  w.assign(std::size_t(D) * nn, 0);
  for (Index v = 0; v < nn; ++v) {
    const Index iv = sp.velocity().node_dof(v), ip = sp.pressure().node_dof(v);
    for (int c = 0; c < D; ++c) u[D * v + c] = flow.field()[sp.velocity_field(iv, c)];
    p[v] = flow.field()[sp.pressure_field(ip)];
    if (!flow.mesh_velocity().empty())
      for (int c = 0; c < D; ++c) w[D * v + c] = flow.mesh_velocity()[v][c];
  }
}

/// The CSV header of body k's columns (the rigid-body model's names).
template <class Model>
void body_csv_header(std::ostream& out, std::size_t k) {
  constexpr int D = Model::dim;
  const char* xyz[] = {"x", "y", "z"};
  for (int c = 0; c < D; ++c) out << ',' << xyz[c] << k;
  for (const char* n : Model::orientation_columns) out << ',' << n << k;
  for (const char* n : Model::velocity_columns) out << ',' << n << k;
  for (const char* n : Model::load_columns) out << ',' << n << k;
  for (int c = 0; c < D; ++c) out << ",fc" << xyz[c] << k;
  out << ",gap" << k;
}

/// Body k's columns at the flow's time.
template <class Flow>
void body_csv_row(std::ostream& out, const Flow& flow, std::size_t k, Real gap) {
  using Model = typename Flow::BodyModel;
  const auto x = flow.body_centre(k);
  const auto z = flow.body_velocity(k);
  const auto f = flow.body_hydrodynamic_load(k);
  const auto fc = flow.body_collision_force(k);
  for (int c = 0; c < x.size(); ++c) out << ',' << x[c];
  for (Real v : Model::orientation_values(flow.body_orientation(k))) out << ',' << v;
  for (int c = 0; c < z.size(); ++c) out << ',' << z[c];
  for (int c = 0; c < f.size(); ++c) out << ',' << f[c];
  for (int c = 0; c < fc.size(); ++c) out << ',' << fc[c];
  out << ',' << gap;
}

/// Keeps the header and the rows of a CSV whose first column is <= t.
inline void truncate_csv_after(const std::filesystem::path& file, Real t) {
  std::ifstream in(file);
  if (!in) return;
  std::vector<std::string> keep;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (header || std::stod(line.substr(0, line.find(','))) <= t * (1 + 1e-14)) keep.push_back(line);
    header = false;
  }
  in.close();
  std::ofstream out(file, std::ios::trunc);
  for (const auto& l : keep) out << l << '\n';
}

}  // namespace detail

template <class Flow>
RunSummary run(Flow& flow, const RunOptions& options) {
  options.validate();
  ALEFSI_CHECK_ARG(options.t_end > flow.time(), "t_end", "must exceed the flow's time ", flow.time(), ", got ",
                   options.t_end);
  flow.prepare();  // a scene that cannot run is refused before anything is written
  // in parts every process writes its VTU piece and learns of the writer's checkpoints, at the
  // same steps (a collective check)
  bool pieces = false;
  const int every = options.output.empty() ? 0 : options.vtu_every;
  const int checkpoint_every = options.output.empty() ? 0 : options.checkpoint_every;
  if (flow.in_parts()) {
    std::vector<int> w{every, -every, checkpoint_every, -checkpoint_every};
    flow.min_parts(w);
    ALEFSI_CHECK_ARG(w[0] == -w[1], "vtu_every",
                     "in parts every process writes its VTU piece at the same steps: give every process the same "
                     "output folder and vtu_every (they range from ", w[0], " to ", -w[1], ")");
    ALEFSI_CHECK_ARG(w[2] == -w[3], "checkpoint_every", "must be the same on every process (they range from ", w[2],
                     " to ", -w[3], ")");
    pieces = every > 0;
  }
  RunOptions opt = options;  // (every check above is made on every rank: they all stop together)
  if (!opt.writer) opt.output.clear(), opt.log = nullptr;
  const auto wall0 = std::chrono::steady_clock::now();
  auto wall = [&] { return std::chrono::duration<Real>(std::chrono::steady_clock::now() - wall0).count(); };
  const std::size_t nb = flow.n_bodies();
  const Real t_start = flow.time();
  RunSummary sum;

  // a file written by one process (the writer): in parts every process learns whether it
  // failed, so that they stop together rather than wait for the one that threw. (Under MPI
  // outside parts, nothing tells the others: the flows in parts are the MPI ones, sim/discretisation.hpp.)
  auto together = [&](const auto& act) {
    detail::together(act, [&](bool ok) { return flow.all_parts(ok); },
                     "the writing process could not write its output (its own error names the file)");
  };
  std::ofstream csv;
  std::unique_ptr<PvdWriter> pvd;
  together([&] {
    if (!opt.output.empty()) {
      std::filesystem::create_directories(opt.output);
      const auto csv_path = opt.output / "bodies.csv";
      const bool restart = t_start > 0 && std::filesystem::exists(csv_path);
      if (restart) detail::truncate_csv_after(csv_path, t_start);
      csv.open(csv_path, restart ? std::ios::app : std::ios::trunc);
      if (!csv) throw IoError("cannot open '" + csv_path.string() + "' for writing");
      csv << std::setprecision(17);
      if (!restart) {
        csv << "t,dt,newton,remeshed,worst_quality,error";
        for (std::size_t k = 0; k < nb; ++k) detail::body_csv_header<typename Flow::BodyModel>(csv, k);
        csv << '\n';
      }
    }
    const std::filesystem::path vtu_output = pieces ? options.output : opt.output;  // pieces: every process
    if (!vtu_output.empty() && opt.vtu_every > 0) {
      std::filesystem::create_directories(vtu_output);
      const std::string name =
          t_start > 0 ? "flow_from_" + std::to_string(flow.stats().steps) + ".pvd" : std::string("flow.pvd");
      pvd = std::make_unique<PvdWriter>(vtu_output / name);
    }
  });
  std::vector<Real> u, p, w;
  auto write_vtu_now = [&] {
    detail::nodal_fields(flow, u, p, w);
    constexpr int D = Flow::Space::dim;
    const std::vector<VtuField> fields{{"velocity", D, u}, {"pressure", 1, p}, {"mesh_velocity", D, w}};
    if (!pieces) return void(pvd->write(flow.time(), flow.mesh(), fields));
    pvd->write(flow.time(), flow.mesh(), fields,
               VtuPiece{flow.own_cells(), flow.part(), flow.parts(), [&](bool ok) { return flow.all_parts(ok); }});
  };
  if (pvd && t_start == 0) write_vtu_now();

  // adaptive: the controller, continued from the flow's memory when the run is a continuation
  using Scheme = typename Flow::Scheme;
  const Real tolerance = opt.tolerance_for<Scheme>(flow.variable_steps());
  const bool adaptive = tolerance > 0;
  ALEFSI_CHECK_ARG(!adaptive || flow.variable_steps(), "tolerance",
                   "adaptive steps need a flow with FlowOptions::variable_steps = true (or tolerance = 0: fixed dt)");
  // The midpoint rule keeps the (-1)^n mode that every jump of dt excites (R(inf) = -1): with
  // steps alternating 1.2 and 0.8 dt, MR/AB is first order (docs/theory.md, section 9), so a
  // controller's step sequence would spoil it.
  ALEFSI_CHECK_ARG(!adaptive || Scheme::theta == 1, "tolerance",
                   Scheme::name, " is not L-stable: the step changes of adaptive runs leave an undamped oscillation "
                   "that makes it first order; use a BDF scheme (BDF2/BDF2E, BDF2/AB, BDF3/BDF3E, BSS) or tolerance = 0");
  constexpr bool stabilised = !std::is_same_v<typename Flow::Config::Pair::Stabilisation, NoStabilisation>;
  ALEFSI_CHECK_ARG(!adaptive || !stabilised || flow.options().tau_dt > 0,
                   "tolerance", "adaptive steps of a stabilised pair (", Flow::Config::Pair::name,
                   ") need a fixed step in its tau (FlowOptions::tau_dt, e.g. the nominal dt): with each step's dt "
                   "in tau the discrete problem changes with dt, which the error estimate cannot tell from a step "
                   "error (or tolerance = 0: fixed dt)");
  const ErrorControl control{tolerance, opt.velocity_scale};
  PiStepController pi(Scheme::order, max_step_ratio<Scheme>(), adaptive ? flow.state().control.last_error : 0.0);
  const Real dt_min = opt.dt_min > 0 ? opt.dt_min : 1e-12 * opt.dt;
  Real dt = adaptive && flow.state().control.next_dt > 0 ? flow.state().control.next_dt : opt.dt;
  int good = 0;
  // adaptive: no gap closes by more than `travel` of itself in one step
  auto travel_limit = [&](Real h) {
    if (opt.travel <= 0) return h;
    for (Real tc : flow.body_times_to_contact())
      if (tc > 0 && std::isfinite(tc)) h = std::min(h, opt.travel * tc);
    return h;
  };
  auto log = [&](const std::string& text) {
    if (opt.log) *opt.log << text << std::endl;
  };
  const bool checkpoints = !opt.output.empty() && opt.checkpoint_every > 0;
  const auto checkpoint = opt.output / "checkpoint.bin";
  // the end is reached when what is left is round-off of the step grid
  auto left = [&] { return opt.t_end - flow.time(); };
  while (left() > 1e-9 * opt.dt) {
    Real h = dt;
    if (adaptive) {
      if (opt.dt_max > 0) h = std::min(h, opt.dt_max);
      h = travel_limit(h);
      // the next time to land on: t_end or the first of land_on after t
      Real to_go = left();
      for (Real t_land : opt.land_on)
        if (t_land - flow.time() > 1e-9 * h) to_go = std::min(to_go, t_land - flow.time());
      if (to_go < (1 + opt.absorb) * h) h = to_go;  // land on it
      else if (to_go < 2 * h) h = to_go / 2;      // in two equal steps rather than with a sliver
    } else if (std::abs(left() - dt) > 1e-9 * dt && left() < (1 + opt.absorb) * dt) {
      h = left();
    }
    decltype(flow.step(Real(1))) rep{};
    int tries = 0, error_tries = 0;
    Real h_try = h;
    for (;;) {
      if (adaptive && h_try < dt_min) {
        if (checkpoints) flow.save_checkpoint(checkpoint);
        throw Error("step at t = " + detail::sci(flow.time()) + ": the step size " + detail::sci(h_try) +
                    " fell below dt_min = " + detail::sci(dt_min));
      }
      auto reject = [&](const Error& e) {
        if (++tries > opt.max_retries) {
          if (checkpoints) flow.save_checkpoint(checkpoint);  // the last good state
          throw Error("step at t = " + detail::sci(flow.time()) + " failed with dt = " + detail::sci(h_try) + " after " +
                      std::to_string(opt.max_retries) + " retries: " + e.what());
        }
        log("  rejected step at t = " + detail::sci(flow.time()) + " (dt " + detail::sci(h_try) + "): " + e.what());
      };
      try {
        rep = flow.step(h_try, control);
        break;
      } catch (const StepRejected& e) {  // the error estimate exceeds the tolerance
        ++sum.rejected, ++sum.error_rejections, ++error_tries;
        h_try = pi.rejected(h_try, e.scaled_error());
        continue;
      } catch (const SolverError& e) {  // Newton failed, non-finite values, an overlap
        reject(e);
      } catch (const MeshError& e) {  // a cell would invert
        reject(e);
      }
      ++sum.rejected;
      h_try *= 0.5;
      dt = h_try;
      good = 0;
    }
    const Real err = rep.error.scaled(control);
    if (adaptive) {
      dt = pi.accepted(h_try, rep.error.available, err, tries + error_tries > 0);
      if (rep.remeshed) dt = std::min(dt, h_try);  // the transferred levels: no growth across a remesh
      flow.set_step_control(dt, pi.last_error());
    } else if (dt < opt.dt && ++good >= opt.recover_after) {
      dt = std::min(opt.dt, 2 * dt), good = 0;
    }
    ++sum.steps;
    sum.dt_smallest = std::min(sum.dt_smallest, h_try), sum.dt_largest = std::max(sum.dt_largest, h_try);
    sum.t_mesh_velocity += rep.t_mesh_velocity, sum.t_assembly += rep.t_assembly;
    sum.t_factorize += rep.t_factorize, sum.t_solve += rep.t_solve, sum.t_remesh += rep.t_remesh;
    sum.linear += rep.linear;
    const Real q = flow.worst_quality();
    sum.worst_quality = std::min(sum.worst_quality, q);
    const std::vector<Real> gaps = flow.body_gaps();
    Real gap_min = std::numeric_limits<Real>::infinity();
    for (Real g : gaps) gap_min = std::min(gap_min, g);
    sum.min_gap = std::min(sum.min_gap, gap_min);
    if (csv.is_open()) {
      csv << flow.time() << ',' << h_try << ',' << rep.newton_iterations << ',' << int(rep.remeshed) << ',' << q << ','
          << err;
      for (std::size_t k = 0; k < nb; ++k) detail::body_csv_row(csv, flow, k, gaps[k]);
      csv << '\n' << std::flush;
    }
    const int n = flow.stats().steps;
    const bool stop = opt.stop_when && opt.stop_when();
    const bool last = stop || left() <= 1e-9 * opt.dt;
    if (pvd && n % opt.vtu_every == 0) write_vtu_now();
    if (checkpoint_every > 0 && (n % checkpoint_every == 0 || last))  // (the same on every process)
      together([&] {
        if (checkpoints) flow.save_checkpoint(checkpoint);
      });
    if (opt.on_step) opt.on_step();
    if (opt.progress_every > 0 && (n % opt.progress_every == 0 || last)) {
      const Real el = wall(), frac = (flow.time() - t_start) / (opt.t_end - t_start);
      std::ostringstream s;
      s << "step " << std::setw(6) << n << "  t " << std::fixed << std::setprecision(4) << flow.time() << "  dt "
        << std::scientific << std::setprecision(2) << h_try << "  newton " << rep.newton_iterations << "  remeshes "
        << flow.stats().remeshes << "  contacts " << flow.stats().contacts << std::fixed << std::setprecision(3)
        << "  q_min " << q << "  gap_min " << std::setprecision(4) << gap_min << std::setprecision(1) << "  wall " << el
        << " s  ETA " << (frac > 0 ? el * (1 - frac) / frac : 0.0) << " s";
      log(s.str());
    }
    if (stop) break;
  }
  sum.t = flow.time();
  sum.remeshes = flow.stats().remeshes;
  sum.wall_seconds = wall();
  return sum;
}

}  // namespace alefsi
