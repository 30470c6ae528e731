// Bindings of core/io/image_io.h: G-buffer EXRs with their sidecars, AO images, channel lists.
// The sidecar crosses the boundary as JSON text, turned into a dict by Python's own json
// module, so every key the Blender bridge writes reaches Python unchanged.
#include "core/io/image_io.h"

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <exception>
#include <string>
#include <utility>

#include "core/base/check.h"
#include "core/python/bindings/numpy_support.h"

namespace aolab::python {

namespace {

// json.dumps for the sidecar dict. allow_nan=False: NaN/inf are not JSON and would make a
// file no JSON reader accepts. numpy scalars and arrays (a camera matrix as ndarray) are
// written through .tolist().
std::string dumps(const py::object& sidecar) {
  if (sidecar.is_none()) return "{}";
  py::module_ json = py::module_::import("json");
  py::cpp_function as_list([](py::object o) -> py::object {
    if (py::hasattr(o, "tolist")) return o.attr("tolist")();
    throw py::type_error("sidecar value of type " +
                         py::str(py::type::of(o).attr("__name__")).cast<std::string>() +
                         " is not JSON serialisable");
  });
  try {
    return json.attr("dumps")(sidecar, py::arg("allow_nan") = false, py::arg("default") = as_list)
        .cast<std::string>();
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ValueError)) throw;
    throw_invalid("sidecar", "must hold JSON values only (no NaN or infinity)",
                  py::str(e.value()).cast<std::string>());
  }
}

// The sidecar text (validated by the core: UTF-8, no BOM, shallow) as a dict through Python's
// json module. Should the two parsers ever disagree, the error still names the file rather
// than surfacing as a bare JSONDecodeError, RecursionError or UnicodeDecodeError.
py::object sidecar_dict(const std::string& text, const std::string& path) {
  try {
    const auto decoded = py::reinterpret_steal<py::object>(
        PyUnicode_DecodeUTF8(text.data(), py::ssize_t(text.size()), "strict"));
    if (!decoded.ptr()) throw py::error_already_set();
    return py::module_::import("json").attr("loads")(decoded);
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ValueError) && !e.matches(PyExc_RecursionError)) throw;
    throw std::invalid_argument("sidecar " + path + " cannot be read as JSON by Python: " +
                                py::str(e.value()).cast<std::string>());
  }
}

// An (H, W), (H, W, 1) or (H, W, 3|4) float array as an image view.
ConstImageView image_view_of(const FloatArray& image) {
  if (image.ndim() == 2) return view_of(image, "image", 0);
  if (image.ndim() == 3 && image.shape(2) == 1) return view_of(image, "image", 1);
  return view_of(image, "image", 3, 4);
}

py::object array_or_none(Image&& image) {
  if (image.pixels().empty()) return py::none();
  return to_numpy(std::move(image));
}

}  // namespace

void bind_image_io(py::module_& m) {
  m.def(
      "load_gbuffer_arrays",
      [](const std::string& path, const std::string& view_layer) {
        GBufferData data;
        {
          py::gil_scoped_release release;
          data = load_gbuffer(path, view_layer);
        }
        py::dict out;
        out["sidecar"] = sidecar_dict(data.sidecar.json_text, sidecar_path_for(path));
        out["channels"] = py::cast(data.channels);
        out["depth"] = to_numpy(std::move(data.depth));
        out["normal"] = array_or_none(std::move(data.normal));
        out["color"] = array_or_none(std::move(data.color));
        out["emission"] = array_or_none(std::move(data.emission));
        out["ao"] = array_or_none(std::move(data.ao));
        return out;
      },
      py::arg("path"), py::arg("view_layer") = "",
      "Reads a Blender multilayer EXR G-buffer and its sidecar (<stem>.json).\n"
      "Returns a dict: depth (H, W) float32; normal (H, W, 3) view-space or None; color\n"
      "(H, W, 3) or None; emission (H, W, 3) or None (the Emit pass); ao (H, W) or None;\n"
      "sidecar (the JSON document as a dict); channels (every channel name in the file). Raises "
      "FileNotFoundError for a missing EXR or\n"
      "sidecar, ValueError for a missing Depth.Z (listing the channels), a bad sidecar or a\n"
      "size mismatch.");

  m.def(
      "save_gbuffer",
      [](const std::string& path, const PyGBuffer& gbuffer, const py::object& reference,
         const py::object& sidecar, const std::string& view_layer) {
        const std::string sidecar_json = dumps(sidecar);
        FloatArray reference_array;  // keeps a converted copy alive during the write
        ConstImageView reference_view;
        if (!reference.is_none()) {
          reference_array = reference.cast<FloatArray>();
          reference_view = view_of(reference_array, "reference", 0);
        }
        py::gil_scoped_release release;
        save_gbuffer(path, gbuffer.view, reference_view, sidecar_json, view_layer);
      },
      py::arg("path"), py::arg("gbuffer"), py::arg("reference") = py::none(),
      py::arg("sidecar") = py::none(), py::arg("view_layer") = "ViewLayer",
      "Writes a G-buffer (and an optional (H, W) AO reference) as a Blender-style multilayer\n"
      "EXR plus its sidecar <stem>.json, both atomically. `sidecar` is a dict of extra keys;\n"
      "width, height, fx, fy, cx, cy, background_depth and normal_space ('view') are set\n"
      "from the G-buffer.");

  m.def(
      "write_image",
      [](const std::string& path, const FloatArray& image) {
        const ConstImageView view = image_view_of(image);
        py::gil_scoped_release release;
        write_image(path, view);
      },
      py::arg("path"), py::arg("image"),
      "Writes an (H, W) or (H, W, 3|4) image durably and atomically: .exr as float32, .png as\n"
      "8-bit round(clamp(v, 0, 1) * 255) with no transfer curve (NaN -> 0).");

  m.def(
      "encode_image",
      [](const std::string& path, const FloatArray& image) {
        const ConstImageView view = image_view_of(image);
        std::string bytes;
        {
          py::gil_scoped_release release;
          bytes = encode_image(path, view);
        }
        return py::bytes(bytes);
      },
      py::arg("path"), py::arg("image"),
      "The bytes write_image would write to `path` (its extension picks EXR or PNG).");

  m.def(
      "exr_channels",
      [](const std::string& path) {
        py::gil_scoped_release release;
        return exr_channel_names(path);
      },
      py::arg("path"), "Names of every channel of an EXR (or other image), in file order.");
}

}  // namespace aolab::python
