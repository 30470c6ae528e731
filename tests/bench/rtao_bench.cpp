// rtao timing at 1280x720 on the `blocks` analytic scene (its faces as triangles), R = 0.25,
// 2 threads (not a test: run `aolab_bench --benchmark_filter=Rtao`). The committed scenes'
// times are the study's (docs/methods/rtao.md, "Cost").
//  - BM_RtaoBuild: the Embree BVH of the scene's triangles (timed apart from the rays).
//  - BM_Rtao/rays: 1, 8, 16, 64 rays per pixel; rays/s counts every pixel's rays.
#include <benchmark/benchmark.h>

#include "core/raytracing/rtao.h"
#include "tests/bench/bench_scene.h"

namespace {

using namespace aolab;

/// Half-side of the squares the analytic planes become: far beyond every visible R-ball.
constexpr double kExtent = 1000.0;

const AnalyticGBuffer& blocks() {
  static const AnalyticGBuffer scene = analytic_scene("blocks", bench::kWidth, bench::kHeight);
  return scene;
}

TriangleMesh blocks_mesh() {
  return analytic_scene_mesh(analytic_scene_geometry("blocks"), kExtent);
}

void BM_RtaoBuild(benchmark::State& state) {
  const TriangleMesh mesh = blocks_mesh();
  for (auto _ : state)
    benchmark::DoNotOptimize(RayScene(mesh, row_major(blocks().camera_to_world), 2));
  state.counters["triangles"] = double(mesh.triangle_count());
}
BENCHMARK(BM_RtaoBuild)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Rtao(benchmark::State& state) {
  const GBuffer g = bench::blocks_gbuffer();
  const RayScene scene(blocks_mesh(), row_major(blocks().camera_to_world), 2);
  RtaoSettings s;
  s.radius = bench::kRadius;
  s.rays = int(state.range(0));
  RunOptions opt;
  opt.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(rtao(g, scene, s, opt));
  state.counters["rays/s"] = benchmark::Counter(double(g.width()) * g.height() * s.rays,
                                                benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_Rtao)->Arg(1)->Arg(8)->Arg(16)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
