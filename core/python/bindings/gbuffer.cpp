// aolab.GBuffer: holds the numpy arrays (no copy for float32 C-contiguous input) and a core
// GBuffer view into them.
#include "core/base/gbuffer.h"

#include <pybind11/stl.h>

#include "core/python/bindings/numpy_support.h"

namespace aolab::python {

namespace {

// An optional (H, W, 3|4) array argument: None, or a view into the (converted) array, which
// `keep` holds.
ConstImageView optional_rgb(const py::object& value, const char* name, py::object& keep) {
  if (value.is_none()) return {};
  FloatArray a = real_array(value, name, "an array (H, W, 3|4) or None");
  const ConstImageView view = view_of(a, name, 3, 4);
  keep = a;
  return view;
}

PyGBuffer make_gbuffer(const py::object& depth, py::object normal, py::object color, float fx,
                       float fy, float cx, float cy, float background_depth, py::object emission) {
  PyGBuffer g;
  g.depth = real_array(depth, "depth", "an array (H, W)");
  g.view.depth = view_of(g.depth, "depth", 0);
  if (!normal.is_none()) {
    FloatArray n = real_array(normal, "normal", "an array (H, W, 3) or None");
    g.view.normal = view_of(n, "normal", 3);
    g.normal = n;
  }
  g.view.color = optional_rgb(color, "color", g.color);
  g.view.emission = optional_rgb(emission, "emission", g.emission);
  g.view.camera = {fx, fy, cx, cy};
  g.view.background_depth = background_depth;
  g.view.validate();
  return g;
}

}  // namespace

void bind_gbuffer(py::module_& m) {
  m.attr("DEFAULT_BACKGROUND_DEPTH") = kDefaultBackgroundDepth;
  py::class_<PyGBuffer>(m, "GBuffer", py::dynamic_attr(), R"doc(
A G-buffer: planar depth (H, W), optional view-space normals (H, W, 3), optional colour
(H, W, 3|4; diffuse albedo, Cycles' DiffCol), optional emission (H, W, 3|4; emitted radiance,
Cycles' Emit; keyword only), and pinhole intrinsics fx, fy, cx, cy in pixels (pixel (i, j) has its centre at
(i + 0.5, j + 0.5), row 0 at the top). float32 C-contiguous arrays are used in place; other
arrays are converted once. Depth that is not finite, <= 0 or >= background_depth is background.)doc")
      .def(py::init(&make_gbuffer), py::arg("depth"), py::arg("normal") = py::none(),
           py::arg("color") = py::none(), py::kw_only(), py::arg("fx"), py::arg("fy"),
           py::arg("cx"), py::arg("cy"), py::arg("background_depth") = kDefaultBackgroundDepth,
           py::arg("emission") = py::none())
      .def_readonly("depth", &PyGBuffer::depth)
      .def_readonly("normal", &PyGBuffer::normal)
      .def_readonly("color", &PyGBuffer::color)
      .def_readonly("emission", &PyGBuffer::emission)
      .def_property_readonly("width", [](const PyGBuffer& g) { return g.view.width(); })
      .def_property_readonly("height", [](const PyGBuffer& g) { return g.view.height(); })
      .def_property_readonly("fx", [](const PyGBuffer& g) { return g.view.camera.fx; })
      .def_property_readonly("fy", [](const PyGBuffer& g) { return g.view.camera.fy; })
      .def_property_readonly("cx", [](const PyGBuffer& g) { return g.view.camera.cx; })
      .def_property_readonly("cy", [](const PyGBuffer& g) { return g.view.camera.cy; })
      .def_property_readonly("background_depth",
                             [](const PyGBuffer& g) { return g.view.background_depth; })
      .def(
          "valid_mask",
          [](const PyGBuffer& g) {
            Image mask = validity_mask(g.view);
            py::array_t<float> f = to_numpy(std::move(mask));
            return f.attr("astype")("bool");
          },
          "Boolean (H, W): True where the pixel holds geometry.")
      .def(
          "view_positions",
          [](const PyGBuffer& g, int threads) {
            Image p;
            {
              py::gil_scoped_release release;
              p = view_positions(g.view, threads);
            }
            return to_numpy(std::move(p));
          },
          py::arg("threads") = 0, "View-space positions (H, W, 3); NaN on background.")
      .def(
          "prepared_normals",
          [](const PyGBuffer& g, int threads) {
            Image n;
            {
              py::gil_scoped_release release;
              n = prepared_normals(g.view, threads);
            }
            return to_numpy(std::move(n));
          },
          py::arg("threads") = 0,
          "The normals methods use: renormalised, facing the camera, estimated from depth "
          "where missing or degenerate; (0, 0, 0) on background.")
      .def("__repr__", [](const PyGBuffer& g) {
        return "<aolab.GBuffer " + std::to_string(g.view.width()) + "x" +
               std::to_string(g.view.height()) + (g.view.has_normal() ? " +normal" : "") +
               (g.view.has_color() ? " +color" : "") + (g.view.has_emission() ? " +emission" : "") +
               ">";
      });
}

}  // namespace aolab::python
