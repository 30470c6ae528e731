// Crytek SSAO timing at 1280x720 on the `blocks` analytic scene (not a test: run
// `aolab_bench --benchmark_filter=CrytekSsao` and record the medians in
// docs/methods/crytek_ssao.md).
//  - BM_CrytekSsao/threads: default settings (16 points, R = 0.25);
//  - BM_CrytekSsaoSamples/N: the presets low/medium/high/ultra (8/16/32/64 points), 2 threads.
#include <benchmark/benchmark.h>

#include "core/methods/crytek_ssao/crytek_ssao.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;
using bench::kRadius;

void BM_CrytekSsao(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  CrytekSsaoSettings s;
  s.radius = kRadius;
  RunOptions opt;
  opt.threads = int(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(crytek_ssao(g, s, opt));
}
BENCHMARK(BM_CrytekSsao)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CrytekSsaoSamples(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  CrytekSsaoSettings s;
  s.radius = kRadius;
  s.samples = int(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(crytek_ssao(g, s, opt));
}
BENCHMARK(BM_CrytekSsaoSamples)
    ->Arg(8)
    ->Arg(16)
    ->Arg(32)
    ->Arg(64)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
