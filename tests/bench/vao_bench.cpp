// VAO++ Table 1 on our CPU (not a test: run `aolab_bench --benchmark_filter=Vao`; the numbers
// in docs/methods/vao_pp.md were measured this way on a quiet machine).
//  - BM_VaoPpTable1/<res>/<samples>/<variant>: the `blocks` analytic scene rendered at
//    1920x1080 (res 0) or 3840x2160 (res 1), R = 0.25 (bench_scene.h), 2 threads, for
//    2/4/8/16/32 samples and the four columns of Table 1: variant 0 = VAO (adaptive sampling
//    and culling off), 1 = adaptive sampling, 2 = culling pre-pass (careful), 3 = both
//    (VAO++). The other extensions keep their defaults (Poisson sets, range check) except
//    the low-pass filter, which is off in every column so that only the occlusion pass is
//    timed. Counters: culled share and mean samples per pixel.
//  - BM_Vao/<samples>: the plain `vao` method (spiral set, random rotation) at 1920x1080.
#include <benchmark/benchmark.h>

#include "core/methods/vao/vao.h"
#include "core/methods/vao_pp/vao_pp.h"
#include "core/scenes/analytic_scenes.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;

GBuffer blocks_at(int res) {
  static const AnalyticGBuffer hd = analytic_scene("blocks", 1920, 1080);
  static const AnalyticGBuffer uhd = analytic_scene("blocks", 3840, 2160);
  const AnalyticGBuffer& scene = res == 0 ? hd : uhd;
  GBuffer g;
  g.depth = scene.depth.view();
  g.normal = scene.normal.view();
  g.camera = scene.camera;
  return g;
}

void BM_VaoPpTable1(benchmark::State& state) {
  const GBuffer g = blocks_at(int(state.range(0)));
  VaoPpSettings s;
  s.radius = bench::kRadius;
  s.samples = int(state.range(1));
  const int variant = int(state.range(2));
  s.adaptive_sampling = variant == 1 || variant == 3;
  s.culling = variant >= 2 ? int(VaoPpCulling::Careful) : int(VaoPpCulling::Off);
  s.filter = false;
  RunOptions opt;
  opt.threads = 2;
  VaoPpStats stats;
  for (auto _ : state) benchmark::DoNotOptimize(vao_pp(g, s, opt, &stats));
  state.counters["culled_share"] = stats.culled_share();
  state.counters["mean_samples"] = stats.mean_samples();
}
BENCHMARK(BM_VaoPpTable1)
    ->ArgsProduct({{0, 1}, {2, 4, 8, 16, 32}, {0, 1, 2, 3}})
    ->ArgNames({"res", "samples", "variant"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Vao(benchmark::State& state) {
  const GBuffer g = blocks_at(0);
  VaoSettings s;
  s.radius = bench::kRadius;
  s.samples = int(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(vao(g, s, opt));
}
BENCHMARK(BM_Vao)->Arg(2)->Arg(8)->Arg(32)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
