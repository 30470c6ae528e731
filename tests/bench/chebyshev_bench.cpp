// Chebyshev AO timing at 1280x720 on the `blocks` analytic scene (not a test: run
// `aolab_bench --benchmark_filter=Chebyshev` and record the medians in
// docs/methods/chebyshev.md).
//  - BM_Chebyshev/threads: default settings (depth-adaptive window, R = 0.25);
//  - BM_ChebyshevRadius/scale: R = 0.25 x 1, 2, 4, 8 on 2 threads (window half-width R fx/d,
//    capped at 64 px: the cost grows with the window, O(2k) per pixel);
//  - BM_ChebyshevFixed/k: fixed windows of half-width 2, 4, 8, 16, 32, 64 px, 2 threads;
//  - BM_ChebyshevMedium/kernel/threads: the `medium` preset (adaptive, max_kernel_radius 32),
//    kernel 0 = Simd, 1 = Scalar, on 1 and 2 threads (aolab bench-table's configuration).
#include <benchmark/benchmark.h>

#include "core/methods/chebyshev/chebyshev.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;
using bench::kRadius;

void BM_Chebyshev(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  ChebyshevSettings s;
  s.radius = kRadius;
  RunOptions opt;
  opt.threads = int(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(chebyshev(g, s, opt));
}
BENCHMARK(BM_Chebyshev)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ChebyshevRadius(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  ChebyshevSettings s;
  s.radius = kRadius * float(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(chebyshev(g, s, opt));
  state.counters["radius"] = s.radius;
}
BENCHMARK(BM_ChebyshevRadius)->Apply(bench::radius_scales);

void BM_ChebyshevFixed(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  ChebyshevSettings s;
  s.radius = kRadius;
  s.kernel_mode = int(ChebyshevKernel::Fixed);
  s.kernel_radius = int(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(chebyshev(g, s, opt));
}
BENCHMARK(BM_ChebyshevFixed)
    ->RangeMultiplier(2)
    ->Range(2, 64)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_ChebyshevMedium(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  ChebyshevSettings s;
  s.radius = kRadius;
  s.max_kernel_radius = 32;
  RunOptions opt;
  opt.kernel = Kernel(state.range(0));
  opt.threads = int(state.range(1));
  for (auto _ : state) benchmark::DoNotOptimize(chebyshev(g, s, opt));
}
BENCHMARK(BM_ChebyshevMedium)
    ->ArgsProduct({{0, 1}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
