// GTAO timing at 1280x720 on the `blocks` analytic scene (not a test: run
// `aolab_bench --benchmark_filter=Gtao` and record the medians in docs/methods/gtao.md).
//  - BM_Gtao/threads: default settings (3 slices, 3 steps per side, R = 0.25);
//  - BM_GtaoQuality/level: XeGTAO's quality levels low/medium/high/ultra (slices 1/2/3/9,
//    steps 2/2/3/3 per side) on 2 threads;
//  - BM_GtaoRadius/scale: R = 0.25 x 1, 2, 4, 8 at the defaults, 2 threads (the samples
//    spread out, so cache misses grow).
#include <benchmark/benchmark.h>

#include "core/methods/gtao/gtao.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;
using bench::kRadius;

void BM_Gtao(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  GtaoSettings s;
  s.radius = kRadius;
  RunOptions opt;
  opt.threads = int(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(gtao(g, s, opt));
}
BENCHMARK(BM_Gtao)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_GtaoQuality(benchmark::State& state) {
  constexpr int kSlices[] = {1, 2, 3, 9}, kSteps[] = {2, 2, 3, 3};
  const GBuffer g = bench::blocks_gbuffer();
  GtaoSettings s;
  s.radius = kRadius;
  s.slices = kSlices[state.range(0)];
  s.steps = kSteps[state.range(0)];
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(gtao(g, s, opt));
  state.counters["slices"] = s.slices;
  state.counters["steps"] = s.steps;
}
BENCHMARK(BM_GtaoQuality)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_GtaoRadius(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  GtaoSettings s;
  s.radius = kRadius * float(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(gtao(g, s, opt));
  state.counters["radius"] = s.radius;
}
BENCHMARK(BM_GtaoRadius)->Apply(bench::radius_scales);

}  // namespace
