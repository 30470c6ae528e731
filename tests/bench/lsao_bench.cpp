// Line-sweep AO timing at 1280x720 on the `blocks` analytic scene (not a test: run
// `aolab_bench --benchmark_filter=Lsao`, or `scripts/bench.sh`, and record the medians in
// docs/benchmarks.md).
//  - BM_Lsao/threads: default settings (K = 16 aligned directions, D_S = 2.43, D_L = 1.64),
//    R = 0.25;
//  - BM_LsaoRadius/scale: R = 0.25 × 1, 2, 4, 8 on 2 threads. The sweep visits every
//    sample once whatever R (§6: "the falloff radius has no impact on the performance"),
//    so the times should stay flat; compare BM_HbaoRadiusDensity;
//  - BM_LsaoSweep, BM_LsaoGather: the two phases apart (the paper's Table 2), args: threads,
//    kernel (0 = Simd, 1 = Scalar).
#include <benchmark/benchmark.h>

#include "core/methods/lsao/lsao.h"
#include "core/methods/lsao/lsao_shared.h"
#include "core/scenes/analytic_scenes.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;
using bench::kRadius;
const auto gbuffer = bench::blocks_gbuffer;

LsaoSettings settings(float radius_scale = 1.0f) {
  LsaoSettings s;
  s.radius = kRadius * radius_scale;
  return s;
}

void BM_Lsao(benchmark::State& state) {
  const GBuffer g = gbuffer();
  RunOptions opt;
  opt.threads = int(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(lsao(g, settings(), opt));
  state.counters["threads"] = double(opt.threads);
}
BENCHMARK(BM_Lsao)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LsaoRadius(benchmark::State& state) {
  const GBuffer g = gbuffer();
  RunOptions opt;
  opt.threads = 2;
  const float scale = float(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(lsao(g, settings(scale), opt));
  state.counters["radius"] = kRadius * scale;
}
BENCHMARK(BM_LsaoRadius)->Apply(bench::radius_scales);

// Args: threads, kernel (0 = Simd, 1 = Scalar).
void BM_LsaoSweep(benchmark::State& state) {
  const GBuffer g = gbuffer();
  RunOptions opt;
  opt.threads = int(state.range(0));
  const bool simd = state.range(1) == 0;
  for (auto _ : state)
    benchmark::DoNotOptimize(simd ? lsao_sweep_simd(g, settings(), opt, false)
                                  : lsao_sweep(g, settings(), opt));
  state.counters["values"] = double(lsao_plan(g, settings()).value_count);
}
BENCHMARK(BM_LsaoSweep)
    ->Args({2, 1})
    ->Args({1, 1})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_LsaoGather(benchmark::State& state) {
  const GBuffer g = gbuffer();
  RunOptions opt;
  opt.threads = int(state.range(0));
  const bool simd = state.range(1) == 0;
  const LsaoSweep sweep =
      simd ? lsao_sweep_simd(g, settings(), opt) : lsao_sweep(g, settings(), opt);
  for (auto _ : state)
    benchmark::DoNotOptimize(simd ? lsao_gather_simd(g, settings(), sweep, opt)
                                  : lsao_gather(g, settings(), sweep, opt));
}
BENCHMARK(BM_LsaoGather)
    ->Args({2, 1})
    ->Args({1, 1})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
