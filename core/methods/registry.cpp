#include "core/methods/registry.h"

#include <cmath>

#include "core/base/check.h"
#include "core/methods/alchemy/alchemy.h"
#include "core/methods/bitmask/bitmask.h"
#include "core/methods/chebyshev/chebyshev.h"
#include "core/methods/crytek_ssao/crytek_ssao.h"
#include "core/methods/gtao/gtao.h"
#include "core/methods/hbao/hbao.h"
#include "core/methods/lsao/lsao.h"
#include "core/methods/pyramid_hbao/pyramid_hbao.h"
#include "core/methods/sao/sao.h"
#include "core/methods/screen_space_limit/screen_space_limit.h"
#include "core/methods/vao/vao.h"
#include "core/methods/vao_pp/vao_pp.h"

namespace aolab {

const std::vector<Method>& methods() {
  // Built on first use (no static-initialisation order issues); every method joins here.
  static const std::vector<Method> all = {
      hbao_method(),
      pyramid_hbao_method(),
      lsao_method(),
      chebyshev_method(),
      vao_method(),
      vao_pp_method(),
      screen_space_limit_method(),
      gtao_method(),
      bitmask_method(),
      alchemy_method(),
      sao_method(),
      crytek_ssao_method(),
  };
  return all;
}

const Method& find_method(const std::string& name) {
  std::string names;
  for (const auto& m : methods()) {
    if (m.name == name) return m;
    names += (names.empty() ? "" : ", ") + m.name;
  }
  throw_invalid("method", "must be one of " + names, "'" + name + "'");
}

SettingDescription power_setting() {
  SettingDescription d;
  d.name = "power";
  d.type = SettingType::Float;
  d.default_value = 1.0;
  d.min = kPowerMin;
  d.max = kPowerMax;
  d.description =
      "AO^power after the method (HBAO+ power exponent, XeGTAO final value power); "
      "1 = off";
  return d;
}

float take_power(SettingValues& values) {
  const auto it = values.find("power");
  if (it == values.end()) return 1.0f;
  const double p = it->second;
  if (!std::isfinite(p) || p < kPowerMin || p > kPowerMax)
    throw_invalid("power", "must be in " + detail::format_range(kPowerMin, kPowerMax), p);
  values.erase(it);
  return float(p);
}

void apply_power(Image& ao, float power, int threads) {
  if (power == 1.0f) return;  // the default: no pow at all, so no bit changes
  // In double: the square of a float is exact there, so power 2 gives exactly the float
  // product ao·ao (powf may be an ulp off), and other powers round once, to float. Rows in
  // parallel: a pow per value is a visible part of a fast method's time at 1280×720.
  const double p = power;
  const std::size_t row = std::size_t(ao.width()) * std::size_t(ao.channels());
  float* data = ao.data();
  parallel_for_rows(ao.height(), threads, [&](int y0, int y1) {
    for (float* v = data + std::size_t(y0) * row; v != data + std::size_t(y1) * row; ++v)
      *v = float(std::pow(double(*v), p));
  });
}

Image compute(const std::string& method, const GBuffer& g, const SettingValues& settings,
              const RunOptions& options) {
  const Method& m = find_method(method);
  g.validate();
  if (m.needs_normal) require_normal(g, m.name);
  if (m.needs_color && !m.color_depends_on_settings) require_color(g, m.name);
  if (!settings.count("radius")) throw_invalid("radius", "is required", "nothing");
  SettingValues own = settings;
  const float power = take_power(own);
  Image ao = m.run(g, own, options);
  apply_power(ao, power, options.threads);
  return ao;
}

}  // namespace aolab
