// Benchmark of 2D mesh adaptation and field transfer (mesh/adapt.hpp): one adaptation of
// an annulus (r1 = 0.25, r2 = 1, uniform size) after one step of the stress test's motion
// (inner disk rotated by 2 pi / 80, rotation decaying with the radius), and the transfer
// of fields from the moved to the adapted mesh; about 1e3 ... 1e5 triangles.
//
//   g++ -std=c++20 -O3 -march=native -I include -I/usr/include/eigen3 bench/bench_adapt.cpp -lbenchmark -lpthread -o /tmp/bench_adapt
//   /tmp/bench_adapt
//
// Counters: triangles, triangles/s; for adapt also the operations of the sweep.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "alefsi/mesh/adapt.hpp"

namespace {

using namespace alefsi;

constexpr double r1 = 0.25, r2 = 1.0;

const std::vector<BoundaryCurve>& curves() {
  static const std::vector<BoundaryCurve> c{Circle{Vec<2>::Zero(), r2, tags::outer}, Circle{Vec<2>::Zero(), r1, tags::inner}};
  return c;
}

// h for about n triangles (measured: 0.244 h^2 per triangle of the annulus)
double size_for(double n) { return std::sqrt(std::numbers::pi * (r2 * r2 - r1 * r1) / (0.244 * n)); }

struct Scene {
  double h;
  Mesh<2> moved;
  Mesh<2> adapted;
};

Scene make_scene(double n) {
  const double h = size_for(n);
  Mesh<2> m = annulus_unstructured(r1, r2, h);
  AdaptOptions opt;
  opt.size = uniform_size(h);
  m = adapt(m, curves(), opt);  // start from an adapted mesh, as in a time loop
  std::vector<Vec<2>> x = m.coordinates();
  const double dtheta = 2 * std::numbers::pi / 80;
  for (auto& p : x) {
    const double u = std::clamp((p.norm() - r1) / (r2 - r1), 0.0, 1.0);
    const double a = dtheta * 0.5 * (1 + std::cos(std::numbers::pi * u));
    p = Vec<2>(std::cos(a) * p[0] - std::sin(a) * p[1], std::sin(a) * p[0] + std::cos(a) * p[1]);
  }
  m.set_coordinates(x);
  Mesh<2> out = adapt(m, curves(), opt);
  return {h, std::move(m), std::move(out)};
}

void BM_adapt(benchmark::State& state) {
  const Scene s = make_scene(double(state.range(0)));
  AdaptOptions opt;
  opt.size = uniform_size(s.h);
  AdaptReport rep;
  for (auto _ : state) {
    Mesh<2> out = adapt(s.moved, curves(), opt, &rep);
    benchmark::DoNotOptimize(out);
  }
  const double cells = s.moved.n_cells();
  state.counters["triangles"] = cells;
  state.counters["triangles/s"] = benchmark::Counter(cells * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["splits"] = rep.splits;
  state.counters["collapses"] = rep.collapses;
  state.counters["flips"] = rep.flips;
  state.counters["smoothed"] = rep.smoothed;
  state.counters["min_angle"] = rep.min_angle_deg;
}

// plan (point location) + application to one field with 2 components
void run_transfer(benchmark::State& state, int degree) {
  const Scene s = make_scene(double(state.range(0)));
  const Index n = s.moved.n_nodes() + (degree == 2 ? s.moved.n_edges() : 0);
  std::vector<Real> u(2 * std::size_t(n));
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = std::sin(0.001 * double(i));
  for (auto _ : state) {
    FieldTransfer2D T(s.moved, s.adapted, degree);
    auto v = T.apply(u, 2);
    benchmark::DoNotOptimize(v);
  }
  const double cells = s.adapted.n_cells();
  state.counters["triangles"] = cells;
  state.counters["triangles/s"] = benchmark::Counter(cells * double(state.iterations()), benchmark::Counter::kIsRate);
}

// application of an existing plan only (per field / history level)
void run_apply(benchmark::State& state, int degree) {
  const Scene s = make_scene(double(state.range(0)));
  const Index n = s.moved.n_nodes() + (degree == 2 ? s.moved.n_edges() : 0);
  std::vector<Real> u(2 * std::size_t(n));
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = std::sin(0.001 * double(i));
  const FieldTransfer2D T(s.moved, s.adapted, degree);
  for (auto _ : state) {
    auto v = T.apply(u, 2);
    benchmark::DoNotOptimize(v);
  }
  state.counters["triangles"] = double(s.adapted.n_cells());
}

void BM_transfer_P1(benchmark::State& state) { run_transfer(state, 1); }
void BM_transfer_P2(benchmark::State& state) { run_transfer(state, 2); }
void BM_apply_P2(benchmark::State& state) { run_apply(state, 2); }

}  // namespace

BENCHMARK(BM_adapt)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_transfer_P1)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_transfer_P2)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_apply_P2)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
