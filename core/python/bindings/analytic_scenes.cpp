#include "core/scenes/analytic_scenes.h"

#include <pybind11/stl.h>

#include "core/python/bindings/numpy_support.h"

namespace aolab::python {

void bind_analytic_scenes(py::module_& m) {
  m.def("analytic_scene_names", &analytic_scene_names);
  m.def(
      "analytic_scene",
      [](const std::string& name, int width, int height, const py::dict& params) {
        const SettingValues values = to_setting_values(params);
        AnalyticGBuffer a;
        {
          py::gil_scoped_release release;
          a = analytic_scene(name, width, height, values);
        }
        py::dict out;
        py::list c2w;
        for (int r = 0; r < 4; ++r) {
          py::list row;
          for (int c = 0; c < 4; ++c) row.append(a.camera_to_world[c][r]);  // glm: [col][row]
          c2w.append(row);
        }
        out["depth"] = to_numpy(std::move(a.depth));
        out["normal"] = to_numpy(std::move(a.normal));
        out["reference"] = to_numpy(std::move(a.reference));
        out["fx"] = a.camera.fx;
        out["fy"] = a.camera.fy;
        out["cx"] = a.camera.cx;
        out["cy"] = a.camera.cy;
        out["camera_to_world"] = c2w;
        return out;
      },
      py::arg("name"), py::arg("width"), py::arg("height"), py::arg("params"));
}

}  // namespace aolab::python
