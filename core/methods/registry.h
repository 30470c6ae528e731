// The method registry: every AO method, by name, with its settings table, behind one call.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/base/settings.h"

namespace aolab {

/// How a computation runs (not what it computes).
struct RunOptions {
  int threads = 0;               ///< worker threads, 0 = all cores
  Progress* progress = nullptr;  ///< optional progress counter and cancel flag
};

/// A registered method.
struct Method {
  std::string name;   ///< e.g. "hbao"
  std::string title;  ///< e.g. "Horizon-based AO"
  std::string paper;  ///< citation
  bool needs_normal = false;
  bool needs_color = false;  ///< may read colour (the bridge renders the colour passes)
  /// Optional, for methods whose colour need depends on settings: the reason these settings
  /// need colour (e.g. "color_bleeding"), or "" when they do not. Unset: needs_color decides.
  std::function<std::string(const SettingValues&)> color_needed_by;
  std::vector<SettingDescription> settings;  ///< including "radius"
  /// Computes AO (1 channel, in [0, 1], background = 1; a method may document an RGB
  /// result for some settings, like vao_pp's colour bleeding) from validated settings values.
  std::function<Image(const GBuffer&, const SettingValues&, const RunOptions&)> run;
};

/// All methods, in the order of DESIGN.md.
const std::vector<Method>& methods();

/// The method called `name`; throws std::invalid_argument listing the available names.
const Method& find_method(const std::string& name);

/// Validates the G-buffer for `method` (normals present if it needs them, ...) and runs it.
/// `settings` must contain "radius". Throws std::invalid_argument naming the parameter.
Image compute(const std::string& method, const GBuffer& g, const SettingValues& settings,
              const RunOptions& options = {});

}  // namespace aolab
