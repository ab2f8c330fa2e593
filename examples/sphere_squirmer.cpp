// sphere_squirmer — the Stokes flow about a sphere squirmer in 3D (paper, section 6.1,
// Figures 3 and 4).
//
// What it shows: a free, massless (force- and torque-free) sphere of radius R = 0.25 at the
// centre of a cube of side 2H = 800 R with no-slip walls, driven only by its slip velocity
// u_s = the tangential projection of Q = (-1, 0, 0) on the eastern hemisphere x > 0 (zero on
// the western one, half the value on the equator: physics/rigid_body.hpp, tangential_slip).
// Steady Stokes: fluid rho -> 0 (1e-12), no convection, zero mesh velocity, one BSS step (the body
// starts at rest, so the geometry does not move and the step is the steady problem), P2/P1.
// Exact (unbounded, Fair & Anderson 1989): V = -<u_s> = (1/3, 0, 0), w = 0; the paper got
// V = (0.3482, 3.6e-4, 2.9e-5) (4.5 % error in V_x). Then the "sedimentation-like" case: the
// same sphere translating at V_E = (1/3, 0, 0) without slip (its surface a Dirichlet boundary):
// its flow decays as r^-1 (a Stokeslet), the squirmer's as r^-2 (a stresslet) and faster.
//
// The mesh: examples/sphere_squirmer.geo, run through the gmsh executable (Debian package
// gmsh; the example stops with a clear message if it is missing, or pass a mesh with --msh).
// By default gmsh meshes the octant x, y, z >= 0 and the example mirrors it into the eight
// octants: the mesh is then symmetric about the three coordinate planes, the equator x = 0
// is made of mesh edges, and the slip's jump there is integrated as the smooth even extension
// of the eastern slip (docs/theory.md). --mesh full meshes the whole cube without symmetry.
// --curved puts the sphere's edge points on the sphere (isoparametric P2, docs/theory.md 1a):
// the polyhedron's geometric O(h^2) goes; V_x here is limited by the rest of the mesh
// (docs/results.md). --slip b1 swaps the paper's slip for
// Blake's smooth first mode with the same exact V (docs/results.md: what limits the accuracy).
//
// How to run: ./sphere_squirmer [--h0 0.04] [--growth 0.5] [--half-side 100] [--hmax 50]
//             [--mesh octant|full] [--msh FILE] [--geo FILE] [--output DIR] [--no-translation]
//             [--curved] [--slip hemisphere|b1]
//             [--grid 161]   (`--help` lists the options with their defaults; a quick run:
//             --h0 0.08 --growth 0.3 --hmax 20 --no-translation)
// What it prints: the options it ran with, mesh and DOF counts, V and w of the squirmer with
// their errors against the exact values, the net force and torque the walls feel from the
// stress integral over them (zero for a force- and torque-free body; relative to the drag
// 6 pi mu R |V| of a sphere at the same speed, and to that drag times H), the drag passed on to
// the walls in the translation case, wall and CPU times of each phase and the peak memory
// (getrusage). It writes into DIR (default sphere_squirmer_out): squirmer.vtu and
// translation.vtu (P1 vertex values of velocity and pressure), plane_<case>_{near,far}.csv (the
// velocity sampled on z = 0: x, y, ux, uy, uz; NaN inside the sphere) and decay.csv (|u|
// against r along the x and y axes, the diagonal and averaged over 200 directions, both cases).
// `python3 examples/plot_sphere_squirmer.py DIR` draws Figure 3 (streamlines on z = 0) and
// Figure 4 (|u| against r, log-log).
// Expected: |V_x - 1/3| / (1/3) under 1 % from h0 = R / 3 on (0.03 % at the default R / 6),
// spurious V_y, V_z, w at round-off level on the symmetric mesh (docs/results.md has the
// measured table and the resolution and box-size study).
//
// Under MPI (target sphere_squirmer_mpi, built when alefsi::petsc is found): the same program
// with one type changed, the solver, to alefsi::PetscDirect (MUMPS through PETSc):
//   mpirun -n 2 ./sphere_squirmer_mpi [options as above] [-- PETSc options, e.g. -ksp_view]
// Every rank holds the mesh and assembles; the solve is distributed; rank 0 runs gmsh, prints
// and writes the files. The answer is the serial one to the direct solver's round-off.
// (PETSc's C types Vec and Mat are global: next to `using namespace alefsi` this file spells
// alefsi::Vec and alefsi::Mat out, in both builds.)
#include <alefsi/alefsi.hpp>
#include <alefsi/app.hpp>
#ifdef ALEFSI_SQUIRMER_PETSC
#include <alefsi/la/petsc.hpp>
#endif

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

using namespace alefsi;
using std::numbers::pi;

// DefaultDirectSolver: UMFPACK (symmetric strategy) when alefsi was built with SuiteSparse, else
// SparseLu<>. UMFPACK was the fastest of UMFPACK symmetric / automatic / unsymmetric and
// SparseLu<> on the 40k-unknown mesh (10 / 10 / 20 / 27 s CPU), SparseLu the leanest (0.9 GB
// against 1.5 GB). UmfPackLu calls UMFPACK's 64-bit interface: the 32-bit one (Eigen's
// wrapper) stopped with "out of memory" near 9e4 unknowns (docs/results.md).
#ifdef ALEFSI_SQUIRMER_PETSC
using Solver = PetscDirect;
#else
using Solver = DefaultDirectSolver;
#endif
using Flow = AleFlow<FlowConfig<3, TaylorHood, BSS, UnsteadyStokes, Solver>>;

namespace {
constexpr Real R = 0.25;
constexpr int tag_walls = 1, tag_sphere = 5;

// --- options -----------------------------------------------------------------------------------
struct Settings {
  Real h0 = 0.04, growth = 0.5, half_side = 100, hmax = 50;
  bool octant = true, translation = true, curved = false, smooth = false;
  int grid = 161;
  std::string msh, geo = ALEFSI_EXAMPLES_DIR "/sphere_squirmer.geo";
  std::filesystem::path output = "sphere_squirmer_out";
};

// false after --help
bool parse(int argc, char** argv, Settings& o) {
  std::string mesh = "octant", slip = "hemisphere";
  Options opt("sphere_squirmer",
              "Stokes flow about a sphere squirmer in a cube (paper 6.1, Figures 3 and 4); meshed by gmsh.");
  opt.add("h0", o.h0, "mesh size on the sphere (R = 0.25)")
      .add("growth", o.growth, "mesh-size growth g: h = h0 + g d at a distance d from the sphere")
      .add("half-side", o.half_side, "half the side H of the cube")
      .add("hmax", o.hmax, "largest mesh size (the cap on h)")
      .add("mesh", mesh, "octant (mirrored into the eight octants: symmetric) or full")
      .add("msh", o.msh, "read this gmsh mesh instead of running gmsh ('': run gmsh)")
      .add("geo", o.geo, "the gmsh geometry")
      .add("output", o.output, "folder for the VTU and CSV files (and gmsh's mesh.msh)")
      .flag("translation", o.translation, "also the sedimentation-like case (--no-translation: skip it)")
      .flag("curved", o.curved, "isoparametric P2 cells on the sphere (default: straight cells, a polyhedron)")
      .add("slip", slip, "hemisphere (the paper's) or b1 (Blake's first mode, smooth, the same V_E)")
      .add("grid", o.grid, "points per side of the z = 0 sampling grids");
  if (!opt.parse(argc, argv, std::cout)) return false;
  ALEFSI_CHECK_ARG(mesh == "octant" || mesh == "full", "--mesh", "must be octant or full, got ", mesh);
  o.octant = mesh == "octant";
  ALEFSI_CHECK_ARG(slip == "hemisphere" || slip == "b1", "--slip", "must be hemisphere or b1, got ", slip);
  o.smooth = slip == "b1";
  ALEFSI_CHECK_ARG(o.h0 > 0 && o.h0 < R, "--h0", "must be in (0, R = 0.25), got ", o.h0);
  ALEFSI_CHECK_ARG(o.growth > 0, "--growth", "must be positive, got ", o.growth);
  ALEFSI_CHECK_ARG(o.half_side > 2 * R, "--half-side", "must exceed 2 R = 0.5, got ", o.half_side);
  ALEFSI_CHECK_ARG(o.grid >= 11, "--grid", "must be >= 11, got ", o.grid);
  opt.print(std::cout);
  return true;
}

// --- timing and memory -------------------------------------------------------------------------
Real cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return Real(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * Real(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}
Real peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return Real(u.ru_maxrss) / 1024.0;  // Linux: kB
}
Real current_mb() {
  std::ifstream in("/proc/self/statm");
  long pages = 0, resident = 0;
  in >> pages >> resident;
  return Real(resident) * Real(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}
struct Stopwatch {
  std::chrono::steady_clock::time_point w = std::chrono::steady_clock::now();
  Real c = cpu_seconds();
  std::string lap() {
    const auto now = std::chrono::steady_clock::now();
    const Real cn = cpu_seconds();
    std::ostringstream s;
    s << std::fixed << std::setprecision(2) << std::chrono::duration<Real>(now - w).count() << " s wall, " << cn - c
      << " s CPU";
    w = now, c = cn;
    return s.str();
  }
};

// --- the mesh ----------------------------------------------------------------------------------
// gmsh on the .geo; throws a clear Error when the executable is not there.
std::filesystem::path run_gmsh(const Settings& o) {
  if (std::system("gmsh --version > /dev/null 2>&1") != 0)
    throw Error("the gmsh executable was not found on PATH (Debian/Ubuntu: apt install gmsh); or pass a mesh "
                "made from examples/sphere_squirmer.geo with --msh FILE");
  ALEFSI_CHECK_ARG(std::filesystem::exists(o.geo), "--geo", "file not found: ", o.geo);
  const auto msh = o.output / "mesh.msh";
  std::ostringstream cmd;
  cmd << std::setprecision(17) << "gmsh -3 -v 2 \"" << o.geo << "\" -setnumber R " << R << " -setnumber H "
      << o.half_side << " -setnumber h0 " << o.h0 << " -setnumber g " << o.growth << " -setnumber hmax " << o.hmax
      << " -setnumber octant " << (o.octant ? 1 : 0) << " -format msh41 -o \"" << msh.string() << "\"";
  if (std::system(cmd.str().c_str()) != 0) throw Error("gmsh failed: " + cmd.str());
  return msh;
}

// The octant mesh (x, y, z >= 0; symmetry planes tagged 2, 3, 4) mirrored into the eight
// octants. A node on a coordinate plane is its own mirror image there (coordinates within
// 1e-12 H of the plane are set to 0 exactly); cells mirrored an odd number of times are
// reoriented; the symmetry-plane facets become interior and are dropped.
Mesh<3> mirror_octant(const Mesh<3>& m, Real H) {
  const Index n = m.n_nodes();
  std::vector<alefsi::Vec<3>> x(m.coordinates());
  for (auto& p : x)
    for (int c = 0; c < 3; ++c) {
      ALEFSI_CHECK_ARG(p[c] >= -1e-12 * H, "mesh", "not an octant mesh: a node has coordinate ", p[c]);
      if (std::abs(p[c]) <= 1e-12 * H) p[c] = 0;
    }
  std::vector<Index> id(8 * std::size_t(n), -1);
  std::vector<alefsi::Vec<3>> nodes;
  auto image = [&](Index v, int s) {  // s: bit c set = mirror coordinate c
    int eff = 0;
    for (int c = 0; c < 3; ++c)
      if ((s >> c & 1) && x[v][c] != 0) eff |= 1 << c;
    Index& k = id[8 * std::size_t(v) + eff];
    if (k < 0) {
      alefsi::Vec<3> p = x[v];
      for (int c = 0; c < 3; ++c)
        if (eff >> c & 1) p[c] = -p[c];
      k = Index(nodes.size());
      nodes.push_back(p);
    }
    return k;
  };
  std::vector<Mesh<3>::Cell> cells;
  std::vector<Mesh<3>::Facet> facets;
  std::vector<int> tags;
  for (int s = 0; s < 8; ++s) {
    const bool odd = (__builtin_popcount(unsigned(s)) & 1) != 0;
    for (Index c = 0; c < m.n_cells(); ++c) {
      Mesh<3>::Cell t;
      for (int a = 0; a < 4; ++a) t[a] = image(m.cell(c)[a], s);
      if (odd) std::swap(t[1], t[2]);
      cells.push_back(t);
    }
    for (Index f : m.boundary_facets()) {
      const int tag = m.facet_tag(f);
      if (tag != tag_walls && tag != tag_sphere) continue;
      Mesh<3>::Facet t;
      for (int a = 0; a < 3; ++a) t[a] = image(m.facet(f)[a], s);
      facets.push_back(t);
      tags.push_back(tag);
    }
  }
  return Mesh<3>(std::move(nodes), std::move(cells), facets, tags);
}

// --- sampling the P2 velocity at points -------------------------------------------------------
// For each point, the first cell containing it (barycentric coordinates >= -1e-10); points in
// no cell (inside the sphere, outside the box) get NaN. Candidates by the cells' bounding boxes
// against the points sorted by x.
std::vector<alefsi::Vec<3>> sample_velocity(const Flow& flow, const std::vector<alefsi::Vec<3>>& pts) {
  const auto& m = flow.mesh();
  const auto& V = flow.space().velocity();
  using P2 = Lagrange<3, 2>;
  std::vector<Index> order(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) order[i] = Index(i);
  std::sort(order.begin(), order.end(), [&](Index a, Index b) { return pts[a][0] < pts[b][0]; });
  std::vector<Real> xs(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) xs[i] = pts[order[i]][0];
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  std::vector<alefsi::Vec<3>> u(pts.size(), alefsi::Vec<3>(nan, nan, nan));
  std::vector<char> found(pts.size(), 0);
  for (Index c = 0; c < m.n_cells(); ++c) {
    alefsi::Vec<3> lo = m.node(m.cell(c)[0]), hi = lo;
    for (Index v : m.cell(c)) lo = lo.cwiseMin(m.node(v)), hi = hi.cwiseMax(m.node(v));
    const Real eps = 1e-10 * (hi - lo).norm();
    auto it = std::lower_bound(xs.begin(), xs.end(), lo[0] - eps);
    bool have_inverse = false;
    alefsi::Mat<3> Jinv = alefsi::Mat<3>::Zero();
    for (; it != xs.end() && *it <= hi[0] + eps; ++it) {
      const Index p = order[std::size_t(it - xs.begin())];
      const alefsi::Vec<3>& y = pts[p];
      if (found[p] || y[1] < lo[1] - eps || y[1] > hi[1] + eps || y[2] < lo[2] - eps || y[2] > hi[2] + eps) continue;
      if (!have_inverse) Jinv = m.jacobian(c).inverse(), have_inverse = true;
      const alefsi::Vec<3> xi = Jinv * (y - m.node(m.cell(c)[0]));
      if (xi.minCoeff() < -1e-10 || xi.sum() > 1 + 1e-10) continue;
      const auto phi = P2::values(xi);
      alefsi::Vec<3> val = alefsi::Vec<3>::Zero();
      const auto& dofs = V.cell_dofs(c);
      for (int a = 0; a < P2::n_dofs; ++a)
        for (int k = 0; k < 3; ++k) val[k] += phi[a] * flow.field()[flow.space().velocity_field(dofs[a], k)];
      u[p] = val;
      found[p] = 1;
    }
  }
  return u;
}

// --- the stress integral over boundary facets ---------------------------------------------------
// F = int sigma n dS and T = int r x sigma n dS (r from the origin = the sphere's centre) over
// the facets tagged `tag`, n pointing into the fluid (the force of the fluid on the solid
// there), sigma = -p I + mu (grad u + grad u^T) from the cell next to each facet: sigma is
// linear there, r x sigma n quadratic, so the three-edge-midpoint rule is exact on each facet.
// On the walls it measures the momentum balance of the fluid: the squirmer is force- and
// torque-free, so the walls feel no net force either (the sphere's own stress integral is a poor
// measure here: the slip's jump at the equator makes its shear stress singular).
alefsi::Vec<6> surface_load(const Flow& flow, int tag, Real mu) {
  const auto& m = flow.mesh();
  using P2 = Lagrange<3, 2>;
  using P1 = Lagrange<3, 1>;
  alefsi::Vec<6> load = alefsi::Vec<6>::Zero();
  for (Index f : m.boundary_facets()) {
    if (m.facet_tag(f) != tag) continue;
    const Index c = m.facet_cells(f)[0];
    const auto& fv = m.facet(f);
    const alefsi::Vec<3> a = m.node(fv[0]), b = m.node(fv[1]), d = m.node(fv[2]);
    alefsi::Vec<3> n = (b - a).cross(d - a);
    const Real area = 0.5 * n.norm();
    n.normalize();
    if (n.dot(m.centroid(c) - (a + b + d) / 3) < 0) n = -n;  // out of the body = into the fluid cell
    const alefsi::Mat<3> Jinv = m.jacobian(c).inverse();
    const auto& vd = flow.space().velocity().cell_dofs(c);
    const auto& pd = flow.space().pressure().cell_dofs(c);
    for (const alefsi::Vec<3>& y : {alefsi::Vec<3>(0.5 * (a + b)), alefsi::Vec<3>(0.5 * (b + d)), alefsi::Vec<3>(0.5 * (d + a))}) {
      const alefsi::Vec<3> xi = Jinv * (y - m.node(m.cell(c)[0]));
      const Eigen::Matrix<Real, P2::n_dofs, 3> G = P2::gradients(xi) * Jinv;
      const auto psi = P1::values(xi);
      alefsi::Mat<3> grad = alefsi::Mat<3>::Zero();  // grad(k, j) = d u_k / d x_j
      for (int i = 0; i < P2::n_dofs; ++i)
        for (int k = 0; k < 3; ++k) grad.row(k) += flow.field()[flow.space().velocity_field(vd[i], k)] * G.row(i);
      Real p = 0;
      for (int i = 0; i < P1::n_dofs; ++i) p += psi[i] * flow.field()[flow.space().pressure_field(pd[i])];
      const alefsi::Mat<3> sigma = -p * alefsi::Mat<3>::Identity() + mu * (grad + grad.transpose());
      const alefsi::Vec<3> t = sigma * n * (area / 3);
      load.head<3>() += t;
      load.tail<3>() += y.cross(t);
    }
  }
  return load;
}

// --- output ------------------------------------------------------------------------------------
void write_flow_vtu(const Flow& flow, const std::filesystem::path& file) {
  const auto& m = flow.mesh();
  std::vector<Real> u(3 * std::size_t(m.n_nodes())), p(std::size_t(m.n_nodes()));
  for (Index v = 0; v < m.n_nodes(); ++v) {  // vertex DOFs come first
    for (int k = 0; k < 3; ++k) u[3 * v + k] = flow.field()[flow.space().velocity_field(v, k)];
    p[v] = flow.field()[flow.space().pressure_field(v)];
  }
  write_vtu(file, m, {{"velocity", 3, u}, {"pressure", 1, p}});
}

// The z = 0 plane, [-a, a]^2 on an n x n grid.
void write_plane(const Flow& flow, Real a, int n, const std::filesystem::path& file) {
  std::vector<alefsi::Vec<3>> pts;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) pts.emplace_back(-a + 2 * a * i / (n - 1), -a + 2 * a * j / (n - 1), 0.0);
  const auto u = sample_velocity(flow, pts);
  std::ofstream out(file);
  out << "x,y,ux,uy,uz\n" << std::setprecision(9);
  for (std::size_t i = 0; i < pts.size(); ++i)
    out << pts[i][0] << ',' << pts[i][1] << ',' << u[i][0] << ',' << u[i][1] << ',' << u[i][2] << '\n';
}

// |u| against r: along +x, -x, +y and the diagonal, and averaged over 200 directions (a
// Fibonacci lattice on the sphere), at 60 radii from 1.02 R to 0.95 H, log-spaced.
struct Decay {
  std::vector<Real> r;
  std::vector<std::array<Real, 5>> u;  // +x, -x, +y, diagonal, mean over directions
};
Decay decay_profile(const Flow& flow, Real H) {
  const int nr = 60, nd = 200;
  Decay d;
  std::vector<alefsi::Vec<3>> dirs = {alefsi::Vec<3>(1, 0, 0), alefsi::Vec<3>(-1, 0, 0), alefsi::Vec<3>(0, 1, 0), alefsi::Vec<3>(1, 1, 1).normalized()};
  const Real golden = pi * (3 - std::sqrt(5.0));
  for (int k = 0; k < nd; ++k) {
    const Real z = 1 - (2 * k + 1.0) / nd, s = std::sqrt(1 - z * z);
    dirs.emplace_back(s * std::cos(golden * k), s * std::sin(golden * k), z);
  }
  std::vector<alefsi::Vec<3>> pts;
  for (int i = 0; i < nr; ++i) {
    const Real r = 1.02 * R * std::pow(0.95 * H / (1.02 * R), Real(i) / (nr - 1));
    d.r.push_back(r);
    for (const auto& e : dirs) pts.push_back(r * e);
  }
  const auto u = sample_velocity(flow, pts);
  for (int i = 0; i < nr; ++i) {
    std::array<Real, 5> row{};
    const std::size_t base = std::size_t(i) * dirs.size();
    for (int k = 0; k < 4; ++k) row[k] = u[base + k].norm();
    Real sum = 0;
    for (int k = 0; k < nd; ++k) sum += u[base + 4 + k].norm();
    row[4] = sum / nd;
    d.u.push_back(row);
  }
  return d;
}

// Steady Stokes: one linear solve of one step dt = 1 from rest, no-slip walls, the mesh at
// rest. The flow kernel (physics/navier_stokes.hpp) requires rho > 0: rho = 1e-12 leaves a
// term rho / dt u whose relative weight against the viscous one is rho L^2 / (mu dt) <= 4e-8
// even for L the whole box (200 cm): the Stokes limit to that accuracy.
constexpr FlowOptions stokes{.rho = 1e-12, .mu = 1, .linearisation = Linearisation::semi_implicit};
void configure(Flow& flow) {
  flow.set_velocity(tag_walls, [](const alefsi::Vec<3>&, Real) { return alefsi::Vec<3>(0, 0, 0); });
  flow.set_prescribed_mesh_velocity([](const alefsi::Vec<3>&, Real) { return alefsi::Vec<3>(0, 0, 0); });
}

void print_report(const StepReport& rep) {
  std::cout << std::fixed << std::setprecision(2) << "    step phases (wall): assembly " << rep.t_assembly
            << " s, factorisation " << rep.t_factorize << " s, solve " << rep.t_solve << " s\n";
}
}  // namespace

int squirmer_main(int argc, char** argv) try {
#ifdef ALEFSI_SQUIRMER_PETSC
  const bool root = PetscSession::rank() == 0;  // it prints (petsc_main) and writes
#else
  const bool root = true;
#endif
  Settings o;
  if (!parse(argc, argv, o)) return 0;
  if (root) std::filesystem::create_directories(o.output);
  const Real H = o.half_side, mu = 1;
  const alefsi::Vec<3> Q(-1, 0, 0), east(1, 0, 0), V_exact(1.0 / 3, 0, 0);
  Stopwatch total, sw;

  // --- mesh
  std::string msh = o.msh;
  if (msh.empty()) {  // rank 0 meshes, the others read its file
    if (root) run_gmsh(o);
    msh = (o.output / "mesh.msh").string();
  }
#ifdef ALEFSI_SQUIRMER_PETSC
  MPI_Barrier(PETSC_COMM_WORLD);
#endif
  const Mesh<3> read = read_gmsh<3>(msh).mesh;
  const bool octant = !read.boundary_nodes(2).empty();  // symmetry planes tagged 2, 3, 4
  const Mesh<3> mesh = octant ? mirror_octant(read, H) : read;
  Real hsphere = 0, hmean = 0;
  const auto sphere_edges = mesh.boundary_edges(tag_sphere);
  for (Index e : sphere_edges) hsphere = std::max(hsphere, mesh.edge_length(e)), hmean += mesh.edge_length(e);
  hmean /= Real(sphere_edges.size());
  std::cout << "mesh (" << (octant ? "octant mirrored" : "as read") << "): " << mesh.n_nodes()
            << " nodes, " << mesh.n_cells() << " tetrahedra, " << mesh.boundary_nodes(tag_sphere).size()
            << " nodes on the sphere (edges there: mean " << std::setprecision(3) << hmean / R << " R, longest "
            << hsphere / R << " R), box [-" << H << ", " << H << "]^3 = " << 2 * H / R << " R; " << sw.lap() << "\n";

  // --- the squirmer (in a block: its matrix and factors are freed before the next case)
  Decay ds;
  {
    Flow flow(mesh, stokes);
    configure(flow);
    RigidBody3D body = massless_sphere(tag_sphere, alefsi::Vec<3>::Zero(), R);
    // the paper's slip has a kink on the equator (half its value there); Blake's first mode
    // B1 ((e.n) n - e) with B1 = 1/2 swims at the same 2 B1 / 3 = 1/3 along e = -Q and is smooth
    body.slip = o.smooth ? squirmer_slip(0.5, 0, east) : tangential_slip(Q, east);
    flow.add_body(body);
    if (o.curved) flow.curve_boundary(tag_sphere, onto_sphere<3>(alefsi::Vec<3>::Zero(), R));
    const Index dofs = flow.space().n_field() + Flow::body_dofs;
    const Real mb_before = current_mb();
    std::cout << std::defaultfloat << "squirmer: " << dofs << " unknowns before constraints (P2/P1 field "
              << flow.space().n_field() << " + 6 body), memory before the solve " << std::fixed << std::setprecision(0)
              << mb_before << " MB\n";
    const StepReport rep = flow.step(1.0);
    std::cout << "    solved: " << sw.lap() << "; memory now " << std::fixed << std::setprecision(0) << current_mb()
              << " MB (the matrix and the LU factors the flow keeps), peak " << peak_mb() << " MB\n";
    print_report(rep);
    // the O(h^2) normal velocity the slip's interpolant leaks through the polyhedral sphere (less
    // through curved facets), which the flow takes off the slip in a closed box (else the pinned
    // pressure DOF would take it up as a point source: physics/rigid_body.hpp, flux_free_slip)
    std::cout << "    slip made flux-free by removing the normal velocity " << std::scientific << std::setprecision(3)
              << flow.slip_flux_removed(0) << " (|Q| = 1)\n";
    const alefsi::Vec<6> Z = flow.body_velocity(0);
    const alefsi::Vec<3> V = Z.head<3>(), w = Z.tail<3>();
    const alefsi::Vec<6> walls = surface_load(flow, tag_walls, mu);
    const Real drag = 6 * pi * mu * R * V.norm();  // Stokes drag of a sphere at the same speed
    std::cout << std::scientific << std::setprecision(6) << "    V = (" << V[0] << ", " << V[1] << ", " << V[2]
              << ")   exact (1/3, 0, 0)\n    w = (" << w[0] << ", " << w[1] << ", " << w[2] << ")   exact 0\n"
              << std::setprecision(3) << "    relative error |V_x - 1/3| / (1/3) = " << std::abs(V[0] / V_exact[0] - 1)
              << ", |V - V_E| / |V_E| = " << (V - V_exact).norm() / V_exact.norm()
              << ", spurious max(|V_y|, |V_z|, |w|) = " << std::max({std::abs(V[1]), std::abs(V[2]), w.norm()}) << "\n"
              << "    stress integral over the walls: |F| / (6 pi mu R |V|) = " << walls.head<3>().norm() / drag
              << ", |T| / (6 pi mu R |V| H) = " << walls.tail<3>().norm() / (drag * H) << "\n";
    if (root) write_flow_vtu(flow, o.output / "squirmer.vtu");
    if (root) write_plane(flow, 8 * R, o.grid, o.output / "plane_squirmer_near.csv");
    if (root) write_plane(flow, H, o.grid, o.output / "plane_squirmer_far.csv");
    ds = decay_profile(flow, H);
    std::cout << "    output written: " << sw.lap() << "\n";
  }

  // --- the sedimentation-like case: the sphere translating at V_E, no slip
  Decay dt;
  if (o.translation) {
    Flow tr(mesh, stokes);
    configure(tr);
    tr.set_velocity(tag_sphere, [&](const alefsi::Vec<3>&, Real) { return V_exact; });
    if (o.curved) tr.curve_boundary(tag_sphere, onto_sphere<3>(alefsi::Vec<3>::Zero(), R));
    const StepReport rt = tr.step(1.0);
    std::cout << "translation at V_E (Dirichlet sphere): " << tr.space().n_field() << " field unknowns; "
              << std::defaultfloat << sw.lap() << "\n";
    print_report(rt);
    const alefsi::Vec<6> wt = surface_load(tr, tag_walls, mu);
    std::cout << "    stress integral over the walls: F_x / (6 pi mu R V_E) = " << std::setprecision(4)
              << wt[0] / (6 * pi * mu * R * V_exact[0]) << " (the drag, passed on to the walls)\n";
    if (root) write_flow_vtu(tr, o.output / "translation.vtu");
    if (root) write_plane(tr, 8 * R, o.grid, o.output / "plane_translation_near.csv");
    if (root) write_plane(tr, H, o.grid, o.output / "plane_translation_far.csv");
    dt = decay_profile(tr, H);
  }
  if (root) {
    std::ofstream out(o.output / "decay.csv");
    out << "r,squirmer_px,squirmer_mx,squirmer_py,squirmer_diag,squirmer_mean";
    if (o.translation) out << ",translation_px,translation_mx,translation_py,translation_diag,translation_mean";
    out << '\n' << std::setprecision(9);
    for (std::size_t i = 0; i < ds.r.size(); ++i) {
      out << ds.r[i];
      for (Real v : ds.u[i]) out << ',' << v;
      if (o.translation)
        for (Real v : dt.u[i]) out << ',' << v;
      out << '\n';
    }
  }
  std::cout << std::defaultfloat << "total: " << total.lap() << ", peak memory " << std::setprecision(0) << std::fixed
            << peak_mb() << " MB; files in " << o.output.string() << "\n";
  return 0;
} catch (const std::exception& e) {
  std::cerr << "sphere_squirmer: " << e.what() << "\n";
  return 1;
}

int main(int argc, char** argv) {
#ifdef ALEFSI_SQUIRMER_PETSC
  return petsc_main(argc, argv, squirmer_main);  // PETSc's options after "--"; all ranks end on an error
#else
  return squirmer_main(argc, argv);
#endif
}
