// Benchmark of the built-in 2D mesher: the 2 x 6 channel with two disks of diameter 0.25,
// uniform and graded sizes, about 1e3 ... 1e6 triangles.
//
//   cmake --preset bench && cmake --build --preset bench --target bench_mesher
//   build/bench/bench/bench_mesher
//
// Counters: triangles, triangles/s (includes the Mesh<2> construction and validation),
// min_angle (degrees, over the whole mesh).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "alefsi/mesh/generate/mesher2d.hpp"

namespace {

using namespace alefsi;

const std::vector<Circle> disks{{Vec<2>(1.0, 4.0), 0.125, 5}, {Vec<2>(1.1, 4.5), 0.125, 6}};

Domain2D channel() {
  Domain2D dom;
  dom.outer = Polyline{{Vec<2>(0, 0), Vec<2>(2, 0), Vec<2>(2, 6), Vec<2>(0, 6)}, 0,
                       {tags::bottom, tags::right, tags::top, tags::left}};
  for (const auto& d : disks) dom.holes.emplace_back(d);
  return dom;
}

void run(benchmark::State& state, const MesherOptions& opt) {
  const Domain2D dom = channel();
  Index cells = 0;
  Real angle = 0;
  for (auto _ : state) {
    Mesh<2> m = generate_mesh(dom, opt);
    cells = m.n_cells();
    state.PauseTiming();
    angle = min_angle_deg(m);
    state.ResumeTiming();
    benchmark::DoNotOptimize(m);
  }
  state.counters["triangles"] = double(cells);
  state.counters["triangles/s"] = benchmark::Counter(double(cells) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["min_angle"] = angle;
}

// uniform h; the argument is the target number of triangles (measured: 0.243 h^2 per triangle)
void BM_channel_uniform(benchmark::State& state) {
  const double h = std::sqrt(12.0 / (0.243 * double(state.range(0))));
  run(state, MesherOptions{uniform_size(h)});
}

// graded h: h_body at the disks, 10 h_body far away (grading 0.2); h_body calibrated (by
// measurement) to give about the number of triangles in the argument
void BM_channel_graded(benchmark::State& state) {
  const double h_body = state.range(0) <= 1000 ? 0.066 : state.range(0) <= 10000 ? 9.1e-3 : state.range(0) <= 100000 ? 2.4e-3 : 7.1e-4;
  run(state, MesherOptions{graded_size(disks, h_body, 10 * h_body)});
}

}  // namespace

BENCHMARK(BM_channel_uniform)->Arg(1000)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_channel_graded)->Arg(1000)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
