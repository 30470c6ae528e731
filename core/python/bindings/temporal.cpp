// Temporal accumulation (core/filters/temporal.h) and the per-frame seed
// (core/sampling/frame_seed.h): the history object, the step, its settings.
#include "core/filters/temporal.h"

#include "core/python/bindings/numpy_support.h"
#include "core/sampling/frame_seed.h"

namespace aolab::python {

namespace {

// A copy of one part of the history for Python (the history keeps its own).
py::object history_part(const Image& part) {
  if (part.width() == 0) return py::none();
  return to_numpy(Image(part));
}

}  // namespace

void bind_temporal(py::module_& m) {
  py::class_<TemporalHistory>(m, "TemporalHistory", R"doc(
What temporal accumulation keeps between frames: the last accumulated AO, each pixel's history
length (frames in its blend), its depth and normals. A new one is empty: the next frame is
frame 0. Pass the same object to every frame of a sequence; reset() starts again.)doc")
      .def(py::init<>())
      .def_property_readonly("empty", &TemporalHistory::empty)
      .def_property_readonly("width", &TemporalHistory::width)
      .def_property_readonly("height", &TemporalHistory::height)
      .def("reset", &TemporalHistory::reset, "Forgets every frame: the next one is frame 0.")
      .def_property_readonly(
          "ao", [](const TemporalHistory& h) { return history_part(h.ao); },
          "The last accumulated AO (a copy), (H, W); None when empty.")
      .def_property_readonly(
          "length", [](const TemporalHistory& h) { return history_part(h.length); },
          "Frames in each pixel's blend (a copy), (H, W); 0 on background; None when empty.");

  m.def(
      "accumulate",
      [](FloatArray ao, const PyGBuffer& g, const py::object& motion, TemporalHistory& history,
         const py::dict& settings, int threads, const std::string& kernel) {
        if (kernel != "simd" && kernel != "scalar")
          throw_invalid("kernel", "must be \"simd\" or \"scalar\"", kernel);
        const ConstImageView ao_view = view_of(ao, "ao", 0);
        const FloatArray motion_array =
            real_array(motion, "motion", "an array (H, W, 2) of pixel offsets");
        const ConstImageView motion_view = view_of(motion_array, "motion", 2);
        const TemporalSettings s =
            settings_from_values(to_setting_values(settings, temporal_setting_descriptions()),
                                 kTemporalFields, "accumulate");
        TemporalResult out;
        {
          py::gil_scoped_release release;
          out = accumulate(ao_view, g.view, motion_view, history, s, threads,
                           kernel == "simd" ? TemporalKernel::Simd : TemporalKernel::Scalar);
        }
        py::array_t<float> mask = to_numpy(std::move(out.disoccluded));
        return py::make_tuple(to_numpy(std::move(out.accumulated)), mask.attr("astype")("bool"));
      },
      py::arg("ao"), py::arg("gbuffer"), py::arg("motion"), py::arg("history"), py::arg("settings"),
      py::kw_only(), py::arg("threads") = 0, py::arg("kernel") = "simd");

  m.def("accumulate_settings",
        [] { return describe_settings_for_python(temporal_setting_descriptions()); });

  m.def(
      "frame_seed",
      [](long long seed, long long frame) {
        if (seed < 0 || seed > kMaxSeed)
          throw_invalid("seed", "must be in [0, " + std::to_string(kMaxSeed) + "]", seed);
        if (frame < 0 || frame > kMaxSeed)
          throw_invalid("frame", "must be in [0, " + std::to_string(kMaxSeed) + "]", frame);
        return frame_seed(std::uint32_t(seed), std::uint32_t(frame));
      },
      py::arg("seed"), py::arg("frame"));
}

}  // namespace aolab::python
