// Tests of mesh/io/vtu.hpp: input checks, atomicity, and a read-back by VTK's own XML reader
// (tests/mesh/vtu_check.py, run with the python named by ALEFSI_PYTHON_VTK).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "alefsi/mesh/generate/structured.hpp"
#include "alefsi/mesh/io/vtu.hpp"

#if __has_include(<sys/resource.h>) && __has_include(<csignal>)
#include <csignal>
#include <sys/resource.h>
#define ALEFSI_TEST_HAVE_RLIMIT 1
#endif

using namespace alefsi;
namespace fs = std::filesystem;

namespace {

struct TempDir {
  fs::path path;
  TempDir() {
    std::random_device rd;
    path = fs::temp_directory_path() / ("alefsi_vtu_" + std::to_string(rd()) + "_" + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Relative paths of everything below `dir`, sorted.
std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) out.push_back(fs::relative(e.path(), dir).string());
  std::sort(out.begin(), out.end());
  return out;
}

template <int D>
Vec<3> to3(const Vec<D>& x) {
  Vec<3> y = Vec<3>::Zero();
  y.template head<D>() = x;
  return y;
}

// ------------------------------------------------------------------ analytic fields
// All take a 3D point (z = 0 in 2D). lin, vel, grad, t4 are affine (interpolated exactly by
// P1); quad is quadratic (interpolated exactly by P2 on straight cells).
Real f_lin(const Vec<3>& x) { return 1 + 2 * x[0] - 3 * x[1] + 0.5 * x[2]; }
Real f_quad(const Vec<3>& x) { return x[0] * x[0] + x[1] * x[2] + x[0] * x[1]; }
std::vector<Real> f_vel(const Vec<3>& x) { return {x[1], -x[0], 2 * x[2] + 1}; }
std::vector<Real> f_grad(const Vec<3>& x) { return {2 * x[0] + x[1], x[0] + x[2], x[1]}; }
std::vector<Real> f_t4(const Vec<3>& x) { return {1, x[0], x[1] - x[2], 3 * x[2]}; }

const std::string special_name = "T [K] & <x> \"q\" 'a'";

// ------------------------------------------------------------------ VTK read-back
struct VtkArray {
  std::string type;
  int components = 0;
  long tuples = 0;
  std::vector<Real> values;
};

struct VtkGrid {
  std::string path;
  long n_points = 0, n_cells = 0;
  std::string points_type;
  std::vector<Vec<3>> points;
  std::vector<int> types;
  std::vector<std::vector<long>> cells;
  std::vector<std::pair<std::string, VtkArray>> point_data, cell_data;
  std::vector<std::vector<Real>> probes;  // per cell: x y z, then every point array's tuple

  const VtkArray* find(const std::vector<std::pair<std::string, VtkArray>>& d, const std::string& name) const {
    for (const auto& [n, a] : d)
      if (n == name) return &a;
    return nullptr;
  }
  /// Offset of array `name`'s tuple within a probe record.
  std::size_t probe_offset(const std::string& name) const {
    std::size_t off = 3;
    for (const auto& [n, a] : point_data) {
      if (n == name) return off;
      off += std::size_t(a.components);
    }
    FAIL("no point array " << name);
    return 0;
  }
};

struct VtkPvd {
  std::string path;
  std::vector<std::pair<Real, std::string>> steps;
};

struct VtkReadback {
  std::vector<VtkGrid> grids;
  std::vector<VtkPvd> pvds;
};

std::string unhex(const std::string& h) {
  std::string s;
  for (std::size_t i = 0; i + 1 < h.size(); i += 2) s += char(std::stoi(h.substr(i, 2), nullptr, 16));
  return s;
}

Real to_real(const std::string& tok) { return std::strtod(tok.c_str(), nullptr); }  // handles nan / inf

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

VtkReadback read_with_vtk(const std::vector<fs::path>& files, const fs::path& workdir) {
  // a missing tool is a failure, not a skipped check (CI installs python3-vtk9)
  INFO("no python with the vtk module was found at configure time: apt install python3-vtk9 or set ALEFSI_PYTHON_VTK");
  REQUIRE(std::string(ALEFSI_PYTHON_VTK) != "");
  const fs::path out = workdir / "vtk_out.txt", err = workdir / "vtk_err.txt";
  std::string cmd = shell_quote(ALEFSI_PYTHON_VTK) + " " +
                    shell_quote((fs::path(ALEFSI_SOURCE_DIR) / "tests/mesh/vtu_check.py").string());
  for (const auto& f : files) cmd += " " + shell_quote(f.string());
  cmd += " > " + shell_quote(out.string()) + " 2> " + shell_quote(err.string());
  const int rc = std::system(cmd.c_str());
  INFO("command: " << cmd);
  INFO("stderr: " << slurp(err));
  REQUIRE(rc == 0);

  VtkReadback rb;
  std::istringstream text(slurp(out));
  std::string line;
  VtkGrid* g = nullptr;
  while (std::getline(text, line)) {
    std::istringstream ls(line);
    std::string tag, tok;
    ls >> tag;
    if (tag == "PVD") {
      rb.pvds.emplace_back();
      ls >> tok;
      rb.pvds.back().path = unhex(tok);
    } else if (tag == "STEP") {
      std::string t, f;
      ls >> t >> f;
      rb.pvds.back().steps.emplace_back(to_real(t), unhex(f));
    } else if (tag == "GRID") {
      g = &rb.grids.emplace_back();
      ls >> tok;
      g->path = unhex(tok);
    } else if (tag == "NPOINTS") {
      ls >> g->n_points;
    } else if (tag == "NCELLS") {
      ls >> g->n_cells;
    } else if (tag == "POINTSTYPE") {
      ls >> g->points_type;
    } else if (tag == "POINTS") {
      std::vector<Real> v;
      while (ls >> tok) v.push_back(to_real(tok));
      for (std::size_t i = 0; i + 2 < v.size(); i += 3) g->points.emplace_back(v[i], v[i + 1], v[i + 2]);
    } else if (tag == "CELL") {
      int type = 0;
      long n = 0;
      ls >> type >> n;
      std::vector<long> ids(std::size_t(n), -1);
      for (auto& id : ids) ls >> id;
      g->types.push_back(type);
      g->cells.push_back(std::move(ids));
    } else if (tag == "POINTDATA" || tag == "CELLDATA") {
      std::string name;
      VtkArray a;
      ls >> name >> a.type >> a.components >> a.tuples;
      while (ls >> tok) a.values.push_back(to_real(tok));
      (tag == "POINTDATA" ? g->point_data : g->cell_data).emplace_back(unhex(name), std::move(a));
    } else if (tag == "PROBE") {
      long c = 0;
      ls >> c;
      std::vector<Real> v;
      while (ls >> tok) v.push_back(to_real(tok));
      g->probes.push_back(std::move(v));
    } else if (tag == "END") {
      g = nullptr;
    } else {
      FAIL("unexpected line from vtu_check.py: " << line);
    }
  }
  return rb;
}

// ------------------------------------------------------------------ test meshes
Mesh<2> tagged_square() {
  const auto m = rectangle_mesh(5, 4, -1.0, 2.0, 0.5, 1.5);
  std::vector<int> tags(std::size_t(m.n_cells()));
  for (std::size_t c = 0; c < tags.size(); ++c) tags[c] = int(c % 3) + 1;
  return Mesh<2>(m.coordinates(), m.cells(), {}, {}, tags);
}

Mesh<3> tagged_box() {
  const auto m = box_mesh(3, 2, 2, Vec<3>(0.0, -1.0, 0.25), Vec<3>(1.5, 1.0, 1.0));
  std::vector<int> tags(std::size_t(m.n_cells()));
  for (std::size_t c = 0; c < tags.size(); ++c) tags[c] = int(c % 5) - 2;
  return Mesh<3>(m.coordinates(), m.cells(), {}, {}, tags);
}

/// Positions of the P2 points: nodes, then edge midpoints or the given curved ones.
template <int D>
std::vector<Vec<3>> p2_points(const Mesh<D>& mesh, const std::vector<Vec<D>>& curved) {
  std::vector<Vec<3>> x;
  for (const auto& p : mesh.coordinates()) x.push_back(to3<D>(p));
  for (Index e = 0; e < mesh.n_edges(); ++e)
    x.push_back(curved.empty() ? to3<D>(Vec<D>(0.5 * (mesh.node(mesh.edge(e)[0]) + mesh.node(mesh.edge(e)[1]))))
                               : to3<D>(curved[std::size_t(e)]));
  return x;
}

/// Samples g (components k, first `comps` used) at the given points.
template <class G>
std::vector<Real> sample(const std::vector<Vec<3>>& x, std::size_t n, int comps, G g) {
  std::vector<Real> v;
  for (std::size_t i = 0; i < n; ++i) {
    const auto val = g(x[i]);
    if constexpr (std::is_same_v<std::decay_t<decltype(val)>, Real>) {
      v.push_back(val);
    } else {
      for (int k = 0; k < comps; ++k) v.push_back(val[std::size_t(k)]);
    }
  }
  return v;
}

/// Everything written for one round-trip case, kept alive until the read-back is checked.
template <int D>
struct Case {
  const Mesh<D>* mesh;
  int order;
  std::vector<Vec<D>> curved;  // empty: straight
  fs::path file;
  std::vector<Vec<3>> x;  // P2 point positions (nodes first)
  std::vector<Real> lin, quad, vel, grad, t4, centroid, special;

  Case(const Mesh<D>& m, int ord, fs::path f, bool curve) : mesh(&m), order(ord), file(std::move(f)) {
    if (curve) {
      for (Index e = 0; e < m.n_edges(); ++e) {
        const Vec<D> mid = 0.5 * (m.node(m.edge(e)[0]) + m.node(m.edge(e)[1]));
        Vec<D> d = Vec<D>::Zero();
        d[0] = 0.01 * std::sin(1.0 + e), d[1] = 0.013 * std::cos(2.0 * e);
        curved.push_back(mid + d);
      }
    }
    x = p2_points<D>(m, curved);
    const std::size_t nn = std::size_t(m.n_nodes()), np2 = x.size();
    lin = sample(x, nn, 1, f_lin);                 // P1
    quad = sample(x, np2, 1, f_quad);              // P2
    vel = sample(x, nn, D, f_vel);                 // P1 vector (padded to 3 in 2D)
    grad = sample(x, np2, D, f_grad);              // P2 vector
    t4 = sample(x, nn, 4, f_t4);                   // P1, 4 components (never padded)
    for (Index c = 0; c < m.n_cells(); ++c)
      for (int k = 0; k < D; ++k) centroid.push_back(m.centroid(c)[k]);
    for (Index c = 0; c < m.n_cells(); ++c) special.push_back(Real(c) * 0.25);
    special[0] = std::numeric_limits<Real>::quiet_NaN();
    special[1] = std::numeric_limits<Real>::infinity();
  }

  // built on use: the spans must view this object's vectors, not those of a copied-from one
  std::vector<VtuField> fields() const {
    return {{"lin", 1, lin},
            {"quad", 1, quad},
            {"vel", D, vel},
            {"grad", D, grad},
            {"t4", 4, t4},
            {"centroid", D, centroid, FieldLocation::cell},
            {special_name, 1, special, FieldLocation::cell}};
  }

  void write() const { write_vtu<D>(file, *mesh, fields(), order, curved); }

  /// Expected tuple (padded) of a P1 function at read-back point p: exact at nodes, the mean
  /// of the end values at mid-edge points.
  template <class G>
  std::vector<Real> p1_expected(std::size_t p, int comps, G g) const {
    const std::size_t nn = std::size_t(mesh->n_nodes());
    auto at = [&](std::size_t i) { return sample(x, i + 1, comps, g); };
    auto tuple = [&](std::size_t i) {
      auto all = at(i);
      return std::vector<Real>(all.end() - comps, all.end());
    };
    if (p < nn) return tuple(p);
    const auto [a, b] = mesh->edge(Index(p - nn));
    auto va = tuple(std::size_t(a)), vb = tuple(std::size_t(b));
    for (std::size_t k = 0; k < va.size(); ++k) va[k] = 0.5 * (va[k] + vb[k]);
    return va;
  }

  void check(const VtkGrid& g) const {
    const Mesh<D>& m = *mesh;
    const std::size_t nn = std::size_t(m.n_nodes()), nc = std::size_t(m.n_cells());
    const std::size_t np = order == 2 ? x.size() : nn;
    INFO("file " << file << ", order " << order << (curved.empty() ? "" : ", curved"));
    // --- the file's header states what we promise
    const std::string text = slurp(file);
    const std::string head = text.substr(0, text.find("\n   _"));  // XML before the raw data
    CHECK(head.find("header_type=\"UInt64\"") != std::string::npos);
    CHECK(head.find("byte_order=\"LittleEndian\"") != std::string::npos);
    CHECK(head.find("type=\"Int64\" Name=\"connectivity\"") != std::string::npos);
    CHECK(head.find("type=\"Int64\" Name=\"offsets\"") != std::string::npos);
    CHECK(head.find("type=\"UInt8\" Name=\"types\"") != std::string::npos);
    CHECK(head.find("encoding=\"raw\"") != std::string::npos);

    // --- sizes and points
    REQUIRE(g.n_points == long(np));
    REQUIRE(g.n_cells == long(nc));
    REQUIRE(g.points.size() == np);
    CHECK(g.points_type == "double");
    for (std::size_t p = 0; p < np; ++p) {
      INFO("point " << p);
      for (int k = 0; k < 3; ++k) REQUIRE(g.points[p][k] == Approx(x[p][k]).margin(1e-14));
    }

    // --- cells, checked against VTK's own edge table (not SimplexTopology)
    const int expected_type = D == 2 ? (order == 2 ? 22 : 5) : (order == 2 ? 24 : 10);
    static const std::vector<std::array<int, 2>> vtk_edges =
        D == 2 ? std::vector<std::array<int, 2>>{{0, 1}, {1, 2}, {2, 0}}
               : std::vector<std::array<int, 2>>{{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
    REQUIRE(g.cells.size() == nc);
    for (std::size_t c = 0; c < nc; ++c) {
      INFO("cell " << c);
      REQUIRE(g.types[c] == expected_type);
      const auto& ids = g.cells[c];
      REQUIRE(ids.size() == std::size_t(order == 2 ? D + 1 + simplex_edges<D> : D + 1));
      for (int v = 0; v <= D; ++v) REQUIRE(ids[std::size_t(v)] == m.cell(Index(c))[std::size_t(v)]);
      if (order == 2)
        for (std::size_t k = 0; k < vtk_edges.size(); ++k) {
          const long mid = ids[std::size_t(D) + 1 + k];
          REQUIRE(mid >= long(nn));
          REQUIRE(mid < long(np));
          std::array<Index, 2> ends{Index(ids[std::size_t(vtk_edges[k][0])]), Index(ids[std::size_t(vtk_edges[k][1])])};
          std::sort(ends.begin(), ends.end());
          REQUIRE(m.edge(Index(mid - long(nn))) == ends);
          if (curved.empty()) {
            const Vec<3> half = 0.5 * (g.points[std::size_t(ends[0])] + g.points[std::size_t(ends[1])]);
            REQUIRE((g.points[std::size_t(mid)] - half).norm() < 1e-14);
          }
        }
    }

    // --- cell data
    const VtkArray* region = g.find(g.cell_data, "region");
    REQUIRE(region);
    CHECK(region->type == "int");
    REQUIRE(region->values.size() == nc);
    for (std::size_t c = 0; c < nc; ++c) REQUIRE(region->values[c] == m.cell_tag(Index(c)));
    const VtkArray* cen = g.find(g.cell_data, "centroid");
    REQUIRE(cen);
    REQUIRE(cen->components == 3);  // 2D vectors padded to 3
    for (std::size_t c = 0; c < nc; ++c)
      for (int k = 0; k < 3; ++k)
        REQUIRE(cen->values[3 * c + std::size_t(k)] == (k < D ? m.centroid(Index(c))[k] : 0.0));
    const VtkArray* sp = g.find(g.cell_data, special_name);
    REQUIRE(sp);
    CHECK(sp->type == "double");
    REQUIRE(sp->values.size() == nc);
    CHECK(std::isnan(sp->values[0]));
    CHECK(sp->values[1] == std::numeric_limits<Real>::infinity());
    for (std::size_t c = 2; c < nc; ++c) REQUIRE(sp->values[c] == Real(c) * 0.25);
    CHECK(g.cell_data.size() == 3);

    // --- point data at every point
    REQUIRE(g.point_data.size() == 5);
    auto check_points = [&](const std::string& name, int written, auto expected) {
      const VtkArray* a = g.find(g.point_data, name);
      REQUIRE(a);
      CHECK(a->type == "double");
      REQUIRE(a->components == written);
      REQUIRE(a->values.size() == np * std::size_t(written));
      for (std::size_t p = 0; p < np; ++p) {
        const std::vector<Real> e = expected(p);
        for (int k = 0; k < written; ++k) {
          INFO(name << " at point " << p << " component " << k);
          const Real want = k < int(e.size()) ? e[std::size_t(k)] : 0.0;
          REQUIRE(a->values[p * std::size_t(written) + std::size_t(k)] == Approx(want).margin(1e-13));
        }
      }
    };
    const int vw = D == 2 ? 3 : D;
    check_points("lin", 1, [&](std::size_t p) { return p1_expected(p, 1, [](const Vec<3>& y) { return std::vector<Real>{f_lin(y)}; }); });
    check_points("vel", vw, [&](std::size_t p) { return p1_expected(p, D, f_vel); });
    check_points("t4", 4, [&](std::size_t p) { return p1_expected(p, 4, f_t4); });
    // P2 fields: exact at every written point, curved or not (mid values are the given ones)
    check_points("quad", 1, [&](std::size_t p) { return std::vector<Real>{f_quad(x[p])}; });
    check_points("grad", vw, [&](std::size_t p) {
      auto v = f_grad(x[p]);
      v.resize(D);
      return v;
    });

    // --- VTK's own interpolation inside each cell: proves VTK interprets the node order as we do
    if (!curved.empty()) return;
    REQUIRE(g.probes.size() == nc);
    const Real r = 0.2, s = 0.3, t = D == 3 ? 0.1 : 0.0;
    for (std::size_t c = 0; c < nc; ++c) {
      INFO("probe in cell " << c);
      const auto& pr = g.probes[c];
      REQUIRE(pr.size() == 3 + 1 + 1 + 2 * std::size_t(vw) + 4);
      const auto& cell = m.cell(Index(c));
      Vec<3> want = to3<D>(m.node(cell[0]));
      want += r * (to3<D>(m.node(cell[1])) - to3<D>(m.node(cell[0])));
      want += s * (to3<D>(m.node(cell[2])) - to3<D>(m.node(cell[0])));
      if constexpr (D == 3) want += t * (to3<D>(m.node(cell[3])) - to3<D>(m.node(cell[0])));
      const Vec<3> at(pr[0], pr[1], pr[2]);
      REQUIRE((at - want).norm() < 1e-12);
      CHECK(pr[g.probe_offset("lin")] == Approx(f_lin(want)).margin(1e-12));
      for (int k = 0; k < D; ++k) {
        CHECK(pr[g.probe_offset("vel") + std::size_t(k)] == Approx(f_vel(want)[std::size_t(k)]).margin(1e-12));
        CHECK(pr[g.probe_offset("grad") + std::size_t(k)] == Approx(f_grad(want)[std::size_t(k)]).margin(1e-12));
      }
      for (int k = 0; k < 4; ++k)
        CHECK(pr[g.probe_offset("t4") + std::size_t(k)] == Approx(f_t4(want)[std::size_t(k)]).margin(1e-12));
      // the quadratic field is reproduced exactly by quadratic cells only
      if (order == 2) CHECK(pr[g.probe_offset("quad")] == Approx(f_quad(want)).margin(1e-12));
    }
  }
};

}  // namespace

// ====================================================================================
TEST_CASE("write_vtu: files read back by VTK's XML reader", "[mesh][vtu]") {
  TempDir tmp;
  const Mesh<2> m2 = tagged_square();
  const Mesh<3> m3 = tagged_box();
  const std::vector<Case<2>> c2{{m2, 1, tmp.path / "tri1.vtu", false},
                                {m2, 2, tmp.path / "tri2.vtu", false},
                                {m2, 2, tmp.path / "tri2_curved.vtu", true}};
  const std::vector<Case<3>> c3{{m3, 1, tmp.path / "tet1.vtu", false},
                                {m3, 2, tmp.path / "tet2.vtu", false},
                                {m3, 2, tmp.path / "tet2_curved.vtu", true}};
  std::vector<fs::path> files;
  for (const auto& c : c2) c.write(), files.push_back(c.file);
  for (const auto& c : c3) c.write(), files.push_back(c.file);
  const VtkReadback rb = read_with_vtk(files, tmp.path);
  REQUIRE(rb.grids.size() == files.size());
  for (std::size_t i = 0; i < c2.size(); ++i) c2[i].check(rb.grids[i]);
  for (std::size_t i = 0; i < c3.size(); ++i) c3[i].check(rb.grids[c2.size() + i]);
}

TEST_CASE("write_vtu: braced field list and no fields", "[mesh][vtu]") {
  TempDir tmp;
  const auto m = rectangle_mesh(2, 2);
  std::vector<Real> p(std::size_t(m.n_nodes()), 1.0);
  write_vtu(tmp.path / "a.vtu", m, {{"p", 1, p}});
  write_vtu(tmp.path / "b.vtu", m, std::span<const VtuField>{}, 2);
  CHECK(fs::is_regular_file(tmp.path / "a.vtu"));
  CHECK(fs::is_regular_file(tmp.path / "b.vtu"));
  CHECK(listing(tmp.path) == std::vector<std::string>{"a.vtu", "b.vtu"});
  // overwriting an existing file replaces it
  const auto before = slurp(tmp.path / "a.vtu");
  write_vtu(tmp.path / "a.vtu", m, {{"p", 1, p}, {"q", 1, p}});
  CHECK(slurp(tmp.path / "a.vtu") != before);
  CHECK(slurp(tmp.path / "a.vtu").find("Name=\"q\"") != std::string::npos);
  CHECK(listing(tmp.path) == std::vector<std::string>{"a.vtu", "b.vtu"});
}

TEST_CASE("write_vtu: bad input throws InvalidArgument before anything is written", "[mesh][vtu]") {
  TempDir tmp;
  const auto m = rectangle_mesh(4, 2);  // 15 nodes, 16 cells, 30 edges: all counts differ
  const fs::path file = tmp.path / "good.vtu";
  const std::size_t nn = std::size_t(m.n_nodes()), ne = std::size_t(m.n_edges()), nc = std::size_t(m.n_cells());
  REQUIRE(nn != nc);
  std::vector<Real> p1(nn, 1.0), p2(nn + ne, 2.0), pc(nc, 3.0), v2(2 * nn, 0.5);
  const std::vector<VtuField> good{{"u", 1, p1}, {"v", 2, v2}, {"c", 1, pc, FieldLocation::cell}};
  write_vtu<2>(file, m, good);
  const std::string original = slurp(file);
  REQUIRE(!original.empty());

  auto expect_invalid = [&](const std::vector<VtuField>& fields, const std::string& param, int order = 1,
                            std::vector<Vec<2>> mids = {}) {
    INFO("expected parameter: " << param);
    try {
      write_vtu<2>(file, m, fields, order, mids);
      FAIL("no exception");
    } catch (const InvalidArgument& e) {
      INFO(e.what());
      CHECK(e.parameter() == param);
    }
    CHECK(slurp(file) == original);
    CHECK(listing(tmp.path) == std::vector<std::string>{"good.vtu"});
  };
  expect_invalid(good, "order", 0);
  expect_invalid(good, "order", 3);
  expect_invalid(good, "edge_midpoints", 2, std::vector<Vec<2>>(ne - 1, Vec<2>::Zero()));
  expect_invalid(good, "edge_midpoints", 1, std::vector<Vec<2>>(nn, Vec<2>::Zero()));
  expect_invalid({{"u", 1, p1}, {"", 1, p1}}, "fields[1]");
  expect_invalid({{"u", 1, p1}, {"u", 1, pc, FieldLocation::cell}}, "field 'u'");
  expect_invalid({{"region", 1, pc, FieldLocation::cell}}, "field 'region'");
  expect_invalid({{"u", 0, p1}}, "field 'u'");
  expect_invalid({{"u", -1, p1}}, "field 'u'");
  expect_invalid({{"u", 1, std::span<const Real>(p2).first(nn + 1)}}, "field 'u'");
  expect_invalid({{"u", 2, p1}}, "field 'u'");  // n_nodes values cannot be 2 components
  expect_invalid({{"u", 1, {}}}, "field 'u'");
  expect_invalid({{"c", 1, p1, FieldLocation::cell}}, "field 'c'");
  expect_invalid({{"c", 1, p2, FieldLocation::cell}}, "field 'c'");
  expect_invalid({{"c", 1, pc, static_cast<FieldLocation>(7)}}, "field 'c'");

  // a valid P2 field and curved midpoints pass
  std::vector<Vec<2>> mids(ne, Vec<2>(0.5, 0.5));
  write_vtu<2>(file, m, std::vector<VtuField>{{"u", 1, p2}}, 2, mids);
  write_vtu<2>(file, m, std::vector<VtuField>{{"u", 1, p2}}, 1, mids);  // midpoints ignored for order 1
  CHECK(listing(tmp.path) == std::vector<std::string>{"good.vtu"});
}

TEST_CASE("write_vtu: I/O failures throw IoError and leave no temporary", "[mesh][vtu]") {
  TempDir tmp;
  const auto m = rectangle_mesh(2, 2);
  std::vector<Real> p(std::size_t(m.n_nodes()), 1.0);
  const std::vector<VtuField> fields{{"p", 1, p}};

  SECTION("missing directory") {
    const fs::path file = tmp.path / "missing" / "a.vtu";
    try {
      write_vtu<2>(file, m, fields);
      FAIL("no exception");
    } catch (const IoError& e) {
      const std::string what = e.what();
      INFO(what);
      CHECK(what.find(file.string()) != std::string::npos);
      CHECK(what.find("No such file or directory") != std::string::npos);
    }
    CHECK(listing(tmp.path).empty());
  }
  SECTION("target is a directory") {
    fs::create_directory(tmp.path / "adir.vtu");
    CHECK_THROWS_AS(write_vtu<2>(tmp.path / "adir.vtu", m, fields), IoError);
    CHECK(listing(tmp.path) == std::vector<std::string>{"adir.vtu"});
  }
  SECTION("path names no file") {
    CHECK_THROWS_AS(write_vtu<2>(tmp.path / "", m, fields), IoError);
    CHECK(listing(tmp.path).empty());
  }
#ifdef ALEFSI_TEST_HAVE_RLIMIT
  SECTION("write error in mid-file keeps the old file") {
    // A file-size limit makes write() fail with EFBIG part-way through the data.
    const fs::path file = tmp.path / "big.vtu";
    const auto small = rectangle_mesh(1, 1);
    std::vector<Real> q(std::size_t(small.n_nodes()), 4.0);
    write_vtu<2>(file, small, std::vector<VtuField>{{"p", 1, q}});
    const std::string original = slurp(file);
    REQUIRE(original.size() < 8192);
    const auto big = rectangle_mesh(40, 40);
    std::vector<Real> pb(std::size_t(big.n_nodes()), 1.0);

    rlimit old{};
    REQUIRE(getrlimit(RLIMIT_FSIZE, &old) == 0);
    const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
    rlimit lim = old;
    lim.rlim_cur = 16384;
    REQUIRE(setrlimit(RLIMIT_FSIZE, &lim) == 0);
    bool threw = false;
    std::string what;
    try {
      write_vtu<2>(file, big, std::vector<VtuField>{{"p", 1, pb}}, 2);
    } catch (const IoError& e) {
      threw = true;
      what = e.what();
    }
    setrlimit(RLIMIT_FSIZE, &old);
    std::signal(SIGXFSZ, old_handler);
    INFO(what);
    CHECK(threw);
    CHECK(what.find("big.vtu") != std::string::npos);
    CHECK(slurp(file) == original);
    CHECK(listing(tmp.path) == std::vector<std::string>{"big.vtu"});
  }
#endif
}

TEST_CASE("PvdWriter: time series", "[mesh][vtu]") {
  TempDir tmp;
  const auto m = tagged_square();
  const fs::path pvd = tmp.path / "series" / "run.pvd";  // "series" does not exist yet
  PvdWriter series(pvd);
  CHECK(series.directory() == tmp.path / "series" / "run");
  CHECK(fs::is_directory(series.directory()));
  CHECK(series.steps() == 0);

  const std::vector<Real> times{0.0, 0.1, 0.25};
  std::vector<std::vector<Real>> values;
  for (Real t : times) {
    std::vector<Real> u;
    for (const auto& x : m.coordinates()) u.push_back(f_lin(to3<2>(x)) + t);
    values.push_back(std::move(u));
  }
  for (std::size_t s = 0; s < times.size(); ++s) {
    const fs::path vtu = series.write(times[s], m, {{"u", 1, values[s]}}, s == 1 ? 2 : 1);
    CHECK(vtu == series.directory() / ("run_00000" + std::to_string(s) + ".vtu"));
    CHECK(fs::is_regular_file(vtu));
    CHECK(series.steps() == s + 1);
    if (s == 1) fs::copy_file(pvd, tmp.path / "series" / "after2.pvd");  // the state after two steps
  }
  // rejected steps leave the series unchanged
  const std::string listed = slurp(pvd);
  CHECK_THROWS_AS(series.write(0.25, m, {{"u", 1, values[0]}}), InvalidArgument);
  CHECK_THROWS_AS(series.write(0.2, m, {{"u", 1, values[0]}}), InvalidArgument);
  CHECK_THROWS_AS(series.write(std::numeric_limits<Real>::quiet_NaN(), m, {{"u", 1, values[0]}}), InvalidArgument);
  CHECK_THROWS_AS(series.write(1.0, m, {{"u", 3, values[0]}}), InvalidArgument);
  CHECK(series.steps() == 3);
  CHECK(slurp(pvd) == listed);
  CHECK(listing(tmp.path / "series") == std::vector<std::string>{"after2.pvd", "run", "run.pvd", "run/run_000000.vtu",
                                                                   "run/run_000001.vtu", "run/run_000002.vtu"});
  CHECK_THROWS_AS(PvdWriter(""), InvalidArgument);
  std::ofstream(tmp.path / "afile") << "x";
  CHECK_THROWS_AS(PvdWriter(tmp.path / "afile" / "x.pvd"), IoError);

  const VtkReadback rb = read_with_vtk({pvd, tmp.path / "series" / "after2.pvd"}, tmp.path);
  REQUIRE(rb.pvds.size() == 2);
  REQUIRE(rb.pvds[0].steps.size() == 3);
  REQUIRE(rb.pvds[1].steps.size() == 2);
  REQUIRE(rb.grids.size() == 5);
  for (std::size_t s = 0; s < 3; ++s) {
    CHECK(rb.pvds[0].steps[s].first == times[s]);  // exact: shortest round-trip text
    CHECK(rb.pvds[0].steps[s].second == "run/run_00000" + std::to_string(s) + ".vtu");
    const VtkGrid& g = rb.grids[s];
    REQUIRE(g.n_cells == m.n_cells());
    const auto* u = g.find(g.point_data, "u");
    REQUIRE(u);
    for (std::size_t p = 0; p < std::size_t(g.n_points); ++p) {
      const Real want = f_lin(g.points[p]) + times[s];  // linear: also right at mid points (step 1)
      REQUIRE(u->values[p] == Approx(want).margin(1e-13));
    }
  }
  CHECK(rb.grids[1].types[0] == 22);
}

// ------------------------------------------------------------------ pieces (MPI output)
namespace {

/// The cells of part k when cell c goes to part c % parts (scattered parts: most points of a
/// piece lie on its border).
std::vector<Index> cells_mod(Index n_cells, int parts, int k) {
  std::vector<Index> cells;
  for (Index c = k; c < n_cells; c += parts) cells.push_back(c);
  return cells;
}

/// The joined grid of the pieces (cells part after part) shows every cell as the whole file
/// shows it: the same points, point data at each of its points, cell data and VTK's probe.
void check_joined(const VtkGrid& joined, const VtkGrid& whole, const std::vector<std::vector<Index>>& parts) {
  std::vector<Index> order;  // whole-mesh cell of each joined cell
  for (const auto& p : parts) order.insert(order.end(), p.begin(), p.end());
  REQUIRE(joined.n_cells == long(order.size()));
  REQUIRE(joined.n_cells == whole.n_cells);
  REQUIRE(joined.point_data.size() == whole.point_data.size());
  REQUIRE(joined.cell_data.size() == whole.cell_data.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t c = std::size_t(order[k]);
    INFO("joined cell " << k << " = cell " << c);
    REQUIRE(joined.types[k] == whole.types[c]);
    REQUIRE(joined.cells[k].size() == whole.cells[c].size());
    for (std::size_t v = 0; v < whole.cells[c].size(); ++v) {
      const auto pj = std::size_t(joined.cells[k][v]), pw = std::size_t(whole.cells[c][v]);
      REQUIRE(joined.points[pj] == whole.points[pw]);  // bit for bit: the same doubles
      for (std::size_t a = 0; a < whole.point_data.size(); ++a) {
        const VtkArray &aj = joined.point_data[a].second, &aw = whole.point_data[a].second;
        REQUIRE(joined.point_data[a].first == whole.point_data[a].first);
        for (int i = 0; i < aw.components; ++i)
          REQUIRE(aj.values[pj * std::size_t(aj.components) + std::size_t(i)] ==
                  aw.values[pw * std::size_t(aw.components) + std::size_t(i)]);
      }
    }
    for (std::size_t a = 0; a < whole.cell_data.size(); ++a) {
      const VtkArray &aj = joined.cell_data[a].second, &aw = whole.cell_data[a].second;
      REQUIRE(joined.cell_data[a].first == whole.cell_data[a].first);
      for (int i = 0; i < aw.components; ++i) {
        const Real vj = aj.values[k * std::size_t(aj.components) + std::size_t(i)];
        const Real vw = aw.values[c * std::size_t(aw.components) + std::size_t(i)];
        REQUIRE((vj == vw || (std::isnan(vj) && std::isnan(vw))));
      }
    }
    REQUIRE(joined.probes[k] == whole.probes[c]);
  }
}

/// Points a piece of `cells` must hold: the nodes (and for order 2 the edges) of its cells.
template <int D>
long used_points(const Mesh<D>& m, const std::vector<Index>& cells, int order) {
  std::vector<char> used(std::size_t(m.n_nodes() + m.n_edges()), 0);
  for (Index c : cells) {
    for (Index v : m.cell(c)) used[std::size_t(v)] = 1;
    if (order == 2)
      for (Index e : m.cell_edges(c)) used[std::size_t(m.n_nodes() + e)] = 1;
  }
  return long(std::count(used.begin(), used.end(), 1));
}

template <int D>
void check_pieces(const Case<D>& c, int parts, const fs::path& dir) {
  const Mesh<D>& m = *c.mesh;
  std::vector<std::vector<Index>> cells;
  std::vector<std::string> sources;
  std::vector<fs::path> files{c.file};
  for (int k = 0; k < parts; ++k) {
    cells.push_back(cells_mod(m.n_cells(), parts, k));
    sources.push_back(c.file.stem().string() + "_p" + std::to_string(k) + ".vtu");
    write_vtu_piece<D>(dir / sources.back(), m, cells.back(), c.fields(), c.order, c.curved);
    files.push_back(dir / sources.back());
  }
  const fs::path pvtu = dir / (c.file.stem().string() + ".pvtu");
  write_pvtu<D>(pvtu, m, c.fields(), sources, c.order);
  files.push_back(pvtu);
  c.write();
  const VtkReadback rb = read_with_vtk(files, dir);
  REQUIRE(rb.grids.size() == std::size_t(parts) + 2);
  const VtkGrid& whole = rb.grids.front();
  c.check(whole);  // the whole file as the round-trip test checks it
  for (int k = 0; k < parts; ++k) {
    INFO("piece " << k);
    CHECK(rb.grids[std::size_t(k) + 1].n_cells == long(cells[std::size_t(k)].size()));
    CHECK(rb.grids[std::size_t(k) + 1].n_points == used_points(m, cells[std::size_t(k)], c.order));
  }
  check_joined(rb.grids.back(), whole, cells);
}

}  // namespace

TEST_CASE("write_vtu_piece + write_pvtu: the pieces joined by VTK's parallel reader are the whole mesh", "[mesh][vtu]") {
  TempDir tmp;
  const Mesh<2> m2 = tagged_square();
  const Mesh<3> m3 = tagged_box();
  check_pieces(Case<2>{m2, 1, tmp.path / "tri1.vtu", false}, 3, tmp.path);
  check_pieces(Case<2>{m2, 2, tmp.path / "tri2_curved.vtu", true}, 2, tmp.path);
  check_pieces(Case<3>{m3, 1, tmp.path / "tet1.vtu", false}, 3, tmp.path);
  check_pieces(Case<3>{m3, 2, tmp.path / "tet2.vtu", false}, 4, tmp.path);
}

TEST_CASE("write_vtu_piece, write_pvtu: bad input throws InvalidArgument before anything is written", "[mesh][vtu]") {
  TempDir tmp;
  const Mesh<2> m = tagged_square();
  std::vector<Real> p(std::size_t(m.n_nodes()), 1.0);
  const std::vector<VtuField> f{{"p", 1, p}};
  const fs::path file = tmp.path / "x.vtu";
  const std::vector<Index> unsorted{3, 2}, repeated{1, 1}, outside{0, m.n_cells()}, negative{-1};
  for (const auto* cells : {&unsorted, &repeated, &outside, &negative})
    CHECK_THROWS_AS(write_vtu_piece<2>(file, m, *cells, f), InvalidArgument);
  CHECK_THROWS_AS(write_vtu_piece<2>(file, m, std::vector<Index>{0}, {{{"p", 2, p}}}), InvalidArgument);
  CHECK_THROWS_AS(write_pvtu<2>(tmp.path / "x.pvtu", m, f, std::vector<std::string>{}), InvalidArgument);
  CHECK_THROWS_AS(write_pvtu<2>(tmp.path / "x.pvtu", m, f, std::vector<std::string>{"a.vtu", ""}), InvalidArgument);
  CHECK(listing(tmp.path).empty());
}

TEST_CASE("PvdWriter: a series of pieces, and a failed piece on one process", "[mesh][vtu]") {
  TempDir tmp;
  const Mesh<3> m = tagged_box();
  const int parts = 3;
  const fs::path pvd = tmp.path / "run.pvd";
  // the processes of a parallel run, played one after the other (part 0 last: it writes the
  // .pvtu and the collection); `agree` plays the collective
  std::vector<std::unique_ptr<PvdWriter>> writers;
  for (int k = 0; k < parts; ++k) writers.push_back(std::make_unique<PvdWriter>(pvd));
  std::vector<std::vector<Index>> cells;
  for (int k = 0; k < parts; ++k) cells.push_back(cells_mod(m.n_cells(), parts, k));
  bool agree = true;
  auto step = [&](Real t, const std::vector<Real>& u, int k) {
    return writers[std::size_t(k)]->write(t, m, {{"u", 1, u}},
                                          VtuPiece{cells[std::size_t(k)], k, parts, [&](bool ok) { return ok && agree; }});
  };
  std::vector<std::vector<Real>> values;
  for (Real t : {0.0, 0.5}) {
    std::vector<Real> u;
    for (const auto& x : m.coordinates()) u.push_back(f_lin(to3<3>(x)) + t);
    values.push_back(std::move(u));
  }
  for (int s = 0; s < 2; ++s)
    for (int k = parts - 1; k >= 0; --k) {
      const fs::path pvtu = step(0.5 * s, values[std::size_t(s)], k);
      CHECK(pvtu == tmp.path / "run" / ("run_00000" + std::to_string(s) + ".pvtu"));
      CHECK(writers[std::size_t(k)]->steps() == std::size_t(s) + 1);
    }
  CHECK(listing(tmp.path) ==
        std::vector<std::string>{"run", "run.pvd", "run/run_000000.pvtu", "run/run_000000_p0000.vtu",
                                 "run/run_000000_p0001.vtu", "run/run_000000_p0002.vtu", "run/run_000001.pvtu",
                                 "run/run_000001_p0000.vtu", "run/run_000001_p0001.vtu", "run/run_000001_p0002.vtu"});
  const std::string listed = slurp(pvd);
  // another process fails: IoError here, and nothing listed
  agree = false;
  CHECK_THROWS_AS(step(1.0, values[0], 0), IoError);
  // this process's own piece fails (cells out of range): its own error, rethrown after the agreement
  std::vector<Index> bad{m.n_cells()};
  bool asked = false;
  CHECK_THROWS_AS(writers[1]->write(1.0, m, {{"u", 1, values[0]}}, VtuPiece{bad, 1, parts, [&](bool ok) {
                                      asked = true;
                                      return ok;
                                    }}),
                  InvalidArgument);
  CHECK(asked);  // it reached the collective call before throwing
  // part 0 alone (the others wrote elsewhere): it finds no pieces of theirs and lists nothing
  agree = true;
  CHECK_THROWS_WITH(step(1.0, values[0], 0), Catch::Contains("the piece of part 1 is not in") &&
                                                 Catch::Contains("same output folder"));
  for (const auto& w : writers) CHECK(w->steps() == 2);
  CHECK(slurp(pvd) == listed);

  const VtkReadback rb = read_with_vtk({pvd}, tmp.path);
  REQUIRE(rb.pvds.size() == 1);
  REQUIRE(rb.pvds[0].steps.size() == 2);
  CHECK(rb.pvds[0].steps[1].second == "run/run_000001.pvtu");
  REQUIRE(rb.grids.size() == 2);
  for (std::size_t s = 0; s < 2; ++s) {
    const VtkGrid& g = rb.grids[s];
    REQUIRE(g.n_cells == m.n_cells());
    const auto* u = g.find(g.point_data, "u");
    REQUIRE(u);
    for (std::size_t p = 0; p < std::size_t(g.n_points); ++p)
      REQUIRE(u->values[p] == Approx(f_lin(g.points[p]) + 0.5 * Real(s)).margin(1e-13));
  }
}
