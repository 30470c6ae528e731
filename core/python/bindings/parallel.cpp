#include "core/base/parallel.h"

#include "core/base/simd_target.h"
#include "core/python/bindings/numpy_support.h"

namespace aolab::python {

void bind_parallel(py::module_& m) {
  py::register_exception<Cancelled>(m, "Cancelled", PyExc_RuntimeError);
  py::class_<Progress>(m, "Progress", R"doc(
Progress of a running computation, to poll from another thread: `done` and `total` rows,
`cancel()` to stop it (the computation then raises aolab.Cancelled).)doc")
      .def(py::init<>())
      .def_property_readonly("done", [](const Progress& p) { return p.done.load(); })
      .def_property_readonly("total", [](const Progress& p) { return p.total.load(); })
      .def_property_readonly("cancelled", [](const Progress& p) { return p.cancel.load(); })
      .def("cancel", [](Progress& p) { p.cancel = true; });
  m.def("simd_target", &simd_target_name,
        "The instruction set the SIMD kernels run on here, as Highway names it (AVX3 = AVX-512, "
        "AVX2, SSE4, NEON, ...).");
}

}  // namespace aolab::python
