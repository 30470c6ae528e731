// Bindings of core/scoring/metrics.h and core/scoring/ssim.h: _core.metrics and _core.ssim_map.
#include "core/scoring/metrics.h"

#include <pybind11/pybind11.h>

#include "core/python/bindings/numpy_support.h"
#include "core/scoring/ssim.h"

namespace aolab::python {

namespace {

// The mask as a float32 array. forcecast turns bool and uint8 masks into 0/1 floats; anything
// numpy cannot convert is a ValueError naming `mask`.
FloatArray mask_array(const py::object& mask) {
  FloatArray array = FloatArray::ensure(mask);
  if (!array)
    throw_invalid("mask", "must be convertible to a float32 array",
                  std::string(py::str(py::type::of(mask).attr("__name__"))));
  return array;
}

}  // namespace

void bind_metrics(py::module_& m) {
  m.def(
      "metrics",
      [](const FloatArray& ao, const FloatArray& reference, const py::object& mask, int threads) {
        const ConstImageView ao_view = view_of(ao, "ao", 0);
        const ConstImageView reference_view = view_of(reference, "reference", 0);
        FloatArray mask_values;  // keeps a converted mask alive while the core reads it
        ConstImageView mask_view;
        if (!mask.is_none()) {
          mask_values = mask_array(mask);
          mask_view = view_of(mask_values, "mask", 0);
          // Checked here too: an empty view means "all pixels" to the core, and a (0, 0) mask
          // must not silently become that.
          require_same_size("ao", ao_view, "mask", mask_view);
        }
        Metrics result;
        {
          py::gil_scoped_release release;
          result = compute_metrics(ao_view, reference_view, mask_view, threads);
        }
        py::dict d;
        d["mae"] = result.mae;
        d["rmse"] = result.rmse;
        d["psnr"] = result.psnr;
        d["bias"] = result.bias;
        d["ssim"] = result.ssim;
        d["count"] = result.count;
        return d;
      },
      py::arg("ao"), py::arg("reference"), py::arg("mask") = py::none(), py::arg("threads") = 0,
      "Accuracy of `ao` against `reference` ((H, W) arrays, AO in [0, 1]) over the pixels where\n"
      "`mask` is non-zero (all pixels when None; bool and integer masks are accepted).\n"
      "Returns a dict: mae, rmse, psnr (dB, data range 1, inf when identical), bias\n"
      "(mean ao - reference; positive = under-occlusion), ssim (mean SSIM, 11x11 Gaussian\n"
      "window, sigma 1.5, as scikit-image) and count (scored pixels). Raises ValueError naming\n"
      "the parameter for bad shapes, an empty mask or non-finite scored values. threads = 0\n"
      "uses all cores; results do not depend on it.");

  m.def(
      "ssim_map",
      [](const FloatArray& a, const FloatArray& b, int threads) {
        const ConstImageView a_view = view_of(a, "a", 0);
        const ConstImageView b_view = view_of(b, "b", 0);
        Image s;
        {
          py::gil_scoped_release release;
          s = ssim_map(a_view, b_view, SsimSettings{}, threads);
        }
        return to_numpy(std::move(s));
      },
      py::arg("a"), py::arg("b"), py::arg("threads") = 0,
      "Per-pixel SSIM of two (H, W) images (Wang et al. 2004 eq. 13; 11x11 Gaussian window,\n"
      "sigma 1.5, data range 1, scipy 'reflect' boundary) as an (H, W) float32 array; equals\n"
      "scikit-image's structural_similarity(..., gaussian_weights=True, sigma=1.5,\n"
      "use_sample_covariance=False, data_range=1, full=True)[1].");
}

}  // namespace aolab::python
