// Visibility bitmask timing at 1280x720 on the `blocks` analytic scene (not a test: run
// `aolab_bench --benchmark_filter=Bitmask` and record the medians in docs/methods/bitmask.md).
//  - BM_Bitmask/threads: default settings (2 slices, 8 steps per side, 32 sectors, R = 0.25);
//  - BM_BitmaskQuality/level: the presets low/medium/high/ultra (slices 1/2/3/4, steps
//    4/8/12/16 per side) on 2 threads;
//  - BM_BitmaskWeighting/cosine: the paper's uniform count against the exact cosine weights
//    (32 sector measures per slice), 2 threads;
//  - BM_BitmaskRadius/scale: R = 0.25 x 1, 2, 4, 8 at the defaults, 2 threads.
#include <benchmark/benchmark.h>

#include "core/methods/bitmask/bitmask.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;
using bench::kRadius;

void BM_Bitmask(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  BitmaskSettings s;
  s.radius = kRadius;
  RunOptions opt;
  opt.threads = int(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(bitmask(g, s, opt));
}
BENCHMARK(BM_Bitmask)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BitmaskQuality(benchmark::State& state) {
  constexpr int kSlices[] = {1, 2, 3, 4}, kSteps[] = {4, 8, 12, 16};
  const GBuffer g = bench::blocks_gbuffer();
  BitmaskSettings s;
  s.radius = kRadius;
  s.slices = kSlices[state.range(0)];
  s.steps = kSteps[state.range(0)];
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(bitmask(g, s, opt));
  state.counters["slices"] = s.slices;
  state.counters["steps"] = s.steps;
}
BENCHMARK(BM_BitmaskQuality)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BitmaskWeighting(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  BitmaskSettings s;
  s.radius = kRadius;
  s.weighting = int(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(bitmask(g, s, opt));
}
BENCHMARK(BM_BitmaskWeighting)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BitmaskRadius(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  BitmaskSettings s;
  s.radius = kRadius * float(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(bitmask(g, s, opt));
  state.counters["radius"] = s.radius;
}
BENCHMARK(BM_BitmaskRadius)->Apply(bench::radius_scales);

}  // namespace
