// SAO timing at 1280x720 on the `blocks` analytic scene, 2 threads unless named (not a test:
// run `aolab_bench --benchmark_filter=Sao`, or `--benchmark_filter=CostVsRadius` for the
// comparison, and record the medians in docs/methods/sao.md).
//  - BM_Sao/threads: default settings (9 taps, pyramid to level 5, filter on, R = 0.25);
//  - BM_SaoQuality/level: the presets low/medium/high/ultra (4/9/11/20 taps);
//  - BM_SaoRadius/scale, BM_SaoRadiusFullResolution/scale: R = 0.25 x 1, 2, 4, 8 with the z
//    pyramid and without it (max_mip_level 0): the paper's claim (§2.2) is that the pyramid
//    keeps the taps' reads local, so the time stays flat as R grows;
//  - BM_SaoZPyramid: building the pyramid alone; BM_SaoFilter: the reconstruction alone.
//  - BM_CostVsRadius{Sao,Hbao,PyramidHbao}/R_in_hundredths: cost against the radius at equal
//    taps per pixel (16: SAO s = 16; HBAO 4 directions x 4 steps; Pyramid HBAO 4 directions
//    x 4 samples per level, its levels derived from R as its paper does), the raw estimate
//    without any filter, at R = 0.25, 0.5, 1, 2, 4 (the argument is R x 100; pass other
//    radii with ->Arg or --benchmark_filter on the argument).
#include <benchmark/benchmark.h>

#include "core/methods/hbao/hbao.h"
#include "core/methods/pyramid_hbao/pyramid_hbao.h"
#include "core/methods/sao/sao.h"
#include "core/methods/sao/sao_blur.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;
using bench::kRadius;

constexpr int kThreads = 2;

void BM_Sao(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  SaoSettings s;
  s.radius = kRadius;
  RunOptions opt;
  opt.threads = int(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(sao(g, s, opt));
}
BENCHMARK(BM_Sao)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SaoQuality(benchmark::State& state) {
  constexpr int kSamples[] = {4, 9, 11, 20};
  const GBuffer g = bench::blocks_gbuffer();
  SaoSettings s;
  s.radius = kRadius;
  s.samples = kSamples[state.range(0)];
  RunOptions opt;
  opt.threads = kThreads;
  for (auto _ : state) benchmark::DoNotOptimize(sao(g, s, opt));
  state.counters["samples"] = s.samples;
}
BENCHMARK(BM_SaoQuality)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

void run_radius(benchmark::State& state, int max_mip_level) {
  const GBuffer g = bench::blocks_gbuffer();
  SaoSettings s;
  s.radius = kRadius * float(state.range(0));
  s.max_mip_level = max_mip_level;
  RunOptions opt;
  opt.threads = kThreads;
  for (auto _ : state) benchmark::DoNotOptimize(sao(g, s, opt));
  state.counters["radius"] = s.radius;
}

void BM_SaoRadius(benchmark::State& state) { run_radius(state, kSaoDefaultMaxMipLevel); }
BENCHMARK(BM_SaoRadius)->Apply(bench::radius_scales);

void BM_SaoRadiusFullResolution(benchmark::State& state) { run_radius(state, 0); }
BENCHMARK(BM_SaoRadiusFullResolution)->Apply(bench::radius_scales);

void BM_SaoZPyramid(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  const Buffer<float> depth = depth_with_background_as_nan(g, kThreads);
  for (auto _ : state)
    benchmark::DoNotOptimize(sao_z_pyramid(depth, g.width(), g.height(), kSaoDefaultMaxMipLevel,
                                           SaoGrid::Paper, kThreads));
}
BENCHMARK(BM_SaoZPyramid)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_SaoFilter(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  const Buffer<float> depth = depth_with_background_as_nan(g, kThreads);
  SaoSettings s;
  s.radius = kRadius;
  s.filter = false;
  RunOptions opt;
  opt.threads = kThreads;
  const Image raw = sao(g, s, opt);
  SaoBlurParams p;
  p.edge_depth = kSaoFilterEdgeDepth * kRadius;
  for (auto _ : state) {
    Image ao = raw;
    sao_bilateral_filter(ao, depth, p, kThreads, nullptr);
    benchmark::DoNotOptimize(ao);
  }
}
BENCHMARK(BM_SaoFilter)->Unit(benchmark::kMillisecond)->UseRealTime();

// The cost-against-radius comparison at equal taps per pixel (16), raw estimates.
constexpr int kTaps = 16, kSide = 4;

void cost_vs_radius(benchmark::State& state, int method) {
  const GBuffer g = bench::blocks_gbuffer();
  const float radius = float(state.range(0)) / 100.0f;
  RunOptions opt;
  opt.threads = kThreads;
  if (method == 0) {
    SaoSettings s;
    s.radius = radius;
    s.samples = kTaps;
    s.filter = false;
    for (auto _ : state) benchmark::DoNotOptimize(sao(g, s, opt));
  } else if (method == 1) {
    HbaoSettings s;
    s.radius = radius;
    s.directions = kSide;
    s.steps = kSide;
    for (auto _ : state) benchmark::DoNotOptimize(hbao(g, s, opt));
  } else {
    PyramidHbaoSettings s;
    s.radius = radius;
    s.directions = kSide;
    s.samples = kSide;
    s.gaussian_filter = false;
    for (auto _ : state) benchmark::DoNotOptimize(pyramid_hbao(g, s, opt));
  }
  state.counters["radius"] = radius;
}

void cost_radii(benchmark::internal::Benchmark* b) {
  for (const int hundredths : {25, 50, 100, 200, 400}) b->Arg(hundredths);
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

void BM_CostVsRadiusSao(benchmark::State& state) { cost_vs_radius(state, 0); }
BENCHMARK(BM_CostVsRadiusSao)->Apply(cost_radii);
void BM_CostVsRadiusHbao(benchmark::State& state) { cost_vs_radius(state, 1); }
BENCHMARK(BM_CostVsRadiusHbao)->Apply(cost_radii);
void BM_CostVsRadiusPyramidHbao(benchmark::State& state) { cost_vs_radius(state, 2); }
BENCHMARK(BM_CostVsRadiusPyramidHbao)->Apply(cost_radii);

}  // namespace
