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
  if (m.needs_normal && !g.has_normal())
    throw_invalid("normal",
                  "is required by " + m.name +
                      ", which reads view-space normals "
                      "(estimate them from depth with GBuffer.prepared_normals())",
                  "none");
  if (m.needs_color && !g.has_color()) {
    if (!m.color_needed_by) throw_invalid("color", "is required by " + m.name, "none");
    if (const std::string reason = m.color_needed_by(settings); !reason.empty())
      throw_invalid("color", "is required by " + m.name + " with " + reason + " on", "none");
  }
  if (!settings.count("radius")) throw_invalid("radius", "is required", "nothing");
  return m.run(g, settings, options);
}

}  // namespace aolab
