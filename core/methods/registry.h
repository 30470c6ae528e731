// The method registry: every AO method, by name, with its settings table, behind one call.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/base/run_options.h"
#include "core/base/settings.h"

namespace aolab {

/// A registered method.
struct Method {
  std::string name;   ///< e.g. "hbao"
  std::string title;  ///< e.g. "Horizon-based AO"
  std::string paper;  ///< citation
  bool needs_normal = false;
  bool needs_color = false;  ///< may read colour (the bridge renders the colour passes)
  /// True when colour is needed only with some settings (vao_pp's colour bleeding): `run`
  /// then checks for it itself, after validating the settings, so that a bad setting is
  /// reported as such rather than as missing colour. False: needs_color decides.
  bool color_depends_on_settings = false;
  /// A bound: the reference's definition evaluated on what a screen-space method can see;
  /// correct, not fast — a bound for the study, not a contender.
  bool bound = false;
  /// True when the method has a SIMD kernel (RunOptions::kernel chooses); false: its scalar
  /// code is all it has, and Kernel::Simd runs that.
  bool has_simd_kernel = false;
  std::vector<SettingDescription> settings;  ///< including "radius"
  /// Computes AO (1 channel, in [0, 1], background = 1; a method may document an RGB
  /// result for some settings, like vao_pp's colour bleeding) from validated settings values.
  std::function<Image(const GBuffer&, const SettingValues&, const RunOptions&)> run;
};

/// `power`: the post-step every shipping SSAO has, AO^p after the method (HBAO+'s power
/// exponent, XeGTAO's FinalValuePower), shared by every method and scored as part of it.
/// [0.1, 10]: p < 1 lightens, p > 1 darkens; 10 takes AO 0.9 to 0.35, 0.1 takes 0.01 to 0.63,
/// which covers every exponent those implementations expose (1 to 4, around 2.2).
constexpr double kPowerMin = 0.1;
constexpr double kPowerMax = 10.0;

/// The description of the shared `power` setting (float, default 1 = off).
SettingDescription power_setting();

/// Settings every method has that the registry, not the method, applies: "power".
inline const std::vector<std::string>& registry_setting_names() {
  static const std::vector<std::string> names = {"power"};
  return names;
}

/// Removes "power" from `values` and returns it (1 if absent); throws std::invalid_argument
/// naming it unless it is finite and in [kPowerMin, kPowerMax].
float take_power(SettingValues& values);

/// AO^power on every value of every channel (background's 1 stays 1), computed in double and
/// rounded once (power 2 is exactly ao·ao); power 1 leaves `ao` untouched, so the default
/// changes no bit. Rows run on `threads` threads (0 = all cores); the bits do not depend on it.
void apply_power(Image& ao, float power, int threads = 0);

/// A registry entry for a method whose settings struct S is described by `fields`, plus the
/// registry's own settings (registry_setting_names: described here, applied by compute()).
/// Its run fills S from the values (unknown names and out-of-range values throw
/// std::invalid_argument naming them) and returns run(g, settings, options).
template <class S, std::size_t N, class Run>
Method registered_method(std::string name, std::string title, std::string paper,
                         const SettingField<S> (&fields)[N], Run run) {
  Method m;
  m.name = std::move(name);
  m.title = std::move(title);
  m.paper = std::move(paper);
  m.settings = describe_settings(fields);
  m.settings.push_back(power_setting());
  m.run = [&fields, run, what = m.name](const GBuffer& g, const SettingValues& values,
                                        const RunOptions& options) {
    return run(g, settings_from_values(values, fields, what, registry_setting_names()), options);
  };
  return m;
}

/// All methods, in the order of docs/conventions.md, "The order of the methods".
const std::vector<Method>& methods();

/// The method called `name`; throws std::invalid_argument listing the available names.
const Method& find_method(const std::string& name);

/// Validates the G-buffer for `method` (normals present if it needs them, ...) and runs it,
/// then applies `power` (taken out of `settings` first, so the method never sees it).
/// `settings` must contain "radius". Throws std::invalid_argument naming the parameter.
Image compute(const std::string& method, const GBuffer& g, const SettingValues& settings,
              const RunOptions& options = {});

}  // namespace aolab
