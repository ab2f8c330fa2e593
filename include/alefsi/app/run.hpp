#pragma once
/// \file app/run.hpp
/// What programs driven by `alefsi::run` share: their output options (--output, --vtu-every,
/// --checkpoint-every, --restart) and the closing lines of a run: the remeshes (wall time,
/// cells, worst quality before and after), the steps with their dt range, the wall and CPU
/// times with the peak memory, the time split by phase, and the linear solves (set-ups, reused
/// solves, iterations per solve).
///
///     app::RunFiles files{.output = "out"};
///     files.add_to(options);             // then options.parse(...)
///     files.apply(run_options);
///     const RunSummary sum = run(flow, run_options);
///     app::print_remeshes(std::cout, remesher.reports());
///     app::print_run(std::cout, sum, wall_seconds, app::cpu_seconds() - cpu0);
#include <filesystem>
#include <iomanip>
#include <ostream>

#include "alefsi/app/options.hpp"
#include "alefsi/app/resources.hpp"
#include "alefsi/core/types.hpp"
#include "alefsi/sim/driver.hpp"

namespace alefsi::app {

/// Where a run writes (bodies.csv, VTU, checkpoints) and whether it continues from there.
struct RunFiles {
  std::filesystem::path output = "out";
  int vtu_every = 0, checkpoint_every = 0;
  bool restart = false;

  Options& add_to(Options& opt) {
    return opt.add("output", output, "folder for bodies.csv, VTU and checkpoints")
        .add("vtu-every", vtu_every, "a VTU file every this many steps (0: none)")
        .add("checkpoint-every", checkpoint_every, "a checkpoint every this many steps and at the end (0: none)")
        .flag("restart", restart, "continue from <output>/checkpoint.bin");
  }
  void apply(RunOptions& r) const {
    r.output = output, r.vtu_every = vtu_every, r.checkpoint_every = checkpoint_every;
  }
  std::filesystem::path checkpoint() const { return output / "checkpoint.bin"; }
};

/// One line per remesh of a 3D remesher's reports (sim/remesher3d.hpp, Remesh3DReport).
template <class Reports>
void print_remeshes(std::ostream& out, const Reports& reports) {
  const auto flags = out.flags();
  const auto precision = out.precision();
  for (const auto& r : reports)
    out << "  remesh: " << std::defaultfloat << std::setprecision(3) << r.mesher.seconds
        << " s, " << r.mesher.cells << " cells, worst quality " << r.before.worst << " -> " << r.mesher.quality.worst
        << "\n";
  out.flags(flags), out.precision(precision);
}

/// The steps, times, memory, phases and linear solves of a run.
inline void print_run(std::ostream& out, const RunSummary& sum, Real wall_seconds, Real cpu_seconds) {
  const auto flags = out.flags();
  const auto precision = out.precision();
  // (defaultfloat: a caller's std::fixed would print dt = 5e-4 as 0.001)
  out << std::defaultfloat << std::setprecision(3) << "  " << sum.steps << " steps (" << sum.rejected << " rejected, dt " << sum.dt_smallest
      << " to " << sum.dt_largest << "), " << sum.remeshes << " remeshes, worst quality " << sum.worst_quality
      << std::fixed << std::setprecision(1) << "; wall " << wall_seconds << " s, CPU " << cpu_seconds << " s, peak "
      << std::setprecision(0) << peak_mb() << " MB\n"
      << std::setprecision(1) << "  phases: mesh velocity " << sum.t_mesh_velocity << " s, assembly " << sum.t_assembly
      << " s, set-up (factorisations, preconditioners) " << sum.t_factorize << " s, solves " << sum.t_solve
      << " s, remeshing " << sum.t_remesh << " s\n";
  const LinearSolveCounts& lin = sum.linear;
  if (lin.iterative_solves > 0)
    out << "  linear solves: " << lin.iterative_solves << " (" << lin.reused << " on a kept preconditioner), "
        << lin.factorisations << " preconditioner set-ups, " << Real(lin.iterative_iterations) / lin.iterative_solves
        << " GMRES iterations per solve\n";
  else
    out << "  linear solves: " << lin.factorisations << " factorisations, " << lin.reused
        << " solves on kept factors\n";
  out.flags(flags), out.precision(precision);
}

}  // namespace alefsi::app
