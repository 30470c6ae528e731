#include "core/filters/blur.h"

#include "core/python/bindings/numpy_support.h"

namespace aolab::python {

void bind_blur(py::module_& m) {
  m.def(
      "gaussian_blur",
      [](FloatArray ao, const PyGBuffer& g, float sigma, int taps, int threads) {
        const ConstImageView view = view_of(ao, "ao", 0);
        BlurSettings s;
        s.sigma = sigma;
        s.taps = taps;
        Image out;
        {
          py::gil_scoped_release release;
          out = gaussian_blur(view, g.view, s, threads);
        }
        return to_numpy(std::move(out));
      },
      py::arg("ao"), py::arg("gbuffer"), py::kw_only(), py::arg("sigma") = kBlurDefaultSigma,
      py::arg("taps") = kBlurDefaultTaps, py::arg("threads") = 0);
}

}  // namespace aolab::python
