// Pyramid HBAO timing at 1280x720 on the `blocks` analytic scene, 2 threads (not a test: run
// `aolab_bench --benchmark_filter=PyramidHbao`, or `scripts/bench.sh`).
//  - BM_PyramidHbaoRadius/scale: R = 0.25 × 1, 2, 4, 8 at the default D = 8, S = 4, K = 3,
//    L derived from R — the paper's claim (§4): only the number of levels grows with R, so
//    time grows with log R. Compare BM_HbaoRadiusDensity (tests/bench/hbao_bench.cpp), HBAO
//    at constant sample density, whose time grows linearly with R at fixed N_d.
//  - BM_PyramidHbaoRaw/scale: the same without the final Gaussian, as the paper times it.
//  - BM_DepthPyramid: building the pyramid alone (K = 3, all levels).
#include <benchmark/benchmark.h>

#include "core/methods/pyramid_hbao/depth_pyramid.h"
#include "core/methods/pyramid_hbao/pyramid_hbao.h"
#include "core/scenes/analytic_scenes.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;
using bench::kRadius;
const auto gbuffer = bench::blocks_gbuffer;

constexpr int kThreads = 2;

void run_radius(benchmark::State& state, bool filter) {
  const GBuffer g = gbuffer();
  RunOptions opt;
  opt.threads = kThreads;
  PyramidHbaoSettings s;
  s.radius = kRadius * float(state.range(0));
  s.gaussian_filter = filter;
  for (auto _ : state) benchmark::DoNotOptimize(pyramid_hbao(g, s, opt));
  state.counters["radius"] = s.radius;
  state.counters["threads"] = kThreads;
}

void BM_PyramidHbaoRadius(benchmark::State& state) { run_radius(state, true); }
BENCHMARK(BM_PyramidHbaoRadius)->Apply(bench::radius_scales);

void BM_PyramidHbaoRaw(benchmark::State& state) { run_radius(state, false); }
BENCHMARK(BM_PyramidHbaoRaw)->Apply(bench::radius_scales);

void BM_DepthPyramid(benchmark::State& state) {
  const GBuffer g = gbuffer();
  for (auto _ : state)
    benchmark::DoNotOptimize(DepthPyramid(g, kDepthPyramidDefaultReduction, 0, kThreads));
  state.counters["threads"] = kThreads;
}
BENCHMARK(BM_DepthPyramid)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
