// Shared pieces of the bindings: numpy <-> ImageView without copies, the Python G-buffer.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"

namespace aolab::python {

namespace py = pybind11;

/// float32, C-contiguous; other dtypes and layouts are converted (copied) once at the boundary,
/// float32 C-contiguous arrays pass through untouched.
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// `value` as a FloatArray, provided it is an array (or nested sequence) of real numbers:
/// integer or floating-point dtype. None, bool, complex, datetime/timedelta, bytes/str, object
/// and structured dtypes are refused with std::invalid_argument naming `name` and the dtype
/// (numpy would otherwise cast some of them silently, a structured array to zeros).
/// float32 C-contiguous arrays pass through untouched.
FloatArray real_array(const py::object& value, const std::string& name,
                      const std::string& expected);

/// An array's shape as Python prints it: "(3, 4)", "(5,)".
std::string shape_string(const py::array& a);

/// Settings described for Python (method_info()["settings"], rtao_info()["settings"]): a dict
/// per setting with name, type, default, min, max (choices for a choice), unit, description.
py::list describe_settings_for_python(const std::vector<SettingDescription>& settings);

/// Checks ndim/shape and returns a view. `channels` = 0 means a 2-D (H, W) array; otherwise
/// (H, W, channels) — or any of `channels` and `alt_channels` when alt_channels > 0.
ConstImageView view_of(const FloatArray& a, const std::string& name, int channels,
                       int alt_channels = 0);

/// Moves an Image into a numpy array (no copy): (H, W) for 1 channel, else (H, W, C).
/// Settings from a Python dict: numbers and bools as they are, and a Choice setting among
/// `descriptions` from its name (std::invalid_argument, i.e. ValueError, for anything else).
SettingValues to_setting_values(const py::dict& d,
                                const std::vector<SettingDescription>& descriptions = {});

py::array_t<float> to_numpy(Image&& image);

/// The G-buffer as Python sees it: keeps its arrays alive and hands out a core view.
struct PyGBuffer {
  FloatArray depth;
  py::object normal = py::none();    // FloatArray or None
  py::object color = py::none();     // FloatArray or None
  py::object emission = py::none();  // FloatArray or None
  GBuffer view;                      // points into the arrays above
};

}  // namespace aolab::python
