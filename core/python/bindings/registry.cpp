// Method registry and compute(): settings dicts become SettingValues before the GIL is
// released for the computation.
#include "core/methods/registry.h"

#include <pybind11/stl.h>

#include "core/methods/screen_space_limit/screen_space_limit.h"
#include "core/methods/vao_pp/vao_pp.h"
#include "core/python/bindings/numpy_support.h"

namespace aolab::python {

namespace {

std::string join_names(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

const char* type_name(SettingType t) {
  switch (t) {
    case SettingType::Bool:
      return "bool";
    case SettingType::Int:
      return "int";
    case SettingType::Choice:
      return "choice";
    default:
      return "float";
  }
}

py::dict describe(const Method& m) {
  py::list settings = describe_settings_for_python(m.settings);
  py::dict out;
  out["name"] = m.name;
  out["title"] = m.title;
  out["paper"] = m.paper;
  out["needs_normal"] = m.needs_normal;
  out["needs_color"] = m.needs_color;
  out["bound"] = m.bound;
  out["simd_kernel"] = m.has_simd_kernel;
  out["settings"] = settings;
  return out;
}

}  // namespace

py::list describe_settings_for_python(const std::vector<SettingDescription>& descriptions) {
  py::list settings;
  for (const auto& s : descriptions) {
    py::dict d;
    d["name"] = s.name;
    d["type"] = type_name(s.type);
    if (s.type == SettingType::Choice) {
      // Names only: the numbers behind them are the C++ side's business.
      d["default"] = s.choices.at(std::size_t(s.default_value - s.min));
      d["choices"] = s.choices;
    } else {
      if (s.type == SettingType::Bool)
        d["default"] = s.default_value != 0.0;
      else if (s.type == SettingType::Int)
        d["default"] = int(s.default_value);
      else
        d["default"] = s.default_value;
      d["min"] = s.min;
      d["max"] = s.max;
    }
    d["unit"] = s.unit;
    d["description"] = s.description;
    settings.append(d);
  }
  return settings;
}

SettingValues to_setting_values(const py::dict& d,
                                const std::vector<SettingDescription>& descriptions) {
  SettingValues values;
  for (const auto& [key, value] : d) {
    const std::string name = py::str(key);
    const SettingDescription* described = nullptr;
    for (const auto& s : descriptions)
      if (s.name == name) described = &s;
    // A choice takes its name only, so that no script depends on the numbers behind it.
    if (described && described->type == SettingType::Choice) {
      if (!py::isinstance<py::str>(value))
        throw_invalid(name, "must be a name: one of " + join_names(described->choices),
                      py::repr(value).cast<std::string>());
      values[name] = choice_value(*described, value.cast<std::string>());
      continue;
    }
    if (py::isinstance<py::bool_>(value) || py::isinstance<py::int_>(value) ||
        py::isinstance<py::float_>(value) || py::hasattr(value, "__float__")) {
      try {
        values[name] = value.cast<double>();
        continue;
      } catch (const py::cast_error&) {
      }
    }
    throw_invalid(name, "must be a number or a bool", py::repr(value).cast<std::string>());
  }
  return values;
}

// "simd" or "scalar" (RunOptions::kernel).
Kernel kernel_from_name(const std::string& name) {
  if (name == "simd") return Kernel::Simd;
  if (name == "scalar") return Kernel::Scalar;
  throw_invalid("kernel", "must be 'simd' or 'scalar'", "'" + name + "'");
}

void bind_methods(py::module_& m) {
  m.def("methods", [] {
    std::vector<std::string> names;
    for (const auto& method : methods()) names.push_back(method.name);
    return names;
  });
  m.def(
      "method_info", [](const std::string& name) { return describe(find_method(name)); },
      py::arg("method"));
  m.def(
      "compute",
      [](const std::string& method, const PyGBuffer& g, const py::dict& settings, int threads,
         Progress* progress, const std::string& kernel) {
        const SettingValues values = to_setting_values(settings, find_method(method).settings);
        RunOptions options{threads, progress, kernel_from_name(kernel)};
        Image ao;
        {
          py::gil_scoped_release release;
          ao = compute(method, g.view, values, options);
        }
        return to_numpy(std::move(ao));
      },
      py::arg("method"), py::arg("gbuffer"), py::arg("settings"), py::kw_only(),
      py::arg("threads") = 0, py::arg("progress") = nullptr, py::arg("kernel") = "simd");

  // The screen-space limit at several thicknesses in one pass (aolab limits).
  m.def(
      "screen_space_limit_thicknesses",
      [](const PyGBuffer& g, const py::dict& settings, const std::vector<float>& thicknesses,
         int threads, Progress* progress) {
        SettingValues values =
            to_setting_values(settings, find_method("screen_space_limit").settings);
        if (!values.count("radius")) throw_invalid("radius", "is required", "nothing");
        const float power = take_power(values);
        const ScreenSpaceLimitSettings s = settings_from_values(
            values, kScreenSpaceLimitFields, "screen_space_limit", registry_setting_names());
        RunOptions options{threads, progress};
        std::vector<Image> images;
        {
          py::gil_scoped_release release;
          images = screen_space_limit_thicknesses(g.view, s, thicknesses, options);
          for (Image& ao : images) apply_power(ao, power, threads);
        }
        py::list out;
        for (Image& ao : images) out.append(to_numpy(std::move(ao)));
        return out;
      },
      py::arg("gbuffer"), py::arg("settings"), py::arg("thicknesses"), py::kw_only(),
      py::arg("threads") = 0, py::arg("progress") = nullptr);

  // VAO++ with what the run did (core/methods/vao_pp/vao_pp.h VaoPpStats): the culled share of §4.2
  // and the mean sample count of §4.1.
  m.def(
      "vao_pp_with_stats",
      [](const PyGBuffer& g, const py::dict& settings, int threads, Progress* progress) {
        SettingValues values = to_setting_values(settings, find_method("vao_pp").settings);
        if (!values.count("radius")) throw_invalid("radius", "is required", "nothing");
        const float power = take_power(values);  // as compute() does: after the method
        const VaoPpSettings s =
            settings_from_values(values, kVaoPpFields, "vao_pp", registry_setting_names());
        RunOptions options{threads, progress};
        VaoPpStats stats;
        Image ao;
        {
          py::gil_scoped_release release;
          ao = vao_pp(g.view, s, options, &stats);
          apply_power(ao, power, threads);
        }
        py::dict d;
        d["pixels"] = stats.pixels;
        d["culled"] = stats.culled;
        d["culled_share"] = stats.culled_share();
        d["samples"] = stats.samples;
        d["mean_samples"] = stats.mean_samples();
        d["prepass_pixels"] = stats.prepass_pixels;
        return py::make_tuple(to_numpy(std::move(ao)), d);
      },
      py::arg("gbuffer"), py::arg("settings"), py::kw_only(), py::arg("threads") = 0,
      py::arg("progress") = nullptr);
}

}  // namespace aolab::python
