#include "core/methods/registry.h"

#include "core/base/check.h"
#include "core/methods/chebyshev/chebyshev.h"
#include "core/methods/hbao/hbao.h"
#include "core/methods/lsao/lsao.h"
#include "core/methods/pyramid_hbao/pyramid_hbao.h"
#include "core/methods/vao/vao.h"
#include "core/methods/vao_pp/vao_pp.h"

namespace aolab {

const std::vector<Method>& methods() {
  // Built on first use (no static-initialisation order issues); every method joins here.
  static const std::vector<Method> all = {
      hbao_method(),      pyramid_hbao_method(), lsao_method(),
      chebyshev_method(), vao_method(),          vao_pp_method(),
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

Image compute(const std::string& method, const GBuffer& g, const SettingValues& settings,
              const RunOptions& options) {
  const Method& m = find_method(method);
  g.validate();
  if (m.needs_normal) require_normal(g, m.name);
  if (m.needs_color && !m.color_depends_on_settings) require_color(g, m.name);
  if (!settings.count("radius")) throw_invalid("radius", "is required", "nothing");
  return m.run(g, settings, options);
}

}  // namespace aolab
