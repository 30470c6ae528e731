// Helpers shared by the C++ tests: analytic scenes as G-buffers, a temporary folder per
// test, and the message of an expected std::invalid_argument.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <stdexcept>
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

/// A fixture owning a fresh temporary folder, removed after the test.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ = std::filesystem::temp_directory_path() / ("aolab_test_" + std::to_string(rd()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::filesystem::path dir_;
};

/// The message of the std::invalid_argument thrown by f, or "" if none is thrown.
template <class F>
std::string invalid_argument_message(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace aolab::testing
