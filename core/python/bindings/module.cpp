// aolab._core: the compiled half of the aolab package. One binding file per core header;
// each defines a bind_* function called here.
#include <pybind11/pybind11.h>

namespace py = pybind11;

namespace aolab::python {
void bind_gbuffer(py::module_& m);
void bind_methods(py::module_& m);
void bind_blur(py::module_& m);
void bind_temporal(py::module_& m);
void bind_parallel(py::module_& m);
void bind_metrics(py::module_& m);
void bind_files(py::module_& m);
void bind_image_io(py::module_& m);
void bind_analytic_scenes(py::module_& m);
void bind_rtao(py::module_& m);
void bind_working_memory(py::module_& m);
}  // namespace aolab::python

PYBIND11_MODULE(_core, m) {
  m.doc() = "AO Lab core: screen-space ambient occlusion methods, metrics and image I/O";
  using namespace aolab::python;
  bind_gbuffer(m);
  bind_methods(m);
  bind_parallel(m);
  bind_blur(m);
  bind_temporal(m);
  bind_metrics(m);
  bind_files(m);
  bind_image_io(m);
  bind_analytic_scenes(m);
  bind_rtao(m);
  bind_working_memory(m);
}
