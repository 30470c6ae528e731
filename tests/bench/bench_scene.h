// The scene every method's benchmark times: `blocks` at 1280x720 (docs/benchmarks.md).
#pragma once

#include <benchmark/benchmark.h>

#include "core/base/gbuffer.h"
#include "core/scenes/analytic_scenes.h"

namespace aolab::bench {

constexpr int kWidth = 1280, kHeight = 720;
// R = 0.25 in the `blocks` scene (size 1) projects to ~44 px at mid-frame (5-95 %: 11-73):
// the usual SSAO setting; scales x2..x8 reach ~350 px.
constexpr float kRadius = 0.25f;

/// The `blocks` G-buffer, rendered once and shared by every benchmark.
inline GBuffer blocks_gbuffer() {
  static const AnalyticGBuffer scene = analytic_scene("blocks", kWidth, kHeight);
  GBuffer g;
  g.depth = scene.depth.view();
  g.normal = scene.normal.view();
  g.camera = scene.camera;
  return g;
}

/// The radius studies' arguments: R scaled by 1, 2, 4 and 8, timed in wall-clock ms.
inline void radius_scales(benchmark::internal::Benchmark* b) {
  for (const int scale : {1, 2, 4, 8}) b->Arg(scale);
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

}  // namespace aolab::bench
