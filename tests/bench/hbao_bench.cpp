// HBAO timing at 1280x720 on the `blocks` analytic scene (not a test: run `aolab_bench`,
// or `scripts/bench.sh`, and record the medians in docs/benchmarks.md).
//  - BM_HbaoTextbook: the straightforward scalar single-thread implementation (the textbook
//    version, tests/textbook);
//  - BM_Hbao/threads: the library's implementation, N_d = 8, N_s = 8;
//  - BM_HbaoRadius/scale: how time grows with R at fixed N_d, N_s (the samples spread out,
//    so cache misses grow) and BM_HbaoRadiusDensity/scale at constant sample density
//    (N_s grows with R), 2 threads.
#include <benchmark/benchmark.h>

#include "core/methods/hbao/hbao.h"
#include "core/scenes/analytic_scenes.h"
#include "tests/bench/bench_scene.h"
#include "tests/textbook/hbao_textbook.h"

namespace {

using namespace aolab;
using bench::kRadius;
const auto gbuffer = bench::blocks_gbuffer;

HbaoSettings settings(float radius_scale = 1.0f, int steps = kHbaoDefaultSteps) {
  HbaoSettings st;
  st.radius = kRadius * radius_scale;
  st.steps = steps;
  return st;
}

void BM_HbaoTextbook(benchmark::State& state) {
  const GBuffer g = gbuffer();
  for (auto _ : state) benchmark::DoNotOptimize(hbao_textbook(g, settings()));
  state.counters["threads"] = 1;
}
BENCHMARK(BM_HbaoTextbook)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Hbao(benchmark::State& state) {
  const GBuffer g = gbuffer();
  RunOptions opt;
  opt.threads = int(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(hbao(g, settings(), opt));
  state.counters["threads"] = double(opt.threads);
}
BENCHMARK(BM_Hbao)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_HbaoRadius(benchmark::State& state) {
  const GBuffer g = gbuffer();
  RunOptions opt;
  opt.threads = 2;
  const float scale = float(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(hbao(g, settings(scale), opt));
  state.counters["radius"] = kRadius * scale;
}
BENCHMARK(BM_HbaoRadius)->Apply(bench::radius_scales);

void BM_HbaoRadiusDensity(benchmark::State& state) {
  const GBuffer g = gbuffer();
  RunOptions opt;
  opt.threads = 2;
  const int scale = int(state.range(0));
  for (auto _ : state)
    benchmark::DoNotOptimize(hbao(g, settings(float(scale), kHbaoDefaultSteps * scale), opt));
  state.counters["radius"] = kRadius * float(scale);
  state.counters["steps"] = kHbaoDefaultSteps * scale;
}
BENCHMARK(BM_HbaoRadiusDensity)->Apply(bench::radius_scales);

// Constant sample density in the disc of radius R: N_s and N_d both grow with R, so the
// samples per pixel grow as R² (at x8: 64 directions x 64 steps).
void BM_HbaoRadiusArea(benchmark::State& state) {
  const GBuffer g = gbuffer();
  RunOptions opt;
  opt.threads = 2;
  const int scale = int(state.range(0));
  HbaoSettings st = settings(float(scale), kHbaoDefaultSteps * scale);
  st.directions = kHbaoDefaultDirections * scale;
  for (auto _ : state) benchmark::DoNotOptimize(hbao(g, st, opt));
  state.counters["radius"] = kRadius * float(scale);
  state.counters["samples"] = double(st.directions * st.steps);
}
BENCHMARK(BM_HbaoRadiusArea)->Apply(bench::radius_scales);

}  // namespace

BENCHMARK_MAIN();
