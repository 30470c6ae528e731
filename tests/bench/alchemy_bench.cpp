// Alchemy AO timing at 1280x720 on the `blocks` analytic scene (not a test: run
// `aolab_bench --benchmark_filter=Alchemy` and record the medians in docs/methods/alchemy.md).
//  - BM_Alchemy/threads: default settings (12 taps, R = 0.25);
//  - BM_AlchemyQuality/level: the presets low/medium/high/ultra (4/8/12/24 taps), 2 threads;
//  - BM_AlchemyRadius/scale: R = 0.25 x 1, 2, 4, 8 at the defaults, 2 threads (the taps
//    spread out over the full-resolution depth, so cache misses grow with R).
#include <benchmark/benchmark.h>

#include "core/methods/alchemy/alchemy.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;
using bench::kRadius;

void BM_Alchemy(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  AlchemySettings s;
  s.radius = kRadius;
  RunOptions opt;
  opt.threads = int(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(alchemy(g, s, opt));
}
BENCHMARK(BM_Alchemy)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_AlchemyQuality(benchmark::State& state) {
  constexpr int kSamples[] = {4, 8, 12, 24};
  const GBuffer g = bench::blocks_gbuffer();
  AlchemySettings s;
  s.radius = kRadius;
  s.samples = kSamples[state.range(0)];
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(alchemy(g, s, opt));
  state.counters["samples"] = s.samples;
}
BENCHMARK(BM_AlchemyQuality)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_AlchemyRadius(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  AlchemySettings s;
  s.radius = kRadius * float(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(alchemy(g, s, opt));
  state.counters["radius"] = s.radius;
}
BENCHMARK(BM_AlchemyRadius)->Apply(bench::radius_scales);

}  // namespace
