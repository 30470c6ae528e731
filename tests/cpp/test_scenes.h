// Helpers shared by the C++ tests: analytic scenes as core G-buffers.
#pragma once

#include <string>

#include "core/analytic_scenes.h"
#include "core/gbuffer.h"

namespace aolab::testing {

/// Owns an analytic scene and exposes it as a G-buffer view.
struct SceneFixture {
  AnalyticGBuffer scene;
  GBuffer g;
  explicit SceneFixture(const std::string& name, int w = 160, int h = 90,
                        const SettingValues& params = {})
      : scene(analytic_scene(name, w, h, params)) {
    g.depth = scene.depth.view();
    g.normal = scene.normal.view();
    g.camera = scene.camera;
  }
};

}  // namespace aolab::testing
