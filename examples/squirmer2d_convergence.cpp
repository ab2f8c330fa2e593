// squirmer2d_convergence — how fast a 2D squirmer's computed speed approaches Blake's B1 / 2.
//
// What it shows: a disk of radius R with the tangential slip B1 sin(theta) e_theta (body frame,
// theta from the swimming axis +x; rigid_body.hpp `squirmer_slip(B1, 0, e)`), force- and
// torque-free, swims at U = B1 / 2 in an unbounded 2D Stokes fluid (Blake 1971). In a box the
// computed U carries two errors: the confinement by the walls and the discretisation. This
// program measures both, separately:
//   - box: the disk at the centre of a square box of side L with no-slip walls, L / R = 4 ..
//     256 at a fixed graded mesh near the body (h_body, grading 0.2; far size L / 16);
//   - the same in a circular container of radius b = L / 2, whose confined speed is known in
//     closed form (derived below): the difference is the discretisation error alone;
//   - mesh: h_body = R / 4 .. R / 64 in the largest box (against B1 / 2) and in the circular
//     container (against its exact speed: the discretisation error alone).
//
// The flow: AleFlow with BSS (theta = 1, no start-up step), one step of dt = 1 from rest, fluid
// density rho = 1e-12 (the kernel needs rho > 0) and an almost massless body (density 1e-12):
// the inertia terms rho u / dt and M U / dt are 1e-12 of the viscous ones (mu = 1, R = 1), the
// mesh velocity at t^0 is zero (the body starts at rest), so the step solves the force- and
// torque-free steady Stokes problem on the initial mesh and Z^1 is the quasi-steady swimming
// velocity (the one-step approach of tests/physics).
//
// Theory (stream function psi = f(r) sin(theta), lab frame, u_r = psi_theta / r, u_theta =
// -psi_r): f = A r^3 + B r + C / r + D r ln r; D is the Stokeslet (the force on the disk), so
// force-free means D = 0. Unbounded: f = U R^2 / r (a potential source dipole, |u| ~ U (R/r)^2);
// the slip condition u_theta(R) = (B1 - U) sin(theta) gives U = B1 / 2. In a no-slip circular
// container of radius b (f(b) = f'(b) = 0) the same conditions give
//     U_b = (B1 / 2) (b^2 - R^2) / (b^2 + R^2),  U_b / (B1/2) - 1 = -2 R^2 / (b^2 + R^2) ~ -2 (R/b)^2.
// The confinement error is second order in R / L because this squirmer has neither a
// Stokeslet (log r: force-free) nor a stresslet (1/r: B2 = 0) in its far field, only the
// dipole (1/r^2); the walls reflect a field of size U (R/L)^2 back to the body. (A towed disk
// would see the Stokes paradox, errors ~ 1 / ln(L / R).)
//
// How to run: ./squirmer2d_convergence [--pair th|gls] [--hbox R/h] [--lmax L/R] [--hmax R/h]
//                                      [--csv FILE]   (`--help` lists them with their defaults)
//   defaults: P2/P1, box study at h_body = R / 32, L / R = 4 .. 256, mesh study h_body = R / 4
//   .. R / 32 (R / hmax) in the L = 256 R box and the b = 128 R container (about 2 minutes);
//   the quickest run: --hbox 4 --lmax 8 --hmax 4.
// What it prints: the options it ran with, two markdown tables (box study, mesh study) with U,
// the errors, observed rates, mesh sizes and solve times, and the CSV named by --csv.
// Expected (measured, docs/results.md "2D squirmer: speed against Blake's B1/2"): the box error
// decays as (R/L)^2 (rates 1.98-2.00) and dominates: the square box's error is -7.1 (R/L)^2
// (the container: its exact U_b to 6e-4 at b = 2R, 2e-5 from b = 16R on); the discretisation
// error (container against U_b, every mesh size scaled together) is 4e-4 .. 1e-3 at
// h = R / 4 and <= 5e-6 from h = R / 16 on, below the box error of every box up to L = 256 R.
#include <alefsi/alefsi.hpp>
#include <alefsi/app.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

using namespace alefsi;
using Clock = std::chrono::steady_clock;

namespace {

// One factorisation per mesh: UMFPACK when alefsi was built with SuiteSparse, else SparseLU with
// the saddle-point AMD ordering (la/suitesparse.hpp).
using Solver = DefaultDirectSolver;

constexpr Real R = 1, B1 = 1, mu = 1;
constexpr int body_tag = 5;

struct Result {
  Vec<3> Z;        // (U, V, w)
  long cells = 0;  // triangles
  long body_nodes = 0;  // mesh nodes on the disk (the polygon's corners)
  Real seconds = 0;
};

// Confined speed in a no-slip circular container of radius b (file comment).
Real container_speed(Real b) { return B1 / 2 * (b * b - R * R) / (b * b + R * R); }

// The squirmer at the centre c of the meshed domain, every outer wall no-slip; one steady step.
template <class Pair>
Result swim(Mesh<2> mesh, const Vec<2>& c, const std::vector<int>& walls) {
  Result res;
  res.cells = long(mesh.n_cells());
  const auto t0 = Clock::now();
  AleFlow<FlowConfig<2, Pair, BSS, UnsteadyStokes, Solver>> flow(std::move(mesh), FlowOptions{.rho = 1e-12, .mu = mu});
  for (int t : walls) flow.set_velocity(t, [](const Vec<2>&, Real) { return Vec<2>(0, 0); });
  RigidBody2D body = disk_body(body_tag, c, R, 1e-12);
  body.slip = squirmer_slip(B1, 0, Vec<2>(1, 0));
  flow.add_body(body);
  res.body_nodes = long(flow.body_surface(0).size());
  flow.step(1.0);
  res.Z = flow.body_velocity(0);
  res.seconds = std::chrono::duration<Real>(Clock::now() - t0).count();
  return res;
}

// Mesh sizes h(x) = min(h_far, h_body + grading * distance to the disk).
struct Sizes {
  Real h_body, grading, h_far;
};
// The box study: h_body fixed, the library's default grading 0.2, far size L / 16.
Sizes box_sizes(Real L, Real h_body) { return {h_body, 0.2, std::max(h_body, L / 16)}; }
// The mesh study: every size scaled with h_body (a uniform refinement of one graded family):
// at h_body = R / 8 the box study's sizes.
Sizes mesh_sizes(Real L, Real h_body) { return {h_body, 0.2 * 8 * h_body / R, std::max(h_body, L / 16 * 8 * h_body / R)}; }

Mesh<2> square_box(Real L, const Sizes& s) {
  const Circle disk{Vec<2>(L / 2, L / 2), R, body_tag};
  Domain2D dom{channel_outline(L, L), {disk}};
  return generate_mesh(dom, MesherOptions{graded_size({disk}, s.h_body, s.h_far, s.grading)});
}

// Container of radius b (its wall a polygon through the mesh nodes, like the disk's surface).
Mesh<2> circular_container(Real b, const Sizes& s) {
  const Circle disk{Vec<2>::Zero(), R, body_tag};
  Domain2D dom{Circle{Vec<2>::Zero(), b, tags::outer}, {disk}};
  return generate_mesh(dom, MesherOptions{graded_size({disk}, s.h_body, s.h_far, s.grading)});
}

std::string rate(Real e0, Real e1, Real ratio) {
  if (!std::isfinite(e0)) return "";
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", std::log(std::abs(e0 / e1)) / std::log(ratio));
  return b;
}

template <class Pair>
int study(int hbox, int lmax, int hmax, const std::string& csv_path) {
  std::ofstream csv;
  if (!csv_path.empty()) {
    csv.open(csv_path);
    csv << "study,L_over_R,R_over_h,U_box,err_box,cells_box,U_circle,U_circle_exact,err_circle_exact,cells_circle\n";
  }
  std::printf("2D squirmer, R = %g, B1 = %g, mu = %g: Blake's unbounded speed B1/2 = %g; %s, %s\n", R, B1, mu, B1 / 2,
              Pair::name, Solver::name);
  // --- box size at a fixed mesh near the body ---
  std::printf("\nBox study, h_body = R/%d (square box of side L; circular container of radius b = L/2):\n\n", hbox);
  std::printf("| L/R | U (square) | U/(B1/2) - 1 | rate | triangles | U (circle) | exact U_b | U/(B1/2) - 1 | rate | "
              "U/U_b - 1 | V, w (square) | s |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  Real prev_sq = NAN, prev_ci = NAN;
  for (int L = 4; L <= lmax; L *= 2) {
    const Result sq = swim<Pair>(square_box(L * R, box_sizes(L * R, R / hbox)), Vec<2>(L * R / 2, L * R / 2),
                                 {tags::bottom, tags::right, tags::top, tags::left});
    const Result ci = swim<Pair>(circular_container(L * R / 2, box_sizes(L * R, R / hbox)), Vec<2>::Zero(), {tags::outer});
    const Real esq = sq.Z[0] / (B1 / 2) - 1, eci = ci.Z[0] / (B1 / 2) - 1, ub = container_speed(L * R / 2);
    std::printf("| %d | %.7f | %.4e | %s | %ld | %.7f | %.7f | %.4e | %s | %.2e | %.1e, %.1e | %.1f |\n", L, sq.Z[0], esq,
                rate(prev_sq, esq, 2).c_str(), sq.cells,
                ci.Z[0], ub, eci, rate(prev_ci, eci, 2).c_str(),
                ci.Z[0] / ub - 1, sq.Z[1], sq.Z[2], sq.seconds + ci.seconds);
    if (csv.is_open())
      csv << "box," << L << ',' << hbox << ',' << sq.Z[0] << ',' << esq << ',' << sq.cells << ',' << ci.Z[0] << ',' << ub
          << ',' << ci.Z[0] / ub - 1 << ',' << ci.cells << '\n'
          << std::flush;
    prev_sq = esq, prev_ci = eci;
  }
  // --- mesh size at the largest box ---
  std::printf("\nMesh study, L = %d R (square) and b = %d R (circle); every size scaled with h_body (grading "
              "1.6 h_body / R, far size L h_body / (2 R)):\n\n", lmax, lmax / 2);
  std::printf("| R/h | nodes on the disk | U (square) | U/(B1/2) - 1 | triangles | U (circle) | U/U_b - 1 | rate | "
              "triangles | s |\n|---|---|---|---|---|---|---|---|---|---|\n");
  Real prev = NAN;
  const Real ub = container_speed(lmax * R / 2);
  for (int k = 4; k <= hmax; k *= 2) {
    const Sizes sz = mesh_sizes(lmax * R, R / k);
    const Result sq = swim<Pair>(square_box(lmax * R, sz), Vec<2>(lmax * R / 2, lmax * R / 2),
                                 {tags::bottom, tags::right, tags::top, tags::left});
    const Result ci = swim<Pair>(circular_container(lmax * R / 2, sz), Vec<2>::Zero(), {tags::outer});
    const Real e = ci.Z[0] / ub - 1;
    std::printf("| %d | %ld | %.7f | %.4e | %ld | %.7f | %.4e | %s | %ld | %.1f |\n", k, sq.body_nodes, sq.Z[0],
                sq.Z[0] / (B1 / 2) - 1, sq.cells, ci.Z[0], e, rate(prev, e, 2).c_str(),
                ci.cells, sq.seconds + ci.seconds);
    if (csv.is_open())
      csv << "mesh," << lmax << ',' << k << ',' << sq.Z[0] << ',' << sq.Z[0] / (B1 / 2) - 1 << ',' << sq.cells << ','
          << ci.Z[0] << ',' << ub << ',' << e << ',' << ci.cells << '\n'
          << std::flush;
    prev = e;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) try {
  std::string pair = "th", csv;
  int hbox = 32, lmax = 256, hmax = 32;
  Options opt("squirmer2d_convergence",
              "A 2D squirmer's speed against Blake's B1/2: box-size and mesh-size studies (see the file comment).");
  opt.add("pair", pair, "th (P2/P1) or gls (P1/P1-GLS)")
      .add("hbox", hbox, "box study: h_body = R / hbox")
      .add("lmax", lmax, "box study: L / R = 4, 8, .., lmax; the mesh study's box")
      .add("hmax", hmax, "mesh study: h_body = R / 4, R / 8, .., R / hmax")
      .add("csv", csv, "CSV file of both studies ('': none)");
  if (!opt.parse(argc, argv, std::cout)) return 0;
  ALEFSI_CHECK_ARG(hbox >= 1, "--hbox", "must be >= 1, got ", hbox);
  ALEFSI_CHECK_ARG(lmax >= 4, "--lmax", "must be >= 4, got ", lmax);
  ALEFSI_CHECK_ARG(hmax >= 4, "--hmax", "must be >= 4, got ", hmax);
  ALEFSI_CHECK_ARG(pair == "th" || pair == "gls", "--pair", "must be th or gls, got ", pair);
  opt.print(std::cout);
  return pair == "th" ? study<TaylorHood>(hbox, lmax, hmax, csv) : study<P1P1Gls>(hbox, lmax, hmax, csv);
} catch (const std::exception& e) {
  std::fprintf(stderr, "squirmer2d_convergence: %s\n", e.what());
  return 1;
}
