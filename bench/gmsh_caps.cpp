// gmsh_caps — how often gmsh's meshes of a sphere in a box have a cap (a tetrahedron with two
// faces on the sphere, in a fold of its triangulated surface), and what removing the caps does to
// the worst cell (mesh/generate/gmsh_mesher.hpp, docs/meshing.md "Caps").
//
// The scene is ten Cate's (docs/results.md): the box 100 x 100 x 160 mm, a sphere of D = 15 mm at
// `positions` heights from its start (bottom 120 mm above the floor) down to 0.4 mm above the
// floor, slightly off the axis, meshed as the example meshes it at `level` (h_body = D / (4 + 4
// level), graded by 0.25 to min(8 h_body, 10 mm)); each position twice, with the caps removed
// (the default) and kept.
//
//   cmake --preset bench && cmake --build build/bench --target gmsh_caps
//   build/bench/bench/gmsh_caps [level] [positions]      (defaults 2 and 40)
//
// Prints per position the cells and worst quality with and without the caps and the caps
// removed, then a summary line (how many meshes fall below quality 0.15, the worst of each).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <vector>

#include "alefsi/mesh/generate/gmsh_mesher.hpp"

int main(int argc, char** argv) try {
  using namespace alefsi;
  const int level = argc > 1 ? std::atoi(argv[1]) : 2, positions = argc > 2 ? std::atoi(argv[2]) : 40;
  ALEFSI_CHECK_ARG(level >= 1 && level <= 4, "level", "must be 1..4, got ", level);
  ALEFSI_CHECK_ARG(positions >= 2, "positions", "must be at least 2, got ", positions);
  const BoxDomain box{.lo = Vec<3>(-0.05, -0.05, 0), .hi = Vec<3>(0.05, 0.05, 0.16)};
  const Real D = 0.015, a = D / 2, h = D / (4 + 4 * level), z0 = 0.12 + a, z1 = a + 0.0004;
  int low[2] = {0, 0}, with_caps = 0;
  Real worst[2] = {1, 1};
  std::cout << "level " << level << " (h_body " << h * 1e3 << " mm)\n"
            << "   z (mm)  cells  worst q (removed)  cells  worst q (kept)  caps\n" << std::fixed;
  for (int k = 0; k < positions; ++k) {
    const Real z = z0 - k * (z0 - z1) / (positions - 1);
    const std::vector<Sphere> s = {{Vec<3>(3e-4 * std::sin(k), 2e-4 * std::cos(k), z), a, 7}};
    GmshMeshReport rep[2];
    for (int keep = 0; keep < 2; ++keep) {
      GmshMeshOptions opt;
      opt.remove_caps = keep == 0;
      opt.quality_floor = 0;
      gmsh_box_mesh(box, s, graded_size(s, h, std::min(8 * h, 0.01), 0.25), opt, &rep[keep]);
      low[keep] += rep[keep].quality.worst < 0.15;
      worst[keep] = std::min(worst[keep], rep[keep].quality.worst);
    }
    with_caps += rep[0].caps_removed > 0;
    std::cout << std::setprecision(2) << std::setw(9) << z * 1e3 << std::setw(7) << rep[0].cells << std::setprecision(3)
              << std::setw(19) << rep[0].quality.worst << std::setw(7) << rep[1].cells << std::setw(16)
              << rep[1].quality.worst << std::setw(6) << rep[0].caps_removed << "\n";
  }
  std::cout << std::setprecision(3) << "summary: level " << level << ", " << positions << " meshes, " << with_caps
            << " with caps; below quality 0.15: " << low[1] << " kept, " << low[0] << " removed; worst " << worst[1]
            << " kept, " << worst[0] << " removed\n";
  return 0;
} catch (const std::exception& e) {
  std::cerr << "gmsh_caps: " << e.what() << "\n";
  return 1;
}
