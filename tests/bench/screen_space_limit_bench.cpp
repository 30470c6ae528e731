// Screen-space limit timing at 1280x720 on the `blocks` analytic scene, R = 0.25, 2 threads
// (not a test: run `aolab_bench --benchmark_filter=ScreenSpaceLimit` and record the medians
// in docs/methods/screen_space_limit.md). The cost is linear in the ray count, so a few low
// counts measure it; the default 256 rays takes minutes: a bound, correct but not fast.
//  - BM_ScreenSpaceLimit/rays: 4, 16, 64 rays, unbounded thickness.
#include <benchmark/benchmark.h>

#include "core/methods/screen_space_limit/screen_space_limit.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;

void BM_ScreenSpaceLimit(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  ScreenSpaceLimitSettings s;
  s.radius = bench::kRadius;
  s.rays = int(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(screen_space_limit(g, s, opt));
  state.counters["rays"] = s.rays;
}
BENCHMARK(BM_ScreenSpaceLimit)
    ->Arg(4)
    ->Arg(16)
    ->Arg(64)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
