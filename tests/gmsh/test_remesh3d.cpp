// 3D meshing and remeshing by gmsh (alefsi::gmsh): the box-with-spheres mesher (spheres exact,
// faces tagged, the volume converging at order 2, the same mesh every time), the scenes it
// refuses, and Remesher3D in the time loop: a settling sphere remeshed as it falls, restarted
// bit for bit from a checkpoint taken between remeshes; a new mesh below the quality floor
// refused with the flow left as it was.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>

#include "alefsi/mesh/generate/gmsh_mesher.hpp"
#include "alefsi/sim/ale_flow.hpp"
#include "alefsi/sim/remesher3d.hpp"

using namespace alefsi;
using std::numbers::pi;

TEST_CASE("dihedral angles and quality of the corner and the regular tetrahedron", "[gmsh][quick]") {
  const auto a = dihedral_angles(Vec<3>(0, 0, 0), Vec<3>(1, 0, 0), Vec<3>(0, 1, 0), Vec<3>(0, 0, 1));
  // the three edges at the corner: right angles; the three others: acos(1 / sqrt 3)
  for (int e : {0, 1, 2}) CHECK(a[e] == Approx(pi / 2).epsilon(1e-14));
  for (int e : {3, 4, 5}) CHECK(a[e] == Approx(std::acos(1 / std::sqrt(3.0))).epsilon(1e-14));
  const Vec<3> p0(1, 1, 1), p1(1, -1, -1), p2(-1, 1, -1), p3(-1, -1, 1);  // regular
  for (Real r : dihedral_angles(p0, p1, p2, p3)) CHECK(r == Approx(std::acos(1.0 / 3)).epsilon(1e-14));
  const Mesh<3> m({p0, p1, p3, p2}, {{0, 1, 2, 3}});
  const QualityStats q = quality_stats(m);
  CHECK(q.worst == Approx(1).epsilon(1e-14));
  CHECK(q.min_dihedral_deg == Approx(std::acos(1.0 / 3) * 180 / pi).epsilon(1e-12));
  CHECK(q.max_dihedral_deg == Approx(q.min_dihedral_deg).epsilon(1e-12));
}

TEST_CASE("gmsh_box_mesh: spheres exact, faces tagged, the volume and the spheres' areas converging at order 2, "
          "the same mesh every time",
          "[gmsh][quick]") {
  const BoxDomain box{.lo = Vec<3>(0, 0, 0), .hi = Vec<3>(1, 1, 1)};
  const std::vector<Sphere> s = {{Vec<3>(0.3, 0.5, 0.5), 0.15, 7}, {Vec<3>(0.7, 0.45, 0.55), 0.12, 8}};
  const Real volume = 1 - 4.0 / 3 * pi * (std::pow(0.15, 3) + std::pow(0.12, 3));
  std::vector<Real> dv, da;
  for (Real h : {0.1, 0.05, 0.025}) {
    GmshMeshReport rep;
    const Mesh<3> m = gmsh_box_mesh(box, s, graded_size(s, h, 4 * h, 0.3), {}, &rep);
    CHECK(rep.cells == m.n_cells());
    CHECK(rep.quality.worst > 0.2);  // gmsh's optimiser; the floor is 0.02
    CHECK(rep.quality.min_dihedral_deg > 5);
    CHECK(rep.quality.max_dihedral_deg < 175);
    std::cout << "gmsh_box_mesh h = " << h << ": " << rep.cells << " cells, " << rep.nodes << " nodes, "
              << rep.seconds << " s, worst quality " << rep.quality.worst << ", dihedral angles "
              << rep.quality.min_dihedral_deg << " to " << rep.quality.max_dihedral_deg << " degrees\n";
    std::array<Real, 6> face{};
    std::array<Real, 2> area{};
    for (Index f : m.boundary_facets()) {
      const int t = m.facet_tag(f);
      if (t >= 1 && t <= 6) face[std::size_t(t - 1)] += m.facet_measure(f);
      if (t == 7 || t == 8) {
        const Sphere& sp = s[std::size_t(t - 7)];
        area[std::size_t(t - 7)] += m.facet_measure(f);
        for (Index v : m.facet(f)) CHECK(std::abs((m.node(v) - sp.centre).norm() - sp.radius) < 1e-15);
      }
      CHECK(t != 0);  // every boundary facet is a wall or a sphere
    }
    for (Real a : face) CHECK(a == Approx(1).epsilon(1e-12));  // flat faces: exact
    // the holes are inscribed polyhedra: less area, more fluid
    CHECK(m.total_measure() > volume);
    for (int k = 0; k < 2; ++k) CHECK(area[k] < 4 * pi * s[k].radius * s[k].radius);
    dv.push_back(m.total_measure() - volume);
    da.push_back(4 * pi * s[0].radius * s[0].radius - area[0]);
  }
  for (int l = 0; l < 2; ++l) {
    const Real ov = std::log2(dv[l] / dv[l + 1]), oa = std::log2(da[l] / da[l + 1]);
    INFO("volume error " << dv[l] << " -> " << dv[l + 1] << " (order " << ov << "), area error " << da[l] << " -> "
                         << da[l + 1] << " (order " << oa << ")");
    CHECK(ov > 1.7);
    CHECK(ov < 2.3);
    CHECK(oa > 1.7);
    CHECK(oa < 2.3);
  }
  // deterministic: a run that remeshes restarts bit for bit
  const Mesh<3> m1 = gmsh_box_mesh(box, s, graded_size(s, 0.05, 0.2, 0.3));
  const Mesh<3> m2 = gmsh_box_mesh(box, s, graded_size(s, 0.05, 0.2, 0.3));
  CHECK(m1.coordinates() == m2.coordinates());
  CHECK(m1.cells() == m2.cells());
}

TEST_CASE("gmsh_box_mesh refuses, by name, the scenes it cannot mesh", "[gmsh][quick]") {
  const BoxDomain box{.lo = Vec<3>(0, 0, 0), .hi = Vec<3>(1, 1, 2)};
  const SizeFunction3D h = [](const Vec<3>&) { return 0.2; };
  // each refusal names the body (InvalidArgument::parameter) and says what is wrong with it
  auto refuse = [&](std::vector<Sphere> s, const std::string& body, const std::string& what) {
    try {
      gmsh_box_mesh(box, s, h);
      FAIL("accepted: " << what);
    } catch (const InvalidArgument& e) {
      CHECK(e.parameter() == body);
      CHECK_THAT(e.what(), Catch::Contains(what));
    }
  };
  refuse({{Vec<3>(0.5, 0.5, 1), 0.2, 7}, {Vec<3>(0.9, 0.5, 1), 0.2, 8}}, "bodies[1]",
         "(tag 8, centre 0.9 0.5   1, radius 0.2) is not inside the box");
  refuse({{Vec<3>(0.5, 0.5, 1.5), 0.2, 7}, {Vec<3>(0.5, 0.5, 2.5), 0.2, 8}}, "bodies[1]", "is not inside the box");
  refuse({{Vec<3>(0.5, 0.5, 0.5), 0.2, 7}, {Vec<3>(0.5, 0.5, 0.85), 0.2, 8}}, "bodies[1]",
         "(tag 8) overlaps or touches bodies[0] (tag 7)");
  refuse({{Vec<3>(0.5, 0.5, 0.5), 0.2, 5}}, "bodies[0]", "has tag 5, a wall's tag");
  refuse({{Vec<3>(0.5, 0.5, 0.5), 0.2, 7}, {Vec<3>(0.5, 0.5, 1.5), 0.2, 7}}, "bodies[1]", "has the tag 7 of bodies[0]");
  refuse({{Vec<3>(0.5, 0.5, 0.5), -0.2, 7}}, "bodies[0]", "(tag 7) needs a finite centre and a positive radius");
  CHECK_THROWS_WITH(gmsh_box_mesh({.lo = Vec<3>(0, 0, 0), .hi = Vec<3>(1, 0, 1), .tags = box.tags}, {}, h),
                    Catch::Contains("box.hi"));
  CHECK_THROWS_WITH(gmsh_box_mesh(box, {}, SizeFunction3D{}), Catch::Contains("size"));
  Remesh3DOptions no_size;
  no_size.box = box;
  CHECK_THROWS_WITH(Remesher3D(no_size), Catch::Contains("remesh.size"));
  // a box without spheres is a mesh too
  const Mesh<3> empty = gmsh_box_mesh(box, {}, h);
  CHECK(empty.total_measure() == Approx(2).epsilon(1e-12));
  // and a scene in SI units (ten Cate's, 0.1 x 0.1 x 0.16 m): every face and the sphere found
  // (OpenCASCADE's tolerances are absolute, 1e-7)
  const BoxDomain small{.lo = Vec<3>(-0.05, -0.05, 0), .hi = Vec<3>(0.05, 0.05, 0.16)};
  const std::vector<Sphere> s = {{Vec<3>(0, 0, 0.1275), 0.0075, 7}};
  const Mesh<3> m = gmsh_box_mesh(small, s, graded_size(s, 0.004, 0.02, 0.3));
  for (int t = 1; t <= 7; ++t) CHECK(!m.boundary_nodes(t).empty());
}

namespace {
// A sphere (a = 0.25, twice the fluid's density) falling from the middle of the box
// [-1, 1]^2 x [0, 3]: Re about 3 at the end of the run.
using SettlingFlow = AleFlow<FlowConfig<3, TaylorHood, BDF2_BDF2E>>;
const BoxDomain settling_box{.lo = Vec<3>(-1, -1, 0), .hi = Vec<3>(1, 1, 3)};
const Real settling_a = 0.25;
const Vec<3> settling_start(0, 0, 2);

Remesh3DOptions settling_remeshing() {
  // tolerance 1: gmsh's new meshes are at 1.0-1.1, so the first step remeshes and then every
  // 10 % of growth in the size deviation as the sphere falls
  return {.box = settling_box,
          .size = [](const std::vector<Sphere>& s) { return graded_size(s, 0.15, 0.6, 0.3); },
          .tolerance = 1.0,
          .mesher = {}};
}

Mesh<3> settling_mesh() {
  const std::vector<Sphere> s = {{settling_start, settling_a, 7}};
  return gmsh_box_mesh(settling_box, s, settling_remeshing().size(s));
}

void configure(SettlingFlow& f, Remesher3D** remesher = nullptr) {
  for (int t : settling_box.tags) f.set_velocity(t, [](const Vec<3>&, Real) { return Vec<3>(0, 0, 0); });
  f.add_body(sphere_body(7, settling_start, settling_a, 2.0));
  f.set_gravity(Vec<3>(0, 0, -10));
  auto r = std::make_unique<Remesher3D>(settling_remeshing());
  if (remesher) *remesher = r.get();
  f.set_remesher(std::move(r));
}
}  // namespace

TEST_CASE("Remesher3D in the time loop: a settling sphere remeshed as it falls, restarted bit for bit from a "
          "checkpoint taken between remeshes",
          "[gmsh][checkpoint][quick]") {
  const int N = 26;
  const Real dt = 0.05;
  const auto dir = std::filesystem::temp_directory_path() / "alefsi_test_remesh3d";
  std::filesystem::create_directories(dir);
  const auto file = dir / "state.bin";
  SettlingFlow straight(settling_mesh(), {.rho = 1, .mu = 0.1});
  Remesher3D* remesher = nullptr;
  configure(straight, &remesher);
  int saved_at = -1, since = 0;
  for (int n = 0; n < N; ++n) {
    since = straight.step(dt).remeshed ? 0 : since + 1;
    // the checkpoint: two steps after the second remesh (before the third)
    if (saved_at < 0 && straight.stats().remeshes == 2 && since == 2) {
      straight.save_checkpoint(file);
      saved_at = n + 1;
    }
  }
  const auto& reports = remesher->reports();
  for (const auto& r : reports)
    std::cout << "remesh: " << r.mesher.seconds << " s, " << r.mesher.cells << " cells, worst quality "
              << r.before.worst << " -> " << r.mesher.quality.worst << ", dihedral angles "
              << r.mesher.quality.min_dihedral_deg << " to " << r.mesher.quality.max_dihedral_deg << "\n";
  REQUIRE(saved_at > 0);
  REQUIRE(straight.stats().remeshes >= 3);  // two before the checkpoint, at least one after
  // it fell (and sped up) and stayed a sphere: its surface nodes on the sphere at t^n
  CHECK(straight.body_velocity(0)[2] < -0.3);
  for (Index v : straight.mesh().boundary_nodes(7))
    CHECK(std::abs((straight.mesh().node(v) - straight.body_centre(0)).norm() - settling_a) < 1e-12);

  SettlingFlow restarted(read_checkpoint_mesh<3>(file), {.rho = 1, .mu = 0.1});
  configure(restarted);
  restarted.load_checkpoint(file);
  for (int n = saved_at; n < N; ++n) restarted.step(dt);
  CHECK(restarted.stats().remeshes == straight.stats().remeshes);
  CHECK(restarted.time() == straight.time());
  REQUIRE(restarted.mesh().n_nodes() == straight.mesh().n_nodes());
  CHECK(restarted.mesh().coordinates() == straight.mesh().coordinates());
  CHECK(restarted.field() == straight.field());  // bit for bit
  CHECK(restarted.body_centre(0) == straight.body_centre(0));
  CHECK(restarted.body_velocity(0) == straight.body_velocity(0));
  CHECK(restarted.body_orientation(0).coeffs() == straight.body_orientation(0).coeffs());
  std::filesystem::remove_all(dir);
}

TEST_CASE("Remesher3D: a new mesh below the quality floor is refused, naming the quality, and the flow and its "
          "checkpoint stay as they were",
          "[gmsh][quick]") {
  const auto dir = std::filesystem::temp_directory_path() / "alefsi_test_remesh3d_floor";
  std::filesystem::create_directories(dir);
  const auto file = dir / "state.bin";
  SettlingFlow flow(settling_mesh(), {.rho = 1, .mu = 0.1});
  configure(flow);
  Remesh3DOptions strict = settling_remeshing();
  strict.mesher.quality_floor = 0.9;  // no tetrahedral mesh of this scene reaches it
  strict.enabled = false;             // remeshed below by hand only
  flow.set_remesher(std::make_unique<Remesher3D>(strict));
  flow.step(0.05);
  flow.save_checkpoint(file);
  const auto before = std::filesystem::file_size(file);
  const VecX u = flow.field();
  const auto x = flow.mesh().coordinates();
  CHECK_THROWS_AS(flow.remesh(), MeshError);
  CHECK_THROWS_WITH(flow.remesh(), Catch::Contains("worst quality") && Catch::Contains("below the floor 0.9"));
  CHECK(flow.field() == u);
  CHECK(flow.mesh().coordinates() == x);
  CHECK(std::filesystem::file_size(file) == before);
  CHECK(flow.stats().remeshes == 0);
  std::filesystem::remove_all(dir);
}
